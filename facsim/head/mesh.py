"""The head model: hm08's head and neck, capped, with eyes, teeth, tongue and lashes.

Built once from :class:`~facsim.assets.FaceData` (topology only depends on the
base mesh); a character's positions are then a cheap gather from its morphed
base vertices (:meth:`HeadModel.positions`).

Geometry vertices are the points engines move (one per mesh point: the skin,
the parts and the generated eyeballs). Render vertices split them at UV seams;
:attr:`HeadModel.topology` is what the renderer uploads once.

Examples
--------
>>> from facsim.head.assets import load_face_data           # doctest: +SKIP
>>> head = build_head(load_face_data())                 # doctest: +SKIP
>>> head.positions(head.base_vertices).shape            # doctest: +SKIP
(5210, 3)
"""
from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property

import numpy as np

from facsim.head.assets import PAINT_UV_BOX

#: The head model's regions ...
HEAD_REGIONS = ("skin", "mouth_interior", "teeth", "tongue", "eyeball", "lashes")
#: ... and every region name (the body's garment too, :mod:`facsim.head.body`);
#: ``RenderTopology.region`` holds indices into this tuple.
REGIONS = HEAD_REGIONS + ("garment",)


@dataclass(frozen=True, eq=False)
class RenderTopology:
    """Static mesh description, uploaded once per :class:`~facsim.render.Renderer`.

    Parameters
    ----------
    faces : (M, 3) uint32
        Triangles as indices into render vertices.
    render_to_geo : (R,) int
        Render vertex -> geometry vertex. Render vertices are split at UV seams; normals are
        computed on geometry vertices so seams do not show.
    uv : (R, 2) float32
        Skin UVs (MakeHuman layout, v up, [0, 1]); unused (zeros, say) for non-skin.
    region : (R,) uint8
        Index into :data:`REGIONS` per render vertex. A triangle takes the region most of
        its vertices have (the first vertex's when all three differ).
    eye_coord : (R, 3) float32
        For eyeball vertices, the unit direction from the eye centre in the eye's own
        (unrotated) frame, +Z = gaze; zeros elsewhere.
    """

    faces: np.ndarray
    render_to_geo: np.ndarray
    uv: np.ndarray
    region: np.ndarray
    eye_coord: np.ndarray

    def __post_init__(self):
        faces = np.ascontiguousarray(self.faces, dtype=np.uint32)
        r2g = np.ascontiguousarray(self.render_to_geo, dtype=np.int64)
        if faces.ndim != 2 or faces.shape[1] != 3 or len(faces) == 0:
            raise ValueError(f"faces must be a non-empty (M, 3) array, got shape {faces.shape}")
        if r2g.ndim != 1 or len(r2g) == 0:
            raise ValueError(f"render_to_geo must be a non-empty (R,) array, got {r2g.shape}")
        n = len(r2g)
        if faces.max() >= n:
            raise ValueError(f"faces index render vertex {faces.max()}, but there are only "
                             f"{n} (len(render_to_geo))")
        if r2g.min() < 0:
            raise ValueError("render_to_geo must be >= 0")
        uv = np.ascontiguousarray(self.uv, dtype=np.float32)
        region = np.ascontiguousarray(self.region, dtype=np.uint8)
        eye = np.ascontiguousarray(self.eye_coord, dtype=np.float32)
        for name, arr, shape in (("uv", uv, (n, 2)), ("region", region, (n,)),
                                 ("eye_coord", eye, (n, 3))):
            if arr.shape != shape:
                raise ValueError(f"{name} must have shape {shape} (one row per render vertex), "
                                 f"got {arr.shape}")
        if region.max() >= len(REGIONS):
            raise ValueError(f"region values must index REGIONS (0..{len(REGIONS) - 1}), "
                             f"got {region.max()}")
        for name, arr in (("faces", faces), ("render_to_geo", r2g), ("uv", uv),
                          ("region", region), ("eye_coord", eye)):
            arr.setflags(write=False)
            object.__setattr__(self, name, arr)

    @property
    def n_render(self) -> int:
        """Number of render vertices R."""
        return len(self.render_to_geo)

    @property
    def n_geo(self) -> int:
        """Number of geometry vertices referenced (positions need at least this many rows)."""
        return int(self.render_to_geo.max()) + 1

    @property
    def geo_faces(self) -> np.ndarray:
        """(M, 3) the triangles as geometry-vertex indices."""
        return self.render_to_geo[self.faces]

    def face_regions(self) -> np.ndarray:
        """(M,) region index of each triangle (majority of its vertices)."""
        r = self.region[self.faces]
        return np.where((r[:, 1] == r[:, 2]) & (r[:, 0] != r[:, 1]), r[:, 1], r[:, 0])


#: Segmentation labels that make up the head surface, its mouth and eye sockets.
HEAD_LABELS = ("head", "mouth_cavity", "eye_cavity.L", "eye_cavity.R")
#: Rings of body quads grown below the head label so the neck cut is clean.
NECK_RINGS = 4
#: Parts taken as they are from base.obj: (OBJ group, region).
PART_GROUPS = (
    ("helper-upper-teeth", "teeth"),
    ("helper-lower-teeth", "teeth"),
    ("helper-tongue", "tongue"),
    ("helper-l-eyelashes-1", "lashes"),
    ("helper-l-eyelashes-2", "lashes"),
    ("helper-r-eyelashes-1", "lashes"),
    ("helper-r-eyelashes-2", "lashes"),
)
EYE_SIDES = ("left", "right")  # the character's left is +X
#: Eyeball tessellation (rings from the back pole to the cornea, segments around).
EYE_RINGS, EYE_SEGMENTS = 24, 32
#: Joint cubes whose centres give the eye pivots and the jaw hinge.
EYE_JOINTS = {"left": "joint-l-eye", "right": "joint-r-eye"}
EYE_HELPERS = {"left": "helper-l-eye", "right": "helper-r-eye"}
JAW_HINGE_JOINT = "joint-mouth"
JAW_TIP_JOINT = "joint-jaw"
NECK_JOINT = "joint-neck"
#: hm08's lash strips are long opaque cards; drawn at this fraction of their
#: length (toward their roots on the lid) they read as lashes, not eyeliner.
LASH_LENGTH = 0.45


@dataclass(frozen=True, eq=False)  # identity-hashed: caches key on the model
class HeadModel:
    """Static head topology plus how to place it from morphed base vertices.

    Attributes
    ----------
    base_vertices : (19158, 3) float32
        The hm08 base mesh; characters add their target offsets to it.
    base_index : (N_base_geo,) int
        Geometry vertex i (for i < N_base_geo) is base vertex ``base_index[i]``.
    triangles : (M, 3) int
        Geometry triangles (for physics and exports).
    region : (N_geo,) uint8
        Index into :data:`REGIONS` per geometry vertex.
    eye_vertices : dict side -> (K,) int
        Geometry indices of each generated eyeball.
    eye_local : (K, 3) float32
        Eyeball vertex positions in the eye's own frame, radius 1, +Z = gaze.
    cap_vertex : int
        The generated centre of the neck cap.
    topology : RenderTopology
        What the renderer uploads.
    """

    base_vertices: np.ndarray
    base_index: np.ndarray
    triangles: np.ndarray
    region: np.ndarray
    eye_vertices: dict
    eye_local: np.ndarray
    cap_vertex: int
    neck_loop: np.ndarray
    joint_groups: dict
    eye_helpers: dict
    topology: RenderTopology
    skin_vertex_count: int
    lashes: np.ndarray  # geometry indices of lash vertices ...
    lash_roots: np.ndarray  # ... and of the lash vertex at the root of each one's strand
    lash_anchors: np.ndarray  # ... and of the lid skin vertex that root grows from
    masks: dict  # MakeHuman's UV masks (lips, eyelids, inside-mouth) over the paint box
    mirror: np.ndarray = field(repr=False)  # geometry index of each vertex's mirror image

    @property
    def vertex_count(self) -> int:
        return len(self.region)

    @cached_property
    def geo_of_base(self) -> np.ndarray:
        """(19158,) geometry index of each base vertex, -1 where the head model leaves it out."""
        out = np.full(len(self.base_vertices), -1, np.int64)
        out[self.base_index] = np.arange(len(self.base_index))
        out.setflags(write=False)
        return out

    def group_geometry(self, data, group: str) -> np.ndarray:
        """Geometry indices of a base-mesh vertex group (e.g. "helper-lower-teeth") kept in the head."""
        ids = self.geo_of_base[data.group_vertices(group)]
        return ids[ids >= 0]

    @cached_property
    def skin(self) -> np.ndarray:
        """Geometry indices of the skin surface (including mouth and eye sockets)."""
        return np.arange(self.skin_vertex_count)

    def positions(self, base_positions: np.ndarray, *, neutral_base=None, eye_rotations=None) -> np.ndarray:
        """Geometry positions (N_geo, 3) from morphed base positions (19158, 3).

        ``neutral_base`` is the character's neutral base mesh when ``base_positions``
        carries an expression: the eye pivots are measured on it (expression targets
        must not move the eyeballs), and lashes follow the lid skin they grow from
        (some targets move the lids but not the lash cards). ``eye_rotations`` maps
        "left"/"right" to a 3×3 rotation about the eye centre.
        """
        neutral = base_positions if neutral_base is None else neutral_base
        out = np.empty((self.vertex_count, 3), np.float32)
        out[: len(self.base_index)] = base_positions[self.base_index]
        for side in EYE_SIDES:
            centre, radius = self.eye_pivot(neutral, side)
            local = self.eye_local if not eye_rotations else self.eye_local @ np.asarray(eye_rotations[side]).T
            out[self.eye_vertices[side]] = centre + radius * local
        if neutral_base is not None:
            skin_moved = out[self.lash_anchors] - neutral[self.base_index[self.lash_anchors]]
            root_moved = out[self.lash_roots] - neutral[self.base_index[self.lash_roots]]
            out[self.lashes] += skin_moved - root_moved
        roots = out[self.lash_roots]
        out[self.lashes] = roots + LASH_LENGTH * (out[self.lashes] - roots)
        out[self.cap_vertex] = out[self.neck_loop].mean(axis=0)
        return out

    def joint(self, base_positions: np.ndarray, name: str) -> np.ndarray:
        """Centre of MakeHuman joint cube ``name`` (e.g. "joint-mouth") after morphing."""
        return base_positions[self.joint_groups[name]].mean(axis=0)

    def eye_pivot(self, base_positions: np.ndarray, side: str) -> tuple[np.ndarray, float]:
        """Centre and radius of the eyeball on ``side`` after morphing."""
        centre = self.joint(base_positions, EYE_JOINTS[side])
        helper = base_positions[self.eye_helpers[side]]
        radius = float(np.linalg.norm(helper - centre, axis=1).mean())
        return centre, radius


def build_head(data) -> HeadModel:
    """Cut the head out of hm08 and assemble the parts (see the module docstring)."""
    base = np.asarray(data.base_vertices)
    quads = np.asarray(data.quads)
    group_id = {str(n): i for i, n in enumerate(data.group_names)}
    body = data.quad_group == group_id["body"]
    head_quads = head_quad_mask(data)

    # Geometry vertices: skin, then parts, then generated eyes and the cap.
    skin = np.unique(quads[head_quads])
    part_quads = {g: data.quad_group == group_id[g] for g, _ in PART_GROUPS}
    part_vertices = [np.setdiff1d(np.unique(quads[q]), skin) for q in part_quads.values()]
    base_index = np.concatenate([skin] + part_vertices)
    base_index = base_index[np.sort(np.unique(base_index, return_index=True)[1])]
    geo_of_base = np.full(len(base), -1, np.int64)
    geo_of_base[base_index] = np.arange(len(base_index))

    region = np.zeros(len(base_index), np.uint8)
    for (group, name), q in zip(PART_GROUPS, part_quads.values()):
        region[geo_of_base[np.unique(quads[q])]] = REGIONS.index(name)
    mouth = body & _label_quads(data, ("mouth_cavity",))
    inner = geo_of_base[np.unique(quads[mouth])]
    region[inner] = REGIONS.index("mouth_interior")
    # The lips' inner rim belongs to the skin/lip shading, not to the dark cavity.
    rim = np.intersect1d(np.unique(quads[mouth]), np.unique(quads[head_quads & ~mouth]))
    region[geo_of_base[rim]] = REGIONS.index("skin")

    # Render corners: (geometry vertex, uv index) pairs, split at UV seams.
    used = head_quads | np.any(np.stack(list(part_quads.values())), axis=0)
    corner_geo = geo_of_base[quads[used]]
    corner_uv = np.asarray(data.quad_uvs)[used]
    is_skin = np.isin(quads[used], skin).all(axis=1)
    corner_uv = np.where(is_skin[:, None], corner_uv, -1)  # parts get no skin UVs

    # Eyes: UV spheres, pivoting about the eye joints.
    eye_local, eye_tris = _uv_sphere(EYE_RINGS, EYE_SEGMENTS)
    n_geo = len(base_index)
    eye_vertices, tri_parts = {}, []
    for side in EYE_SIDES:
        idx = np.arange(n_geo, n_geo + len(eye_local))
        eye_vertices[side] = idx
        tri_parts.append(eye_tris + n_geo)
        n_geo += len(eye_local)
    region = np.concatenate([region, np.full(n_geo - len(region), REGIONS.index("eyeball"), np.uint8)])

    # Neck cap: fan from a centre vertex over the boundary loop under the jaw.
    loop = _boundary_loop(geo_of_base[quads[head_quads]])
    cap_vertex = n_geo
    n_geo += 1
    region = np.concatenate([region, np.array([REGIONS.index("skin")], np.uint8)])
    cap = np.stack([np.full(len(loop), cap_vertex), np.roll(loop, -1), loop], axis=1)
    if _cap_faces_up(base[base_index], loop):
        cap = cap[:, [0, 2, 1]]

    # Render vertices: skin quads keep their UV; parts, eyes and cap are UV-less.
    tri_corners = _triangulate(np.stack([corner_geo, corner_uv], axis=-1))
    keys = tri_corners.reshape(-1, 2)
    extra = np.concatenate([np.concatenate(tri_parts), cap]).reshape(-1)
    keys = np.concatenate([keys, np.stack([extra, np.full(len(extra), -1)], axis=1)])
    uniq, inverse = np.unique(keys, axis=0, return_inverse=True)
    render_faces = inverse.reshape(-1, 3).astype(np.uint32)
    render_to_geo = uniq[:, 0]
    uv_table = np.asarray(data.uvs)
    u0, v0, u1, v1 = PAINT_UV_BOX
    uv = (uv_table[np.maximum(uniq[:, 1], 0)] - (u0, v0)) / (u1 - u0, v1 - v0)
    uv = np.where(uniq[:, 1:2] >= 0, uv, -1.0).astype(np.float32)  # outside the box: no paint
    eye_coord = np.zeros((len(uniq), 3), np.float32)
    for side in EYE_SIDES:
        hit = np.isin(render_to_geo, eye_vertices[side])
        eye_coord[hit] = eye_local[render_to_geo[hit] - eye_vertices[side][0]]

    triangles = np.concatenate([tri_corners[..., 0].reshape(-1, 3)] + tri_parts + [cap])
    joints = {n: np.unique(quads[data.quad_group == group_id[n]]) for n in (*EYE_JOINTS.values(), JAW_HINGE_JOINT, JAW_TIP_JOINT, NECK_JOINT)}
    helpers = {side: data.group_vertices(g) for side, g in EYE_HELPERS.items()}
    topology = RenderTopology(
        faces=render_faces,
        render_to_geo=render_to_geo.astype(np.int64),
        uv=uv,
        region=region[render_to_geo],
        eye_coord=eye_coord,
    )
    return HeadModel(
        base_vertices=base,
        base_index=base_index,
        triangles=triangles.astype(np.int64),
        region=region,
        eye_vertices=eye_vertices,
        eye_local=eye_local.astype(np.float32),
        cap_vertex=cap_vertex,
        neck_loop=loop,
        joint_groups=joints,
        eye_helpers=helpers,
        topology=topology,
        skin_vertex_count=len(skin),
        **_lash_roots(base[base_index], region[: len(base_index)]),
        masks={str(n): data.masks[i] for i, n in enumerate(data.mask_names)},
        mirror=_geo_mirror(np.asarray(data.mirror), base_index, eye_vertices, eye_local, n_geo),
    )


def head_quad_mask(data) -> np.ndarray:
    """(F,) bool: the base mesh's quads that make up the head's skin (the head, mouth and eye
    sockets by the segmentation, grown :data:`NECK_RINGS` rings into the neck)."""
    quads = np.asarray(data.quads)
    names = [str(n) for n in data.group_names]
    body = data.quad_group == names.index("body")
    return _grow(quads, body & _label_quads(data, HEAD_LABELS), body, NECK_RINGS)


# ------------------------------------------------------------------ helpers


def _label_quads(data, labels) -> np.ndarray:
    """Which quads the body-part segmentation image labels with one of ``labels``."""
    seg = data.segmentation
    size = seg.shape[0]
    uv = np.asarray(data.uvs)[data.quad_uvs].mean(axis=1)
    px = np.clip((uv[:, 0] * size).astype(int), 0, size - 1)
    py = np.clip(((1.0 - uv[:, 1]) * size).astype(int), 0, size - 1)
    colour = seg[py, px]
    names = [str(n) for n in data.segmentation_labels]
    wanted = np.zeros(len(uv), bool)
    for label in labels:
        wanted |= (colour == data.segmentation_colors[names.index(label)]).all(axis=1)
    return wanted


def _grow(quads, selected, allowed, rings) -> np.ndarray:
    """Add ``rings`` rings of ``allowed`` quads that share a vertex with the selection."""
    selected = selected.copy()
    for _ in range(rings):
        touched = np.zeros(quads.max() + 1, bool)
        touched[quads[selected]] = True
        selected |= allowed & touched[quads].any(axis=1)
    return selected


def _triangulate(quads):
    """Split quads (F, 4, ...) into triangles (2F, 3, ...); degenerate quads give one."""
    first = quads[:, [0, 1, 2]]
    second = quads[:, [0, 2, 3]]
    degenerate = np.all(quads[:, 2] == quads[:, 3], axis=tuple(range(1, quads[:, 2].ndim)))
    return np.concatenate([first, second[~degenerate]])


def _boundary_loop(quads: np.ndarray) -> np.ndarray:
    """The single boundary loop of a quad surface (vertex indices, in order)."""
    edges = np.concatenate([quads[:, [i, (i + 1) % 4]] for i in range(4)])
    edges = edges[edges[:, 0] != edges[:, 1]]
    key = np.sort(edges, axis=1)
    _, inverse, counts = np.unique(key, axis=0, return_inverse=True, return_counts=True)
    boundary = edges[counts[inverse.ravel()] == 1]
    nxt = dict(map(tuple, boundary))
    start = int(boundary[0, 0])
    loop = [start]
    while (v := nxt[loop[-1]]) != start:
        loop.append(v)
        if len(loop) > len(boundary):
            raise RuntimeError("head surface boundary is not a single loop")
    if len(loop) != len(boundary):
        raise RuntimeError(f"head surface has {len(boundary) - len(loop)} boundary edges off the neck loop")
    return np.array(loop, np.int64)


def _cap_faces_up(positions, loop) -> bool:
    """True if the fan (cap, next, this) would face up into the head (then flip it)."""
    pts = positions[loop]
    normal = np.cross(pts - pts.mean(0), np.roll(pts, -1, axis=0) - pts.mean(0)).sum(axis=0)
    return normal[1] < 0  # the cap must face down, out of the neck


def _uv_sphere(rings: int, segments: int) -> tuple[np.ndarray, np.ndarray]:
    """Unit sphere with poles on ±Z (the front pole at +Z is the pupil's centre)."""
    theta = np.linspace(0, np.pi, rings + 1)[1:-1]  # from +Z (front) to -Z
    phi = np.linspace(0, 2 * np.pi, segments, endpoint=False)
    t, p = np.meshgrid(theta, phi, indexing="ij")
    ring_pts = np.stack([np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), np.cos(t)], axis=-1).reshape(-1, 3)
    pts = np.concatenate([[[0, 0, 1]], ring_pts, [[0, 0, -1]]]).astype(np.float32)
    tris = []
    ring = lambda r, s: 1 + r * segments + (s % segments)  # noqa: E731
    for s in range(segments):
        tris.append([0, ring(0, s), ring(0, s + 1)])
        for r in range(rings - 2):
            a, b, c, d = ring(r, s), ring(r + 1, s), ring(r + 1, s + 1), ring(r, s + 1)
            tris += [[a, b, c], [a, c, d]]
        tris.append([len(pts) - 1, ring(rings - 2, s + 1), ring(rings - 2, s)])
    return pts, np.array(tris, np.int64)


def _lash_roots(positions, region) -> dict:
    """Pair every lash vertex with the lash vertex nearest the lid skin along its strand."""
    from scipy.spatial import cKDTree

    lashes = np.flatnonzero(region == REGIONS.index("lashes"))
    skin = np.flatnonzero(region == REGIONS.index("skin"))
    depth = cKDTree(positions[skin]).query(positions[lashes])[0]
    # Roots: the half of the lash vertices closest to the skin; each tip takes its nearest root.
    roots = lashes[depth <= np.median(depth)]
    nearest = cKDTree(positions[roots]).query(positions[lashes])[1]
    lash_roots = roots[nearest]
    anchors = skin[cKDTree(positions[skin]).query(positions[lash_roots])[1]]
    return {"lashes": lashes, "lash_roots": lash_roots, "lash_anchors": anchors}


def _geo_mirror(base_mirror, base_index, eye_vertices, eye_local, n_geo) -> np.ndarray:
    """Mirror map on geometry vertices (hm08 is exactly symmetric; eyes swap sides)."""
    mirror = np.arange(n_geo)
    geo_of_base = np.full(len(base_mirror), -1)
    geo_of_base[base_index] = np.arange(len(base_index))
    mirrored = geo_of_base[base_mirror[base_index]]
    mirror[: len(base_index)] = np.where(mirrored >= 0, mirrored, np.arange(len(base_index)))
    flipped = eye_local * np.array([-1.0, 1.0, 1.0])
    match = np.argmin(((flipped[:, None] - eye_local[None]) ** 2).sum(-1), axis=1)
    mirror[eye_vertices["left"]] = eye_vertices["right"][match]
    mirror[eye_vertices["right"]] = eye_vertices["left"][match]
    return mirror
