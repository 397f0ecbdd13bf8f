"""The register engine: AUs → morph-target weights (HapFACS §3.2) → geometry.

Each AU drives a set of ⟨target, maximum weight⟩ pairs read from
``facsim/data/registers.yaml``; targets shared by several active AUs combine by
HapFACS Eq. 1 (:func:`combine_registers`). Head codes 51–58 move the head
rigidly with a smooth blend into the neck, eye codes 61–66 rotate the
eyeballs about their centres (and the lids follow vertical gaze via registers).

Examples
--------
>>> combine_registers([(0.3, 0.6), (0.5, 1.0)])   # AUs x, y share a register
0.6
>>> round(combine_registers([(0.2, 0.6), (0.3, 1.0)]), 2)   # 0.2·0.6 + 0.3·1.0, under 0.6
0.42
"""
from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from importlib import resources
from typing import Iterable

import numpy as np
import yaml
from scipy.spatial.transform import Rotation

from facsim.facs.activations import SIDES, Activations

#: Half-width (dm) of the smooth left/right split of two-sided targets at the midline.
MIDLINE_BLEND = 0.06
#: One-sided targets may act across the midline (the lips are one piece) but not
#: beyond this band (dm): the authored Face Units carry stray offsets on the far
#: side (eyeBlinkLeft moves the right eye socket), which unilateral AUs must not show.
SIDED_REACH = (0.05, 0.15)


@lru_cache(maxsize=1)
def register_table() -> dict:
    """The parsed ``registers.yaml`` (the one source of the mapping)."""
    return yaml.safe_load(resources.files("facsim").joinpath("data/registers.yaml").read_text())


def simulated_codes() -> set[int]:
    """AU codes this engine renders."""
    t = register_table()
    return set(t["action_units"]) | set(t["head_motions"]) | set(t["eye_rotations"])


def combine_registers(contributions: Iterable[tuple[float, float]]) -> float:
    """HapFACS Eq. 1: sum of ``intensity × max`` over AUs, clamped to the smallest max.

    ``contributions`` holds one ``(intensity, max)`` pair per active AU sharing the register.
    """
    pairs = list(contributions)
    if not pairs:
        return 0.0
    total = sum(level * vmax for level, vmax in pairs)
    return min(total, min(vmax for _, vmax in pairs))


@dataclass(frozen=True)
class Column:
    """One morph direction: a target (or an ethnicity mix of one) on one side or both."""

    pattern: str         # target name with {Side}/{side}/{s} (and maybe {ethnicity}) unexpanded
    side: str            # "left" or "right"

    @property
    def target(self) -> str:
        return _expand(self.pattern, self.side)[0]

    @property
    def sided(self) -> bool:
        """A one-sided target; otherwise this column is the ``side`` half of a two-sided one."""
        return _expand(self.pattern, self.side)[1]


def _expand(pattern: str, side: str) -> tuple[str, bool]:
    """Fill the side placeholders; returns (name, whether the target is one-sided)."""
    sided = any(k in pattern for k in ("{Side}", "{side}", "{s}"))
    name = pattern.replace("{Side}", side.capitalize()).replace("{side}", side).replace("{s}", side[0])
    return name, sided


def register_weights(act: Activations) -> dict[Column, float]:
    """Column weights for ``act`` by Eq. 1 — the pure heart of the engine.

    A two-sided target used by an AU on one side only is split at the midline:
    it gets a left and a right column, each weighted by its own side's AUs.
    """
    table = register_table()["action_units"]
    contributions: dict[Column, list[tuple[float, float]]] = {}
    for (code, side), level in act:
        if table.get(code, {}).get("direction") and side == "right" and act[code, "left"] == level:
            continue  # a direction code given without a side (e.g. 30) moves to the left only
        for reg in table.get(code, {}).get("registers", []):
            contributions.setdefault(Column(reg["target"], side), []).append((level, float(reg["max"])))
    return {col: combine_registers(pairs) for col, pairs in contributions.items()}


class RegisterEngine:
    """Callable engine: :class:`Activations` → geometry positions (N_geo, 3).

    Parameters
    ----------
    head : HeadModel
    data : FaceData
    character : Character
    base_positions : (19158, 3) array
        The character's neutral base mesh.
    """

    name = "registers"

    def __init__(self, head, data, character, base_positions):
        self.head = head
        self.data = data
        self.base_positions = np.asarray(base_positions, np.float32)
        self.ethnicity = character.ethnicity
        self.neutral = head.positions(self.base_positions)
        self._geo_of_base = np.full(len(data.base_vertices), -1, np.int64)
        self._geo_of_base[head.base_index] = np.arange(len(head.base_index))
        x = self.base_positions[head.base_index, 0]
        self._half = _smoothstep(-MIDLINE_BLEND, MIDLINE_BLEND, x)
        self._reach = _smoothstep(-SIDED_REACH[1], -SIDED_REACH[0], x)  # left-side targets
        self._columns: dict[Column, np.ndarray] = {}
        self._table = register_table()
        self.last_wrinkle = None  # this engine computes no skin compression

    def column(self, col: Column) -> np.ndarray:
        """Offsets (N_base_geo, 3) of one column, mixed by ethnicity and split by side.

        Right-side columns are the mirror images of the left ones: the authored
        targets are a little asymmetric, and FACS stimuli must not be.
        """
        if col not in self._columns and col.side == "right":
            left = self.column(Column(col.pattern, "left"))
            mirror = self.head.mirror[: len(self.head.base_index)]
            self._columns[col] = left[mirror] * np.array([-1.0, 1.0, 1.0], np.float32)
        if col not in self._columns:
            offsets = np.zeros((len(self.head.base_index), 3), np.float32)
            mixes = self.ethnicity.items() if "{ethnicity}" in col.target else [(None, 1.0)]
            for ethnicity, weight in mixes:
                name = col.target.replace("{ethnicity}", ethnicity) if ethnicity else col.target
                idx, delta = self.data.target(name)
                geo = self._geo_of_base[idx]
                keep = geo >= 0
                offsets[geo[keep]] += weight * delta[keep]
            offsets *= (self._reach if col.sided else self._half)[:, None]
            self._columns[col] = offsets
        return self._columns[col]

    def __call__(self, act: Activations) -> np.ndarray:
        base = self.base_positions[self.head.base_index]  # a copy (fancy indexing)
        for col, weight in register_weights(act).items():
            if weight:
                base += weight * self.column(col)
        morphed = np.array(self.base_positions, copy=True)
        morphed[self.head.base_index] = base
        positions = self.head.positions(morphed, neutral_base=self.base_positions, eye_rotations=self.eye_rotations(act))
        self.head.keep_skin_off_eyes(positions, self.neutral, self.base_positions)
        return self.move_head(positions, act)

    def eye_rotations(self, act: Activations) -> dict[str, np.ndarray]:
        """3×3 rotation per eye from codes 61–66 (summed as rotation vectors)."""
        rotvec = {side: np.zeros(3) for side in SIDES}
        for code, spec in self._table["eye_rotations"].items():
            level = act.level(code)
            if level:
                for side in SIDES:
                    rotvec[side] += np.radians(spec[side] * level) * np.asarray(spec["axis"], float)
        return {side: Rotation.from_rotvec(v).as_matrix() for side, v in rotvec.items()}

    def move_head(self, positions: np.ndarray, act: Activations) -> np.ndarray:
        """Rigid head motion (51–58) blended smoothly into the neck."""
        rotvec, shift = np.zeros(3), np.zeros(3)
        for code, spec in self._table["head_motions"].items():
            level = act.level(code)
            if not level:
                continue
            if "translate" in spec:
                shift += level * np.asarray(spec["translate"], float)
            else:
                rotvec += np.radians(spec["degrees"] * level) * np.asarray(spec["axis"], float)
        if not rotvec.any() and not shift.any():
            return positions
        pivot = self.head.joint(self.base_positions, "joint-neck")
        blend = self._table["neck_blend"]
        height = self.neutral[:, 1] - pivot[1]
        weight = _smoothstep(blend["none_below"], blend["full_above"], height)[:, None]
        # Interpolate the rotation angle per vertex (not the moved positions), so the neck twists smoothly.
        rel = positions - pivot
        moved = Rotation.from_rotvec(weight * rotvec[None, :]).apply(rel) + pivot + weight * shift
        return moved.astype(np.float32)


def _smoothstep(edge0: float, edge1: float, x: np.ndarray) -> np.ndarray:
    t = np.clip((x - edge0) / (edge1 - edge0), 0, 1)
    return (t * t * (3 - 2 * t)).astype(np.float32)


def coverage() -> dict[int, str]:
    """AU code → one line on how this engine renders it (or why it cannot)."""
    table = register_table()
    out = {code: spec["why"] for code, spec in table["action_units"].items()}
    out.update({code: spec["why"] for code, spec in table["head_motions"].items()})
    out.update({code: spec["why"] for code, spec in table["eye_rotations"].items()})
    out.update({code: "not simulated: " + why for code, why in table["not_simulated"].items()})
    return dict(sorted(out.items()))
