"""How the lips' red deforms, per expression (geometry only, no rendering).

``--stretch`` (default): the longest edge of each lip's red (the lips mask over 0.5, edges within one
lip) as a multiple of its rest length, and the 99th percentile - where the red smears instead of
stretching evenly (session 25: the dropped jaw tore the lower lip's outer part, 5-9 times at 26E).
``--red``: the upper and the lower lip's red seen from the front (mm), at the midline and 0.6 of the
way to the corners: the height of the lip's points there that face the camera (normal's z over 0.3).
(In an open mouth the column 0.6 of the way out runs down along the lip's slope: read it for closed lips.)

Usage::

    python3 scripts/lip_figures.py [EXPR ...] [--characters ava,george] [--red] [--engine registers]

Emotion names (``fear``) stand for their full-intensity AUs.
"""
from __future__ import annotations

import argparse

import numpy as np

#: What the table shows by default: the jaw's drop and the emotions that use it, and the lips pressed.
EXPRESSIONS = ["26", "27", "25+26", "20+25+26", "fear", "surprise", "23", "24", "anger", "sadness", "6+12+25"]
MM = 100.0


def lips_red(face):
    """(red, lip, anatomy): the lips' red (mask over 0.5, made symmetric) on the skin, each point's lip
    (+1 upper, -1 lower, 0 neither) and the head's :class:`~facsim.engines.muscle.net.Anatomy`."""
    from facsim.engines.muscle.net import anatomy, mask_per_vertex

    anat = anatomy(face.head)
    n = anat.skin_count
    mask = mask_per_vertex(face.head, "lips")[:n]
    return np.maximum(mask, mask[anat.mirror[:n]]) > 0.5, anat.lip_half[:n], anat


def stretch(face, positions) -> dict[str, float]:
    """Each lip's longest red edge on ``positions`` as a multiple of its rest length, and the 99th percentile."""
    red, lip, anat = lips_red(face)
    a, b = anat.edges.T
    rest = np.asarray(face.neutral, np.float64)
    moved = np.asarray(positions, np.float64)
    out = {}
    for name, which in (("upper", 1), ("lower", -1)):
        keep = red[a] & red[b] & (lip[a] == which) & (lip[b] == which)
        ratio = (np.linalg.norm(moved[a[keep]] - moved[b[keep]], axis=1)
                 / np.linalg.norm(rest[a[keep]] - rest[b[keep]], axis=1))
        out[f"{name} max"], out[f"{name} p99"] = float(ratio.max()), float(np.percentile(ratio, 99))
    return out


def red_heights(face, positions) -> dict[str, float]:
    """The upper and the lower lip's red seen from the front (mm) at the midline and 0.6 of the way to the corners."""
    from facsim.head.landmarks import landmarks
    from facsim.head.surface import vertex_normals

    red, lip, anat = lips_red(face)
    n = anat.skin_count
    rest = np.asarray(face.neutral, np.float64)[:n]
    skin = np.asarray(positions, np.float64)[:n]
    facing = vertex_normals(skin, anat.triangles)[:, 2] > 0.3
    half_width = abs(rest[landmarks(face.head)["lip_corner_left"], 0])
    out = {}
    for where, x in (("mid", 0.0), ("0.6", 0.6 * half_width)):
        column = np.abs(np.abs(rest[:, 0]) - x) < 0.02
        for name, which in (("upper", 1), ("lower", -1)):
            ys = skin[red & facing & column & (lip == which), 1]
            out[f"{name} {where}"] = MM * float(ys.max() - ys.min()) if len(ys) > 1 else 0.0
    return out


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("expressions", nargs="*", default=EXPRESSIONS)
    parser.add_argument("--characters", default="ava,george,kwame,mei,liam,amara")
    parser.add_argument("--red", action="store_true", help="the lips' red heights (mm) instead of the stretch")
    parser.add_argument("--engine", default="registers")
    args = parser.parse_args(argv)

    from facsim import Face
    from facsim.facs.emotions import emotion, emotion_names

    measure = red_heights if args.red else stretch
    for character in args.characters.split(","):
        face = Face(character, engine=args.engine)
        rows = [("rest", face.neutral)] if args.red else []
        rows += [(text, face.deform(emotion(text) if text in emotion_names() else text).positions)
                 for text in args.expressions]
        for text, positions in rows:
            figures = measure(face, positions)
            print(f"{character:8s} {text:10s} " + "  ".join(f"{k} {v:5.2f}" for k, v in figures.items()), flush=True)


if __name__ == "__main__":
    main()
