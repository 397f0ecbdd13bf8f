"""Contact sheets of expressions on a few presets, for looking at AUs against the FACS manual.

Each cell is a front view (the same renderer and camera as ``facsim render``),
cropped to the face so that lids, furrows and lips are large enough to judge,
with the neutral face in the first column for comparison.

Usage::

    python3 scripts/au_sheet.py -o out/sheet.png --engine muscle --characters ava,noah 4E 6E 9E
    python3 scripts/au_sheet.py -o out/sheet.png --emotions        # the emotion presets instead

Rows are characters, columns are the expressions.
"""
from __future__ import annotations

import argparse
import sys

import numpy as np
from PIL import Image, ImageDraw

import facsim

#: Part of the front view that holds the face (fractions of width and height: left, top, right, bottom).
FACE_BOX = (0.2, 0.12, 0.8, 0.78)


def cell(face, expression, size: int) -> np.ndarray:
    image = face.render(expression, size=size, background=(1.0, 1.0, 1.0))[..., :3]
    h, w = image.shape[:2]
    l, t, r, b = FACE_BOX
    return image[int(t * h):int(b * h), int(l * w):int(r * w)]


def sheet(characters, engine: str, expressions, labels, size: int) -> Image.Image:
    rows = []
    for name in characters:
        face = facsim.Face(name, engine=engine)
        rows.append([cell(face, None, size)] + [cell(face, e, size) for e in expressions])
        face.close()
    ch, cw = rows[0][0].shape[:2]
    label_h = 16
    out = Image.new("RGB", (cw * len(rows[0]), (ch + label_h) * len(rows)), "white")
    draw = ImageDraw.Draw(out)
    for r, row in enumerate(rows):
        for c, img in enumerate(row):
            x, y = c * cw, r * (ch + label_h)
            out.paste(Image.fromarray(img), (x, y + label_h))
            draw.text((x + 3, y + 2), f"{characters[r]} {(['neutral'] + labels)[c]}", fill="black")
    return out


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("expressions", nargs="*")
    parser.add_argument("-o", "--output", required=True)
    parser.add_argument("--engine", default="registers", choices=("registers", "muscle"))
    parser.add_argument("--characters", default="ava,noah")
    parser.add_argument("--size", type=int, default=384, help="render size before cropping to the face")
    parser.add_argument("--emotions", action="store_true", help="the emotion presets (HapFACS table)")
    args = parser.parse_args(argv)
    exprs, labels = list(args.expressions), list(args.expressions)
    if args.emotions:
        from facsim.facs.emotions import emotion_names

        names = [n for n in emotion_names() if n != "neutral"]
        exprs += [facsim.emotion(n) for n in names]
        labels += names
    if not exprs:
        parser.error("give expressions or --emotions")
    img = sheet(args.characters.split(","), args.engine, exprs, labels, args.size)
    from facsim.atomic import atomic_write

    atomic_write(args.output, lambda tmp: img.save(tmp, format="PNG"))
    print(f"wrote {args.output}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
