"""Print how far the jaw, lips and brows move in each engine (mm), side by side.

Measured on the deformed mesh, against the character's neutral face:
chin and lower-lip drop, lower-teeth (jaw) drop, the lips' inner gap at the
midline, inner and outer brow rise (mean of both sides), and the change of the
distance between the inner brows (negative: drawn together, AU 4).
With ``--upper``: the upper-face figures instead — brow rise and spread, the
glabella's drop, the upper and lower lids' rise, the eye's aperture change
(negative: narrowed), the cheek's and nose wing's rise (AU 6, 9, 10).
With ``--lower``: the lower face — the chin's drop, the lip corners' rise (mean of both sides),
the change of the mouth's width, the rise of the upper lip's inner edge at the
midline, the rise of the nasolabial fold beside the nose (the skin over the maxilla:
about 0 when the jaw drops), the forward motion of the lips, how far the upper lip's inner
edge lies above the upper incisors' edge (positive: that much upper tooth
shows when the lips are parted; about -1 at rest), and how far on average the skin over the
mandible's body lies off the rigid motion that fits it best, a turn about the jaw's hinge and a shift
("bone": about 0 when it moves with the bone).

Usage::

    python3 scripts/engine_amplitudes.py [EXPR ...] [--character ava] [--upper | --lower] [--engines registers muscle]
"""
from __future__ import annotations

import argparse

import numpy as np

#: What the table shows by default: the jaw and lip parting, the brows, and the emotions using them.
EXPRESSIONS = ["25", "26", "27", "25+26", "1", "2", "4", "1+2", "1+4", "1+2+4",
               "surprise", "fear", "sadness"]
#: The lower face's AUs and the emotions that use them (``--lower``).
LOWER = ["10", "12", "12C", "6+12", "6+12+25", "14", "15", "16", "16+25", "17", "20", "20+25",
         "22", "23", "24", "25", "9+15+16", "happiness", "disgust", "fear", "anger", "sadness"]
MM = 100.0
COLUMNS = ("chin", "lo-lip", "jaw", "gap", "in-brow", "out-brow", "brow-dx")
#: The upper face (``--upper``): AUs 1, 2, 4, 5, 6, 7, 9, 41-44 and the emotions that show them.
UPPER_EXPRESSIONS = ["1", "2", "4", "1+2", "1+4", "1+2+4", "5", "6", "7", "9", "41", "42", "43", "44",
                     "anger", "fear", "sadness", "surprise", "disgust", "happiness"]
UPPER_COLUMNS = ("in-brow", "out-brow", "brow-dx", "glab", "up-lid", "lo-lid", "aperture", "cheek", "nose")
LOWER_COLUMNS = ("chin", "lo-lip", "jaw", "gap", "corner", "width", "up-lip", "naso", "protr", "teeth", "bone")


def amplitudes(face, expression) -> dict[str, float]:
    """Motion figures (mm) of ``face`` showing ``expression``."""
    from facsim.facs.emotions import emotion, emotion_names
    from facsim.head.landmarks import landmarks
    from facsim.speech.mouth import mouth_shape

    marks = landmarks(face.head)
    rest = np.asarray(face.neutral, float)
    if expression in emotion_names():
        expression = emotion(expression)
    p = np.asarray(face.deform(expression).positions, float)
    shape = mouth_shape(face, positions=p)
    rest_shape = mouth_shape(face, positions=rest)
    gauge = face._mouth_gauge
    corners = [marks["lip_corner_left"], marks["lip_corner_right"]]

    def rise(name):
        return MM * np.mean([p[marks[f"{name}_{s}"], 1] - rest[marks[f"{name}_{s}"], 1] for s in ("left", "right")])

    def spread(q):
        return q[marks["inner_brow_left"], 0] - q[marks["inner_brow_right"], 0]

    return {
        "chin": MM * (rest[marks["chin"], 1] - p[marks["chin"], 1]),
        "lo-lip": MM * (rest[marks["lower_lip"], 1] - p[marks["lower_lip"], 1]),
        "jaw": shape.jaw_drop,
        "gap": shape.gap - rest_shape.gap,
        "in-brow": rise("inner_brow"),
        "out-brow": rise("outer_brow"),
        "brow-dx": MM * (spread(p) - spread(rest)),
        "glab": MM * (p[marks["glabella"], 1] - rest[marks["glabella"], 1]),
        "up-lid": rise("upper_lid"),
        "lo-lid": rise("lower_lid"),
        "aperture": rise("upper_lid") - rise("lower_lid"),
        "cheek": rise("cheek"),
        "nose": rise("nose_wing"),
        "corner": MM * np.mean(p[corners, 1] - rest[corners, 1]),
        "width": shape.width - rest_shape.width,
        "up-lip": MM * (p[gauge.upper_lip, 1] - rest[gauge.upper_lip, 1]),
        "naso": rise("nasolabial_fold"),
        "protr": shape.protrusion,
        "teeth": MM * (p[gauge.upper_lip, 1] - p[gauge.incisor_edge, 1]),
        "bone": MM * float(off_the_bone(face, p, marks)[1].mean()),
    }


def off_the_bone(face, positions, marks) -> tuple[float, np.ndarray]:
    """The mandible's turn (radians, + opening) and the distance (dm) of each point of the skin over
    its body (the muscle engine's jaw attachment, 12 mm or more below the lip corners) from where the
    bone's rigid motion (:func:`bone_motion`) would take it."""
    turn, _, off = bone_motion(face, positions, marks)
    return turn, off


def bone_motion(face, positions, marks) -> tuple[float, np.ndarray, np.ndarray]:
    """The mandible's rigid motion in the midsagittal plane, fitted to the skin over its body (the muscle
    engine's jaw attachment, 12 mm or more below the lip corners): its turn about the jaw's hinge (radians,
    + opening), the shift (dm, height and depth) that goes with it - the condyles gliding forward - and
    each of those points' distance (dm) from where that motion takes it."""
    from facsim.engines.muscle.net import OUTER, anatomy

    anat = anatomy(face.head)
    count = anat.skin_count
    rest = np.asarray(face.neutral, float)[:count]
    moved = np.asarray(positions, float)[:count]
    corners = np.mean([rest[marks[f"lip_corner_{s}"], 1] for s in ("left", "right")])
    on_the_bone = (anat.jaw_weight > 0.99) & (anat.kind == OUTER) & (rest[:, 1] < corners - 0.12)
    hinge = np.asarray(face.head.joint(face.engine.base_positions, "joint-mouth"), float)[[2, 1]]
    before, after = rest[on_the_bone][:, [2, 1]] - hinge, moved[on_the_bone][:, [2, 1]] - hinge  # (depth, height)
    b, a = before - before.mean(axis=0), after - after.mean(axis=0)
    turn = np.arctan2((b[:, 0] * a[:, 1] - b[:, 1] * a[:, 0]).sum(), (b * a).sum())  # 2-D Procrustes
    c, s = np.cos(turn), np.sin(turn)
    turned = np.stack([before[:, 0] * c - before[:, 1] * s, before[:, 0] * s + before[:, 1] * c], axis=1)
    shift = (after - turned).mean(axis=0)
    return float(-turn), shift[::-1], np.linalg.norm(after - turned - shift, axis=1)


def main(argv=None) -> None:
    from facsim.face import Face

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("expressions", nargs="*")
    parser.add_argument("--lower", action="store_true",
                        help="the lower face's AUs and columns (lip corners, width, upper lip, teeth)")
    parser.add_argument("--character", default="ava")
    parser.add_argument("--engines", nargs="+", default=["registers", "muscle"])
    parser.add_argument("--upper", action="store_true", help="upper-face columns (brows, lids, cheek, nose)")
    args = parser.parse_args(argv)
    if args.upper and args.lower:
        parser.error("choose one of --upper and --lower")
    columns, defaults = ((UPPER_COLUMNS, UPPER_EXPRESSIONS) if args.upper else
                         (LOWER_COLUMNS, LOWER) if args.lower else (COLUMNS, EXPRESSIONS))
    expressions = args.expressions or defaults

    faces = {name: Face(args.character, engine=name) for name in args.engines}
    print(f"{args.character}: motion from neutral in mm (gap: change of the lips' inner gap)")
    print(f"{'expression':<12}{'engine':<10}" + "".join(f"{c:>9}" for c in columns))
    for expr in expressions:
        for name, face in faces.items():
            row = amplitudes(face, expr)
            print(f"{expr:<12}{name:<10}" + "".join(f"{row[c]:9.1f}" for c in columns))


if __name__ == "__main__":
    main()
