"""Loose strands over a hairstyle's cards: fuzz, a few flyaways and tapering ends.

MakeHuman's hair cards end in a clean cut: seen against the background their outline is
a hard edge, and a hairstyle reads as a helmet. Real hair's outline is soft: short stray
hairs stand off the mass (fuzz), a few longer ones arc away from it (flyaways), and every
strand thins to its tip. This module grows such strands on the outer layer of a
hairstyle's cards, most where the hair's volume turns away from a frontal view (its
outline), configured per style under ``wisps:`` in ``facsim/data/hair.yaml``; coily hair
(afro01) gets tight coils standing out from the mass instead.

Each strand is a polyline of ``points`` points; the renderer draws it as a thin ribbon
turned toward the camera, tapered from root to tip, in the hair's colour
(:mod:`facsim.render.proxies`, kind ``"wisps"``). Every point is bound like the hair
vertex nearest to it, so the strands follow the hair (and the head) frame by frame.

Everything here is numpy on the neutral face; nothing is cached on disk (a style's
strands take a few hundredths of a second).
"""
from __future__ import annotations

import hashlib
from dataclasses import dataclass

import numpy as np

from facsim.head.surface import smoothstep

#: Radius (dm) of the rounded top of the hair volume whose outward direction the strands
#: stand off along (as the renderer's :data:`facsim.render.proxies.VOLUME_RADIUS`).
VOLUME_RADIUS = 0.9
#: Depth (dm) below the cards' surface at which a strand's root starts (hidden in the mass).
ROOT_DEPTH = 0.003


@dataclass(frozen=True)
class WispStyle:
    """How one hairstyle's loose strands grow (``wisps:`` in ``facsim/data/hair.yaml``).

    Attributes
    ----------
    fuzz, flyaways : int
        Number of short stray strands and of long arcing ones.
    fuzz_length_mm, flyaway_length_mm : (float, float)
        Their length range (millimetres).
    lift : float
        How far strands stand off the mass: 0 along the cards' flow … 1 straight out.
    width_mm : float
        A strand's width at its root (a few hairs together); it tapers to a tenth at the tip.
    alpha : float
        Its opacity at the root, where it is as wide as drawn.
    points : int
        Points per strand.
    coil_radius_mm, coil_turns : float
        Coily hair: the coils' radius and turns per strand (0: straight strands).
    front : float
        Share of strands (0 … 1) grown where the hair faces the viewer; the rest grow where
        it turns away (the outline of a frontal view).
    """

    fuzz: int = 0
    flyaways: int = 0
    fuzz_length_mm: tuple[float, float] = (5.0, 12.0)
    flyaway_length_mm: tuple[float, float] = (15.0, 35.0)
    lift: float = 0.9
    width_mm: float = 0.12
    alpha: float = 0.6
    points: int = 6
    coil_radius_mm: float = 0.0
    coil_turns: float = 0.0
    front: float = 0.25

    @property
    def count(self) -> int:
        return int(self.fuzz) + int(self.flyaways)


def wisp_style(table: dict, style: str) -> WispStyle | None:
    """The :class:`WispStyle` of ``style`` from ``table`` (the ``wisps:`` mapping: a
    ``default`` entry and per-style overrides), or None where it grows no strands."""
    if not table:
        return None
    entry = {**table.get("default", {}), **table.get(style, {})}
    unknown = set(entry) - set(WispStyle.__dataclass_fields__)
    if unknown:
        raise ValueError(f"wisps: {style}: unknown keys {sorted(unknown)}; expected {sorted(WispStyle.__dataclass_fields__)}")
    entry = {k: tuple(v) if isinstance(v, list) else v for k, v in entry.items()}
    out = WispStyle(**entry)
    return out if out.count > 0 and out.points >= 2 else None


@dataclass(frozen=True, eq=False)
class Wisps:
    """Strands grown on a hairstyle (:func:`grow_wisps`).

    Attributes
    ----------
    points : (S * K, 3) float32
        The strands' points on the neutral face, strand by strand, root first (K per strand).
    along : (S * K,) float32
        0 at each strand's root … 1 at its tip.
    anchor : (S * K,) int
        The hair vertex nearest each point (the point is bound as that vertex is).
    per_strand : int
        K, the points per strand.
    """

    points: np.ndarray
    along: np.ndarray
    anchor: np.ndarray
    per_strand: int

    @property
    def strand_count(self) -> int:
        return len(self.points) // self.per_strand

    def ribbon(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The strands as ribbons for the renderer: ``(triangles (T, 3), corner_vertex (2P,),
        uv (2P, 2))``, two corners per point (u 0 and 1 across the ribbon, v from root to
        tip), two triangles per segment."""
        k, s = self.per_strand, self.strand_count
        corner_vertex = np.repeat(np.arange(len(self.points), dtype=np.int32), 2)
        uv = np.column_stack([np.tile([0.0, 1.0], len(self.points)), np.repeat(self.along, 2)]).astype(np.float32)
        seg = (np.arange(s)[:, None] * k + np.arange(k - 1)[None, :]).reshape(-1)
        a, b = 2 * seg, 2 * seg + 1
        c, d = a + 2, b + 2
        triangles = np.concatenate([np.stack([a, b, c], 1), np.stack([b, d, c], 1)]).astype(np.int32)
        return triangles, corner_vertex, uv


def outward(points: np.ndarray) -> np.ndarray:
    """(N, 3) unit direction out of a hairstyle's volume (a dome over a vertical axis through
    the crown, as the renderer shades it) at ``points`` (the style's own vertices)."""
    points = np.asarray(points, np.float64)
    y = points[:, 1]
    axis = points[y >= np.percentile(y, 90)].mean(axis=0)
    q = np.empty_like(points)
    q[:, 0], q[:, 2] = axis[0], axis[2]
    q[:, 1] = np.minimum(y, float(y.max()) - VOLUME_RADIUS)
    out = points - q
    return out / (np.linalg.norm(out, axis=1, keepdims=True) + 1e-12)


def _flow(points: np.ndarray, triangles: np.ndarray, uv: np.ndarray) -> np.ndarray:
    """(T, 3) unit strand direction per card triangle (dP/dv; MakeHuman's hair textures run
    along v), turned from the crown toward the tips."""
    p, t = points[triangles], uv[triangles]
    e1, e2 = p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]
    d1, d2 = t[:, 1] - t[:, 0], t[:, 2] - t[:, 0]
    det = d1[:, 0] * d2[:, 1] - d2[:, 0] * d1[:, 1]
    det = np.where(np.abs(det) < 1e-12, 1e-12, det)
    tv = (-d2[:, :1] * e1 + d1[:, :1] * e2) / det[:, None]
    tv /= np.linalg.norm(tv, axis=1, keepdims=True) + 1e-12
    above = points.mean(axis=0) + np.array([0.0, np.ptp(points[:, 1]), 0.0])
    flip = np.einsum("ij,ij->i", tv, p.mean(axis=1) - above) < 0
    tv[flip] *= -1
    return tv


def grow_wisps(points: np.ndarray, triangles: np.ndarray, corner_vertex: np.ndarray, uv: np.ndarray,
               exposure: np.ndarray, style: WispStyle, *, texture: np.ndarray | None = None,
               seed: int | str = 0) -> Wisps:
    """Grow ``style``'s strands on a hairstyle's cards.

    Parameters
    ----------
    points : (V, 3) float
        Hair vertices on the neutral face (dm).
    triangles : (T, 3) int
        Triangles over render corners; ``corner_vertex`` (R,) maps corners to vertices and
        ``uv`` (R, 2) gives their texture coordinates (v up).
    exposure : (V,) float
        How open each vertex lies (1 outermost layer … 0 under other cards;
        :func:`facsim.head.proxies.hair_exposure`): strands grow on the outer layer.
    texture : (H, W, 4) uint8, optional
        The cards' texture (image order): roots are placed on its strands, not in its gaps.
    seed : int or str
        The same seed grows the same strands.
    """
    if isinstance(seed, str):
        seed = int(hashlib.sha256(seed.encode()).hexdigest()[:8], 16)
    rng = np.random.default_rng(seed)
    points = np.asarray(points, np.float64)
    triangles = np.asarray(triangles, np.int64)
    corner_vertex = np.asarray(corner_vertex, np.int64)
    uv = np.asarray(uv, np.float64)
    tri_v = corner_vertex[triangles]
    corners = points[tri_v]
    area = 0.5 * np.linalg.norm(np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]), axis=1)
    flow = _flow(points[corner_vertex], triangles, uv)

    # Candidate roots: area-weighted random points on the cards.
    n_candidates = max(20 * style.count, 2000)
    tri = rng.choice(len(triangles), n_candidates, p=area / area.sum())
    r1, r2 = rng.random(n_candidates), rng.random(n_candidates)
    flip = r1 + r2 > 1.0
    r1[flip], r2[flip] = 1.0 - r1[flip], 1.0 - r2[flip]
    bary = np.stack([1.0 - r1 - r2, r1, r2], axis=1)
    root = np.einsum("nk,nkd->nd", bary, corners[tri])
    open_ = np.einsum("nk,nk->n", bary, np.asarray(exposure, np.float64)[tri_v[tri]])
    out = outward(np.concatenate([points, root]))[len(points):]
    # Weight: the outer layer, most where the volume turns away from a frontal view.
    turned = 1.0 - np.abs(out[:, 2])
    weight = smoothstep(0.55, 0.9, open_) * (style.front + (1.0 - style.front) * turned ** 2)
    if texture is not None:
        tex_uv = np.einsum("nk,nkd->nd", bary, uv[triangles[tri]])
        h, w = texture.shape[:2]
        col = np.clip((tex_uv[:, 0] % 1.0 * w).astype(np.int64), 0, w - 1)
        row = np.clip(((1.0 - tex_uv[:, 1] % 1.0) * h).astype(np.int64), 0, h - 1)
        weight = weight * (texture[row, col, 3] > 128)
    if weight.sum() <= 0:
        weight = np.ones(n_candidates)
    n = min(style.count, int(np.count_nonzero(weight)))
    pick = rng.choice(n_candidates, n, replace=False, p=weight / weight.sum())
    root, out, flow = root[pick], out[pick], flow[tri[pick]]
    flyaway = np.zeros(n, bool)
    flyaway[: min(style.flyaways, n)] = True
    rng.shuffle(flyaway)

    lo, hi = np.where(flyaway[:, None], np.asarray(style.flyaway_length_mm, float), np.asarray(style.fuzz_length_mm, float)).T
    length = 0.01 * (lo + (hi - lo) * rng.random(n))
    k = int(style.points)
    s = np.linspace(0.0, 1.0, k)
    jitter = rng.standard_normal((n, 3))
    jitter -= np.einsum("ij,ij->i", jitter, out)[:, None] * out
    if style.coil_radius_mm > 0 and style.coil_turns > 0:
        # A coil around an axis leaning out of the mass.
        axis = out + 0.35 * jitter
        axis /= np.linalg.norm(axis, axis=1, keepdims=True)
        e1 = np.cross(axis, jitter + np.array([0.0, 0.0, 1e-3]))
        e1 /= np.linalg.norm(e1, axis=1, keepdims=True) + 1e-12
        e2 = np.cross(axis, e1)
        phase = 2.0 * np.pi * rng.random(n)
        theta = phase[:, None] + 2.0 * np.pi * style.coil_turns * s[None, :]
        radius = 0.01 * style.coil_radius_mm * (0.7 + 0.6 * rng.random(n))
        centre = root[:, None, :] + (length[:, None] * s[None, :])[..., None] * axis[:, None, :]
        ring = (np.cos(theta) - np.cos(phase)[:, None])[..., None] * e1[:, None, :] + \
               (np.sin(theta) - np.sin(phase)[:, None])[..., None] * e2[:, None, :]
        strands = centre + radius[:, None, None] * ring
    else:
        # Leaving along the flow, lifted off the mass, then bending back toward the flow and
        # down (flyaways stand further off and arc wider).
        lift = np.clip(style.lift * np.where(flyaway, 1.2, 1.0) * (0.5 + rng.random(n)), 0.0, 1.5)
        start = flow + lift[:, None] * out + 0.35 * jitter
        start /= np.linalg.norm(start, axis=1, keepdims=True)
        end = flow + np.where(flyaway, 0.2, 0.4)[:, None] * lift[:, None] * out + np.array([0.0, -0.4, 0.0]) \
            + np.where(flyaway, 0.6, 0.15)[:, None] * jitter
        end /= np.linalg.norm(end, axis=1, keepdims=True)
        step = length / (k - 1)
        strands = np.empty((n, k, 3))
        strands[:, 0] = root
        for i in range(1, k):
            d = (1.0 - s[i]) * start + s[i] * end
            d /= np.linalg.norm(d, axis=1, keepdims=True)
            strands[:, i] = strands[:, i - 1] + step[:, None] * d
    strands -= ROOT_DEPTH * out[:, None, :]
    flat = strands.reshape(-1, 3)
    from scipy.spatial import cKDTree

    anchor = cKDTree(points).query(flat)[1]
    return Wisps(points=flat.astype(np.float32), along=np.tile(s, n).astype(np.float32),
                 anchor=anchor.astype(np.int64), per_strand=k)


def strand_profile(width: int = 16) -> np.ndarray:
    """(2, width, 4) uint8 RGBA: a strand's cover across its ribbon (u), soft at both sides,
    mid brightness (R 128; the colour is the hair's)."""
    u = (np.arange(width) + 0.5) / width
    alpha = 1.0 - smoothstep(0.55, 1.0, np.abs(2.0 * u - 1.0))
    out = np.empty((2, width, 4), np.uint8)
    out[..., 0] = 128
    out[..., 1:3] = 128
    out[..., 3] = np.clip(alpha * 255 + 0.5, 0, 255).astype(np.uint8)[None, :]
    return out
