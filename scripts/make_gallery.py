"""Write the README's gallery: small JPEG contact sheets in docs/.

    python3 scripts/make_gallery.py [--out docs] [--tile 160] [--engine registers]

Sheets (front view, white background, 4x MSAA):

- ``gallery-presets.jpg``: the 18 character presets at neutral with their hair;
- ``gallery-emotions.jpg``: the 10 emotions of the default preset table (neutral included) on 4 presets;
- ``gallery-aus.jpg``: every single AU the engine renders, at intensity E, on 2 presets.

Deterministic: the same code and data give the same images.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

EMOTION_PRESETS = ("ava", "kwame", "mei", "george")
AU_PRESETS = ("emma", "tunde")
#: Single AUs shown (face AUs; head and eye movements are in the emotion sheet).
FACE_AUS = (1, 2, 4, 5, 6, 7, 9, 10, 11, 12, 13, 14, 15, 16, 17, 18, 19, 20, 22, 23, 24, 25, 26, 27, 28,
            33, 34, 35, 38, 39, 41, 42, 43, 44, 46, 61, 62, 63, 64)


def tile(face, expression, size: int) -> np.ndarray:
    return face.render(expression, size=size, antialias=4, background=(1.0, 1.0, 1.0))[..., :3]


def sheet(tiles: list[np.ndarray], labels: list[str], columns: int, *, label_height: int = 16):
    from PIL import Image, ImageDraw

    h, w = tiles[0].shape[:2]
    rows = (len(tiles) + columns - 1) // columns
    out = Image.new("RGB", (columns * w, rows * (h + label_height)), "white")
    draw = ImageDraw.Draw(out)
    for i, (image, label) in enumerate(zip(tiles, labels)):
        x, y = (i % columns) * w, (i // columns) * (h + label_height)
        out.paste(Image.fromarray(image), (x, y))
        draw.text((x + 4, y + h + 2), label, fill=(40, 40, 40))
    return out


def save(image, path: Path) -> None:
    from facsim.atomic import atomic_write

    atomic_write(path, lambda tmp: image.save(tmp, format="JPEG", quality=82, optimize=True))
    print(f"wrote {path} ({path.stat().st_size / 1e3:.0f} kB)")


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--out", type=Path, default=Path(__file__).resolve().parents[1] / "docs")
    parser.add_argument("--tile", type=int, default=160, help="tile size in pixels")
    parser.add_argument("--engine", default="registers", choices=("registers", "muscle"))
    parser.add_argument("--only", choices=("presets", "emotions", "aus"), help="write one sheet")
    args = parser.parse_args(argv)

    import facsim
    from facsim.head.character import preset_names
    from facsim.facs.emotions import emotion_names

    args.out.mkdir(parents=True, exist_ok=True)
    suffix = "" if args.engine == "registers" else f"-{args.engine}"
    faces = {}

    def face(name):
        if name not in faces:
            faces[name] = facsim.Face(name, engine=args.engine)
        return faces[name]

    size = args.tile
    if args.only in (None, "presets"):
        names = preset_names()
        tiles = [tile(face(n), None, size) for n in names]
        save(sheet(tiles, names, 6), args.out / f"gallery-presets{suffix}.jpg")
    if args.only in (None, "emotions"):
        emotions = emotion_names()
        tiles, labels = [], []
        for person in EMOTION_PRESETS:
            for e in emotions:
                tiles.append(tile(face(person), facsim.emotion(e), size))
                labels.append(f"{e} ({person})")
        save(sheet(tiles, labels, len(emotions)), args.out / f"gallery-emotions{suffix}.jpg")
    if args.only in (None, "aus"):
        tiles, labels = [], []
        for au in FACE_AUS:
            for person in AU_PRESETS:
                tiles.append(tile(face(person), f"{au}E", size))
                labels.append(f"AU {au}E ({person})")
        save(sheet(tiles, labels, 12), args.out / f"gallery-aus{suffix}.jpg")
    return 0


if __name__ == "__main__":
    sys.exit(main())
