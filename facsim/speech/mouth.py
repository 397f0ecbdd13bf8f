"""Measure the mouth on a deformed mesh: lip gap, width, protrusion, lip-to-teeth, jaw drop (mm).

What a viewer checks in a talking face, measured on geometry positions (any
engine): lips closed on /p b m/, rounded on /uw ow w/, lower lip at the upper
teeth on /f v/, the jaw lower on open vowels than on close ones.

The lips' inner rim is the ring of skin vertices bordering the mouth cavity;
its two midline vertices are the upper and lower lip's inner edges (which is
which is read from the undeformed hm08 mesh, where the mouth is slightly open).
The upper and lower teeth are the two connected parts of the teeth region.

Examples
--------
>>> face = facsim.Face("ava")                               # doctest: +SKIP
>>> gauge = MouthGauge(face.head, face.neutral)             # doctest: +SKIP
>>> gauge.measure(face.deform("24").positions).gap < 1.0              # doctest: +SKIP
True
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: Geometry units (decimetres) → millimetres.
MM = 100.0


@dataclass(frozen=True)
class MouthShape:
    """Mouth measurements in millimetres.

    Attributes
    ----------
    gap : float
        Distance between the upper and lower lips' inner edges at the midline;
        negative when the lower edge is above the upper one (lips pressed).
    width : float
        Lip corner to lip corner.
    protrusion : float
        How far the lips' midline points moved forward from rest (+ forward).
    lip_to_teeth : float
        Lower lip's inner edge to the upper incisors' edge.
    jaw_drop : float
        How far the lower teeth moved down from rest.
    """

    gap: float
    width: float
    protrusion: float
    lip_to_teeth: float
    jaw_drop: float


class MouthGauge:
    """Measures :class:`MouthShape` on positions of one head (``neutral``: its rest positions)."""

    def __init__(self, head, neutral: np.ndarray):
        from scipy.sparse import coo_matrix
        from scipy.sparse.csgraph import connected_components

        from facsim.head.landmarks import landmarks
        from facsim.head.mesh import REGIONS

        region = np.asarray(head.region)
        tri = np.asarray(head.triangles)
        cavity = region[tri] == REGIONS.index("mouth_interior")
        skin = region[tri] == REGIONS.index("skin")
        border = tri[cavity.any(axis=1) & skin.any(axis=1)]
        rim = np.unique(border[region[border] == REGIONS.index("skin")])
        base = head.base_vertices[head.base_index[rim]]
        midline = rim[np.abs(base[:, 0]) < 1e-4]
        if midline.size != 2:
            raise ValueError(f"expected 2 midline vertices on the lips' inner rim, found {midline.size}")
        by_height = midline[np.argsort(head.base_vertices[head.base_index[midline]][:, 1])]
        self.lower_lip, self.upper_lip = int(by_height[0]), int(by_height[1])

        teeth = np.flatnonzero(region == REGIONS.index("teeth"))
        inside = tri[np.isin(tri, teeth).all(axis=1)]
        edges = np.concatenate([inside[:, [0, 1]], inside[:, [1, 2]], inside[:, [2, 0]]])
        n = len(region)
        graph = coo_matrix((np.ones(len(edges)), (edges[:, 0], edges[:, 1])), shape=(n, n))
        labels = connected_components(graph, directed=False)[1][teeth]
        parts = [teeth[labels == label] for label in np.unique(labels)]
        if len(parts) != 2:
            raise ValueError(f"expected upper and lower teeth as two parts, found {len(parts)}")
        parts.sort(key=lambda part: neutral[part, 1].mean())
        self.lower_teeth, upper_teeth = parts
        front = upper_teeth[np.abs(neutral[upper_teeth, 0]) < 0.03]
        self.incisor_edge = int(front[np.argmin(neutral[front, 1])])

        marks = landmarks(head)
        self.corners = (marks["lip_corner_left"], marks["lip_corner_right"])
        self.lip_points = np.array([marks["upper_lip"], marks["lower_lip"]])
        self.neutral = np.asarray(neutral, dtype=np.float64)

    def measure(self, positions: np.ndarray) -> MouthShape:
        p = np.asarray(positions, dtype=np.float64)
        up, lo = p[self.upper_lip], p[self.lower_lip]
        gap = float(np.linalg.norm(up - lo)) * (1.0 if up[1] >= lo[1] else -1.0)
        width = float(np.linalg.norm(p[self.corners[0]] - p[self.corners[1]]))
        protrusion = float((p[self.lip_points, 2] - self.neutral[self.lip_points, 2]).mean())
        lip_to_teeth = float(np.linalg.norm(lo - p[self.incisor_edge]))
        jaw = float((self.neutral[self.lower_teeth, 1] - p[self.lower_teeth, 1]).mean())
        return MouthShape(gap * MM, width * MM, protrusion * MM, lip_to_teeth * MM, jaw * MM)


def mouth_shape(face, expression=None, *, positions=None) -> MouthShape:
    """:class:`MouthShape` of ``face`` showing ``expression`` (or given ``positions``)."""
    gauge = getattr(face, "_mouth_gauge", None)
    if gauge is None:
        gauge = MouthGauge(face.head, face.neutral)
        face._mouth_gauge = gauge
    return gauge.measure(face.deform(expression).positions if positions is None else positions)
