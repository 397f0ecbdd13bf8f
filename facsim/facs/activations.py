"""Expression → activations: the stage between notation and the engines.

An :class:`Activations` is what every engine consumes: one intensity in [0, 1]
per (AU code, side), sides being ``"left"`` and ``"right"`` of the *character*
(+X in the mesh is the character's left). Bilateral actions fill both sides.

Examples
--------
>>> from facsim.facs.notation import parse
>>> act = activations(parse("1+2+L12C"))
>>> act[12, "left"], act[12, "right"]
(0.55, 0.0)
>>> sorted(act.codes)
[1, 2, 12]
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Iterable, Mapping

SIDES = ("left", "right")

#: Where FACS says "unilateral" without naming the side (``U12``), facsim acts
#: on the character's right, as FACS coders conventionally score R before L.
UNILATERAL_DEFAULT_SIDE = "right"


@dataclass(frozen=True)
class Activations:
    """Intensity per (AU code, side), each in [0, 1]; missing keys are 0.

    Activations are plain data: engines read them, nobody mutates them.
    """

    levels: Mapping[tuple[int, str], float] = field(default_factory=dict)

    def __post_init__(self):
        clean = {}
        for (code, side), value in dict(self.levels).items():
            if side not in SIDES:
                raise ValueError(f"side must be 'left' or 'right', got {side!r} for AU{code}")
            value = float(value)
            if not 0.0 <= value <= 1.0:
                raise ValueError(f"intensity of AU{code} ({side}) must be in [0, 1], got {value}")
            if value > 0.0:
                clean[(int(code), side)] = value
        object.__setattr__(self, "levels", dict(sorted(clean.items())))

    def __getitem__(self, key: tuple[int, str]) -> float:
        return self.levels.get((int(key[0]), key[1]), 0.0)

    def __iter__(self):
        return iter(self.levels.items())

    def __len__(self) -> int:
        return len(self.levels)

    def __bool__(self) -> bool:
        return bool(self.levels)

    @property
    def codes(self) -> set[int]:
        """The AU codes active on at least one side."""
        return {code for code, _ in self.levels}

    def level(self, code: int) -> float:
        """The larger of the two sides' intensities (for codes without sides)."""
        return max(self[code, "left"], self[code, "right"])

    def scaled(self, factor: float) -> "Activations":
        """Every intensity multiplied by ``factor`` (clamped to [0, 1])."""
        return Activations({k: min(1.0, max(0.0, v * factor)) for k, v in self.levels.items()})

    def combined(self, other: "Activations") -> "Activations":
        """Sum of two activation sets, clamped to 1 (overlapping timeline tracks)."""
        keys = set(self.levels) | set(other.levels)
        return Activations({k: min(1.0, self.levels.get(k, 0.0) + other.levels.get(k, 0.0)) for k in keys})

    @classmethod
    def merge(cls, parts: Iterable["Activations"]) -> "Activations":
        """Sum of many activation sets, clamped to 1."""
        total: dict[tuple[int, str], float] = {}
        for part in parts:
            for key, value in part.levels.items():
                total[key] = min(1.0, total.get(key, 0.0) + value)
        return cls(total)


def activations(expression) -> Activations:
    """Resolve an :class:`~facsim.notation.Expression` into per-side intensities.

    ``both`` fills the left and right sides, ``unilateral`` (FACS ``U``) acts on
    :data:`UNILATERAL_DEFAULT_SIDE`. The same AU given twice on one side sums,
    clamped to 1.
    """
    levels: dict[tuple[int, str], float] = {}
    for unit in expression.units:
        if unit.side == "both":
            sides = SIDES
        elif unit.side == "unilateral":
            sides = (UNILATERAL_DEFAULT_SIDE,)
        else:
            sides = (unit.side,)
        for side in sides:
            key = (unit.code, side)
            levels[key] = min(1.0, levels.get(key, 0.0) + unit.intensity)
    return Activations(levels)
