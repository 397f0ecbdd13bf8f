"""How dark the skin's creases draw: mean darkening in small patches, and how much of it is a thin stroke.

Each expression is rendered twice on the same deformed geometry: as ``facsim render`` draws it,
and with every crease taken out (no wrinkle field, no age lines, no fold map). Their difference
is what the creases do, in 8-bit luma levels; per patch it prints

- ``dark``: the mean darkening over the patch (a broad soft fold shows here too), and
- ``stroke``: the mean of the darkening's narrow part (what is left after subtracting the same
  difference blurred by ~2 mm): thin dark lines score high, soft shading low.

Patches (about 8 x 5 mm, following the skin): under each eye, crow's feet beside each outer eye
corner, the nasolabial folds, the forehead, between the brows (glabella: 4's furrows), across the
nose's root and along its sides (9's wrinkles). Left/right figures are the character's left/right
(on the midline the same patch twice).

    python3 scripts/measure_creases.py --characters george,kofi "6E+12E" "1E+2E"

Works on older checkouts too (it only uses the Face and Renderer APIs), so the same command
measures a baseline: ``PYTHONPATH=/path/to/old/checkout python3 scripts/measure_creases.py``.
"""
from __future__ import annotations

import argparse
import dataclasses

import numpy as np

#: Patch centres on the base mesh (decimetres, character's left; mirrored for the right).
PATCHES = {
    "under_eye": (0.30, 7.13, 1.42),
    "crows_feet": (0.58, 7.27, 1.21),
    "nasolabial": (0.215, 6.76, 1.46),
    "forehead": (0.15, 7.64, 1.5),
    "glabella": (0.0, 7.38, 1.51),
    "nose_root": (0.0, 7.17, 1.57),
    "nose_side": (0.07, 7.04, 1.6),
}
#: Patch half-size (decimetres): across the face, up.
HALF = (0.04, 0.025)
LUMA = np.array([0.2126, 0.7152, 0.0722])


def creaseless(appearance):
    """The appearance with its age lines (and fold map, where there is one) taken out."""
    detail = appearance.detail.copy()
    detail[..., 3] = 0
    changes = {"detail": detail}
    if any(f.name == "folds" for f in dataclasses.fields(appearance)):
        changes["folds"] = None
    return dataclasses.replace(appearance, **changes)


def render(face, deformation, appearance, size, creased):
    """Luma of ``deformation`` drawn as ``facsim render`` draws it (body included), with ``appearance``
    and with or without the wrinkle field."""
    from facsim.engines.base import Deformation

    if not creased:
        deformation = Deformation(np.asarray(deformation.positions, np.float32))
    own = face.__dict__.get("appearance")
    face.__dict__["appearance"] = appearance
    try:
        image = face.render(deformation=deformation, size=size)
    finally:
        if own is None:
            del face.__dict__["appearance"]
        else:
            face.__dict__["appearance"] = own
    return image[..., :3].astype(float) @ LUMA, face.camera(size=(size, size))


def patch_box(face, deformation, camera, size, centre):
    """Pixel box (x0, x1, y0, y1) around the deformed skin under a base-mesh point."""
    from facsim.render.camera import project

    head = face.head
    skin = head.base_vertices[head.base_index[: head.skin_vertex_count]]
    corners = np.array([[dx, dy, 0.0] for dx in (-HALF[0], HALF[0]) for dy in (-HALF[1], HALF[1])])
    points = []
    for corner in corners + np.asarray(centre):
        vertex = int(np.argmin(((skin - corner) ** 2).sum(1)))
        points.append(np.asarray(deformation.positions)[vertex])
    xy = project(camera, np.array(points), size)[0]
    x0, y0 = np.floor(xy.min(0)).astype(int)
    x1, y1 = np.ceil(xy.max(0)).astype(int)
    return x0, x1 + 1, y0, y1 + 1


def measure(face, expression, size, save=None):
    from scipy.ndimage import gaussian_filter

    deformation = face.deform(expression)
    full, camera = render(face, deformation, face.appearance, size, True)
    boxes = []
    plain, _ = render(face, deformation, creaseless(face.appearance), size, False)
    darkening = plain - full
    sigma = 0.02 * _px_per_dm(camera, size)  # ~2 mm
    stroke = np.maximum(darkening - gaussian_filter(darkening, sigma), 0.0)
    out = {}
    for name, (x, y, z) in PATCHES.items():
        for side, sx in (("left", 1.0), ("right", -1.0)):
            x0, x1, y0, y1 = patch_box(face, deformation, camera, size, (sx * x, y, z))
            out[name, side] = (darkening[y0:y1, x0:x1].mean(), stroke[y0:y1, x0:x1].mean())
            boxes.append((x0, y0, x1 - 1, y1 - 1))
    if save:
        from PIL import Image, ImageDraw

        image = Image.fromarray(np.clip(full, 0, 255).astype(np.uint8)).convert("RGB")
        draw = ImageDraw.Draw(image)
        for box in boxes:
            draw.rectangle(box, outline=(255, 0, 0))
        image.save(save)
    return out


def _px_per_dm(camera, size):
    from facsim.render.camera import project

    p = np.array([[0.0, 7.2, 1.5], [0.1, 7.2, 1.5]])
    xy = project(camera, p, size)[0]
    return float(np.linalg.norm(xy[1] - xy[0]) / 0.1)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("expressions", nargs="*", default=["6E+12E"])
    parser.add_argument("--characters", default="george,kofi,ava,mei")
    parser.add_argument("--size", type=int, default=512)
    parser.add_argument("--save", metavar="DIR", help="write each luma render with its patches outlined here")
    args = parser.parse_args(argv)
    from facsim.face import Face

    print(f"{'character':9} {'expression':10} {'patch':11}  dark L/R     stroke L/R")
    for name in args.characters.split(","):
        face = Face(name)
        for expression in args.expressions:
            save = None
            if args.save:
                from pathlib import Path

                Path(args.save).mkdir(parents=True, exist_ok=True)
                save = Path(args.save) / f"{name}-{expression}.png"
            figures = measure(face, expression, args.size, save)
            for patch in PATCHES:
                (dl, sl), (dr, sr) = figures[patch, "left"], figures[patch, "right"]
                print(f"{name:9} {expression:10} {patch:11}  {dl:4.1f} / {dr:4.1f}  {sl:4.1f} / {sr:4.1f}")
        face.close()
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
