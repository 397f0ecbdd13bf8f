"""The tension net: skin points, bone beneath them, and the arcs between them.

Platt & Badler (1981) model the face as points (skin, muscle, bone) joined by
arcs that carry a rest length and an elasticity. This module builds that net
for a character, in two stages:

1. :func:`anatomy` — once per head *topology*: which base-mesh vertices are
   outer skin, lids, the conjunctival sac, the mouth lining; the tissue
   properties per vertex (blended from the soft zones of ``muscles.yaml``); the
   part of the skin riding the mandible; lid margins and canthi. Everything is
   chosen on the hm08 base mesh by geometric rules, so the same vertex ids hold
   on every character.
2. :func:`build_net` — once per *character*: rest lengths, spring constants,
   the skull (the skin pushed inward by its tissue depth: a bone surface that is
   thin over the forehead and nose bridge and thick over the cheeks and lips),
   skin-to-bone attachment arcs, contact data (skull, eyeballs, teeth, lips) and
   the jaw's hinge.

The jaw is a rigid bone: :func:`jaw_transform` turns a jaw pose (opening angle,
protrusion, lateral shift) into a rotation and translation about the hinge.
"""
from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from importlib import resources

import numpy as np
import scipy.sparse as sp
import yaml
from scipy.sparse.csgraph import connected_components, dijkstra
from scipy.spatial import cKDTree

from facsim.head.landmarks import landmarks
from facsim.head.mesh import REGIONS
from facsim.head.surface import smoothstep, vertex_normals

SPEC_FILE = "muscles.yaml"
#: Tissue properties blended per vertex from the zones of ``muscles.yaml``.
TISSUE_KEYS = ("stiffness", "depth", "attach", "bone", "beta", "compress", "volume")
#: Skin vertex kinds.
OUTER, LID, SOCKET, MOUTH = 0, 1, 2, 3
#: How many nearby bone sites each point may slide onto (skull contact search).
SITE_CANDIDATES = 8
SIDES = ("left", "right")


@lru_cache(maxsize=1)
def load_spec() -> dict:
    """The parsed ``facsim/data/muscles.yaml`` (tissue, jaw, muscles, pressure, tongue)."""
    text = resources.files("facsim").joinpath("data", SPEC_FILE).read_text(encoding="utf-8")
    return yaml.load(text, Loader=getattr(yaml, "CSafeLoader", yaml.SafeLoader))


# ------------------------------------------------------------ mesh helpers ---

def skin_triangles(head) -> np.ndarray:
    """(T, 3) triangles whose three corners are skin vertices."""
    tri = head.triangles
    return tri[(tri < head.skin_vertex_count).all(axis=1)]


def unique_edges(triangles: np.ndarray) -> np.ndarray:
    """(E, 2) undirected edges of a triangle list, sorted, each once."""
    e = np.concatenate([triangles[:, [0, 1]], triangles[:, [1, 2]], triangles[:, [2, 0]]])
    return np.unique(np.sort(e, axis=1), axis=0)


def bending_pairs(triangles: np.ndarray) -> np.ndarray:
    """(P, 2) the two far corners of every pair of triangles sharing an edge.

    Arcs between them resist folding and in-plane shear (the net's "bending" arcs).
    """
    corners = np.concatenate([triangles[:, [0, 1, 2]], triangles[:, [1, 2, 0]], triangles[:, [2, 0, 1]]])
    key = np.sort(corners[:, :2], axis=1)
    order = np.lexsort((key[:, 1], key[:, 0]))
    key, far = key[order], corners[order, 2]
    same = (key[1:] == key[:-1]).all(axis=1)
    pairs = np.stack([far[:-1][same], far[1:][same]], axis=1)
    pairs = pairs[pairs[:, 0] != pairs[:, 1]]
    return np.unique(np.sort(pairs, axis=1), axis=0)


def vertex_areas(positions: np.ndarray, triangles: np.ndarray, count: int) -> np.ndarray:
    """(count,) a third of the area of the triangles around each vertex."""
    area = 0.5 * np.linalg.norm(np.cross(positions[triangles[:, 1]] - positions[triangles[:, 0]],
                                         positions[triangles[:, 2]] - positions[triangles[:, 0]]), axis=1)
    return np.bincount(triangles.ravel(), np.repeat(area / 3.0, 3), minlength=count)


def adjacency(edges: np.ndarray, count: int) -> sp.csr_matrix:
    """Symmetric 0/1 adjacency matrix of an edge list."""
    a = sp.coo_matrix((np.ones(len(edges)), (edges[:, 0], edges[:, 1])), shape=(count, count))
    a = (a + a.T).tocsr()
    a.data[:] = 1.0
    return a


def smooth_field(values: np.ndarray, adj: sp.csr_matrix, iterations: int) -> np.ndarray:
    """Laplacian smoothing (average with the neighbours) of a per-vertex field."""
    degree = np.asarray(adj.sum(axis=1)).ravel() + 1.0
    for _ in range(iterations):
        values = (adj @ values + values) / (degree if values.ndim == 1 else degree[:, None])
    return values


def mask_per_vertex(head, name: str) -> np.ndarray:
    """A MakeHuman UV mask (0..1) sampled at each geometry vertex (max over its UV copies)."""
    mask = np.asarray(head.masks[name], np.float32) / 255.0
    rows, cols = mask.shape
    topo = head.topology
    uv = topo.uv
    valid = (uv >= 0).all(axis=1) & (uv <= 1).all(axis=1)
    r = np.clip((uv[:, 1] * rows).astype(int), 0, rows - 1)
    c = np.clip((uv[:, 0] * cols).astype(int), 0, cols - 1)
    sample = np.where(valid, mask[r, c], 0.0)
    out = np.zeros(head.vertex_count, np.float32)
    np.maximum.at(out, topo.render_to_geo, sample)
    return out


# ---------------------------------------------------------------- anatomy ---

@dataclass(frozen=True, eq=False)
class Anatomy:
    """What every character shares: selections and tissue fields on the base topology.

    Attributes
    ----------
    base : (N_geo, 3) float
        The hm08 base mesh as geometry vertices (the reference for all selectors).
    base_normal : (N_skin, 3) float
    kind : (N_skin,) int8
        ``OUTER``, ``LID`` (on an eyeball), ``SOCKET`` (conjunctival sac) or ``MOUTH``.
    eye_side : (N_skin,) int8
        0 left, 1 right for lid and socket vertices, -1 elsewhere.
    tissue : dict of (N_skin,) float
        :data:`TISSUE_KEYS` blended from the zones.
    jaw_weight : (N_skin,) float
        1 where the tissue is attached to the mandible, 0 to the skull.
    lip_half : (N_skin,) int8
        +1 upper lip, -1 lower lip (lips mask and the rim of the mouth), 0 elsewhere.
    rim_pairs : (P, 2) int
        Upper/lower lip rim vertices facing each other across the mouth line.
    margins : dict
        ``margins[side]["upper"|"lower"]``: lid-margin vertex ids ordered medial → lateral.
    canthi : dict
        ``canthi[side] = (medial, lateral)`` vertex ids.
    fixed : (K,) int
        The neck cut, held in place.
    """

    base: np.ndarray
    base_normal: np.ndarray
    skin_count: int
    triangles: np.ndarray
    edges: np.ndarray
    bends: np.ndarray
    kind: np.ndarray
    eye_side: np.ndarray
    tissue: dict
    jaw_weight: np.ndarray
    lip_half: np.ndarray
    rim_pairs: np.ndarray
    margins: dict
    canthi: dict
    fixed: np.ndarray
    mirror: np.ndarray
    eye_centre: dict
    eye_radius: float
    landmarks: dict
    mouth_corner: int

    @property
    def outer(self) -> np.ndarray:
        """Ids of outer skin vertices (not lids on the eyeball, socket or mouth lining)."""
        return np.flatnonzero(self.kind == OUTER)


@lru_cache(maxsize=4)
def anatomy(head) -> Anatomy:
    """Select and classify the base topology (cached per head model)."""
    spec = load_spec()
    n = head.skin_vertex_count
    base = head.positions(head.base_vertices)
    tri = skin_triangles(head)
    edges = unique_edges(tri)
    adj = adjacency(edges, n)
    normal = vertex_normals(base[:n], tri, dtype=np.float64)
    # MakeHuman's UV masks are not quite symmetric; the anatomy must be (hm08 is).
    mirror = np.asarray(head.mirror)[:n]
    lids_mask = mask_per_vertex(head, "eyelids")[:n]
    lids_mask = np.maximum(lids_mask, lids_mask[mirror])
    lips_mask = mask_per_vertex(head, "lips")[:n]
    lips_mask = np.maximum(lips_mask, lips_mask[mirror])

    kind = np.full(n, OUTER, np.int8)
    kind[head.region[:n] == REGIONS.index("mouth_interior")] = MOUTH
    eye_centre, eye_radius, eye_side = {}, 0.0, np.full(n, -1, np.int8)
    # The lid-margin mask cuts each conjunctival sac off the outer skin.
    margin_band = lids_mask > 0.5
    keep = ~margin_band[edges[:, 0]] & ~margin_band[edges[:, 1]]
    _, label = connected_components(adjacency(edges[keep], n), directed=False)
    main = np.bincount(label[~margin_band]).argmax()
    for s, side in enumerate(SIDES):
        centre, radius = head.eye_pivot(head.base_vertices, side)
        eye_centre[side], eye_radius = np.asarray(centre, float), float(radius)
        dist = np.linalg.norm(base[:n] - centre, axis=1)
        socket = (label != main) & ~margin_band & (dist < 2.5 * radius) & (kind == OUTER)
        kind[socket] = SOCKET
        eye_side[socket] = s
        reach = spec["tissue"]["lids"]["reach"] * radius
        lid = (kind == OUTER) & (dist < reach) & (base[:n, 2] > centre[2])
        kind[lid] = LID
        eye_side[lid] = s

    margins, canthi = _lid_margins(base, edges, kind, eye_side)
    tissue = _tissue_fields(spec["tissue"], base[:n], kind, eye_side, eye_centre, eye_radius,
                            lips_mask, adj)
    tissue = {key: 0.5 * (v + v[mirror]) for key, v in tissue.items()}
    lip_half, rim_pairs = _lip_halves(base[:n], edges, kind, lips_mask)
    jaw_weight = _jaw_weight(spec["jaw"], base[:n], kind, lip_half)
    jaw_weight = 0.5 * (jaw_weight + jaw_weight[mirror])
    return Anatomy(
        base=base, base_normal=normal, skin_count=n, triangles=tri, edges=edges,
        bends=bending_pairs(tri), kind=kind, eye_side=eye_side, tissue=tissue,
        jaw_weight=jaw_weight, lip_half=lip_half, rim_pairs=rim_pairs, margins=margins,
        canthi=canthi, fixed=np.asarray(head.neck_loop), mirror=np.asarray(head.mirror),
        eye_centre=eye_centre, eye_radius=eye_radius, landmarks=dict(landmarks(head)),
        mouth_corner=_mouth_corner(base[:n], edges, kind),
    )


def _mouth_corner(points, edges, kind) -> int:
    """The left corner of the mouth: the outer-skin vertex on the lips' rim furthest from the midline."""
    lining = kind == MOUTH
    rim = np.zeros(len(kind), bool)
    for a, b in (edges.T, edges[:, ::-1].T):
        rim[a[(~lining[a]) & lining[b]]] = True
    ids = np.flatnonzero(rim & (points[:, 0] > 0))
    return int(ids[np.argmax(points[ids, 0])])


def _lid_margins(base, edges, kind, eye_side):
    """Lid-margin vertices (lid skin touching the sac), split upper/lower, and the canthi."""
    touches = np.zeros(len(kind), bool)
    for a, b in (edges.T, edges[:, ::-1].T):
        hit = (kind[a] == LID) & (kind[b] == SOCKET)
        touches[a[hit]] = True
    margins, canthi = {}, {}
    for s, side in enumerate(SIDES):
        ids = np.flatnonzero(touches & (eye_side == s))
        out = np.abs(base[ids, 0])  # distance from the midline: medial → lateral
        medial, lateral = ids[np.argmin(out)], ids[np.argmax(out)]
        a, b = base[medial], base[lateral]
        t = (np.abs(base[ids, 0]) - abs(a[0])) / (abs(b[0]) - abs(a[0]))
        chord_y = a[1] + t * (b[1] - a[1])
        upper = ids[(base[ids, 1] > chord_y) & (t > 0) & (t < 1)]
        lower = ids[(base[ids, 1] <= chord_y) & (t > 0) & (t < 1)]
        margins[side] = {"upper": upper[np.argsort(np.abs(base[upper, 0]))],
                         "lower": lower[np.argsort(np.abs(base[lower, 0]))]}
        canthi[side] = (int(medial), int(lateral))
    return margins, canthi


def _zone_weight(zone, points, masks) -> np.ndarray:
    """Weight (0..1) of one tissue zone at each point: a soft ellipsoid or a mask."""
    if "mask" in zone:
        return masks[zone["mask"]]
    centre, radii = np.asarray(zone["centre"], float), np.asarray(zone["radii"], float)
    rel = points.copy()
    rel[:, 0] = np.abs(rel[:, 0]) if centre[0] > 0 else rel[:, 0]
    rho2 = (((rel - centre) / radii) ** 2).sum(axis=1)
    return np.clip(1.0 - rho2, 0.0, 1.0) ** 2


def _tissue_fields(spec, points, kind, eye_side, eye_centre, eye_radius, lips_mask, adj) -> dict:
    """Blend the zones' properties per vertex; special kinds (lids, sac, lining) override."""
    default = spec["default"]
    masks = {"lips": lips_mask}
    weights = [_zone_weight(z, points, masks) for z in spec["zones"]]
    total = np.sum(weights, axis=0)
    base_weight = np.clip(1.0 - total, 0.0, None)
    norm = base_weight + total
    fields = {}
    for key in TISSUE_KEYS:
        acc = base_weight * default[key]
        for w, zone in zip(weights, spec["zones"]):
            acc = acc + w * zone.get(key, default[key])
        fields[key] = acc / norm
    # Smooth the depth so the skull (skin minus depth) has no steps.
    fields["depth"] = smooth_field(fields["depth"], adj, 6)
    for name, code in (("lids", LID), ("socket", SOCKET), ("mouth", MOUTH)):
        sel = kind == code
        for key, value in spec[name].items():
            if key in fields:
                fields[key][sel] = value
        fields["bone"][sel] = 0.0
    # The lining near the lips is soft (it must follow the lips), firm on the gums and palate.
    lining = kind == MOUTH
    near_lips = smoothstep(1.2, 1.45, points[:, 2])
    fields["attach"][lining] *= (1.0 - (1.0 - spec["mouth"]["soft_near_lips"]) * near_lips[lining])
    return fields


#: Share of the mouth's half-width (from the midline) where lip halves follow the rims over the skin
#: (at 0.6 the tongue of AU 19 pushed the lower lip up and back instead of down).
CENTRAL_LIPS = 0.3


def _lip_halves(points, edges, kind, lips_mask):
    """Upper (+1) and lower (-1) lip vertices, and facing rim pairs across the mouth line."""
    lining = kind == MOUTH
    rim = np.zeros(len(kind), bool)
    for a, b in (edges.T, edges[:, ::-1].T):
        rim[a[(~lining[a]) & lining[b]]] = True
    rim_ids = np.flatnonzero(rim)
    # The mouth line: for each rim vertex, the mean height of rim vertices at about its x.
    x, y = points[rim_ids, 0], points[rim_ids, 1]
    corner = np.abs(x).max()
    line = np.array([y[np.abs(x - xi) < 0.03].mean() for xi in x])
    half = np.zeros(len(kind), np.int8)
    upper_rim = rim_ids[(y >= line) & (np.abs(x) < corner - 0.02)]
    lower_rim = rim_ids[(y < line) & (np.abs(x) < corner - 0.02)]
    lips = np.flatnonzero((lips_mask > 0.3) & ~lining)
    # Which lip a vertex belongs to is which rim it is nearer to over the skin (not through the
    # mouth): the upper lip's red curls down below the mouth line before it turns in to its rim,
    # and a height test gave that curl to the jaw, which then dragged the upper lip down on 26/27.
    # Toward the corners, where both rims are near, the height test stays (there it held the
    # corners as AU 14 and 20 need them).
    ref = np.interp(points[lips, 0], np.sort(x), line[np.argsort(x)])
    half[lips] = np.where(points[lips, 1] >= ref, 1, -1)
    if len(upper_rim) and len(lower_rim):
        i, j = edges[~lining[edges[:, 0]] & ~lining[edges[:, 1]]].T
        length = np.linalg.norm(points[i] - points[j], axis=1)
        graph = sp.csr_matrix((np.r_[length, length], (np.r_[i, j], np.r_[j, i])), shape=(len(kind), len(kind)))
        to_upper, to_lower = (dijkstra(graph, indices=rim_half, min_only=True) for rim_half in (upper_rim, lower_rim))
        central = lips[np.abs(points[lips, 0]) < CENTRAL_LIPS * corner]
        half[central] = np.where(to_upper[central] <= to_lower[central], 1, -1)
    half[upper_rim], half[lower_rim] = 1, -1
    if len(lower_rim):
        _, j = cKDTree(points[lower_rim]).query(points[upper_rim])
        pairs = np.stack([upper_rim, lower_rim[j]], axis=1)
    else:
        pairs = np.zeros((0, 2), int)
    return half, pairs


def _polyline(points_zy, z):
    """A (z, y) border polyline evaluated at z (flat beyond its ends)."""
    pz, py = np.asarray(points_zy, float).T
    order = np.argsort(pz)
    return np.interp(z, pz[order], py[order])


def _jaw_weight(spec, points, kind, lip_half) -> np.ndarray:
    """How much of each skin vertex's bone is the mandible (0 skull … 1 jaw)."""
    y, z = points[:, 1], points[:, 2]
    b = spec["blend"]
    upper = _polyline(spec["upper_border"], z)
    lower = _polyline(spec["lower_border"], z)
    weight = (smoothstep(-b, b, upper - y) * smoothstep(-b, b, y - lower)
              * smoothstep(spec["back"] - b, spec["back"] + b, z))
    lining = kind == MOUTH
    line = _polyline(spec["lining_border"], z)
    weight[lining] = (smoothstep(-0.02, 0.02, line - y) * smoothstep(spec["lining_back"] - 0.03,
                                                                     spec["lining_back"] + 0.03, z))[lining]
    weight[lip_half == 1] = 0.0
    weight[lip_half == -1] = 1.0
    return weight


# -------------------------------------------------------------- selectors ---

def resolve_vertex(anat: Anatomy, sel: dict, side: str = "left") -> int:
    """The base-topology skin vertex a selector names (on the character's ``side``)."""
    base, outer = anat.base, anat.outer
    if "landmark" in sel:
        name = sel["landmark"]
        if name in ("medial_canthus", "lateral_canthus"):
            vid = anat.canthi["left"][0 if name == "medial_canthus" else 1]
        elif name == "mouth_corner":
            vid = anat.mouth_corner
        else:
            marks = anat.landmarks
            vid = marks[name] if name in marks else marks[name + "_left"]
            # The project's landmarks may fall on the mouth lining; muscles insert into outer skin.
            vid = outer[np.argmin(np.linalg.norm(base[outer] - base[vid], axis=1))]
    elif "lid" in sel:
        ids = anat.margins["left"][sel["lid"]]
        ax = np.abs(base[ids, 0])
        target = ax.min() + sel["at"] * (ax.max() - ax.min())
        vid = ids[np.argmin(np.abs(ax - target))]
        if sel.get("above"):  # into the lid, away from the margin
            sign = 1.0 if sel["lid"] == "upper" else -1.0
            goal = base[vid] + [0.0, sign * sel["above"], 0.0]
            lids = np.flatnonzero(anat.kind == LID)
            vid = lids[np.argmin(np.linalg.norm(base[lids] - goal, axis=1))]
    elif "front" in sel:
        vid = _ray(base, outer, anat.base_normal, (0, 1), 2, sel["front"])
    elif "side" in sel:
        vid = _ray(base, outer, anat.base_normal, (1, 2), 0, sel["side"])
    elif "near" in sel:
        vid = outer[np.argmin(np.linalg.norm(base[outer] - sel["near"], axis=1))]
    else:
        raise ValueError(f"muscles.yaml: a skin selector needs one of front, side, near, landmark, lid; got {sel}")
    vid = int(vid)
    return vid if side == "left" else int(anat.mirror[vid])


def _ray(base, outer, normal, plane, axis, coords) -> int:
    """The outer-skin vertex hit by a ray along -axis through ``coords`` in ``plane``."""
    facing = outer[normal[outer, axis] > 0.1]
    p = base[facing]
    dist = np.hypot(p[:, plane[0]] - coords[0], p[:, plane[1]] - coords[1])
    near = dist < 0.04
    if plane[0] == 0 and abs(coords[0]) < 1e-9:  # on the midline: only midline vertices (keeps rings symmetric)
        near &= np.abs(p[:, 0]) < 1e-5
    if not near.any():
        return int(facing[np.argmin(dist)])
    return int(facing[near][np.argmax(p[near, axis])])


def patch(anat: Anatomy, centre_vertex: int, radius: float, *, kinds=(OUTER, LID)) -> tuple[np.ndarray, np.ndarray]:
    """Skin vertices within ``radius`` (base dm) of a vertex and their weights (sum 1).

    Cosine-like fall-off, as Waters' muscle zones: full at the centre, zero at the rim.
    """
    ok = np.isin(anat.kind, kinds)
    ids = np.flatnonzero(ok)
    d = np.linalg.norm(anat.base[ids] - anat.base[centre_vertex], axis=1)
    inside = d < radius
    ids, d = ids[inside], d[inside]
    w = (1.0 - (d / radius) ** 2) ** 2
    if not len(ids):
        ids, w = np.array([centre_vertex]), np.array([1.0])
    return ids, w / w.sum()


# ---------------------------------------------------------------- the net ---

@dataclass(frozen=True, eq=False)
class Arcs:
    """Springs between points: rest length, spring constant, stiffening, compression factor."""

    i: np.ndarray
    j: np.ndarray
    rest: np.ndarray
    k: np.ndarray
    beta: np.ndarray
    compress: np.ndarray

    def __len__(self) -> int:
        return len(self.i)

    @staticmethod
    def concat(parts) -> "Arcs":
        parts = [p for p in parts if len(p)]
        fields = ("i", "j", "rest", "k", "beta", "compress")
        return Arcs(*(np.concatenate([getattr(p, f) for p in parts]) for f in fields))


@dataclass(frozen=True, eq=False)
class TensionNet:
    """A character's skin net over its skull and jaw (frozen; see :func:`build_net`).

    Point arrays are over the skin vertices (the first ``N_skin`` geometry vertices).

    Attributes
    ----------
    rest : (N_skin, 3) float
        Neutral skin positions.
    normal, area : rest outward normals and vertex areas.
    arcs : Arcs
        Skin arcs (mesh edges and bending arcs) with per-region elasticity.
    depth : (N_skin,) float
        Soft-tissue depth; the skull lies at ``rest - depth * normal``.
    attach_skull, attach_jaw : (N_skin,) float
        Stiffness of each point's soft-tissue attachment to the skull and to the jaw.
    volume_k : (N_skin,) float
        Stiffness of each tissue column's volume (0 where there is no column).
    jaw_weight : (N_skin,) float
    sites, site_normal, site_on_jaw : the bone surface as samples (points with bone beneath).
    candidates : (N_skin, C) int
        Bone sites each skin point may slide onto.
    floor : (N_skin,) float
        Least tissue thickness over bone (the skin cannot be pushed closer).
    eye_ids, eye_index, eye_floor : lid/sac points, their eye (0 left, 1 right), least distance to its centre.
    eye_centre : (2, 3), eye_radius : float
    rim_pairs : (P, 2) upper/lower lip rim points facing each other.
    tether_ids, tether_anchor, tether_length, tether_k : the upper lip's tether to the maxilla
        (points, their skull anchors (T, 3), the length each may reach before it holds, stiffness).
    hinge : (3,) the jaw's hinge (temporomandibular axis along X through it).
    scale : character size relative to the base mesh (eye-centre distance ratio).
    """

    rest: np.ndarray
    normal: np.ndarray
    area: np.ndarray
    triangles: np.ndarray
    arcs: Arcs
    depth: np.ndarray
    attach_skull: np.ndarray
    attach_jaw: np.ndarray
    volume_k: np.ndarray
    jaw_weight: np.ndarray
    sites: np.ndarray
    site_normal: np.ndarray
    site_on_jaw: np.ndarray
    candidates: np.ndarray
    floor: np.ndarray
    contact_k: np.ndarray
    eye_ids: np.ndarray
    eye_index: np.ndarray
    eye_floor: np.ndarray
    eye_centre: np.ndarray
    eye_radius: float
    rim_pairs: np.ndarray
    hinge: np.ndarray
    scale: float
    constants: dict
    tether_ids: np.ndarray = None
    tether_anchor: np.ndarray = None
    tether_length: np.ndarray = None
    tether_k: np.ndarray = None
    laplacian: sp.csr_matrix = None   # (N_skin, N_skin) umbrella Laplacian of the skin
    bend_k: np.ndarray = None         # (N_skin,) bending stiffness per point

    @property
    def count(self) -> int:
        return len(self.rest)


def character_scale(head, base_positions) -> float:
    """A character's size relative to hm08's base mesh (ratio of eye-centre distances)."""
    def span(vertices):
        return np.linalg.norm(head.joint(vertices, "joint-l-eye") - head.joint(vertices, "joint-r-eye"))
    return float(span(base_positions) / span(head.base_vertices))


def carry_points(anat: Anatomy, rest: np.ndarray, points_base: np.ndarray, *, neighbours: int = 8) -> np.ndarray:
    """Carry points inside the base head to a character: add the morph's displacement around them.

    ``rest`` are the character's skin positions; the displacement field of the
    ``neighbours`` nearest skin vertices (inverse-distance weighted) moves each point.
    """
    points_base = np.atleast_2d(np.asarray(points_base, float))
    skin = anat.base[: anat.skin_count]
    outer = anat.outer
    d, j = cKDTree(skin[outer]).query(points_base, k=neighbours)
    w = 1.0 / np.maximum(d, 1e-4) ** 2
    w /= w.sum(axis=1, keepdims=True)
    shift = rest[outer][j] - skin[outer][j]
    return points_base + (w[..., None] * shift).sum(axis=1)


def build_net(head, base_positions, *, anat: Anatomy | None = None, spec: dict | None = None) -> TensionNet:
    """The tension net of a character from its neutral base mesh (19158, 3)."""
    anat = anat or anatomy(head)
    spec = spec or load_spec()
    constants = spec["net"]
    n = anat.skin_count
    rest = head.positions(np.asarray(base_positions, np.float64))[:n].astype(np.float64)
    scale = character_scale(head, base_positions)
    tri = anat.triangles
    normal = vertex_normals(rest[:n], tri, dtype=np.float64)
    area = vertex_areas(rest, tri, n)
    tissue = anat.tissue
    depth = tissue["depth"] * scale

    # Arcs: mesh edges and bending arcs, spring constants and stiffening from the tissue.
    def arcs_of(pairs, factor):
        i, j = pairs[:, 0], pairs[:, 1]
        rest_len = np.linalg.norm(rest[i] - rest[j], axis=1)
        mean = lambda key: 0.5 * (tissue[key][i] + tissue[key][j])  # noqa: E731
        # Harmonic mean of the stiffness: a soft end makes the whole arc soft (lids next to brow).
        k = 2.0 / (1.0 / tissue["stiffness"][i] + 1.0 / tissue["stiffness"][j])
        return Arcs(i, j, rest_len, factor * k, mean("beta"), mean("compress"))

    # Arcs across each pair of triangles (shear and folding) only where asked for: the
    # bending energy below holds the surface's shape more cheaply.
    parts = [arcs_of(anat.edges, 1.0)]
    if constants.get("shear_arcs", 0.0) > 0:
        parts.append(arcs_of(anat.bends, constants["shear_arcs"]))
    # Where the mouth's lining runs close under the skin (the upper vestibule beneath the nose and
    # lip), arcs through the tissue keep it there, so it neither pokes through nor is left behind.
    lining, outer = np.flatnonzero(anat.kind == MOUTH), anat.outer
    dist, near = cKDTree(rest[outer]).query(rest[lining])
    close = dist < constants["lining_tie"] * scale
    # Only to skin on the same bone: a tie from the lower lining to the upper lip's rim held the
    # lips together as the jaw opened (issue 13: 26 parted the lips 4 mm for 13 mm of chin drop).
    close &= np.abs(anat.jaw_weight[lining] - anat.jaw_weight[outer[near]]) < 0.5
    if close.any():
        i, j = lining[close], outer[near[close]]
        parts.append(Arcs(i, j, dist[close], np.full(close.sum(), 0.5), np.zeros(close.sum()), np.ones(close.sum())))
    arcs = Arcs.concat(parts)

    # Bending: the umbrella Laplacian of the skin keeps its rest value (per point, in the frame of
    # the bone beneath); stiffness ∝ D / h² — at fine mesh scales bending, not stretching, holds
    # the skin's shape (lips, lids, the corners of the mouth).
    adj = adjacency(anat.edges, n)
    degree = np.asarray(adj.sum(axis=1)).ravel()
    laplacian = (sp.identity(n) - sp.diags(1.0 / np.maximum(degree, 1)) @ adj).tocsr()
    edge_sum = np.bincount(anat.edges.ravel(), np.repeat(parts[0].rest, 2), minlength=n)
    spacing = edge_sum / np.maximum(np.bincount(anat.edges.ravel(), minlength=n), 1)
    bend_k = constants["bend_modulus"] * scale ** 2 * tissue["stiffness"] / np.maximum(spacing, 1e-3) ** 2

    # Attachments: shear of the soft tissue column (stiffness ∝ area / depth).
    column = constants["shear_modulus"] * tissue["attach"] * area / np.maximum(depth, 1e-3)
    attach_jaw = column * anat.jaw_weight
    attach_skull = column * (1.0 - anat.jaw_weight)
    attach_skull[anat.fixed] += 1e3 * column.max()  # the neck cut stays put
    volume_k = constants["bulk_modulus"] * tissue["volume"] * area / np.maximum(depth, 1e-3)
    volume_k[anat.kind != OUTER] = 0.0

    # The bone surface: every skin point with bone beneath gives a site (point and normal).
    has_bone = (tissue["bone"] > 0.5) & (anat.kind == OUTER)
    site_ids = np.flatnonzero(has_bone)
    sites = rest[site_ids] - depth[site_ids, None] * normal[site_ids]
    site_on_jaw = anat.jaw_weight[site_ids] > 0.5
    # Each point may slide onto the sites near its own anchor (same bone only).
    anchor = rest - depth[:, None] * normal
    cand = np.empty((n, SITE_CANDIDATES), np.int64)
    on_jaw = anat.jaw_weight > 0.5
    for flag in (False, True):
        pool = np.flatnonzero(site_on_jaw == flag)
        who = np.flatnonzero(on_jaw == flag)
        _, j = cKDTree(sites[pool]).query(anchor[who], k=SITE_CANDIDATES)
        cand[who] = pool[j]
    floor = constants["min_depth"] * depth
    contact_k = constants["contact"] * area / np.maximum(depth, 1e-3)
    contact_k[~has_bone] = 0.0

    # Lids and the sac rest on the eyeballs: they keep their rest gap or the clearance. So does
    # every other skin point near an eye that lies outside it at rest: the cheek that the orbital
    # ring (AU 6) pushes up under the lower lid would otherwise pass into the eyeball.
    eye_centre = np.stack([np.asarray(head.eye_pivot(base_positions, s)[0], float) for s in SIDES])
    eye_radius = float(head.eye_pivot(base_positions, "left")[1])
    side = anat.eye_side.astype(np.int64)
    dist = np.linalg.norm(rest[:, None, :] - eye_centre[None], axis=2)       # (N, 2)
    nearest = np.argmin(dist, axis=1)
    near = (dist.min(axis=1) < constants["eye_contact_reach"] * eye_radius) & (dist.min(axis=1) >= eye_radius)
    near &= anat.kind != MOUTH
    eye_ids = np.flatnonzero((side >= 0) | near)
    eye_index = np.where(side[eye_ids] >= 0, side[eye_ids], nearest[eye_ids])
    gap = np.linalg.norm(rest[eye_ids] - eye_centre[eye_index], axis=1)
    eye_floor = np.minimum(gap, eye_radius + constants["lid_clearance"] * scale)

    tether = _upper_lip_tether(anat, rest, area, depth, constants["upper_lip_tether"], scale)

    return TensionNet(
        rest=rest, normal=normal, area=area, triangles=tri, arcs=arcs, depth=depth,
        attach_skull=attach_skull, attach_jaw=attach_jaw, volume_k=volume_k,
        jaw_weight=anat.jaw_weight.copy(), sites=sites, site_normal=normal[site_ids],
        site_on_jaw=site_on_jaw, candidates=cand, floor=floor, contact_k=contact_k,
        eye_ids=eye_ids, eye_index=eye_index, eye_floor=eye_floor, eye_centre=eye_centre,
        eye_radius=eye_radius, rim_pairs=anat.rim_pairs,
        hinge=np.asarray(head.joint(base_positions, "joint-mouth"), float),
        scale=scale, constants=constants, laplacian=laplacian, bend_k=bend_k, **tether,
    )


def _upper_lip_tether(anat: Anatomy, rest, area, depth, spec: dict, scale: float) -> dict:
    """The upper lip hangs from the maxilla: each point of its middle part is tied to a skull point
    ``height`` above it by a tension-only spring that is slack for ``slack`` more than its rest length.

    Its mucosa runs up the vestibule to the gum (the labial frenum in the middle), so the lip rises
    freely (10, 12 shorten the tie) but cannot be dragged far down: without it the skin stretched
    between the lip and the opening jaw pulled the upper lip 8.6 mm down on 27 and 1-2 mm on 25,
    closing a smile's show of upper teeth (issue 13). The corners are left free (15, 20).
    """
    n = anat.skin_count
    base = anat.base[:n]
    corner = abs(base[anat.mouth_corner, 0])
    share = np.abs(base[:, 0]) / (spec["reach"] * corner)
    # The red of the upper lip and its skin up to the nose (the white lip, over the maxilla).
    white = (anat.lip_half[:n] == 0) & (anat.jaw_weight < 0.01) & (base[:, 1] > base[anat.mouth_corner, 1]) & (
        base[:, 1] < spec["top"])
    ids = np.flatnonzero(((anat.lip_half[:n] == 1) | white) & (anat.kind[:n] == OUTER) & (share < 1.0))
    weight = (1.0 - share[ids] ** 2) ** 2
    height = spec["height"] * scale
    anchor = rest[ids] + np.array([0.0, height, 0.0])
    return dict(tether_ids=ids, tether_anchor=anchor, tether_length=np.full(len(ids), height + spec["slack"] * scale),
                tether_k=spec["stiffness"] * weight * area[ids] / np.maximum(depth[ids], 1e-3))


# -------------------------------------------------------------------- jaw ---

def jaw_transform(pose, hinge, yaw_per_lateral: float) -> tuple[np.ndarray, np.ndarray]:
    """Rotation (B, 3, 3) and translation (B, 3) of the mandible for poses (B, 3).

    ``pose = (opening angle in rad, protrusion in dm, lateral shift in dm toward +X)``.
    The jaw opens about the X axis through the hinge (chin down and back), yaws a
    little toward its lateral shift, and translates. A point ``p`` on the jaw
    goes to ``R @ (p - hinge) + hinge + t``.
    """
    pose = np.atleast_2d(np.asarray(pose, float))
    angle, forward, lateral = pose[:, 0], pose[:, 1], pose[:, 2]
    yaw = yaw_per_lateral * lateral
    ca, sa, cy, sy = np.cos(angle), np.sin(angle), np.cos(yaw), np.sin(yaw)
    one, zero = np.ones_like(angle), np.zeros_like(angle)
    rx = np.stack([np.stack([one, zero, zero], -1),
                   np.stack([zero, ca, -sa], -1),
                   np.stack([zero, sa, ca], -1)], -2)
    ry = np.stack([np.stack([cy, zero, sy], -1),
                   np.stack([zero, one, zero], -1),
                   np.stack([-sy, zero, cy], -1)], -2)
    rot = ry @ rx
    shift = np.stack([lateral, zero, forward], -1)
    return rot, shift


def move_with_jaw(points, rot, shift, hinge) -> np.ndarray:
    """Points (K, 3) carried by jaw transforms (B, 3, 3), (B, 3) → (B, K, 3)."""
    rel = np.asarray(points, float) - hinge
    return np.einsum("bij,kj->bki", rot, rel) + hinge + shift[:, None, :]
