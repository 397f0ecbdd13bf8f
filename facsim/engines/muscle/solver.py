"""Quasi-static equilibrium of the tension net: a frozen Model, a State, ``solve``.

The face at rest under a set of muscle actions is the minimiser of

    E(x) = Σ_arcs k (½δ² + ¼βδ⁴/L²)              elastic arcs (δ = l − L), stiffening in stretch,
                                                 ½ c k δ² in compression (the skin buckles)
         + ½ Σ_points k_a |x − anchor(bone)|²      soft tissue tying skin to skull or jaw
         + ½ Σ_columns k_v (A h / A₀ − d)²          tissue columns keep their volume (bulges)
         + Σ_fibers T L₀ Φ(λ)                      muscles: tension × path length (λ = l/L₀, the
                                                 fiber's path), weakening as the fiber shortens
         + ½ Σ_segments k_g (g L − l)₊²            no muscle segment shorter than g of its rest
         + ½ Σ penalties                           lips against each other, the tongue's tip,
                                                 the upper lip's tie to the maxilla
         − Σ f · x                                  released tone, air pressure, muscle bellies

over the skin and muscle points ``x``, subject to one-sided contacts: the
flesh stays above the skull (it slides over bone, not through it) and the lids
stay outside the eyeballs. Stretched arcs stiffen, so a force added where the
tissue is already stretched moves it little — the masking Platt & Badler
describe (F/k → 0 as k grows). A muscle's active force follows a force-length
relation: full while its fiber is longer than the top of its ``active_range``
(of the rest length), falling smoothly to nothing at the bottom, so a strong
contraction settles instead of collapsing; a segment guard keeps each segment
of a muscle's path above ``segment_guard`` of its rest length.

The minimiser is a projected L-BFGS whose initial inverse Hessian is the
factorised rest stiffness (the projective-dynamics system matrix: arcs,
attachments and muscles as isotropic springs; Liu, Bouaziz & Kavan 2017). The
sparse factorisation is computed once per model and reused by every iteration
of every frame. Arrays are laid out ``(xyz, B, points)`` — component-major, so
numpy's inner loops run over the points — and ``B`` configurations are solved
at once, so many expressions cost little more than one.

Animation follows the paper: a change of activations is applied in ``steps``
increments of 1/n, each relaxed to equilibrium from the previous one; the
state persists between frames, so each frame only applies what changed.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from facsim.engines.muscle.muscles import Drive, MuscleLayer, TongueModel, jaw_pose
from facsim.engines.muscle.net import Arcs, TensionNet, jaw_transform

#: Passes of re-choosing the bone under the flesh and projecting onto it at the end of a static solve.
SETTLE_PASSES = 30
#: Least share of its rest area a skin triangle keeps along its rest normal (no folding through).
FOLD_GUARD = 0.35
#: Animation frames for which the choice of bone under each point is kept (the skin slides slowly).
FLOOR_AGE = 4
#: L-BFGS memory.
HISTORY = 10


# ------------------------------------------------------------------ model ---

@dataclass(frozen=True, eq=False)
class Model:
    """Everything constant about one character's simulation (built by :func:`build_model`).

    Points ``0 … N_skin-1`` are the skin, then the muscle points. Per-point
    constants are 1-D and broadcast over ``(xyz, B, points)``.
    """

    net: TensionNet
    layer: MuscleLayer
    rest: np.ndarray             # (N, 3)
    arc_diff: sp.csr_matrix      # (A, N): x_j − x_i
    arc_scatter: sp.csr_matrix   # (N, A): its transpose
    arc_rest: np.ndarray         # (A,)
    arc_k: np.ndarray            # (A,) stiffness in stretch ...
    arc_kq: np.ndarray           # ... its quartic (stiffening) term k β / L² ...
    arc_kc: np.ndarray           # ... and in compression
    attach_k: np.ndarray         # (N,)
    bend: sp.csr_matrix          # (N, N) umbrella Laplacian (skin points; muscle points have none) ...
    bend_scatter: sp.csr_matrix  # ... its transpose
    bend_k: np.ndarray           # (N,) bending stiffness
    bend_rest: np.ndarray        # (N, 3) the Laplacian at rest
    bend_jaw: np.ndarray         # (N,) how much of it turns with the jaw
    jaw_nodes: np.ndarray        # points whose attachment rides the jaw (partly) ...
    jaw_share: np.ndarray        # (J,) ... by this much
    vol_ids: np.ndarray
    vol_k: np.ndarray            # (V,)
    vol_depth: np.ndarray        # (V,)
    vol_area: np.ndarray         # (V,) rest area of each column
    vol_anchor: np.ndarray       # (V, 3) rest bone point under each column ...
    vol_normal: np.ndarray       # (V, 3) ... and its normal
    vol_jaw: np.ndarray          # (V,) share riding the jaw
    tri: np.ndarray              # (T, 3) skin triangles around the tissue columns
    tri_edges: sp.csr_matrix     # (2T, N): b − a, then c − a, for every triangle (a, b, c)
    corner_scatter: sp.csr_matrix  # (N, 3T)
    area_matrix: sp.csr_matrix   # (V, T) a third of each triangle's area to its column vertices
    area_scatter: sp.csr_matrix  # (T, V) its transpose
    fold_edges: sp.csr_matrix    # (2F, N): b − a, then c − a, for every skin triangle (a, b, c) ...
    fold_scatter: sp.csr_matrix  # (N, 3F) per-corner vectors to points
    fold_normal: np.ndarray      # (3, 1, F) rest normal of each triangle
    fold_area2: np.ndarray       # (F,) twice its rest area
    fold_k: np.ndarray           # (F,) stiffness of the guard against turning inside out
    contact_ids: np.ndarray      # points kept above the skull ...
    contact_floor: np.ndarray    # (K, C) ... by at least this much (never more than at rest) ...
    contact_site: np.ndarray     # (K, C, 3) ... over one of these bone sites (rest, in their bone's frame)
    contact_site_normal: np.ndarray  # (K, C, 3)
    contact_jaw: np.ndarray      # (K,) bool: the bone is the jaw
    site_blend: float            # distance over which neighbouring bone sites blend into one surface
    eye_ids: np.ndarray          # points kept outside an eyeball ...
    eye_centre: np.ndarray       # (3, 1, E) ... centred here ...
    eye_floor: np.ndarray        # (E,) ... by at least this radius
    lip_pairs: np.ndarray        # (P, 2) upper/lower rim points
    lip_floor: np.ndarray        # (P,) least separation (the rest one where the lips already overlap)
    lip_k: float
    tether_ids: np.ndarray       # (T,) upper-lip points hanging from the maxilla ...
    tether_anchor: np.ndarray    # (3, 1, T) ... from these skull points ...
    tether_length: np.ndarray    # (T,) ... free up to this distance ...
    tether_k: np.ndarray         # (T,) ... then held this stiffly
    seg_a: sp.csr_matrix         # (S, N) picks a segment's first end when it is a point ...
    seg_b: sp.csr_matrix
    seg_scatter_a: sp.csr_matrix  # (N, S)
    seg_scatter_b: sp.csr_matrix
    seg_bone_a: np.ndarray       # ... or names its bone point (-1 if none)
    seg_bone_b: np.ndarray
    seg_rest: np.ndarray         # (S,) rest length of each segment
    seg_guard_k: np.ndarray      # (S,) stiffness of its guard against shortening below segment_guard
    fiber_sum: sp.csr_matrix     # (F, S) sums a fiber's segment lengths, weighted by their share of its tension
    fiber_of: np.ndarray         # (S,) the fiber of each segment
    fiber_first: np.ndarray      # (F,) one segment of each fiber ...
    fiber_rest: np.ndarray       # (F,) ... and the fiber's weighted path length at rest
    active_range: tuple          # (shortest, full): force-length relation, in rest lengths
    segment_guard: float         # least length of a segment, in rest lengths
    force_matrix: sp.csr_matrix  # (3N, C): constant forces per unit of each control
    tongue: TongueModel
    node_mirror: np.ndarray | None   # (N,) each point's mirror image (None: no symmetry known)
    muscle_mirror: np.ndarray        # (M,) each muscle's twin on the other side (itself on the midline)
    stiffness: sp.csr_matrix     # (N, N) the rest stiffness ...
    stiffness_diagonal: np.ndarray  # ... its diagonal (a cheap curvature scale) ...
    solve_rest: object           # ... factorised: solve((N, k)) -> (N, k)
    max_step: float              # no point moves further than this in one iteration (dm)
    jaw_spec: dict

    @property
    def count(self) -> int:
        return len(self.rest)


@dataclass(frozen=True, eq=False)
class Loads:
    """Per-configuration inputs of the energy (axis B), derived from a :class:`Drive`."""

    tension: np.ndarray          # (B, S) segment tensions
    force: np.ndarray            # (3, B, N) constant forces
    jaw_offset: np.ndarray       # (3, B, J) how far the jaw carried each jaw point's anchor
    bend_target: np.ndarray      # (3, B, N) the rest Laplacian, turned with the jaw where it rides it
    bone: np.ndarray             # (3, B, P) the muscles' bone points
    vol_anchor: np.ndarray       # (3, B, V)
    vol_normal: np.ndarray       # (3, B, V)
    lip_up: np.ndarray           # (3, B, 1) "up" between skull and jaw, for the lips
    tongue_centre: np.ndarray    # (3, B, 1)
    jaw: np.ndarray              # (B, 3) pose
    jaw_rot: np.ndarray          # (B, 3, 3)
    jaw_shift: np.ndarray        # (B, 3)


@dataclass(frozen=True, eq=False)
class State:
    """The face between frames: point positions (3, B, N) and the drive that holds them there."""

    x: np.ndarray
    drive: Drive
    jaw: np.ndarray
    memory: tuple = ()           # the minimiser's curvature history, carried to the next frame
    floors: object = None        # the skull under the flesh at the last frame (reused for a few frames)
    age: int = 0                 # frames since the floors were chosen
    known: tuple | None = None   # (loads, energy, gradient) at x, so the next frame need not recompute them

    @property
    def batch(self) -> int:
        return self.x.shape[1]

    def points(self, index: int = 0) -> np.ndarray:
        """Positions (N, 3) of configuration ``index``."""
        return self.x[:, index].T


def _laplacian(i, j, k, n) -> sp.csc_matrix:
    """(n, n) stiffness of springs k between points i and j (a weighted graph Laplacian)."""
    return sp.coo_matrix((np.r_[k, k, -k, -k], (np.r_[i, j, i, j], np.r_[i, j, j, i])), shape=(n, n)).tocsc()


def _pick_matrix(rows: np.ndarray, count: int) -> sp.csr_matrix:
    """(len(rows), count) sparse matrix picking row ``rows[k]`` of a (count, ·) array (none if < 0)."""
    keep = rows >= 0
    r = np.arange(len(rows))[keep]
    return sp.csr_matrix((np.ones(keep.sum()), (r, rows[keep])), shape=(len(rows), count))


def build_model(net: TensionNet, layer: MuscleLayer, spec: dict, tongue: TongueModel, pressure: dict,
                teeth: dict | None = None, mirror: np.ndarray | None = None) -> Model:
    """Assemble the net and its muscles, and factorise the rest stiffness once."""
    ns, q = net.count, len(layer.node_rest)
    n = ns + q
    rest = np.concatenate([net.rest, layer.node_rest])
    arcs = Arcs.concat([_stiff_insertions(net, layer), layer.arcs])
    na = len(arcs)
    arc_diff = sp.csr_matrix((np.r_[np.ones(na), -np.ones(na)],
                              (np.r_[np.arange(na), np.arange(na)], np.r_[arcs.j, arcs.i])), shape=(na, n))
    beta = np.where(arcs.rest > 1e-4, arcs.beta, 0.0)

    # Muscle points are held weakly where they are (their skin heads carry them), on their parent's bone.
    parent = layer.node_parent
    reg = 0.02 * np.median(net.attach_skull + net.attach_jaw)
    attach = np.r_[net.attach_skull + net.attach_jaw, np.full(q, reg)]
    share = np.r_[net.attach_jaw / np.maximum(net.attach_skull + net.attach_jaw, 1e-12), net.jaw_weight[parent]]
    jaw_nodes = np.flatnonzero(share > 1e-6)

    vol_ids = np.flatnonzero(net.volume_k > 0)
    vol_index = np.full(ns, -1)
    vol_index[vol_ids] = np.arange(len(vol_ids))
    tri = net.triangles
    t = len(tri)
    tri = tri[(vol_index[tri] >= 0).any(axis=1)]  # only triangles around a tissue column matter here
    t = len(tri)
    rows = vol_index[tri.T.ravel()]
    cols = np.tile(np.arange(t), 3)
    area_matrix = sp.csr_matrix((np.full((rows >= 0).sum(), 1.0 / 3.0), (rows[rows >= 0], cols[rows >= 0])),
                                shape=(len(vol_ids), t))
    tri_area = 0.5 * np.linalg.norm(np.cross(rest[tri[:, 1]] - rest[tri[:, 0]],
                                             rest[tri[:, 2]] - rest[tri[:, 0]]), axis=1)
    corner_scatter = sp.csr_matrix((np.ones(3 * t), (tri.T.ravel(), np.arange(3 * t))), shape=(n, 3 * t))
    rows2 = np.r_[np.arange(2 * t), np.arange(2 * t)]
    tri_edges = sp.csr_matrix((np.r_[np.ones(2 * t), -np.ones(2 * t)],
                               (rows2, np.r_[tri[:, 1], tri[:, 2], tri[:, 0], tri[:, 0]])), shape=(2 * t, n))

    # A guard against triangles turning inside out (the skin would fold through itself): the
    # signed area along the rest normal may not fall below FOLD_GUARD of the rest area.
    ft = net.triangles
    f = len(ft)
    fold_rows = np.r_[np.arange(2 * f), np.arange(2 * f)]
    fold_edges = sp.csr_matrix((np.r_[np.ones(2 * f), -np.ones(2 * f)],
                                (fold_rows, np.r_[ft[:, 1], ft[:, 2], ft[:, 0], ft[:, 0]])), shape=(2 * f, n))
    fold_scatter = sp.csr_matrix((np.ones(3 * f), (ft.T.ravel(), np.arange(3 * f))), shape=(n, 3 * f))
    fold_cross = np.cross(rest[ft[:, 1]] - rest[ft[:, 0]], rest[ft[:, 2]] - rest[ft[:, 0]])
    fold_area2 = np.linalg.norm(fold_cross, axis=1)
    fold_normal = fold_cross / np.maximum(fold_area2, 1e-12)[:, None]
    # (∝ area, as the membrane's own energy; with a floor so the tiny triangles where muscles
    # gather — the corners of the mouth and eyes — are guarded too.)
    fold_k = net.constants["fold_guard"] * net.arcs.k.mean() * np.where(
        fold_area2 > 1e-10, np.maximum(fold_area2, (0.015 * net.scale) ** 2), 0.0)

    # Skull contact for every point over bone and every muscle point (on its parent's bone).
    skin_contact = np.flatnonzero(net.contact_k > 0)
    muscle_contact = np.flatnonzero(net.contact_k[parent] > 0)
    contact_ids = np.r_[skin_contact, ns + muscle_contact]
    contact_parent = np.r_[skin_contact, parent[muscle_contact]]
    contact_floor = np.r_[net.floor[skin_contact], layer.node_floor[muscle_contact]]
    candidates = net.candidates[contact_parent]
    site_pos, site_normal = net.sites[candidates], net.site_normal[candidates]
    site_jaw = net.site_on_jaw[candidates[:, 0]]
    # A point may not be held further out than it rests over each site (in concave places —
    # the nostrils, the ear — a site across the cavity would otherwise push it), and sites
    # facing away from the point's own bone normal are not its skull at all.
    height = ((rest[contact_ids][:, None, :] - site_pos) * site_normal).sum(-1)
    facing = (site_normal * net.normal[contact_parent][:, None, :]).sum(-1) > 0.3
    contact_floor = np.where(facing, np.minimum(contact_floor[:, None], height), -np.inf)

    # The lips (and the lining in front of the teeth) rest on the teeth: the upper ones on the
    # skull's, the lower ones on the jaw's. Same machinery, with tooth vertices as the sites.
    if teeth is not None:
        more = _teeth_contacts(net, teeth, exclude=set(skin_contact.tolist()))
        contact_ids = np.r_[contact_ids, more["ids"]]
        contact_floor = np.r_[contact_floor, more["floor"]]
        site_pos = np.r_[site_pos, more["site"]]
        site_normal = np.r_[site_normal, more["normal"]]
        site_jaw = np.r_[site_jaw, more["jaw"]]
    node_mirror = _node_mirror(rest, layer, ns, mirror) if mirror is not None else None
    if mirror is not None:
        site_pos, site_normal, site_jaw, contact_floor = _mirror_right_from_left(
            contact_ids, site_pos, site_normal, site_jaw, contact_floor, rest, node_mirror)

    # Eyeball contact for lids, the sac and the lid muscles' points.
    eye_of = np.full(ns, -1)
    eye_of[net.eye_ids] = net.eye_index
    floor_of = np.zeros(ns)
    floor_of[net.eye_ids] = net.eye_floor
    lid_muscle = np.flatnonzero(eye_of[parent] >= 0)
    eye_ids = np.r_[net.eye_ids, ns + lid_muscle]
    eye_index = np.r_[net.eye_index, eye_of[parent[lid_muscle]]]
    # (A muscle point under the skin may lie deeper than its skin point: never above its rest.)
    muscle_gap = np.linalg.norm(layer.node_rest[lid_muscle] - net.eye_centre[eye_of[parent[lid_muscle]]], axis=1)
    eye_floor = np.r_[net.eye_floor, np.minimum(floor_of[parent[lid_muscle]], muscle_gap)]

    def ends(ref):
        return np.where(ref >= 0, ref, -1), np.where(ref < 0, -1 - ref, -1)

    node_a, bone_a = ends(layer.seg_a)
    node_b, bone_b = ends(layer.seg_b)
    seg_a, seg_b = _pick_matrix(node_a, n), _pick_matrix(node_b, n)

    # Constant forces per unit control: released tone (M), bellies (M), cheeks (2), lips (1); rows xyz-major.
    m = len(layer.names)
    relax = np.zeros((3, n, m))
    np.add.at(relax, (slice(None), layer.relax_node, layer.relax_muscle),
              -(layer.relax_weight[:, None] * layer.relax_dir).T)
    bulge = np.zeros((3, n, m))
    np.add.at(bulge, (slice(None), layer.bulge_ids, layer.bulge_muscle), layer.bulge_vec.T)
    air = np.zeros((3, n, 3))
    for s, (ids, vec) in enumerate(pressure["cheek"]):
        air[:, ids, s] = vec.T
    ids, vec = pressure["lips"]
    air[:, ids, 2] = vec.T
    force_matrix = sp.csr_matrix(np.concatenate([relax, bulge, air], axis=2).reshape(3 * n, -1))

    bend = sp.block_diag([net.laplacian, sp.csr_matrix((q, q))]).tocsr()
    bend_k = np.r_[net.bend_k, np.zeros(q)]

    # The rest stiffness (isotropic springs): arcs, bending, attachments, a third of the volume columns,
    # and the muscles at full tension (T/L sideways; a stiffer preconditioner only shortens steps).
    lap = _laplacian(arcs.i, arcs.j, arcs.k, n)
    diag = attach.copy()
    diag[vol_ids] += net.volume_k[vol_ids] / 3.0
    everything = np.r_[rest, layer.bone_points]
    idx = lambda ref: np.where(ref >= 0, ref, n - 1 - ref)  # noqa: E731  (bone b is row n + b)
    seg_len = np.linalg.norm(everything[idx(layer.seg_a)] - everything[idx(layer.seg_b)], axis=1)
    fibers = int(layer.seg_fiber.max()) + 1 if len(layer.seg_fiber) else 0
    # (A sphincter's segments may pull unequally (`bias`): its length is weighted by their shares.)
    fiber_sum = sp.csr_matrix((layer.seg_weight, (layer.seg_fiber, np.arange(len(seg_len)))),
                              shape=(fibers, len(seg_len)))
    fiber_first = np.zeros(fibers, np.int64)
    fiber_first[layer.seg_fiber[::-1]] = np.arange(len(seg_len))[::-1]
    seg_rest = np.maximum(seg_len, 1e-6)
    const = net.constants
    k_seg = layer.force[layer.seg_muscle] * layer.seg_weight / np.maximum(seg_len, 0.02 * net.scale)
    both = (node_a >= 0) & (node_b >= 0)
    ia, ib, kb = node_a[both], node_b[both], k_seg[both]
    lap = lap + _laplacian(ia, ib, kb, n)
    for nodes in (node_a, node_b):
        one = (nodes >= 0) & ~both
        np.add.at(diag, nodes[one], k_seg[one])
    system = (lap + bend.T @ sp.diags(bend_k) @ bend + sp.diags(diag)).tocsc()
    lu = spla.splu(system, permc_spec="MMD_AT_PLUS_A", options={"SymmetricMode": True})

    rim = net.rim_pairs
    lip_sep = net.rest[rim[:, 0], 1] - net.rest[rim[:, 1], 1]
    model = Model(
        net=net, layer=layer, rest=rest, arc_diff=arc_diff, arc_scatter=arc_diff.T.tocsr(),
        arc_rest=np.maximum(arcs.rest, 1e-6), arc_k=arcs.k,
        arc_kq=arcs.k * beta / np.maximum(arcs.rest, 1e-6) ** 2, arc_kc=arcs.k * arcs.compress,
        attach_k=attach, jaw_nodes=jaw_nodes, jaw_share=share[jaw_nodes],
        bend=bend, bend_scatter=bend.T.tocsr(), bend_k=bend_k, bend_rest=bend @ rest, bend_jaw=share,
        vol_ids=vol_ids, vol_k=net.volume_k[vol_ids], vol_depth=net.depth[vol_ids],
        vol_area=area_matrix @ tri_area,
        vol_anchor=net.rest[vol_ids] - net.depth[vol_ids, None] * net.normal[vol_ids],
        vol_normal=net.normal[vol_ids], vol_jaw=net.jaw_weight[vol_ids], tri=tri, tri_edges=tri_edges,
        corner_scatter=corner_scatter, area_matrix=area_matrix, area_scatter=area_matrix.T.tocsr(),
        fold_edges=fold_edges, fold_scatter=fold_scatter, fold_normal=fold_normal.T[:, None, :],
        fold_area2=np.maximum(fold_area2, 1e-12), fold_k=fold_k,
        contact_ids=contact_ids, contact_floor=contact_floor, contact_site=site_pos,
        contact_site_normal=site_normal, contact_jaw=site_jaw,
        eye_ids=eye_ids, eye_centre=net.eye_centre[eye_index].T[:, None, :], eye_floor=eye_floor,
        site_blend=0.02 * net.scale,
        lip_pairs=rim, lip_floor=np.minimum(lip_sep, 0.0), lip_k=float(np.median(net.contact_k[net.contact_k > 0])),
        tether_ids=net.tether_ids, tether_anchor=net.tether_anchor.T[:, None, :], tether_length=net.tether_length,
        tether_k=net.tether_k,
        seg_a=seg_a, seg_b=seg_b, seg_scatter_a=seg_a.T.tocsr(), seg_scatter_b=seg_b.T.tocsr(),
        seg_bone_a=bone_a, seg_bone_b=bone_b, seg_rest=seg_rest,
        seg_guard_k=const["guard_stiffness"] * layer.force[layer.seg_muscle] * layer.seg_weight / seg_rest,
        fiber_sum=fiber_sum, fiber_of=layer.seg_fiber, fiber_first=fiber_first,
        fiber_rest=np.maximum(fiber_sum @ seg_rest, 1e-6),
        active_range=tuple(float(v) for v in const["active_range"]), segment_guard=float(const["segment_guard"]),
        force_matrix=force_matrix, tongue=tongue,
        node_mirror=node_mirror, muscle_mirror=np.array([layer.index(mu, {"left": "right", "right": "left"}.get(sd, sd))
                                                         for mu, sd in zip(layer.muscle, layer.side)]),
        stiffness=system.tocsr(), stiffness_diagonal=system.diagonal(), solve_rest=lu.solve,
        max_step=0.025 * net.scale, jaw_spec=spec["jaw"],
    )
    # The blended bone surface under a point is not exactly any one site's plane: lower each
    # point's floors by whatever the rest face would violate, so that rest is feasible.
    rest_state_ = rest_state(model)
    skull_gap, _, _ = _gaps(model, rest_state_.x, select_sites(model, rest_state_.x, loads(model, rest_state_.drive)))
    model.contact_floor[:] -= np.maximum(skull_gap[0], 0.0)[:, None] + 1e-9 * (skull_gap[0] > 0)[:, None]
    return model


def _stiff_insertions(net: TensionNet, layer: MuscleLayer) -> Arcs:
    """The skin's arcs, stiffer (``insertion_skin`` times at an insertion's centre) where a
    linear muscle inserts: the fibres interlace with the dermis there, so the patch moves
    as a piece and the pull reaches the lip corners and cheeks instead of stretching them."""
    factor = float(net.constants.get("insertion_skin", 1.0))
    arcs = net.arcs
    if factor == 1.0 or not len(layer.head_ids):
        return arcs
    weight = np.zeros(net.count)
    np.maximum.at(weight, layer.head_ids, layer.head_weight)
    near = 0.5 * (weight[arcs.i] + weight[arcs.j])
    return Arcs(arcs.i, arcs.j, arcs.rest, arcs.k * (1.0 + (factor - 1.0) * near), arcs.beta, arcs.compress)


def _node_mirror(rest: np.ndarray, layer: MuscleLayer, skin: int, mirror: np.ndarray) -> np.ndarray:
    """Mirror image of every point: the skin's from the mesh; a muscle point's is the same point
    of the same muscle on the other side (built in the same order); a midline muscle's by position."""
    from scipy.spatial import cKDTree

    out = np.arange(len(rest))
    out[:skin] = mirror[:skin]
    for k, (name, side) in enumerate(zip(layer.muscle, layer.side)):
        segs = np.flatnonzero(layer.seg_muscle == k)
        if side == "left":
            twin = np.flatnonzero(layer.seg_muscle == layer.index(name, "right"))
            for ends in ("seg_a", "seg_b"):
                a, b = getattr(layer, ends)[segs], getattr(layer, ends)[twin]
                points = (a >= skin) & (b >= skin)
                out[a[points]], out[b[points]] = b[points], a[points]
        elif side == "both":
            nodes = np.unique(np.r_[layer.seg_a[segs], layer.seg_b[segs]])
            nodes = nodes[nodes >= skin]
            if len(nodes):
                _, j = cKDTree(rest[nodes]).query(rest[nodes] * [-1.0, 1.0, 1.0])
                out[nodes] = nodes[j]
    return out


def _mirror_right_from_left(ids, site, normal, jaw, floor, rest, node_mirror):
    """Give each point on the right the mirror image of its left twin's bone sites (nearest-site
    searches break ties arbitrarily; a symmetric face must stay symmetric)."""
    where = {int(i): k for k, i in enumerate(ids)}
    flip = np.array([-1.0, 1.0, 1.0])
    site, normal, jaw, floor = site.copy(), normal.copy(), jaw.copy(), floor.copy()
    for k, i in enumerate(ids):
        twin = where.get(int(node_mirror[i]))
        if rest[i, 0] < -1e-6 and twin is not None:
            site[k], normal[k], jaw[k], floor[k] = site[twin] * flip, normal[twin] * flip, jaw[twin], floor[twin]
    return site, normal, jaw, floor


def _teeth_contacts(net: TensionNet, teeth: dict, *, exclude: set, candidates: int = 8) -> dict:
    """Contacts of the lips and the lining in front of the teeth with the tooth rows.

    ``teeth`` gives the rest positions of the ``upper`` and ``lower`` rows. A
    tooth's outward normal points away from the dental arch's centre line; a
    point in front of the teeth may come no closer to them than it rests, nor
    than a share of its tissue depth.
    """
    from scipy.spatial import cKDTree

    rows = {}
    for name in ("upper", "lower"):
        p = np.asarray(teeth[name], float)
        back = p[:, 2].min() - 0.1 * net.scale
        out = np.c_[p[:, 0], np.zeros(len(p)), p[:, 2] - back]
        rows[name] = (p, out / np.linalg.norm(out, axis=1, keepdims=True))
    everything = np.r_[rows["upper"][0], rows["lower"][0]]
    near = cKDTree(everything).query(net.rest)[0] < 0.16 * net.scale
    ids, floor, site, normal, jaw = [], [], [], [], []
    for i in np.flatnonzero(near):
        if i in exclude:
            continue
        name = "lower" if net.jaw_weight[i] >= 0.5 else "upper"
        p, n = rows[name]
        _, j = cKDTree(p).query(net.rest[i], k=candidates)
        height = ((net.rest[i] - p[j]) * n[j]).sum(1)
        if height.max() <= 0:  # behind the teeth (palate, floor of the mouth): not resting on them
            continue
        ids.append(i)
        floor.append(np.where(height > 0, np.minimum(0.5 * net.depth[i], height), -np.inf))
        site.append(p[j])
        normal.append(n[j])
        jaw.append(name == "lower")
    return {"ids": np.asarray(ids, np.int64), "floor": np.asarray(floor), "site": np.asarray(site),
            "normal": np.asarray(normal), "jaw": np.asarray(jaw, bool)}


# ----------------------------------------------------------- array helpers ---

try:  # scipy's compiled CSR mat-vec, without the dispatch of ``@`` (a third of the time of small products)
    from scipy.sparse._sparsetools import csr_matvec as _csr_matvec
except ImportError:  # pragma: no cover
    _csr_matvec = None


def _apply(matrix: sp.csr_matrix, x: np.ndarray) -> np.ndarray:
    """A sparse (K, N) operator applied to every component and configuration: (3, B, N) → (3, B, K).

    One sparse mat-vec per contiguous row (no transposes, the rows stay in cache).
    """
    c, b, n = x.shape
    rows, cols = matrix.shape
    if _csr_matvec is not None and x.flags.c_contiguous and matrix.data.dtype == np.float64:
        out = np.zeros((c, b, rows))
        for i in range(c):
            for j in range(b):
                _csr_matvec(rows, cols, matrix.indptr, matrix.indices, matrix.data, x[i, j], out[i, j])
        return out
    if c * b <= 1000:
        out = np.empty((c, b, rows))
        for i in range(c):
            for j in range(b):
                out[i, j] = matrix @ x[i, j]
        return out
    out = matrix @ x.reshape(c * b, n).T
    return np.ascontiguousarray(out.T).reshape(c, b, -1)


def _per_row(matrix: sp.csr_matrix, rows: np.ndarray) -> np.ndarray:
    """A sparse (K, N) operator applied to each row of (B, N) → (B, K), one mat-vec per row (a
    product with all B at once sums in another order, and a batch's solves drifted from the
    same solves alone)."""
    return np.stack([matrix @ row for row in np.asarray(rows)])


def _dot(a, b):
    """Dot product over the xyz axis: (3, B, K) · (3, B, K) → (B, K)."""
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def _cross(a, b):
    return np.stack([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]])


def carry(points, rot, shift, hinge) -> np.ndarray:
    """Points (K, 3) carried by jaw transforms (B, 3, 3), (B, 3) → (3, B, K)."""
    rel = np.asarray(points, float) - hinge
    return np.einsum("bij,kj->ibk", rot, rel) + (hinge[None, :] + shift).T[:, :, None]


def turn(vectors, rot) -> np.ndarray:
    """Directions (K, 3) turned by rotations (B, 3, 3) → (3, B, K)."""
    return np.einsum("bij,kj->ibk", rot, vectors)


def _batch(points, B) -> np.ndarray:
    """(K, 3) → (3, B, K), the same for every configuration."""
    return np.repeat(np.asarray(points, float).T[:, None, :], B, axis=1)


# ------------------------------------------------------------------ loads ---

def loads(model: Model, d: Drive) -> Loads:
    """Turn a drive (B configurations) into the energy's inputs."""
    layer, net = model.layer, model.net
    B = d.muscle.shape[0]
    act = d.muscle
    contraction = np.maximum(act, 0.0) * layer.force                 # (B, M)
    released = np.maximum(-act, 0.0) * layer.force * layer.tone      # (B, M)
    tension = contraction[:, layer.seg_muscle] * layer.seg_weight    # (B, S)
    controls = np.concatenate([released, contraction, d.pressure, d.lip_pressure[:, None]], axis=1).T
    force = _per_row(model.force_matrix, controls.T).T.reshape(3, model.count, B).transpose(0, 2, 1).copy()

    jaw = jaw_pose(layer, act, model.jaw_spec)
    rot, shift = jaw_transform(jaw, net.hinge, model.jaw_spec["yaw_per_lateral"])
    nodes = model.jaw_nodes
    jaw_offset = model.jaw_share * (carry(model.rest[nodes], rot, shift, net.hinge) - model.rest[nodes].T[:, None, :])

    bend_target = _batch(model.bend_rest, B)
    turning = model.bend_jaw > 1e-6
    if turning.any():
        w = model.bend_jaw[turning]
        rest_lap = model.bend_rest[turning]
        bend_target[:, :, turning] = (1 - w) * rest_lap.T[:, None, :] + w * turn(rest_lap, rot)

    bone = _batch(layer.bone_points, B)
    on_jaw = layer.bone_on_jaw
    if on_jaw.any():
        bone[:, :, on_jaw] = carry(layer.bone_points[on_jaw], rot, shift, net.hinge)

    vol_anchor = _batch(model.vol_anchor, B)
    vol_normal = _batch(model.vol_normal, B)
    moving = model.vol_jaw > 0
    if moving.any():
        w = model.vol_jaw[moving]
        anchor, normal = model.vol_anchor[moving], model.vol_normal[moving]
        vol_anchor[:, :, moving] += w * (carry(anchor, rot, shift, net.hinge) - anchor.T[:, None, :])
        blend = (1 - w) * normal.T[:, None, :] + w * turn(normal, rot)
        vol_normal[:, :, moving] = blend / np.sqrt(_dot(blend, blend))

    half = 0.5 * jaw[:, 0]
    lip_up = np.stack([np.zeros(B), np.cos(half), np.sin(half)])[:, :, None]  # between skull and jaw
    tongue_centre = tongue_tip(model.tongue, d.tongue, rot, shift, net.hinge).T[:, :, None]
    return Loads(tension, force, jaw_offset, bend_target, bone, vol_anchor, vol_normal, lip_up, tongue_centre,
                 jaw, rot, shift)


def tongue_frame(tongue: TongueModel, control: np.ndarray, rot, shift, hinge):
    """Rigid motion of the tongue, (B, 3, 3) and (B, 3): it rides the jaw, turns about its root
    toward a cheek, slides forward by ``reach × protrusion`` and rises by ``lift`` of its tip radius."""
    protrude, sweep, lift = control[:, 0], control[:, 1], control[:, 2]
    yaw = np.radians(tongue.sweep) * sweep
    cy, sy = np.cos(yaw), np.sin(yaw)
    one, zero = np.ones_like(yaw), np.zeros_like(yaw)
    local = np.stack([np.stack([cy, zero, sy], -1), np.stack([zero, one, zero], -1), np.stack([-sy, zero, cy], -1)], -2)
    ahead = local @ np.array([0.0, 0.0, 1.0])                           # forward, turned with it
    forward = tongue.reach * protrude[:, None] * ahead + np.c_[zero, tongue.radius * lift, zero]
    # p → jaw(root + local (p − root) + forward)
    r = rot @ local
    t = (np.einsum("bij,bj->bi", rot, tongue.root - hinge + forward) + hinge + shift
         - np.einsum("bij,j->bi", r, tongue.root))
    return r, t


def tongue_tip(tongue: TongueModel, control, rot, shift, hinge) -> np.ndarray:
    """Centre of the tongue's tip sphere per configuration (B, 3)."""
    r, t = tongue_frame(tongue, control, rot, shift, hinge)
    return np.einsum("bij,j->bi", r, tongue.tip) + t


# ----------------------------------------------------------------- energy ---

def energy(model: Model, x: np.ndarray, ld: Loads):
    """Total energy (B,) and its gradient (3, B, N) at points ``x`` (3, B, N).

    The contacts with the skull and the eyeballs are not in it: they are
    one-sided constraints the minimiser keeps by projection.
    """
    _, B, n = x.shape

    # Elastic arcs: k(½δ² + ¼qδ⁴) stretched, ½ c k δ² compressed.
    d = _apply(model.arc_diff, x)                                        # (3, B, A)
    length = np.sqrt(_dot(d, d))
    delta = length - model.arc_rest
    pos, neg = np.maximum(delta, 0.0), np.minimum(delta, 0.0)
    pos2 = pos * pos
    total = (model.arc_k * (0.5 * pos2) + model.arc_kq * (0.25 * pos2 * pos2)
             + model.arc_kc * (0.5 * neg * neg)).sum(-1)
    tension = model.arc_k * pos + model.arc_kq * pos2 * pos + model.arc_kc * neg
    grad = _apply(model.arc_scatter, d * (tension / np.maximum(length, 1e-12)))

    # Bending: ½ k |L x − L x_rest|² (the rest curvature turning with the jaw).
    r = _apply(model.bend, x) - ld.bend_target
    kr = model.bend_k * r
    total += 0.5 * (kr * r).sum((0, 2))
    grad += _apply(model.bend_scatter, kr)

    # Attachments to bone (skull, or the jaw for points riding it).
    r = x - model.rest.T[:, None, :]
    r[:, :, model.jaw_nodes] -= ld.jaw_offset
    total += 0.5 * (model.attach_k * _dot(r, r)).sum(-1)
    grad += model.attach_k * r

    # Volume of tissue columns: (A h / A0 − d), A the column's area, h its height over bone.
    t = len(model.tri)
    edges = _apply(model.tri_edges, x)
    e1, e2 = edges[:, :, :t], edges[:, :, t:]                            # b − a, c − a
    cross = _cross(e1, e2)
    twice = np.sqrt(_dot(cross, cross))                                  # (B, T)
    area = _per_row(model.area_matrix, 0.5 * twice)                      # (B, V)
    vid = model.vol_ids
    h = _dot(x[:, :, vid] - ld.vol_anchor, ld.vol_normal)
    excess = area * h / model.vol_area - model.vol_depth
    g = model.vol_k * excess
    total += 0.5 * (g * excess).sum(-1)
    grad[:, :, vid] += (g * area / model.vol_area) * ld.vol_normal
    # Through the areas: ∂area/∂a = ½ (b − c) × n̂, ∂/∂b = ½ (c − a) × n̂, ∂/∂c = ½ (a − b) × n̂.
    per_tri = _per_row(model.area_scatter, g * h / model.vol_area)      # dE/d(triangle area) (B, T)
    unit = cross * (0.5 * per_tri / np.maximum(twice, 1e-12))
    c1, c2 = _cross(e1, unit), _cross(e2, unit)
    corners = np.concatenate([c1 - c2, c2, -c1], axis=-1)
    grad += _apply(model.corner_scatter, corners)

    # No skin triangle turns inside out: its area along the rest normal stays above FOLD_GUARD.
    f = len(model.fold_area2)
    fe = _apply(model.fold_edges, x)
    e1, e2 = fe[:, :, :f], fe[:, :, f:]
    n0 = model.fold_normal
    signed = _dot(_cross(e1, e2), n0) / model.fold_area2                # (B, F), 1 at rest
    short = np.maximum(FOLD_GUARD - signed, 0.0)
    if short.any():
        total += 0.5 * (model.fold_k * short * short).sum(-1)
        w = -model.fold_k * short / model.fold_area2                     # dE/d(area along n0) per unit
        gb, gc = w * _cross(e2, n0), w * _cross(n0, e1)
        grad += _apply(model.fold_scatter, np.concatenate([-(gb + gc), gb, gc], axis=-1))

    # The lips do not pass through each other (the upper rim stays above the lower one).
    up, lo = model.lip_pairs[:, 0], model.lip_pairs[:, 1]
    sep = _dot(x[:, :, up] - x[:, :, lo], ld.lip_up)
    pen = np.maximum(model.lip_floor - sep, 0.0)
    total += 0.5 * model.lip_k * (pen * pen).sum(-1)
    push = model.lip_k * pen * ld.lip_up
    np.add.at(grad, (slice(None), slice(None), up), -push)
    np.add.at(grad, (slice(None), slice(None), lo), push)

    # The upper lip hangs from the maxilla: a tie longer than its free length pulls back.
    v = x[:, :, model.tether_ids] - model.tether_anchor
    dist = np.sqrt(_dot(v, v))
    over = np.maximum(dist - model.tether_length, 0.0)
    total += 0.5 * (model.tether_k * over * over).sum(-1)
    grad[:, :, model.tether_ids] += (model.tether_k * over / np.maximum(dist, 1e-12)) * v

    # The tongue's tip pushes what it meets (the lining directly; lips and cheeks through their tissue).
    tg = model.tongue
    v = x[:, :, tg.contact_ids] - ld.tongue_centre
    dist = np.sqrt(_dot(v, v))
    pen = np.maximum(tg.radius + tg.contact_offset - dist, 0.0)
    total += 0.5 * (tg.contact_k * pen * pen).sum(-1)
    grad[:, :, tg.contact_ids] -= (tg.contact_k * pen / np.maximum(dist, 1e-12)) * v

    # Muscles (tension × path length) and constant forces: the part that changes with the drive.
    e_load, g_load = load_energy(model, x, ld)
    total += e_load
    grad += g_load

    return total, grad


def force_length(ratio: np.ndarray, active_range: tuple) -> tuple[np.ndarray, np.ndarray]:
    """A muscle's active force-length relation f(λ) and its integral Φ(λ), λ = length / rest.

    f is 1 from the top of ``active_range`` up and falls smoothly (a smoothstep) to 0 at its
    bottom; Φ(λ) = ∫ f with Φ = 0 below the range, so a fiber of rest length L₀ under
    tension T stores T L₀ Φ(λ) (T × its length, up to a constant, while at full force).

    >>> f, phi = force_length(np.array([0.3, 0.625, 1.0]), (0.45, 0.8))
    >>> f.round(3).tolist(), phi.round(4).tolist()
    ([0.0, 0.5, 1.0], [0.0, 0.0328, 0.375])
    """
    lo, hi = active_range
    width = hi - lo
    t = np.clip((ratio - lo) / width, 0.0, 1.0)
    f = t * t * (3.0 - 2.0 * t)
    phi = width * (t ** 3 - 0.5 * t ** 4) + np.maximum(ratio - hi, 0.0)
    return f, phi


def load_energy(model: Model, x: np.ndarray, ld: Loads):
    """The drive's share of the energy and gradient: the muscles' work (tension × path length,
    through the force-length relation) and their segments' guard, minus the work of the
    constant forces. When only the drive changes (not the jaw), a new frame's energy is the
    last one's with this part swapped — no full evaluation needed."""
    pa = _apply(model.seg_a, x)
    pb = _apply(model.seg_b, x)
    ba, bb = model.seg_bone_a >= 0, model.seg_bone_b >= 0
    pa[:, :, ba] = ld.bone[:, :, model.seg_bone_a[ba]]
    pb[:, :, bb] = ld.bone[:, :, model.seg_bone_b[bb]]
    seg = pb - pa
    seg_len = np.sqrt(_dot(seg, seg))                                    # (B, S)
    ratio = _per_row(model.fiber_sum, seg_len) / model.fiber_rest        # (B, F)
    f, phi = force_length(ratio, model.active_range)
    # Per fiber: its muscle's tension (a segment's tension over its share), × its weighted length.
    first = model.fiber_first
    fiber_tension = ld.tension[:, first] / model.layer.seg_weight[first]
    short = np.maximum(model.segment_guard * model.seg_rest - seg_len, 0.0)
    pull = ld.tension * f[:, model.fiber_of] - model.seg_guard_k * short
    u = seg * (pull / np.maximum(seg_len, 1e-12))
    total = ((fiber_tension * model.fiber_rest * phi).sum(-1) + 0.5 * (model.seg_guard_k * short * short).sum(-1)
             - (ld.force * x).sum((0, 2)))
    return total, _apply(model.seg_scatter_b, u) - _apply(model.seg_scatter_a, u) - ld.force


# --------------------------------------------------------------- contacts ---

@dataclass(frozen=True, eq=False)
class Floors:
    """The skull under each contact point for one minimisation (world frame)."""

    site: np.ndarray             # (3, B, K) bone point under each contact point
    normal: np.ndarray           # (3, B, K) its outward normal
    floor: np.ndarray            # (B, K) least height over it


def select_sites(model: Model, x: np.ndarray, ld: Loads) -> Floors:
    """The bone beneath each contact point now: the skull (or jaw) the flesh slides on.

    The nearby bone sites are blended with weights falling off with distance
    (a smooth skull between the samples, and no arbitrary choice between two
    sites equally near — which would break the face's symmetry). Distances are
    measured in the bone's own frame, where the sites are fixed. Each configuration is
    blended on its own (einsum sums in an order that depends on the batch's width).
    """
    parts = [_select_sites(model, x[:, b:b + 1], ld.jaw_rot[b:b + 1], ld.jaw_shift[b:b + 1])
             for b in range(x.shape[1])]
    return Floors(*(np.concatenate([getattr(f, name) for f in parts], axis=axis)
                    for name, axis in (("site", 1), ("normal", 1), ("floor", 0))))


def _select_sites(model: Model, x: np.ndarray, rot: np.ndarray, shift: np.ndarray) -> Floors:
    p = x[:, :, model.contact_ids].transpose(2, 1, 0)          # (K, B, 3)
    jaw = model.contact_jaw
    hinge = model.net.hinge
    if jaw.any():  # into the jaw's frame: Rᵀ (p − hinge − t) + hinge
        p = p.copy()
        p[jaw] = np.einsum("bji,kbj->kbi", rot, p[jaw] - hinge - shift) + hinge
    diff = model.contact_site[:, :, None, :] - p[:, None]      # (K, C, B, 3)
    dist2 = (diff * diff).sum(-1)                              # (K, C, B)
    usable = np.isfinite(model.contact_floor)[:, :, None]
    dist2 = np.where(usable, dist2, np.inf)
    weight = np.exp(-(dist2 - dist2.min(axis=1, keepdims=True)) / model.site_blend ** 2)
    weight /= weight.sum(axis=1, keepdims=True)
    site = np.einsum("kcb,kci->kbi", weight, model.contact_site)
    normal = np.einsum("kcb,kci->kbi", weight, model.contact_site_normal)
    normal /= np.linalg.norm(normal, axis=-1, keepdims=True)
    floor = np.einsum("kcb,kc->bk", weight, np.where(usable[:, :, 0], model.contact_floor, 0.0))
    if jaw.any():
        site[jaw] = np.einsum("bij,kbj->kbi", rot, site[jaw] - hinge) + hinge + shift
        normal[jaw] = np.einsum("bij,kbj->kbi", rot, normal[jaw])
    return Floors(np.ascontiguousarray(site.transpose(2, 1, 0)), np.ascontiguousarray(normal.transpose(2, 1, 0)),
                  np.ascontiguousarray(floor))


def _gaps(model: Model, x: np.ndarray, floors: Floors):
    """Gaps (> 0: through the floor) of the skull and eyeball contacts, and the eyeball normals."""
    skull_gap = floors.floor - _dot(x[:, :, model.contact_ids] - floors.site, floors.normal)
    v = x[:, :, model.eye_ids] - model.eye_centre
    dist = np.sqrt(_dot(v, v))
    return skull_gap, model.eye_floor - dist, v / np.maximum(dist, 1e-12)


def _hold_on_contacts(model: Model, field, gaps, floors: Floors, *, sign: float = -1.0) -> np.ndarray:
    """Remove, for points resting on their floor, the part of ``field`` that points into it.

    For a step (``sign=-1``) that is its inward component; for a gradient
    (``sign=+1``) the outward one (the force pushing the point in, which the
    wall takes up). Acts in place and returns ``field``.
    """
    skull_gap, eye_gap, eye_n = gaps
    for ids, gap, normal in ((model.contact_ids, skull_gap, floors.normal), (model.eye_ids, eye_gap, eye_n)):
        part = field[:, :, ids]
        along = _dot(part, normal)
        blocked = (sign * along > 0) * (gap > -1e-6)
        field[:, :, ids] = part - (along * blocked) * normal
    return field


def project_contacts(model: Model, x: np.ndarray, floors: Floors):
    """Push points through the skull or an eyeball back onto their floor; returns x and the gaps after."""
    x = x.copy()
    skull_gap, eye_gap, eye_n = _gaps(model, x, floors)
    x[:, :, model.contact_ids] += np.maximum(skull_gap, 0.0) * floors.normal
    x[:, :, model.eye_ids] += np.maximum(eye_gap, 0.0) * eye_n
    return x, (np.minimum(skull_gap, 0.0), np.minimum(eye_gap, 0.0), eye_n)


def folded(model: Model, x: np.ndarray, *, guard: float = 0.0) -> np.ndarray:
    """How many skin triangles of each configuration (B,) have turned (nearly) inside out: their
    area along the rest normal at or below ``guard`` of the rest area."""
    f = len(model.fold_area2)
    fe = _apply(model.fold_edges, x)
    signed = _dot(_cross(fe[:, :, :f], fe[:, :, f:]), model.fold_normal) / model.fold_area2
    return ((signed <= guard) & (model.fold_k > 0)).sum(-1)


def clearances(model: Model, x: np.ndarray, ld: Loads) -> tuple[np.ndarray, np.ndarray]:
    """How far each contact point is above its floor: skull (B, K) and eyeballs (B, E); < 0 penetrates."""
    skull_gap, eye_gap, _ = _gaps(model, x, select_sites(model, x, ld))
    return -skull_gap, -eye_gap


# -------------------------------------------------------------- minimiser ---

def _precondition(model: Model, r: np.ndarray) -> np.ndarray:
    """Apply the inverse rest stiffness to (3, B, N).

    One back-substitution per configuration: with all of them at once the batch's width
    changed the last bits of each (SuperLU's blocked solves), and the solves of a batch then
    drifted from the same solves alone.
    """
    out = np.empty_like(r)
    for b in range(r.shape[1]):
        out[:, b] = model.solve_rest(np.ascontiguousarray(r[:, b].T)).T
    return out


def _per_config(a, b) -> np.ndarray:
    """Inner product of two fields per configuration: (3, B, N) × (3, B, N) → (B,), each summed
    alike whatever the batch's width and however many threads BLAS runs.

    (numpy's pairwise sum, not ``np.dot``: OpenBLAS splits a long dot product over its threads,
    so its last bits changed with ``OMP_NUM_THREADS`` or a ``threadpool_limits`` left by other
    code, and a held 1+2+12 on noah ended 2.6 mm from the static solve on one thread, 4.9 on two.)
    """
    return np.array([np.add.reduce((a[:, k] * b[:, k]).ravel()) for k in range(a.shape[1])])


def minimise(model: Model, x: np.ndarray, ld: Loads, iterations: int, *, tolerance: float = 1e-7,
             residual: float = 0.0, memory: tuple = (), floors: "Floors | None" = None, start=None):
    """Projected L-BFGS from ``x`` (3, B, N), H₀⁻¹ = the factorised rest stiffness.

    A point on its contact floor may not step further in (that part of the
    step is removed), and every step ends by projecting back onto the feasible
    side. The skull site under each point is chosen once per call, so the
    energy is fixed during the iterations. Each configuration keeps its own
    history and its own backtracking step.

    ``memory`` is the L-BFGS history of a previous call (pairs of steps and
    gradient changes): the net's curvature changes little from one increment
    or frame to the next, so carrying it over saves relearning it. Returns the
    new points, the updated memory and the energy and gradient there.
    ``floors`` (the skull under each point) may be passed in to reuse a
    previous frame's choice, ``start = (energy, gradient)`` at ``x`` to skip
    evaluating them.

    Each configuration stops when its residual — the norm of the gradient that the
    contacts do not take up, i.e. the net force left on the points — falls below
    ``residual`` times its norm at the start of the call (or every entry below the
    absolute ``tolerance``); the others go on. A configuration stops where it would
    have stopped solved alone.
    """
    if floors is None:
        floors = select_sites(model, x, ld)

    def energy_at(p):
        return energy(model, p, ld)

    def hold(field, gaps, floors, sign=-1.0):
        return _hold_on_contacts(model, field, gaps, floors, sign=sign)

    def project(p):
        return project_contacts(model, p, floors)

    x_in = x
    x, gaps = project(x)
    known = start is not None and np.abs(x - x_in).max() < 1e-12  # the start is still where we are
    e, g = start if known else energy_at(x)
    raw = (e, g)
    g = hold(g.copy(), gaps, floors, sign=1.0)  # the walls take up what pushes into them
    s_hist, y_hist, rho_hist = (list(part) for part in memory[:3]) if memory else ([], [], [])
    # Which configurations each pair belongs to (rho may also be 0 after a failed step: still theirs).
    own_hist = list(memory[4]) if len(memory) > 4 else [rho != 0 for rho in rho_hist]
    # The step that worked last time, but never below a quarter: a converged frame's failed steps
    # must not leave the next frame (a new drive) crawling.
    trust = np.maximum(memory[3], 0.25) if len(memory) > 3 else np.ones(x.shape[1])
    start_norm = np.sqrt(_per_config(g, g))
    for _ in range(iterations):
        norm = np.sqrt(_per_config(g, g))
        active = (norm > residual * start_norm) & (np.abs(g).max(axis=(0, 2)) >= tolerance)
        if not active.any():
            break
        q = g.copy()
        alphas = []
        for s, y, rho in zip(reversed(s_hist), reversed(y_hist), reversed(rho_hist)):
            alpha = rho * _per_config(s, q)
            q -= alpha[:, None] * y
            alphas.append(alpha)
        z = _precondition(model, q)
        for (s, y, rho), alpha in zip(zip(s_hist, y_hist, rho_hist), reversed(alphas)):
            z += (alpha - rho * _per_config(y, z))[:, None] * s
        direction = hold(-z, gaps, floors)
        direction[:, ~active] = 0.0  # converged: stays where it is
        slope = _per_config(g, direction)
        bad = (slope >= 0) & active  # not a descent direction: fall back to the preconditioned gradient
        if bad.any():
            fallback = hold(-_precondition(model, g), gaps, floors)
            direction[:, bad] = fallback[:, bad]
            slope = _per_config(g, direction)
        # Trust region: no point moves further than max_step in one iteration.
        reach = np.sqrt(_dot(direction, direction)).max(axis=-1)
        step = np.minimum(1.0, model.max_step / np.maximum(reach, 1e-12))
        step = np.minimum(step, trust)
        for _attempt in range(8):
            x_new, gaps_new = project(x + step[:, None] * direction)
            e_new, g_new = energy_at(x_new)
            ok = (e_new <= e + 1e-4 * step * np.minimum(slope, 0.0)) | ~active
            if ok.all():
                break
            # Backtrack to the minimum of the quadratic through e, the slope and e_new.
            curve = e_new - e - slope * step
            guess = -slope * step * step / np.maximum(2.0 * curve, 1e-300)
            step = np.where(ok, step, np.clip(guess, 0.1 * step, 0.5 * step))
        # Next time start from about what worked (grow it back while steps succeed).
        trust = np.where(active, np.where(ok, np.minimum(1.0, 2.0 * step), step), trust)
        raw_new = (e_new, g_new)
        g_new = hold(g_new.copy(), gaps_new, floors, sign=1.0)
        rho_hist = [np.where(ok, rho, 0.0) for rho in rho_hist] if not ok.all() else rho_hist  # failed: afresh
        moved = ok & active  # a configuration whose step failed, or that has converged, stays where it was
        if not moved.all():
            x_new[:, ~moved], e_new[~moved], g_new[:, ~moved] = x[:, ~moved], e[~moved], g[:, ~moved]
            raw_new = (np.where(moved, raw_new[0], raw[0]), np.where(moved[None, :, None], raw_new[1], raw[1]))
            if gaps is not None:
                gaps_new = tuple(np.where(moved[:, None], gn, go) for gn, go in zip(gaps_new[:2], gaps[:2])) + (
                    np.where(moved[None, :, None], gaps_new[2], gaps[2]),)
        s, y = x_new - x, g_new - g
        sy = _per_config(s, y)
        x, e, g, gaps, raw = x_new, e_new, g_new, gaps_new, raw_new
        # Keep the pair only if the energy curved up along the step at least a little, compared
        # with the rest stiffness (projections onto contacts and kinks can break the secant pair).
        # (Per configuration: a rejected pair gets rho = 0, which makes it a no-op in the recursion.)
        shs = _per_config(s, model.stiffness_diagonal * s)
        keep = (sy > 1e-3 * shs) & (shs > 0)
        if keep.any():
            s_hist.append(s)
            y_hist.append(y)
            rho_hist.append(np.where(keep, 1.0 / np.where(keep, sy, 1.0), 0.0))
            own_hist.append(keep)
            # Each configuration keeps its own last HISTORY pairs, as it would solved alone: a
            # pair another one kept must not push its oldest out (the batch's shared slots did,
            # and longer solves then drifted from the same solve alone).
            owned = np.sum(own_hist, axis=0)
            for b in np.flatnonzero(owned > HISTORY):
                oldest = next(k for k, own in enumerate(own_hist) if own[b])
                rho_hist[oldest] = np.where(np.arange(len(keep)) == b, 0.0, rho_hist[oldest])
                own_hist[oldest] = own_hist[oldest] & (np.arange(len(keep)) != b)
            while own_hist and not own_hist[0].any():
                del s_hist[0], y_hist[0], rho_hist[0], own_hist[0]
    return x, (tuple(s_hist), tuple(y_hist), tuple(rho_hist), trust, tuple(own_hist)), raw


# ------------------------------------------------------------------ solve ---

_FLIP = np.array([-1.0, 1.0, 1.0])[:, None, None]


def symmetric_drive(model: Model, d: Drive) -> np.ndarray:
    """Which configurations (B,) are driven the same on both sides (so their face is symmetric)."""
    if model.node_mirror is None:
        return np.zeros(d.muscle.shape[0], bool)
    same = np.abs(d.muscle - d.muscle[:, model.muscle_mirror]).max(axis=1) < 1e-12
    same &= np.abs(d.pressure[:, 0] - d.pressure[:, 1]) < 1e-12
    same &= np.abs(d.tongue[:, 1]) < 1e-12
    return same


def rest_state(model: Model, batch: int = 1) -> State:
    """The neutral face (no activation), ``batch`` copies."""
    m = len(model.layer.names)
    zero = Drive(np.zeros((batch, m)), np.zeros((batch, 2)), np.zeros(batch), np.zeros((batch, 3)))
    return State(_batch(model.rest, batch), zero, np.zeros((batch, 3)))


def _lerp_drive(a: Drive, b: Drive, t: float) -> Drive:
    return Drive(*(pa + t * (pb - pa) for pa, pb in zip((a.muscle, a.pressure, a.lip_pressure, a.tongue),
                                                         (b.muscle, b.pressure, b.lip_pressure, b.tongue))))


def solve(model: Model, state: State, target: Drive, *, steps: int = 3, iterations: int = 12,
          residual: float = 0.0, settle: bool = True) -> State:
    """Apply the change from ``state.drive`` to ``target`` in ``steps`` increments.

    Each increment adds 1/steps of the change and relaxes the net toward
    equilibrium from the previous one (Platt & Badler's n-step contraction);
    every intermediate state is a valid expression (an animation steps with
    ``steps=1`` per frame). Each increment iterates until the net force left on
    the points falls below ``residual`` of what the increment added (see
    :func:`minimise`), ``iterations`` at most.

    ``settle`` re-chooses, at the end, the bone each point lies over after
    sliding and projects onto it (a static solve's last word). Without it (the
    animation path) the choice is kept for up to :data:`FLOOR_AGE` frames while
    the jaw does not move, and the next frame starts from it.
    """
    x, memory, floors, age, jaw = state.x, state.memory, state.floors, state.age, state.jaw
    known = state.known  # (loads, energy, gradient) at x from the last frame
    for k in range(1, steps + 1):
        d = _lerp_drive(state.drive, target, k / steps)
        ld = loads(model, d)
        same_jaw = np.abs(ld.jaw - jaw).max() <= 1e-9
        stale = floors is None or age >= FLOOR_AGE or floors.site.shape[1] != x.shape[1] or not same_jaw
        if stale:
            floors, age = select_sites(model, x, ld), 0
        start = None
        if known is not None and same_jaw and known[0].jaw.shape == ld.jaw.shape:
            # Only the drive changed: swap its share of the last energy instead of recomputing it all.
            old_e, old_g = load_energy(model, x, known[0])
            new_e, new_g = load_energy(model, x, ld)
            start = (known[1] - old_e + new_e, known[2] - old_g + new_g)
        x, memory, (e, g) = minimise(model, x, ld, iterations, residual=residual, memory=memory,
                                   floors=floors, start=start)
        known = (ld, e, g)
        mirrored = symmetric_drive(model, d) if settle else np.zeros(0, bool)
        if mirrored.any():  # a symmetric drive moves the face symmetrically: drop the round-off that breaks it
            rest = model.rest.T[:, None, :]
            moved = x[:, mirrored] - rest
            x = x.copy()
            x[:, mirrored] = rest + 0.5 * (moved + moved[:, :, model.node_mirror] * _FLIP)
            known = None
        age, jaw = age + 1, ld.jaw
        if settle:  # the flesh may have slid onto other bone: settle on it (the sites follow: repeat)
            for _ in range(SETTLE_PASSES):
                floors, age = select_sites(model, x, ld), 0
                skull_gap, eye_gap, _ = _gaps(model, x, floors)
                through = np.maximum(skull_gap.max(axis=-1, initial=0.0), eye_gap.max(axis=-1, initial=0.0)) >= 1e-9
                if not through.any():
                    break
                # (Only the configurations still through a floor: each settles as it would alone.)
                x = np.where(through[None, :, None], project_contacts(model, x, floors)[0], x)
            known = None
    return State(x, target, ld.jaw, memory, floors, age, known)
