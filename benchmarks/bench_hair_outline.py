"""How soft a hairstyle's outline is: the share of the hair's silhouette with partial coverage.

Renders a character's neutral face on a transparent background without multisampling (so a
hard cut edge gives only fully covered pixels, and partial alpha comes only from what is
drawn translucent: the cards' blended fringe, loose strands), once with its hair and once
without. The hair's outline is the set of pixels covered by the hair only (not by the bare
head) that touch the background (an 8-neighbour with alpha below 0.02); the figure is the
share of them with partial coverage (alpha below 0.9). Cut-out cards give a share near 0;
hair whose outline breaks into strands, nearer 1.

    PYTHONPATH=. python3 benchmarks/bench_hair_outline.py [--character ava] [--size 512] [--save out.png]
"""
from __future__ import annotations

import argparse
import sys

import numpy as np


def outline_share(with_hair: np.ndarray, without_hair: np.ndarray, *, partial: float = 0.9) -> tuple[float, int]:
    """(share of the hair's outline pixels with alpha below ``partial``, outline pixel count)
    from two (H, W, 4) uint8 RGBA renders of the same view with and without hair."""
    a = with_hair[..., 3].astype(np.float32) / 255.0
    bare = without_hair[..., 3].astype(np.float32) / 255.0
    background = np.pad(a < 0.02, 1, constant_values=True)
    h, w = a.shape
    touches = np.zeros_like(a, bool)
    for dy in (-1, 0, 1):
        for dx in (-1, 0, 1):
            if dy or dx:
                touches |= background[1 + dy : 1 + dy + h, 1 + dx : 1 + dx + w]
    outline = (a >= 0.02) & (bare < 0.02) & touches
    count = int(outline.sum())
    return (float((a[outline] < partial).mean()) if count else 0.0), count


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--character", default="ava")
    parser.add_argument("--size", type=int, default=512)
    parser.add_argument("--save", help="write the render with hair here (PNG)")
    args = parser.parse_args(argv)

    from facsim.face import Face
    from facsim.head.character import resolve_character

    character = resolve_character(args.character)
    images = [Face(c).render(None, size=args.size, background=None, antialias=1)
              for c in (character, character.with_(hair="none"))]
    share, count = outline_share(*images)
    if args.save:
        from PIL import Image

        Image.fromarray(images[0]).save(args.save)
    print(f"{args.character}: {share:.2f} of the hair's {count} outline pixels have partial coverage "
          f"({args.size}², no MSAA, transparent background)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
