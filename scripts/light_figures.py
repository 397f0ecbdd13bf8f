"""Print how the studio light models a face, per character: ratios of the light on the skin.

Front view at 448² (the blind review's size), the default rig. Each figure is a ratio of the
median linear luminance (the display transform inverted, as in ``scripts/skin_figures.py``) over
small boxes on the skin, placed at points of the neutral head and followed through the expression:

- ``lit/other``: the cheek on the key's side (the character's right) over the other cheek, halfway
  out (both halves must stay readable: stimuli show AUs on either side);
- ``side``: the face's side (over the cheekbone, near the outline) over the mid-cheek, both sides
  pooled (how the face falls off toward its outline);
- ``socket``: the eye socket's inner corner (between the eye and the bridge of the nose) over the
  mid-cheek (the eyes sit in a little shade in a studio photograph);
- ``neck``: the throat just under the jaw over the chin (the chin's shadow, the floor's little light);
- ``forehead``: the forehead's middle over the chin (falls under a fringe's shadow);
- ``cheek``: the mid-cheeks' luminance itself (the exposure).

``--astronaut`` prints the same ratios measured by hand-placed boxes on scikit-image's studio
portrait (``skimage.data.astronaut()``; its sRGB taken as the linear light). Session 25: lit/other
1.09, side 0.52, socket 0.58, neck 0.16.

Usage::

    python3 scripts/light_figures.py [CHARACTER ...] [--expression "1+2"] [--emotion surprise] [--astronaut]
"""
from __future__ import annotations

import argparse

import numpy as np

from skin_figures import radiance, srgb_to_linear   # (scripts/: the display transform inverted)

SIZE = 448
LUMINANCE = np.array([0.2126, 0.7152, 0.0722])
#: Box centres on the neutral head (decimetres; +X the character's left), the sided ones mirrored.
SIDED = {"cheek": (0.36, 6.84, 1.38), "side": (0.58, 6.95, 1.08), "socket": (0.12, 7.33, 1.50)}
MIDLINE = {"forehead": (0.0, 7.60, 1.52), "chin": (0.0, 6.34, 1.52), "neck": (0.0, 5.92, 1.02)}
#: The same places on skimage.data.astronaut() (x, y pixels; her right is the image's left).
ASTRONAUT = {"cheek_right": (197, 127), "cheek_left": (255, 127), "side_right": (183, 117), "side_left": (268, 117),
             "socket_right": (214, 103), "socket_left": (237, 103), "forehead": (225, 87), "chin": (225, 168),
             "neck": (225, 181)}


def ratios(v: dict) -> dict:
    cheeks = v["cheek_left"] + v["cheek_right"]
    return {"lit/other": v["cheek_right"] / v["cheek_left"],
            "side": (v["side_left"] + v["side_right"]) / cheeks,
            "socket": (v["socket_left"] + v["socket_right"]) / cheeks,
            "neck": v["neck"] / v["chin"],
            "forehead": v["forehead"] / v["chin"],
            "cheek": cheeks / 2}


def box_medians(luminance: np.ndarray, pixels: dict, r: int) -> dict:
    return {k: float(np.median(luminance[int(y) - r:int(y) + r + 1, int(x) - r:int(x) + r + 1]))
            for k, (x, y) in pixels.items()}


def figures(name: str, expression=None) -> dict:
    from facsim import Face
    from facsim.render.camera import project

    with Face(name) as face:
        head = face.head
        skin = head.base_vertices[head.base_index[: head.skin_vertex_count]]

        def nearest(point):
            return int(np.argmin(((skin - np.asarray(point)) ** 2).sum(1)))
        vertex = {k: nearest(p) for k, p in MIDLINE.items()}
        for k, p in SIDED.items():
            vertex[f"{k}_left"] = nearest(p)
            vertex[f"{k}_right"] = int(head.mirror[vertex[f"{k}_left"]])
        deformation = face.deform(expression)
        image = face.render(deformation=deformation, size=SIZE)
        camera = face.camera(size=(SIZE, SIZE))
        positions = np.asarray(deformation.positions)[list(vertex.values())]
        pixels = dict(zip(vertex, project(camera, positions, SIZE)[0]))
        return ratios(box_medians(radiance(image) @ LUMINANCE, pixels, 5))


def astronaut_figures() -> dict:
    from skimage import data

    return ratios(box_medians(srgb_to_linear(data.astronaut() / 255.0) @ LUMINANCE, ASTRONAUT, 3))


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("characters", nargs="*", default=["ava", "liam", "amara", "kwame", "mei", "george"])
    parser.add_argument("--expression", default=None, help="a FACS string (default: neutral)")
    parser.add_argument("--emotion", default=None, help="an emotion preset at 100 %% instead")
    parser.add_argument("--astronaut", action="store_true", help="also the studio portrait's ratios")
    args = parser.parse_args(argv)
    expression = args.expression
    if args.emotion:
        from facsim.facs.emotions import emotion

        expression = emotion(args.emotion, intensity=1.0)
    rows = [(name, figures(name, expression)) for name in args.characters]
    if args.astronaut:
        rows.append(("astronaut", astronaut_figures()))
    keys = list(rows[0][1])
    print(f"{'':10s}" + "".join(f"{k:>11s}" for k in keys))
    for name, out in rows:
        print(f"{name:10s}" + "".join(f"{out[k]:11.3f}" for k in keys))


if __name__ == "__main__":
    main()
