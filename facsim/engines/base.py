"""The engine contract: what every deformation engine implements, and what it returns.

An engine is built once per character (``Engine(head, data, character,
base_positions)``) and turns :class:`~facsim.facs.activations.Activations` into
a :class:`Deformation`:

- ``deform(act)``: a static expression, reached from the neutral face;
- ``reset()`` then ``step(act)`` per frame: an animation, the engine keeping
  its state between frames (a stateless engine simply deforms each frame).

Examples
--------
>>> d = Deformation(np.zeros((3, 3), np.float32))
>>> d.wrinkle is None and d.crease_phase is None
True
>>> d = Deformation(np.zeros((3, 3), np.float32), creases=lambda: (np.ones(3), np.zeros(3)))
>>> d.wrinkle.tolist()
[1.0, 1.0, 1.0]
"""
from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property
from typing import Callable, Protocol

import numpy as np


@dataclass(frozen=True)
class Deformation:
    """A deformed face: geometry positions, and the skin's creases where the engine computes them.

    Parameters
    ----------
    positions : (N_geo, 3) float32 array
        Every geometry vertex of the head model (skin, eyes, teeth, tongue, lashes).
    creases : callable, optional
        Returns ``(wrinkle, crease_phase)``, two (N_geo,) float32 arrays: skin
        compression (≥ 0) and where across its furrows each vertex lies (in
        furrow spacings; the renderer draws furrows at whole numbers). Called
        once, when a renderer or exporter first asks (a solve alone does not
        need them). None: the engine computes no creases.
    """

    positions: np.ndarray
    creases: Callable[[], tuple[np.ndarray, np.ndarray]] | None = field(default=None, repr=False, compare=False)

    @cached_property
    def _creases(self) -> tuple[np.ndarray | None, np.ndarray | None]:
        return self.creases() if self.creases is not None else (None, None)

    @property
    def wrinkle(self) -> np.ndarray | None:
        """Skin compression per vertex (N_geo,), or None."""
        return self._creases[0]

    @property
    def crease_phase(self) -> np.ndarray | None:
        """Furrow phase per vertex (N_geo,), or None."""
        return self._creases[1]


class Engine(Protocol):
    """What :class:`facsim.face.Face` needs of an engine (see the module docstring).

    Parameters
    ----------
    head : HeadModel
    data : FaceData
    character : Character
    base_positions : (19158, 3) array
        The character's neutral base mesh.
    """

    name: str
    #: Neutral geometry positions (N_geo, 3) float32.
    neutral: np.ndarray

    def __init__(self, head, data, character, base_positions) -> None: ...

    def deform(self, act) -> Deformation:
        """The expression ``act`` reached from the neutral face."""

    def reset(self) -> None:
        """Back to the neutral face: the next :meth:`step` starts an animation."""

    def step(self, act) -> Deformation:
        """The next animation frame, showing ``act``."""
