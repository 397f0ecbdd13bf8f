"""Mesh geometry for rendering, in numpy alone (no GL): normals, regions, lashes, creases.

Pure functions on positions, faces and UVs: area-weighted vertex normals through a
precomputed sparse face -> vertex matrix (:func:`normal_operator`, :func:`vertex_normals`),
the connected pieces of a region (:func:`region_components`), lash root-to-tip coordinates
(:func:`lash_coordinates`), where across a crease each vertex lies (:func:`crease_phase`),
evenly spread directions for occlusion baking (:func:`sphere_directions`), and the winding
and UV-coverage checks :class:`~facsim.render.Renderer` makes.

Examples
--------
>>> faces = np.array([[0, 1, 2]])
>>> vertex_normals(np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0]]), faces).tolist()
[[0.0, 0.0, 1.0], [0.0, 0.0, 1.0], [0.0, 0.0, 1.0]]
"""
from __future__ import annotations

import math

import numpy as np
import scipy.sparse as sp

from facsim.engines.lids import spherical
from facsim.head.mesh import REGIONS, RenderTopology
from facsim.head.surface import normal_operator, vertex_normals  # noqa: F401 — re-exported for the renderer


def region_components(topology: RenderTopology, region: str) -> list[np.ndarray]:
    """Geometry-vertex index arrays of the connected pieces of one region (e.g. each eyeball)."""
    from scipy.sparse.csgraph import connected_components

    faces = topology.geo_faces[topology.face_regions() == REGIONS.index(region)]
    if len(faces) == 0:
        return []
    verts, local = np.unique(faces, return_inverse=True)
    local = local.reshape(-1, 3)
    edges = np.concatenate([local[:, [0, 1]], local[:, [1, 2]], local[:, [2, 0]]])
    graph = sp.coo_matrix((np.ones(len(edges)), (edges[:, 0], edges[:, 1])),
                          shape=(len(verts), len(verts)))
    n, labels = connected_components(graph, directed=False)
    return [verts[labels == i] for i in range(n)]


def sphere_centre(points: np.ndarray) -> np.ndarray:
    """Least-squares centre of a sphere through ``points`` (N >= 4, not coplanar)."""
    p = np.asarray(points, dtype=float)
    a = np.c_[2.0 * p, np.ones(len(p))]
    b = np.einsum("ij,ij->i", p, p)
    sol, *_ = np.linalg.lstsq(a, b, rcond=None)
    return sol[:3]


def lash_coordinates(positions: np.ndarray, eyes: list[np.ndarray],
                     lashes: list[np.ndarray]) -> np.ndarray:
    """Root-to-tip coordinate (0 at the lid, 1 at the tip) of every lash vertex.

    Each lash piece is measured from the centre of the nearest eyeball (a sphere fitted to
    its vertices) and normalised over the piece.

    Returns
    -------
    (K,) float32 for ``np.concatenate(lashes)``; zeros when there are no eyeballs.
    """
    if not lashes:
        return np.zeros(0, dtype=np.float32)
    if not eyes:
        return np.zeros(sum(len(piece) for piece in lashes), dtype=np.float32)
    p = np.asarray(positions, dtype=np.float64)
    centres = np.array([sphere_centre(p[e]) if len(e) >= 4 else p[e].mean(0) for e in eyes])
    out = []
    for piece in lashes:
        q = p[piece]
        c = centres[np.argmin(np.linalg.norm(centres - q.mean(0), axis=1))]
        d = np.linalg.norm(q - c, axis=1)
        span = d.max() - d.min()
        out.append((d - d.min()) / span if span > 0 else np.zeros_like(d))
    return np.concatenate(out).astype(np.float32)


def teeth_normal_operator(topology: RenderTopology, faces: np.ndarray, n_vertices: int) -> sp.csr_matrix:
    """:func:`normal_operator` of ``faces`` (geometry triangles of ``topology``) whose teeth keep
    their biting edge's normals off the band's lingual slope.

    hm08's teeth bands fold at the biting edge: the outer wall turns back into the lingual
    slope there, so the edge row's averaged normals point down, and across the wall's lowest
    triangles (8 mm tall) every crown darkened toward its edge in a V-shaped facet. Here the
    lingual faces do not count toward the edge's and the outer wall's normals (the teeth's
    coordinates, :func:`facsim.head.mouth.teeth_coordinates`: height 0 at the edge, -1 on the
    lingual slope). Without teeth coordinates (all zeros) this is :func:`normal_operator`.
    """
    from facsim.head.mouth import LOWER_ROW_OFFSET

    operator = normal_operator(faces, n_vertices).tocoo()
    teeth = np.flatnonzero(topology.region == REGIONS.index("teeth"))
    height = np.full(n_vertices, np.nan, np.float32)
    h = topology.uv[teeth, 1]
    height[topology.render_to_geo[teeth]] = h - LOWER_ROW_OFFSET * (h > 0.5 * LOWER_ROW_OFFSET)
    lingual_face = (height[faces] < -0.5).any(axis=1)   # NaN (not teeth) compares false
    wall = height >= 0.0
    keep = ~(lingual_face[operator.col] & wall[operator.row])
    return sp.csr_matrix((operator.data[keep], (operator.row[keep], operator.col[keep])),
                         shape=operator.shape, dtype=np.float32)


def smoothing_operator(faces: np.ndarray, n_vertices: int) -> sp.csr_matrix:
    """Sparse (n_vertices, n_vertices) float32 matrix averaging each vertex with its one-ring
    neighbours (rows sum to one; a vertex on no face keeps its own value).

    >>> op = smoothing_operator(np.array([[0, 1, 2]]), 4)
    >>> np.round(op @ np.array([3.0, 0, 0, 5]), 6).tolist()
    [1.0, 1.0, 1.0, 5.0]
    """
    faces = np.asarray(faces, dtype=np.int64)
    edges = np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]])
    rows = np.concatenate([edges[:, 0], edges[:, 1], np.arange(n_vertices)])
    cols = np.concatenate([edges[:, 1], edges[:, 0], np.arange(n_vertices)])
    adjacency = sp.csr_matrix((np.ones(len(rows), np.float32), (rows, cols)), shape=(n_vertices, n_vertices))
    adjacency.data[:] = 1.0   # (an edge shared by two faces counts once)
    return sp.diags(1.0 / np.asarray(adjacency.sum(axis=1)).ravel()).astype(np.float32) @ adjacency


def scattered_normals(normals: np.ndarray, operator: sp.csr_matrix, passes: int = 2) -> np.ndarray:
    """Unit normals averaged over ``passes`` rings of neighbours (``operator``:
    :func:`smoothing_operator`): the surface as light that travels a few millimetres under the
    skin before it leaves sees it, without the folds and creases finer than that (subsurface
    scattering softens their shading, red most)."""
    n = np.asarray(normals, np.float32)
    for _ in range(passes):
        n = operator @ n
    length = np.linalg.norm(n, axis=1, keepdims=True)
    return np.where(length > 1e-8, n / np.maximum(length, 1e-8), normals).astype(np.float32)


def surface_curvature(positions: np.ndarray, normals: np.ndarray, operator: sp.csr_matrix) -> np.ndarray:
    """(N,) float32 signed curvature (1 / radius, per world unit) per vertex: how far each
    vertex stands off its one-ring's mean along its normal, over the ring's spread (``operator``:
    :func:`smoothing_operator`), averaged once more over the ring. Positive where the surface
    bulges toward its normal (on a sphere of radius R with outward normals about 1 / R),
    negative in hollows and creases (the shader shades those as ambient occlusion); on a plane
    0; the same whatever the mesh's density (for a ring of k neighbours at distance e the lift
    is k e² / (2 R (k + 1)) and the spread k e² / (k + 1)).
    """
    p = np.asarray(positions, np.float32)
    n = np.asarray(normals, np.float32)
    mean = operator @ p
    spread = operator @ np.einsum("ij,ij->i", p, p) - np.einsum("ij,ij->i", mean, mean)
    lift = np.einsum("ij,ij->i", p - mean, n)
    curvature = 2.0 * lift / np.maximum(spread, 1e-12)
    return np.asarray(operator @ np.where(spread > 1e-12, curvature, 0.0), np.float32)


CREASES_PER_DM = 11.0  # spacing of the creases drawn along a wrinkle field's contours: about 9 mm


def crease_phase(positions: np.ndarray, uv: np.ndarray, faces: np.ndarray,
                 wrinkle: np.ndarray, operator: sp.csr_matrix | None = None) -> np.ndarray:
    """Where across a crease each vertex lies, in crease spacings, so creases can run along
    the contours of ``wrinkle`` (for a wrinkle field that comes without its own phase): the
    distance from the UV centre along the direction in which the wrinkle changes most,
    times :data:`CREASES_PER_DM`.

    Worked out in UV space, where the face is flat (a 3-D distance would bend the lines
    over the curved forehead): the direction is the principal axis of the area-weighted
    structure tensor of the wrinkle's UV gradient around each vertex (sign-free, so it
    holds on a crease's crest, where the gradient flips), and UV distance is converted to
    surface distance with the mesh's local UV metric. The origin is fixed, so the lines do
    not swim as the wrinkle grows.

    Parameters
    ----------
    positions : (R, 3) render-vertex positions
    uv : (R, 2) render-vertex UVs
    faces : (M, 3) render triangles
    wrinkle : (R,) render-vertex wrinkle
    operator : :func:`normal_operator` of ``faces`` (face -> vertex sums)

    Returns
    -------
    (R,) float32, unsigned; 0 where the wrinkle is 0 all around or the UVs are degenerate.
    """
    p = np.asarray(positions, dtype=np.float64)
    t = np.asarray(uv, dtype=np.float64)
    w = np.asarray(wrinkle, dtype=np.float64)
    faces = np.asarray(faces)
    phase = np.zeros(len(p), dtype=np.float32)
    live = np.flatnonzero((w[faces] > 0).any(axis=1))
    if len(live) == 0:
        return phase
    f = faces[live]
    du1, du2 = t[f[:, 1]] - t[f[:, 0]], t[f[:, 2]] - t[f[:, 0]]
    det = du1[:, 0] * du2[:, 1] - du2[:, 0] * du1[:, 1]
    ok = np.abs(det) > 1e-12
    f, du1, du2, det, live = f[ok], du1[ok], du2[ok], det[ok], live[ok]
    if len(f) == 0:
        return phase
    # Gradients per unit u and v: invert [[du1.u, du2.u], [du1.v, du2.v]] by hand (batched
    # einsum on 2x2s is slow): d/du = (e1 du2.v - e2 du1.v) / det,
    # d/dv = (e2 du1.u - e1 du2.u) / det.
    cu1, cv1 = du1[:, 0] / det, du1[:, 1] / det
    cu2, cv2 = du2[:, 0] / det, du2[:, 1] / det
    dw1, dw2 = w[f[:, 1]] - w[f[:, 0]], w[f[:, 2]] - w[f[:, 0]]
    g = np.stack([dw1 * cv2 - dw2 * cv1, dw2 * cu1 - dw1 * cu2], axis=1)   # dw/d(u, v)
    e1, e2 = p[f[:, 1]] - p[f[:, 0]], p[f[:, 2]] - p[f[:, 0]]
    ju = e1 * cv2[:, None] - e2 * cv1[:, None]                            # d(xyz)/du
    jv = e2 * cu1[:, None] - e1 * cu2[:, None]                            # d(xyz)/dv
    metric = np.stack([(ju * ju).sum(1), (jv * jv).sum(1), (ju * jv).sum(1)], axis=1)
    area = 0.5 * np.abs(det)                                      # UV area as the weight
    rows = np.zeros((len(faces), 7))
    rows[live] = area[:, None] * np.stack([
        g[:, 0] ** 2, g[:, 1] ** 2, g[:, 0] * g[:, 1],
        metric[:, 0], metric[:, 1], metric[:, 2], np.ones(len(f))], axis=1)
    if operator is None:
        operator = normal_operator(faces, len(p))
    acc = operator @ rows
    verts = np.flatnonzero(acc[:, 0] + acc[:, 1] > 0)
    a = acc[verts]
    angle = 0.5 * np.arctan2(2.0 * a[:, 2], a[:, 0] - a[:, 1])  # principal axis of [[a0 a2][a2 a1]]
    d = np.stack([np.cos(angle), np.sin(angle)], 1)
    g00, g11, g01 = a[:, 3] / a[:, 6], a[:, 4] / a[:, 6], a[:, 5] / a[:, 6]
    scale = np.sqrt(np.maximum(d[:, 0] ** 2 * g00 + 2 * d[:, 0] * d[:, 1] * g01
                               + d[:, 1] ** 2 * g11, 0.0))        # dm per UV unit along d
    phase[verts] = np.abs(((t[verts] - 0.5) * d).sum(axis=1)) * scale * CREASES_PER_DM
    return phase


def sphere_directions(n: int) -> np.ndarray:
    """(n, 3) unit vectors spread evenly over the sphere (Fibonacci lattice)."""
    i = np.arange(n) + 0.5
    z = 1.0 - 2.0 * i / n
    phi = i * math.pi * (3.0 - math.sqrt(5.0))
    r = np.sqrt(1.0 - z * z)
    return np.stack([r * np.cos(phi), r * np.sin(phi), z], axis=1)


def eye_rotation(eye_coord: np.ndarray, offsets: np.ndarray) -> np.ndarray:
    """(3, 3) the orthogonal map that takes an eye's own frame to the world this frame.

    ``eye_coord`` (N, 3) are the eyeball's vertices as directions in its own frame (+Z the
    gaze), ``offsets`` (N, 3) the same vertices now, less the eyeball's centre. The best fit
    in least squares (Kabsch); a mirrored eye frame gives a reflection, which is what maps
    its directions to the world.
    """
    u, _, vt = np.linalg.svd(offsets.T @ eye_coord)
    return u @ vt


def _orientation(p: np.ndarray, faces: np.ndarray) -> float:
    """> 0 when the triangles' winding normals point away from their centroid (outward)."""
    a, b, c = p[faces[:, 0]], p[faces[:, 1]], p[faces[:, 2]]
    normals = np.cross(b - a, c - a)
    centres = (a + b + c) / 3.0
    area = np.linalg.norm(normals, axis=1)
    centroid = (centres * area[:, None]).sum(0) / max(area.sum(), 1e-30)
    return float(np.einsum("ij,ij->", centres - centroid, normals))


def _faces_touching(face_uv: np.ndarray, mask: np.ndarray) -> np.ndarray:
    """(M,) whether each triangle's UV bounding box covers any set texel of ``mask``.

    ``mask`` is (H, W) in GL row order (row 0 = v = 0); a summed-area table answers each
    box in four look-ups. Conservative: a box may hold set texels the triangle misses.
    """
    h, w = mask.shape
    sat = np.zeros((h + 1, w + 1), dtype=np.int64)
    sat[1:, 1:] = np.cumsum(np.cumsum(mask, axis=0), axis=1)
    lo = face_uv.min(axis=1)
    hi = face_uv.max(axis=1)
    c0 = np.clip(np.floor(lo[:, 0] * w).astype(np.int64) - 1, 0, w)
    c1 = np.clip(np.ceil(hi[:, 0] * w).astype(np.int64) + 1, 0, w)
    r0 = np.clip(np.floor(lo[:, 1] * h).astype(np.int64) - 1, 0, h)
    r1 = np.clip(np.ceil(hi[:, 1] * h).astype(np.int64) + 1, 0, h)
    count = sat[r1, c1] - sat[r0, c1] - sat[r1, c0] + sat[r0, c0]
    return count > 0



#: A lid margin's vertices lie in two or three rows a few degrees of arc apart (its outer
#: and inner edges); the eyeball shows up to the row nearest it. A margin's elevation is a
#: soft envelope of its vertices (the lowest row of the upper lid, the highest of the lower):
#: weighted over this many degrees of azimuth, softened over this many of elevation.
MARGIN_SMOOTHING = (2.5, 1.0)
#: Azimuth step (degrees) at which the margins' curves are sampled for distances to them.
MARGIN_STEP = 1.0
#: Eyeball vertices further than this (degrees) above or below a margin get their vertical
#: distance to it, not the distance to its curve.
MARGIN_NEAR = 12.0


def margin_elevation(lam: np.ndarray, m_lam: np.ndarray, m_phi: np.ndarray, *, lowest: bool = True) -> np.ndarray:
    """A lid margin's elevation (degrees) at azimuths ``lam``, from its vertices' azimuths
    ``m_lam`` and elevations ``m_phi``: the soft lower (``lowest``, the upper lid) or upper
    envelope of the rows near each azimuth (:data:`MARGIN_SMOOTHING`), so the edge is as
    smooth as a lid's and does not zigzag between the rows. Held at the end values beyond
    the corners.

    >>> m_lam, m_phi = np.array([-10.0, -1.0, 1.0, 10.0]), np.array([5.0, 4.0, 9.0, 5.0])
    >>> [round(float(x), 1) for x in margin_elevation(np.array([0.0, 50.0]), m_lam, m_phi)]
    [4.7, 5.0]
    >>> [round(float(x), 1) for x in margin_elevation(np.array([0.0, 50.0]), m_lam, m_phi, lowest=False)]
    [8.3, 5.0]
    """
    width, soft = MARGIN_SMOOTHING
    sign = 1.0 if lowest else -1.0
    lam = np.clip(np.asarray(lam, np.float64), m_lam.min(), m_lam.max())
    log_w = -(((lam[:, None] - m_lam[None, :]) / width) ** 2) - sign * m_phi[None, :] / soft
    top = log_w.max(axis=1, keepdims=True)
    norm = -(((lam[:, None] - m_lam[None, :]) / width) ** 2)
    top_n = norm.max(axis=1, keepdims=True)
    log_mean = (np.log(np.exp(log_w - top).sum(axis=1)) + top[:, 0]) - (np.log(np.exp(norm - top_n).sum(axis=1)) + top_n[:, 0])
    return -sign * soft * log_mean


def lid_elevations(positions: np.ndarray, centre: np.ndarray, eye: np.ndarray, upper: np.ndarray,
                   lower: np.ndarray) -> np.ndarray:
    """How far (degrees of eyeball arc) each of one eyeball's vertices ``eye`` lies below its
    upper lid's margin and above its lower lid's, about the eyeball's ``centre``.

    (N_eye, 2) float32: column 0 is the distance to the upper margin, column 1 to the lower
    one, both positive on the eyeball that shows between the lids (on its side of the margin)
    and negative beyond. A distance is to the nearest point of the margin's curve
    (:func:`margin_elevation` sampled along its azimuths), not straight up or down: near the
    corners, where the margins turn steeply, a band drawn at a fixed distance hugs the lid
    instead of cutting across the sclera. The eyeball shader draws what lies along the margins from them (the lash line's
    shadow under the upper lid, the wet rim and tear line over the lower one): they follow
    the lids in every frame (5 bares lit sclera, 43 closes the shadow away).

    >>> p = np.array([[0.0, 0, 1], [0.0, 0.5, 0.87], [0.1, 0.5, 0.86], [0.0, -0.5, 0.87], [0.1, -0.5, 0.86]])
    >>> [round(float(x)) for x in lid_elevations(p, np.zeros(3), np.array([0]), np.array([1, 2]), np.array([3, 4]))[0]]
    [30, 30]
    """
    p = np.asarray(positions)
    lam, phi = spherical(p[eye].astype(np.float64), centre)
    out = np.full((len(eye), 2), 90.0)
    radius = np.linalg.norm(p[eye] - centre, axis=1).max()
    for k, (margin, sign) in enumerate(((upper, 1.0), (lower, -1.0))):
        # Margin vertices tucked in behind the eyeball's surface (at the canthi) are hidden
        # by it: the edge the eye shows against is the lid's part in front of it.
        outside = margin[np.linalg.norm(p[margin] - centre, axis=1) > 0.97 * radius]
        margin = outside if len(outside) >= 2 else margin
        if len(margin) < 2:
            continue
        m_lam, m_phi = spherical(p[margin].astype(np.float64), centre)
        vertical = sign * (margin_elevation(lam, m_lam, m_phi, lowest=sign > 0) - phi)
        out[:, k] = vertical
        # Only what lies near the margin needs the distance to its curve (the bands drawn
        # from it are a few degrees wide); further off, straight up or down will do.
        near = np.flatnonzero(np.abs(vertical) < MARGIN_NEAR)
        c_lam = np.arange(m_lam.min(), m_lam.max() + MARGIN_STEP, MARGIN_STEP)
        c_phi = margin_elevation(c_lam, m_lam, m_phi, lowest=sign > 0)
        # Equirectangular distances: the visible eye spans well under 60 degrees of elevation.
        d_lam = (lam[near, None] - c_lam[None, :]) * np.cos(np.radians(phi[near, None]))
        dist = np.sqrt((d_lam ** 2 + (phi[near, None] - c_phi[None, :]) ** 2).min(axis=1))
        out[near, k] = np.where(vertical[near] < 0.0, -1.0, 1.0) * np.minimum(dist, np.abs(vertical[near]))
    return out.astype(np.float32)


#: The upper lid's crease (the supratarsal fold, where the levator's fibres pull the lid skin
#: in): its height above the lid margin at rest (dm), half-width (dm) and shade.
LID_CREASE = (0.07, 0.012, 0.3)


def lid_crease_weights(rest: np.ndarray, centre: np.ndarray, skin: np.ndarray, upper: np.ndarray,
                       radius: float) -> tuple[np.ndarray, np.ndarray]:
    """The skin vertices of the upper lid's crease, chosen once at rest: (vertices, weights in
    (0, 1]) of those within two half-widths of :data:`LID_CREASE`'s height above the margin
    (measured straight up from the margin at the vertex's azimuth, in front of the eyeball)."""
    p = np.asarray(rest, dtype=np.float64)
    near = skin[(np.linalg.norm(p[skin] - centre, axis=1) < 1.6 * radius) & (p[skin, 2] > centre[2])]
    height = _height_above(p, centre, near, upper)
    h0, w, _ = LID_CREASE
    keep = np.abs(height - h0) < 2.0 * w
    return near[keep], np.exp(-((height[keep] - h0) / w) ** 2)


def lid_crease_shade(positions: np.ndarray, centre: np.ndarray, vertices: np.ndarray, weights: np.ndarray,
                     upper: np.ndarray, rest_height: np.ndarray) -> np.ndarray:
    """Shade (K,) of the crease ``vertices``: deepest when the lid is raised (5 folds more lid
    skin into it), gone as the lid closes (the skin above the margin is stretched flat)."""
    height = _height_above(np.asarray(positions), centre, vertices, upper)
    deepen = np.clip(1.0 + (rest_height - height) / 0.03, 0.0, 1.6)
    return (1.0 - LID_CREASE[2] * weights * deepen).astype(np.float32)


def _height_above(p: np.ndarray, centre: np.ndarray, vertices: np.ndarray, upper: np.ndarray) -> np.ndarray:
    """Height (dm) of ``vertices`` above the upper margin at their azimuth about ``centre``."""
    lam, _ = spherical(p[vertices].astype(np.float64), centre)
    m_lam, _ = spherical(p[upper].astype(np.float64), centre)
    order = np.argsort(m_lam)
    return p[vertices, 1] - np.interp(lam, m_lam[order], p[upper, 1][order])
