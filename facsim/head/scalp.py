"""The scalp's own hair: a fine layer on the skin under a hairstyle's cards.

MakeHuman's hair is a few dozen textured cards floating a few millimetres over the scalp.
Where they end (the hairline) or part, the skin between and beyond them showed bare and,
shadowed by the cards, reddish: a seam around a painted helmet (issue 13: "a visible hairline
seam on the old man"). Real hair grows out of the skin: from the hairline inward it thickens
over a centimetre or so from single fine hairs to full cover, and the scalp only shows
through where the hair is sparse.

This module builds that layer as plain data for the renderer (one more proxy, kind
``"scalp"``): the skin triangles under the hair, lifted a fraction of a millimetre, with

- a **density** per vertex (0 bare … 1 full cover): 1 where cards lie over the skin within
  a short reach, falling off smoothly past the cards' edge (:func:`scalp_density`);
- **strand coordinates** as UVs, ``u`` across the strands and ``v`` along them, which follow
  the direction the cards' own strands run (:func:`strand_coordinates`), so a tiling texture
  of fine hairs (:func:`strand_texture`) lies along the hair's flow.

A close crop (``crops:`` in ``facsim/data/hair.yaml``) is this layer alone, with no cards: its
hairline is drawn from an anatomical table (:func:`crop_hairline_height`), off the ears
(:func:`thin_skin`), rounded off and handed to the renderer as a distance from it
(:func:`crop_hairline`), so the hair thins over a band a few millimetres wide per pixel.

The layer is bound to the skin vertices it covers, so it follows every frame exactly as the
skin does (head motion, and the forehead under AU 1 and 2 carries the hairline's fine hairs).
"""
from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from facsim.head.surface import smoothstep, vertex_normals

#: How far (dm) over the skin a card may lie and still count as growing from it.
REACH = 0.12
#: Distance (dm) from a ray to a card sample that counts as passing through the card.
CARD_RADIUS = 0.035
#: Width (dm) of the hairline's gradient from bare skin to full cover.
HAIRLINE_WIDTH = 0.06
#: Height (dm) of the layer over the skin: enough not to fight it in the depth buffer.
LIFT = 0.004
#: Bump when the layer a character gets changes (its disk cache is keyed by it).
VERSION = 14  # 2: afro01's cards stand off the skull (volume_mm in hair.yaml); 12: crops' anatomical, rounded hairline;
#   13: every layer carries its height above the hairline; 14: the hairline's hairs rise from it, thinning
#: Under a hairstyle's cards: the width (dm) over which the hair thins from full cover at the
#: hairline (:func:`hairline_height`) to bare skin ...
HAIRLINE_THINNING = 0.04
#: ... and the band (dm above the hairline) over which its hairs turn from rising straight off
#: it, up and back, to the cards' own flow.
HAIRLINE_RISE = (0.1, 0.25)
#: How much more the rising hairs' direction counts in the strand coordinates' fit than the
#: cards' flow under them (:func:`strand_coordinates`).
RISE_FIT_WEIGHT = 8.0
#: Close crops (:func:`crop_hairline`): the radius (dm) over which the hairline is rounded off
#: (the skin's vertices lie about a centimetre apart: an edge along them runs in steps) ...
CROP_ROUNDING = 0.07
#: ... and the width (dm) of the band over which the hair thins from full cover to bare skin.
CROP_EDGE = 0.1
#: One texture tile's size (dm) across and along the strands.
TILE = (0.1, 0.2)


def outward_skin(head, neutral_geometry) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The neutral skin's points (N_skin, 3), triangles (T, 3) and vertex normals (N_skin, 3),
    all float64 and wound outward (the mesh's winding is turned if it faces inward)."""
    n_skin = head.skin_vertex_count
    skin = np.asarray(neutral_geometry, np.float64)[:n_skin]
    tris = np.asarray(head.topology.geo_faces)
    tris = tris[np.all(tris < n_skin, axis=1)]
    normals = vertex_normals(skin, tris).astype(np.float64)
    if np.einsum("ij,ij->i", normals, skin - skin.mean(axis=0)).mean() < 0:
        tris, normals = tris[:, ::-1], -normals
    return skin, tris, normals


def hairline_height(normals: np.ndarray, skin_z: np.ndarray, eye_y: float, eye_z: float, hairline: dict) -> np.ndarray:
    """(N,) height (dm) below which skin facing along ``normals`` (at depths ``skin_z``)
    grows no scalp hair.

    ``hairline`` (``scalp: hairline_above_eyes_mm`` in ``facsim/data/hair.yaml``) gives it over the forehead (skin
    facing forward, +z), the temples (sideways, ±x, near the eyes), the sideburns (sideways,
    near the ears) and the nape (backward); between them it blends by the way the skin faces. Cards hanging over skin below it (a fringe over the
    forehead, long hair beside the cheeks) do not grow from it.
    """
    table = hairline
    n = np.asarray(normals, np.float64)
    w = np.stack([np.clip(n[:, 2], 0, None), np.abs(n[:, 0]), np.clip(-n[:, 2], 0, None)], axis=1) ** 2 + 1e-6
    # Skin facing sideways is temple near the eyes and sideburn near the ear.
    side = np.interp(np.asarray(skin_z, np.float64), (eye_z - 0.8, eye_z - 0.45), (table["sideburn"], table["temple"]))
    mm = (w[:, 0] * table["front"] + w[:, 1] * side + w[:, 2] * table["back"]) / w.sum(axis=1)
    return eye_y + 0.01 * mm


def scalp_density(skin: np.ndarray, normals: np.ndarray, cards: np.ndarray, triangles: np.ndarray,
                  *, floor_y=None) -> np.ndarray:
    """(N,) hair density on the skin (0 bare … 1 full cover) under a hairstyle's cards.

    A skin vertex is under the hair when its outward normal passes through a card within
    :data:`REACH`. The cover is then averaged over :data:`HAIRLINE_WIDTH` along the skin,
    so it thickens over that width from the cards' edge inward instead of stopping at it.

    Parameters
    ----------
    skin : (N, 3) float
        Skin vertices on the neutral face (dm).
    normals : (N, 3) float
        Their unit outward normals.
    cards : (P, 3) float
        Hair vertices; ``triangles`` (T, 3) index them.
    floor_y : float or (N,) float, optional
        Skin below this height is never scalp (:func:`hairline_height`).
    """
    from scipy.spatial import cKDTree

    skin = np.asarray(skin, np.float64)
    cards = np.asarray(cards, np.float64)
    triangles = np.asarray(triangles)
    # Only cards that come within reach of the skin matter (long hair hangs far from it).
    corners = cards[triangles]
    size = np.linalg.norm(corners - corners.mean(axis=1, keepdims=True), axis=2).max(axis=1)
    gap = cKDTree(skin).query(corners.mean(axis=1))[0]
    near = triangles[gap < REACH + CARD_RADIUS + size]
    if not len(near):
        return np.zeros(len(skin), np.float32)
    tree = cKDTree(card_samples(cards, near, k=8))  # a few millimetres apart on cards of a few cm
    hits = np.zeros(len(skin))
    for d in np.linspace(0.005, REACH, 8):
        near = tree.query(skin + d * normals, k=1, distance_upper_bound=CARD_RADIUS)[0]
        hits = np.maximum(hits, np.isfinite(near))
    if floor_y is not None:
        hits *= skin[:, 1] > floor_y
    # Averaged over the skin within the hairline's width (Gaussian weights): 0.5 on the
    # cards' edge, full a half-width inside it.
    pairs = cKDTree(skin).query_pairs(HAIRLINE_WIDTH, output_type="ndarray")
    i = np.concatenate([pairs[:, 0], pairs[:, 1], np.arange(len(skin))])
    j = np.concatenate([pairs[:, 1], pairs[:, 0], np.arange(len(skin))])
    w = np.exp(-np.sum((skin[i] - skin[j]) ** 2, axis=1) / (2.0 * (0.4 * HAIRLINE_WIDTH) ** 2))
    mean = np.bincount(i, weights=w * hits[j], minlength=len(skin)) / np.bincount(i, weights=w, minlength=len(skin))
    return smoothstep(0.2, 0.65, mean).astype(np.float32)


def flow_directions(skin: np.ndarray, normals: np.ndarray, cards: np.ndarray, card_triangles: np.ndarray,
                    card_uv: np.ndarray, triangles: np.ndarray, *, rise=None) -> np.ndarray:
    """(N, 3) unit direction the hair runs over each skin vertex, in the skin's tangent plane.

    Taken from the nearest cards' strands (dP/dv: MakeHuman's hair textures run along v)
    as an axis, not an arrow (the cards' v runs either way), averaged with the neighbours
    (``triangles`` over the N vertices) and then given one sense by walking the mesh, each
    vertex agreeing with the one it was reached from: strand coordinates need directions
    that agree locally, whichever way the hair is combed.

    ``rise``: optional (N,) weight (0 … 1) of the direction hair grows out of the hairline
    (:func:`rising_directions`) over the cards' flow where that runs more than about 30° off
    it. Near the hairline the cards' strands may run along it (long01's run sideways over the
    whole front), and the fine hairs taking them lay parallel to the forehead as a band of hair
    colour, a headband under the cards' edge.
    """
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import breadth_first_order, connected_components
    from scipy.spatial import cKDTree

    p = np.asarray(cards, np.float64)[card_triangles]
    uv = np.asarray(card_uv, np.float64)[card_triangles]
    e1, e2 = p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]
    d1, d2 = uv[:, 1] - uv[:, 0], uv[:, 2] - uv[:, 0]
    det = d1[:, 0] * d2[:, 1] - d2[:, 0] * d1[:, 1]
    det = np.where(np.abs(det) < 1e-12, 1e-12, det)
    tv = (-d2[:, :1] * e1 + d1[:, :1] * e2) / det[:, None]
    tv /= np.linalg.norm(tv, axis=1, keepdims=True) + 1e-12
    _, nearest = cKDTree(p.mean(axis=1)).query(skin, k=6)
    tensor = np.einsum("nki,nkj->nij", tv[nearest], tv[nearest])       # axes, sign-free
    n = len(skin)
    edges = np.concatenate([triangles[:, [0, 1]], triangles[:, [1, 2]], triangles[:, [2, 0]]])
    adjacency = coo_matrix((np.ones(2 * len(edges)), (np.r_[edges[:, 0], edges[:, 1]], np.r_[edges[:, 1], edges[:, 0]])),
                           shape=(n, n)).tocsr()
    adjacency.data[:] = 1.0
    for _ in range(2):  # a little smoothing along the skin
        tensor = tensor + (adjacency @ tensor.reshape(n, 9)).reshape(n, 3, 3) * 0.5
    proj = np.eye(3)[None] - np.einsum("ni,nj->nij", normals, normals)
    tensor = proj @ tensor @ proj
    t = np.linalg.eigh(tensor)[1][:, :, -1]                             # the principal axis
    if rise is not None:
        up = rising_directions(normals)
        cos = np.einsum("ij,ij->i", t, up)
        t *= np.where(cos < 0, -1.0, 1.0)[:, None]  # the axis's sense nearer the rise
        # Cards whose strands already rise from the hairline (short hair combed back, fanning
        # out over the temples) keep their flow; those running along it turn to rise.
        turn = np.asarray(rise, np.float64) * smoothstep(0.5, 0.85, np.sqrt(np.clip(1.0 - cos * cos, 0.0, 1.0)))
        t = t + turn[:, None] * (up - t)
    # One sense: walk each connected piece of the layer, agreeing with the predecessor.
    _, piece = connected_components(adjacency, directed=False)
    for k in np.unique(piece):
        seed = int(np.flatnonzero(piece == k)[0])
        order, parent = breadth_first_order(adjacency, seed, directed=False, return_predecessors=True)
        for v in order[1:]:
            if np.dot(t[v], t[parent[v]]) < 0:
                t[v] = -t[v]
    return (t / (np.linalg.norm(t, axis=1, keepdims=True) + 1e-12)).astype(np.float32)


def rising_directions(normals: np.ndarray) -> np.ndarray:
    """(N, 3) unit direction in the skin's tangent plane (outward ``normals`` (N, 3)) in which
    hair grows out of the hairline: up and back (over the forehead and temples the hairs rise
    off the skin toward the crown, under a fringe or a parting alike)."""
    n = np.asarray(normals, np.float64)
    up_back = np.array([0.0, 1.0, -0.5])
    t = up_back[None, :] - np.einsum("ij,j->i", n, up_back)[:, None] * n
    # skin facing up (the crown) has no "up" in its plane: back along it
    t += 1e-3 * (np.array([0.0, 0.0, -1.0])[None, :] + n[:, 2:3] * n)
    return t / (np.linalg.norm(t, axis=1, keepdims=True) + 1e-12)


def strand_coordinates(points: np.ndarray, normals: np.ndarray, flow: np.ndarray,
                       triangles: np.ndarray, *, weight=None) -> np.ndarray:
    """(N, 2) coordinates (dm) across and along the strands whose gradients best follow
    ``flow`` (least squares over the mesh's edges, as a stripe pattern is fitted to a
    direction field), so a texture tiled in them lies along the hair.

    ``weight``: optional (N,) weight of each vertex's edges in the fit. A flow that turns
    (rising from the hairline, then along the cards) has no exact fit; where it shows, the
    hairline, the fit should follow it and leave the error under the cards."""
    from scipy.sparse import coo_matrix, vstack
    from scipy.sparse.linalg import lsqr

    n = len(points)
    t = np.asarray(flow, np.float64)
    b = np.cross(np.asarray(normals, np.float64), t)
    edges = np.unique(np.sort(np.concatenate([triangles[:, [0, 1]], triangles[:, [1, 2]], triangles[:, [2, 0]]]),
                              axis=1), axis=0)
    i, j = edges[:, 0], edges[:, 1]
    e = np.asarray(points, np.float64)[j] - np.asarray(points, np.float64)[i]
    rows = np.arange(len(edges))
    w = np.ones(len(edges)) if weight is None else 0.5 * (np.asarray(weight, np.float64)[i] + np.asarray(weight, np.float64)[j])
    d = coo_matrix((np.r_[-w, w], (np.r_[rows, rows], np.r_[i, j])), shape=(len(edges), n))
    tie = coo_matrix((np.full(n, 1e-3), (np.arange(n), np.arange(n))), shape=(n, n))  # fixes the offsets
    a = vstack([d, tie]).tocsr()
    out = np.empty((n, 2), np.float32)
    for k, axis in enumerate((b, t)):
        target = w * np.einsum("ij,ij->i", e, 0.5 * (axis[i] + axis[j]))
        out[:, k] = lsqr(a, np.r_[target, np.zeros(n)], atol=1e-8, btol=1e-8, iter_lim=4000)[0]
    return out


@lru_cache(maxsize=1)
def strand_texture(size: int = 256, seed: int = 13) -> np.ndarray:
    """(size, size, 4) uint8 RGBA tile of fine hair running along v (image rows), periodic
    in both directions.

    R: brightness (0.5 = mean). G: rank (0 … 1, uniform) of small tufts a fraction of a
    millimetre wide and several long; the shader keeps the tufts whose rank is under the
    local density, so a thinning hairline breaks into separate tufts and single hairs rather
    than fading like a film. B: unused. A: the hairs' cover inside a tuft.
    """
    rng = np.random.default_rng(seed)
    fu = np.fft.fftfreq(size)[None, :]
    fv = np.fft.fftfreq(size)[:, None]

    def field(width_u: float, width_v: float) -> np.ndarray:
        """Periodic Gaussian-filtered noise: ``width_*`` the correlation length in texels."""
        noise = np.fft.fft2(rng.standard_normal((size, size)))
        f = np.real(np.fft.ifft2(noise * np.exp(-2.0 * np.pi ** 2 * ((fu * width_u) ** 2 + (fv * width_v) ** 2))))
        return (f - f.mean()) / (f.std() + 1e-12)

    tufts = field(16.0, 50.0)  # about 0.6 mm across, 4 mm along (TILE)
    rank = np.empty(size * size)
    rank[np.argsort(tufts, axis=None)] = np.linspace(0.0, 1.0, size * size)  # uniform ranks
    strands = field(1.5, 20.0)
    alpha = 0.6 + 0.4 * smoothstep(-0.8, 0.6, strands)
    bright = 0.5 + 0.2 * np.tanh(field(6.0, 60.0)) + 0.08 * np.tanh(field(1.5, 20.0))  # streaks along the flow
    out = np.empty((size, size, 4), np.uint8)
    out[..., 0] = np.clip(bright * 255 + 0.5, 0, 255)
    out[..., 1] = np.clip(rank.reshape(size, size) * 255 + 0.5, 0, 255)
    out[..., 2] = 128
    out[..., 3] = np.clip(alpha * 255 + 0.5, 0, 255)
    return out


@dataclass(frozen=True, eq=False)
class ScalpLayer:
    """The scalp hair under a hairstyle (:func:`scalp_layer`).

    Attributes
    ----------
    vertices : (K,) int
        Skin geometry vertices the layer covers (its vertex ``i`` lies over ``vertices[i]``).
    triangles : (M, 3) int32
        Its triangles over those K vertices (the skin's own, wound outward).
    density : (K,) float32
        Hair density (0 bare … 1 full cover) per vertex.
    uv : (K, 2) float32
        Strand coordinates in texture tiles (:data:`TILE`): u across the strands, v along.
    normals : (K, 3) float32
        The skin's outward normals there at neutral (the layer is lifted along them).
    hairline : (K,) float32 or None
        Each vertex's distance inside the hairline in :data:`CROP_EDGE` widths. A close crop's:
        along the skin from its own hairline (:func:`crop_hairline`); the renderer thins the hair
        over the band from 0 to 1 per pixel, so the hairline is a smooth curve however coarse the
        skin's triangles. Under a hairstyle's cards: the height above :func:`hairline_height`;
        the renderer lights the hairs near it in the open (the cards' edge stands off the skin
        there, and its shadow on the hairs under it drew a dark brim along the forehead).
    """

    vertices: np.ndarray
    triangles: np.ndarray
    density: np.ndarray
    uv: np.ndarray
    normals: np.ndarray
    hairline: np.ndarray | None = None

    def to_array(self) -> np.ndarray:
        """One (1 + K + M, 8) float64 array (for the disk cache; :meth:`from_array` reads it):
        a header row (K, M), a row per vertex (vertex, density, u, v, normal, hairline (NaN
        without one)), a row per triangle."""
        k, m = len(self.vertices), len(self.triangles)
        out = np.zeros((1 + k + m, 8))
        out[0, :2] = k, m
        hairline = np.full(k, np.nan) if self.hairline is None else self.hairline
        out[1 : 1 + k] = np.column_stack([self.vertices, self.density, self.uv, self.normals, hairline])
        out[1 + k :, :3] = self.triangles
        return out

    @classmethod
    def from_array(cls, array: np.ndarray) -> ScalpLayer:
        k, m = (int(x) for x in array[0, :2])
        rows, tris = array[1 : 1 + k], array[1 + k : 1 + k + m, :3]
        hairline = None if np.isnan(rows[:, 7]).all() else rows[:, 7].astype(np.float32)
        return cls(vertices=rows[:, 0].astype(np.int64), triangles=tris.astype(np.int32),
                   density=rows[:, 1].astype(np.float32), uv=rows[:, 2:4].astype(np.float32),
                   normals=rows[:, 4:7].astype(np.float32), hairline=hairline)


def off_the_ears(skin: np.ndarray, normals: np.ndarray, grown: np.ndarray) -> np.ndarray:
    """(N,) 1 where skin faces out from the skull (as the ``grown`` (N,) bool skin does, on the
    whole), 0 on the ears, whose skin faces up and back: a hairstyle's footprint covers them,
    but a close crop grows no hair on their rims."""
    points = skin[grown]
    centre = points.mean(axis=0) - np.array([0.0, 0.3 * np.ptp(points[:, 1]), 0.0])
    radial = (skin - centre) / (np.linalg.norm(skin - centre, axis=1, keepdims=True) + 1e-12)
    return smoothstep(0.45, 0.75, np.einsum("ij,ij->i", radial, normals))


def thin_skin(skin: np.ndarray, normals: np.ndarray, *, depths=(0.05, 0.3), tolerance: float = 0.04) -> np.ndarray:
    """(N,) bool: skin with skin again close behind it (within ``depths`` (dm) along the
    inward normal, to ``tolerance``): the ears, thin flaps standing off the head, not the
    scalp, behind which lies the skull."""
    from scipy.spatial import cKDTree

    skin = np.asarray(skin, np.float64)
    tree = cKDTree(skin)
    thin = np.zeros(len(skin), bool)
    for d in np.arange(depths[0], depths[1] + 1e-9, 0.015):
        thin |= np.isfinite(tree.query(skin - d * normals, distance_upper_bound=tolerance)[0])
    return thin


def crop_hairline_height(skin: np.ndarray, normals: np.ndarray, eye_y: float, hairline: list) -> np.ndarray:
    """(N,) height (dm) of a close crop's hairline over each skin vertex: ``hairline``
    (``hairline_mm`` of its ``crops:`` entry in ``facsim/data/hair.yaml``), pairs of (azimuth in
    degrees around the head's vertical axis from the front, height in mm above the eyes'
    centres ``eye_y``), interpolated (the two sides alike). The axis runs through the middle
    of the cranium (the skin 3 cm above the eyes). Skin facing in toward the axis and down
    (under the jaw, where the throat lies behind the axis's front) grows none (infinite)."""
    skin = np.asarray(skin, np.float64)
    cranium = skin[skin[:, 1] > eye_y + 0.3]
    x, z = skin[:, 0] - cranium[:, 0].mean(), skin[:, 2] - cranium[:, 2].mean()
    azimuth = np.degrees(np.abs(np.arctan2(x, z)))
    table = np.asarray(hairline, np.float64)
    height = eye_y + 0.01 * np.interp(azimuth, table[:, 0], table[:, 1])
    outward = (normals[:, 0] * x + normals[:, 2] * z) / (np.hypot(x, z) + 1e-9)
    return np.where((outward > -0.2) | (normals[:, 1] > 0.5), height, np.inf)


def crop_hairline(skin: np.ndarray, triangles: np.ndarray, inside: np.ndarray, *,
                  rounding: float = CROP_ROUNDING) -> np.ndarray:
    """(N,) signed distance (dm) of each skin vertex (``triangles`` (T, 3) over them) from the
    edge of the region ``inside`` (N,) bool, positive inside, with the edge rounded over
    ``rounding``.

    The edge is where the region's share of the skin around each vertex (Gaussian weights of
    sd ``rounding``) crosses one half, traced through the triangles: it runs between the
    vertices in and out, rounding off the steps a centimetre mesh draws (scalloped temples).
    The distance from it varies about linearly across the skin's triangles, so the renderer
    can place a hairline a few millimetres wide anywhere inside them.
    """
    from scipy.spatial import cKDTree

    skin = np.asarray(skin, np.float64)
    triangles = np.asarray(triangles)
    pairs = cKDTree(skin).query_pairs(3.0 * rounding, output_type="ndarray")
    i = np.concatenate([pairs[:, 0], pairs[:, 1], np.arange(len(skin))])
    j = np.concatenate([pairs[:, 1], pairs[:, 0], np.arange(len(skin))])
    w = np.exp(-np.sum((skin[i] - skin[j]) ** 2, axis=1) / (2.0 * rounding ** 2))
    share = (np.bincount(i, weights=w * np.asarray(inside, np.float64)[j], minlength=len(skin))
             / np.bincount(i, weights=w, minlength=len(skin))) - 0.5
    # The edge: points along the half-share line in every triangle it crosses (each edge it
    # crosses gives one, and a few between the two of a triangle, so it is sampled densely).
    edges = np.concatenate([triangles[:, [0, 1]], triangles[:, [1, 2]], triangles[:, [2, 0]]])
    crossing = np.sign(share[edges[:, 0]]) != np.sign(share[edges[:, 1]])
    t = share[edges[:, 0]] / np.where(crossing, share[edges[:, 0]] - share[edges[:, 1]], 1.0)
    points = skin[edges[:, 0]] + np.clip(t, 0.0, 1.0)[:, None] * (skin[edges[:, 1]] - skin[edges[:, 0]])
    cut = crossing.reshape(3, -1).T                                    # (T, 3) which sides it crosses
    ends = points.reshape(3, -1, 3).transpose(1, 0, 2)                  # (T, 3 sides, 3)
    two = cut.sum(axis=1) == 2
    a = ends[two][cut[two]].reshape(-1, 2, 3)
    steps = np.linspace(0.0, 1.0, 6)[:, None, None]
    samples = (a[None, :, 0] * (1.0 - steps) + a[None, :, 1] * steps).reshape(-1, 3)
    samples = np.concatenate([samples, points[crossing]])
    if not len(samples):
        return np.where(share > 0, 1.0, -1.0)
    distance = cKDTree(samples).query(skin)[0]
    return np.where(share > 0, distance, -distance)


def scalp_layer(head, neutral_geometry: np.ndarray, cards: np.ndarray, card_triangles: np.ndarray,
                card_uv: np.ndarray, *, eye_y: float, eye_z: float, hairline: dict,
                crop: list | None = None) -> ScalpLayer | None:
    """The scalp hair layer under a hairstyle's cards (``cards`` (P, 3) on the neutral face,
    ``card_triangles`` over them, ``card_uv`` (P, 2)), or None where they cover no skin.

    ``eye_y``, ``eye_z``: the eyes' centres' height and depth (the hairline is placed from them).
    ``crop``: the layer is a close crop (no cards drawn) and this its hairline
    (:func:`crop_hairline_height`): hair on the skin above it but the ears, its edge rounded
    off (:func:`crop_hairline`), the density full :data:`CROP_EDGE` inside it. The cards then
    only lay out the strand coordinates.
    """
    n_skin = head.skin_vertex_count
    skin, tris, normals = outward_skin(head, neutral_geometry)
    floor_y = hairline_height(normals, skin[:, 2], eye_y, eye_z, hairline)
    density = scalp_density(skin, normals, cards, card_triangles, floor_y=floor_y)
    # Under cards: the height above the table's hairline, in the same widths (the hairs
    # there grow in the open, however full their density: the shader lights them so).
    above = np.clip((skin[:, 1] - floor_y) / CROP_EDGE, -6.0, 6.0).astype(np.float32)
    if crop is not None:
        # The hairline: the table's, on the skin off the ears, rounded off.
        grown = skin[:, 1] > crop_hairline_height(skin, normals, eye_y, crop)
        ears = off_the_ears(skin, normals, grown) * ~thin_skin(skin, normals)
        above = crop_hairline(skin, tris, grown & (ears > 0.5)) / CROP_EDGE
        # None on the ears' own skin, however near the scalp it lies: their skin faces away from
        # the skull's centre (the hair ends where it turns, at the ear's root).
        above = np.clip(np.minimum(above, 10.0 * (ears - 0.5)), -6.0, 6.0).astype(np.float32)
        density = smoothstep(0.0, 1.0, above).astype(np.float32)
        keep = tris[(above[tris] > -3.0).any(axis=1)]   # the band, and room for it to wander
        rise = None
    else:
        # The hair thins toward the hairline over a few millimetres (it was full cover up to the
        # first row of skin above it, a band of hair colour along the forehead) ...
        density = density * smoothstep(0.0, HAIRLINE_THINNING / CROP_EDGE, above)
        keep = tris[(density[tris] > 0.0).any(axis=1)]
        # ... and over the forehead its hairs rise from it up and back, under the cards, rather
        # than running along it as the cards' strands may. Only where the skin faces forward:
        # at the temples the hairline runs up and down, and hair swept back there already grows
        # away from it (george's fan); at the nape hair hangs down.
        rise = ((1.0 - smoothstep(HAIRLINE_RISE[0] / CROP_EDGE, HAIRLINE_RISE[1] / CROP_EDGE, above))
                * smoothstep(0.25, 0.55, normals[:, 2]))
    if not len(keep):
        return None
    vertices = np.unique(keep)
    local = np.full(n_skin, -1, np.int64)
    local[vertices] = np.arange(len(vertices))
    triangles = local[keep]
    flow = flow_directions(skin[vertices], normals[vertices], cards, card_triangles, card_uv, triangles,
                           rise=None if rise is None else rise[vertices])
    uv = strand_coordinates(skin[vertices], normals[vertices], flow, triangles,
                            weight=None if rise is None else 1.0 + RISE_FIT_WEIGHT * rise[vertices])
    uv /= np.asarray(TILE, np.float32)
    return ScalpLayer(vertices=vertices, triangles=triangles.astype(np.int32), density=density[vertices],
                      uv=uv.astype(np.float32), normals=normals[vertices].astype(np.float32),
                      hairline=above[vertices])


def card_cover(cards: np.ndarray, skin: np.ndarray, density: np.ndarray, *, reach: float = 0.06) -> np.ndarray:
    """(V,) the scalp's hair density under each card vertex, for the cards to thin with it.

    Cards within ``reach`` of the skin over a thinning hairline (0 < density < 1) take its
    density, so they break up into strands there and fade into the scalp layer's fine hairs;
    cards away from the skin, over full cover or over bare skin the scalp layer leaves alone
    (a fringe over the forehead) keep 1.

    Parameters
    ----------
    cards : (V, 3) float
        Hair vertices on the neutral face.
    skin, density : (N, 3), (N,) float
        Skin vertices and the scalp's hair density there (0 where none grows).
    """
    from scipy.spatial import cKDTree

    distance, nearest = cKDTree(np.asarray(skin, np.float64)).query(np.asarray(cards, np.float64))
    d = np.asarray(density, np.float64)[nearest]
    thinning = (1.0 - d) * smoothstep(0.0, 0.15, d) * smoothstep(reach, 0.5 * reach, distance)
    return (1.0 - thinning).astype(np.float32)


def card_samples(points: np.ndarray, triangles: np.ndarray, *, k: int = 4) -> np.ndarray:
    """Points spread over the cards (a barycentric grid of ``k`` steps per triangle), so
    distances to the hair are distances to its cards, not to its sparse vertices (cards
    are a few centimetres across)."""
    tri = np.asarray(points, np.float64)[np.asarray(triangles)]
    a, b = np.meshgrid(np.arange(k + 1), np.arange(k + 1), indexing="ij")
    keep = a + b <= k
    bary = np.stack([a[keep], b[keep], k - a[keep] - b[keep]], axis=1) / k
    return np.einsum("sk,tkd->tsd", bary, tri).reshape(-1, 3)


def split_edges(triangles: np.ndarray, points: np.ndarray, normals: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Each triangle split in four at its edges' midpoints, the midpoints raised onto the
    smooth surface through ``points`` (V, 3) with ``normals`` (V, 3, unit).

    A close crop is a layer over the skin (no cards), so its outline is the head's: hm08's
    scalp triangles are a centimetre or two across, and the crop's silhouette showed their
    facets (blind review, session 18). An edge's midpoint is raised ``(b - a)·(n_b - n_a) / 8``
    along its ends' mean normal (on a sphere of radius r, |b - a|² / 8r: the arc's rise over
    its chord for short edges), as PN triangles do.

    Returns ``(edges, triangles, bulge)``: the (E, 2) vertex pairs of the new vertices V … V+E-1,
    the (4T, 3) triangles over the V + E vertices (winding kept), and each new vertex's
    (E, 3) offset from its edge's midpoint.
    """
    t = np.asarray(triangles, np.int64)
    pairs = np.concatenate([t[:, [0, 1]], t[:, [1, 2]], t[:, [2, 0]]])
    edges, inverse = np.unique(np.sort(pairs, axis=1), axis=0, return_inverse=True)
    mid = len(points) + inverse.reshape(3, -1).T          # (T, 3): midpoints of edges 01, 12, 20
    a, b, c = t.T
    ab, bc, ca = mid.T
    out = np.concatenate([np.stack([a, ab, ca], 1), np.stack([ab, b, bc], 1), np.stack([ca, bc, c], 1),
                          np.stack([ab, bc, ca], 1)])
    p = np.asarray(points, np.float64)
    n = np.asarray(normals, np.float64)
    d = p[edges[:, 1]] - p[edges[:, 0]]
    rise = np.einsum("ij,ij->i", d, n[edges[:, 1]] - n[edges[:, 0]]) / 8.0   # > 0 where convex
    mean = n[edges[:, 0]] + n[edges[:, 1]]
    mean /= np.linalg.norm(mean, axis=1, keepdims=True) + 1e-12
    return edges, out.astype(np.int32), (rise[:, None] * mean).astype(np.float32)
