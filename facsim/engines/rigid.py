"""Rigid motions shared by both engines: the head (51–58) and the eyes (61–66).

Forward: AU levels → a head rotation vector and shift, and a rotation per eye
(:func:`head_motion`, :func:`eye_motion`); :class:`RigidMotion` applies them to
a character's geometry, blending the head's motion smoothly into the neck.
Inverse: measured rotations → AU levels (:func:`head_levels`,
:func:`eye_levels`), for recorded performances. The table is
``facsim/data/rigid.yaml``.

Examples
--------
>>> rotvec, shift = head_motion({51: 1.0}.get)
>>> round(float(np.degrees(rotvec[1])), 1), shift.tolist()
(35.0, [0.0, 0.0, 0.0])
>>> head_levels(np.degrees(rotvec))[51]
1.0
"""
from __future__ import annotations

from typing import Callable

import numpy as np

from facsim._data import load_yaml, require
from facsim.head.surface import smoothstep

SIDES = ("left", "right")
RIGID_FILE = "rigid.yaml"


def rigid_table() -> dict:
    """The parsed ``rigid.yaml``."""
    table = load_yaml(RIGID_FILE)
    for key in ("head_motions", "eye_rotations", "neck_blend"):
        require(table, RIGID_FILE, key)
    return table


def rigid_codes() -> set[int]:
    """The codes moved rigidly (51–58, 61–66)."""
    table = rigid_table()
    return set(table["head_motions"]) | set(table["eye_rotations"])


def head_motion(levels: Callable[[int], float]) -> tuple[np.ndarray, np.ndarray]:
    """Head rotation vector (radians) and shift (dm) from codes 51–58.

    ``levels(code)`` gives each code's intensity (e.g. ``Activations.level``);
    rotations add as rotation vectors.
    """
    rotvec, shift = np.zeros(3), np.zeros(3)
    for code, spec in rigid_table()["head_motions"].items():
        level = levels(code)
        if level:
            if "translate" in spec:
                shift += level * np.asarray(spec["translate"], float)
            else:
                rotvec += np.radians(spec["degrees"] * level) * np.asarray(spec["axis"], float)
    return rotvec, shift


def eye_motion(levels: Callable[[int], float]) -> dict[str, np.ndarray]:
    """Rotation vector (radians) per eye ("left", "right") from codes 61–66."""
    rotvec = {side: np.zeros(3) for side in SIDES}
    for code, spec in rigid_table()["eye_rotations"].items():
        level = levels(code)
        if level:
            for side in SIDES:
                rotvec[side] += np.radians(spec[side] * level) * np.asarray(spec["axis"], float)
    return rotvec


def head_levels(rotvec_degrees) -> dict[int, float]:
    """Levels of the head-turn codes that give rotation vector ``rotvec_degrees`` (clipped to 1).

    Each code takes the component of the rotation along its axis, divided by
    its angle at intensity 1; the opposite code of a pair gets 0.
    """
    rotvec = np.asarray(rotvec_degrees, float)
    out = {}
    for code, spec in rigid_table()["head_motions"].items():
        if "degrees" in spec:
            axis = np.asarray(spec["axis"], float)
            out[code] = float(np.clip(rotvec @ axis / spec["degrees"], 0.0, 1.0))
    return out


def eye_levels(left_degrees, right_degrees) -> dict[int, float]:
    """Levels of codes 61–66 from each eye's rotation vector in degrees (clipped to 1).

    Codes that turn both eyes the same way (61–64) take the eyes' mean
    rotation along their axis; codes that turn them apart (65, 66) take half
    the difference.
    """
    left, right = np.asarray(left_degrees, float), np.asarray(right_degrees, float)
    out = {}
    for code, spec in rigid_table()["eye_rotations"].items():
        axis = np.asarray(spec["axis"], float)
        if spec["left"] == spec["right"]:
            amount, full = (left + right) @ axis / 2, spec["left"]
        else:
            amount, full = (left - right) @ axis / 2, (spec["left"] - spec["right"]) / 2
        out[code] = float(np.clip(amount / full, 0.0, 1.0))
    return out


def neck_weight(head, neutral: np.ndarray, base_positions: np.ndarray) -> np.ndarray:
    """How much each vertex follows the head (N_geo,): 1 above the neck blend, 0 below, smooth between."""
    pivot = np.asarray(head.joint(base_positions, "joint-neck"), neutral.dtype)
    blend = rigid_table()["neck_blend"]
    return smoothstep(blend["none_below"], blend["full_above"], neutral[:, 1] - pivot[1])


class RigidMotion:
    """A character's rigid motions: eye rotations to place the eyeballs, head motion to move the result.

    Parameters
    ----------
    head : HeadModel
    base_positions : (19158, 3) array
        The character's neutral base mesh.
    """

    def __init__(self, head, base_positions):
        self.head = head
        self.base_positions = np.asarray(base_positions, np.float32)
        self.pivot = head.joint(self.base_positions, "joint-neck")
        self.weight = neck_weight(head, head.positions(self.base_positions), self.base_positions)[:, None]

    @staticmethod
    def eye_rotations(act) -> dict[str, np.ndarray]:
        """3×3 rotation per eye from codes 61–66 (summed as rotation vectors)."""
        from scipy.spatial.transform import Rotation

        return {side: Rotation.from_rotvec(v).as_matrix() for side, v in eye_motion(act.level).items()}

    @staticmethod
    def head_turn(act) -> np.ndarray:
        """The head's rotation (3, 3) from codes 51-58 (identity for none)."""
        from scipy.spatial.transform import Rotation

        return Rotation.from_rotvec(head_motion(act.level)[0]).as_matrix()

    def weight_at(self, positions: np.ndarray) -> np.ndarray:
        """The neck blend (N_geo, 1) read where the points of ``positions`` are now, not at rest.

        Points that an expression brought together then follow the head alike: under a wide-open
        jaw (27) the lower lip, 11 mm tall at rest, is pressed to 3 mm, and on faces whose lips sit
        in the blend (george) their rest weights, 0.19 and 0.36, turned it inside out under 54.
        """
        return neck_weight(self.head, np.asarray(positions), self.base_positions)[:, None]

    def move_head(self, positions: np.ndarray, act, weight: np.ndarray | None = None) -> np.ndarray:
        """Rigid head motion (51–58) blended smoothly into the neck; float32 positions.

        ``weight`` (N_geo, 1): how much each point follows the head; the rest blend by default
        (:meth:`weight_at` reads it where the points are)."""
        from scipy.spatial.transform import Rotation

        rotvec, shift = head_motion(act.level)
        if not rotvec.any() and not shift.any():
            return positions
        weight = self.weight if weight is None else weight
        # Interpolate the rotation angle per vertex (not the moved positions), so the neck twists smoothly.
        rel = positions - self.pivot
        moved = Rotation.from_rotvec(weight * rotvec[None, :]).apply(rel) + self.pivot + weight * shift
        return moved.astype(np.float32)
