"""Is a deformed face still physical? Checks over every skin vertex, for any engine.

Two things a real face never does: skin turned inside out (a triangle whose
normal now points against its rest normal, turned with the head: the
surface folded through itself), and skin inside an eyeball (a point outside the eyeball at rest that
an expression moved into it: the eye would show through the lid). Both are
checked on every skin vertex and triangle, not only on an engine's contact
points, so they catch what a solver's constraints miss.

Examples
--------
>>> face = facsim.Face("ava")                           # doctest: +SKIP
>>> check = GeometryCheck(face.head, face.engine.neutral)  # doctest: +SKIP
>>> check(face.engine(facsim.activations(facsim.parse("4+6")))).ok   # doctest: +SKIP
True
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: Rest triangles smaller than this (twice the area, dm²) have no reliable orientation.
DEGENERATE_AREA2 = 1e-10
#: Skin this far (dm) above the eyes' centres is scalp, moved only by the head (51–58).
SCALP_ABOVE_EYES = 0.9
#: Depth (dm) below the eyeball surface that counts as inside: 0.01 mm, well under rounding of a render.
EYE_TOLERANCE = 1e-4


@dataclass(frozen=True)
class GeometryReport:
    """What :class:`GeometryCheck` found in one set of positions."""

    flipped: int            # skin triangles turned inside out (against the rest normal turned with the head)
    flipped_unturned: int   # ... against the rest normal itself (the same, except under head motion 51-58)
    inside: int             # skin vertices inside an eyeball
    depth: float            # how deep the deepest of them is (dm; 0 if none)
    flipped_triangles: np.ndarray  # indices into GeometryCheck.triangles
    inside_vertices: np.ndarray    # geometry vertex indices

    @property
    def ok(self) -> bool:
        return self.flipped == 0 and self.inside == 0


class GeometryCheck:
    """Checks positions (N_geo, 3) of a head against its neutral ``rest`` positions.

    The eyeballs are found in the checked positions themselves (the centre of
    each generated eyeball's vertices), and the head's rotation from the scalp,
    so rigid head motion and eye rotations need no special case.
    """

    def __init__(self, head, rest: np.ndarray):
        rest = np.asarray(rest, float)
        skin = head.skin_vertex_count
        tris = np.asarray(head.triangles)
        tris = tris[(tris < skin).all(axis=1)]
        normal = _normals(rest, tris)
        self.triangles = tris[(normal * normal).sum(1) > DEGENERATE_AREA2 ** 2]
        self.rest_normal = _normals(rest, self.triangles)
        self.skin = skin
        self.eyes = [np.asarray(head.eye_vertices[s]) for s in ("left", "right")]
        # The scalp well above the eyes: no AU moves it, so it shows the head's own rotation.
        top = max(rest[ids].mean(axis=0)[1] for ids in self.eyes) + SCALP_ABOVE_EYES
        self.scalp = np.flatnonzero(rest[:skin, 1] > top)
        self.rest = rest
        self.radius = []
        self.outside = []
        for ids in self.eyes:
            centre = rest[ids].mean(axis=0)
            radius = float(np.linalg.norm(rest[ids] - centre, axis=1).mean())
            self.radius.append(radius)
            self.outside.append(np.flatnonzero(np.linalg.norm(rest[:skin] - centre, axis=1) >= radius))

    def __call__(self, positions: np.ndarray) -> GeometryReport:
        p = np.asarray(positions, float)
        turn = head_rotation(self.rest[self.scalp], p[self.scalp])
        normal = _normals(p, self.triangles)
        flipped = np.flatnonzero((normal * (self.rest_normal @ turn.T)).sum(1) <= 0)
        unturned = int(((normal * self.rest_normal).sum(1) <= 0).sum())
        inside, depth = [], 0.0
        for ids, radius, outside in zip(self.eyes, self.radius, self.outside):
            centre = p[ids].mean(axis=0)
            gap = np.linalg.norm(p[outside] - centre, axis=1) - radius
            bad = gap < -EYE_TOLERANCE
            inside.append(outside[bad])
            if bad.any():
                depth = max(depth, float(-gap[bad].min()))
        inside = np.concatenate(inside)
        return GeometryReport(len(flipped), unturned, len(inside), depth, flipped, inside)


def head_rotation(rest: np.ndarray, now: np.ndarray) -> np.ndarray:
    """The rotation (3, 3) that best turns points ``rest`` (K, 3) onto ``now`` (Kabsch; no mirroring)."""
    a, b = rest - rest.mean(axis=0), now - now.mean(axis=0)
    u, _, vt = np.linalg.svd(a.T @ b)
    d = np.sign(np.linalg.det(u @ vt))
    return (u @ np.diag([1.0, 1.0, d]) @ vt).T


def _normals(p: np.ndarray, tris: np.ndarray) -> np.ndarray:
    return np.cross(p[tris[:, 1]] - p[tris[:, 0]], p[tris[:, 2]] - p[tris[:, 0]])
