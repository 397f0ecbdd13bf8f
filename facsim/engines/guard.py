"""Keep a deformed face physical: skin off the eyeballs, no skin turned inside out.

Both engines end with this step, after their own deformation and before the
rigid head motion (51–58):

1. **Eyeball contact.** Skin that lies outside an eyeball at rest may not
   enter it: summed targets (registers) or a cheek pushed up by the orbital
   ring (muscles, AU 6) can otherwise move the lower lid or the skin under it
   into the eye, which then shows through the skin. Such points are moved out
   along the eyeball's radius to the surface plus a clearance (never further
   out than they rest).
2. **Untangling.** A skin triangle whose area along its rest normal falls
   below a small share of its rest area has folded (or is about to fold)
   through its neighbours — two targets that each move the lid crease, or
   one that moves the lid margin further than the lid's skin can follow. The
   displacement of its corners (and, if that is not enough, of a widening ring
   around them) is relaxed toward the average of their neighbours' — a
   membrane that refuses to fold — while every other vertex keeps its
   displacement. A constant displacement is a rigid shift of the rest
   surface, which is fold-free, so the relaxation always ends.
3. **Opening slivers.** What the relaxation leaves folded is opened by the
   least motion that gives each such triangle its share of area back
   (its corners moved along the gradient of its area, the triangles in turn
   until none is folded). The eye corners of the East Asian presets are
   drawn together by their character morphs into fans of slivers 0.1-0.3 mm
   wide (mei's outer corner: 0.13 mm, ava's 1.0 mm); a lid target made on
   the base mesh moves one row of the fan past the other (7 on mei: the
   lower row rises 0.4 mm more than the upper one, 0.13 mm above it), and a
   rigid copy of a rest patch fitted there folds the next sliver as it
   opens one. Opening them takes 0.2-0.3 mm; the lid keeps its motion.

The two can undo each other a little (relaxing a lid may move it into the eye,
pushing it out may fold a triangle), so they alternate a few times.

Examples
--------
>>> guard = SkinGuard(head, rest, eye_centres, eye_radius)   # doctest: +SKIP
>>> positions = guard(positions)                              # doctest: +SKIP
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

#: Least share of its rest area a skin triangle keeps along its rest normal.
MIN_AREA_SHARE = 0.05
#: ... and below the jaw: head motion (51-58) blends into the neck there AFTER this step, and
#: shears any pleat an open jaw (27) leaves under the chin through itself unless it keeps room.
NECK_AREA_SHARE = 0.25
#: Skin within this height (dm) over an eyeball at rest keeps its rest height over it when an
#: expression moves it there (the lid slides over the eye keeping its thickness); skin further
#: out is kept at least this high. 3 mm: a lid's thickness at its margin and a little more.
LID_HEIGHT = 0.03
#: Rounds of (eye contact, untangling); relaxation passes per round; rings grown per stuck round.
ROUNDS = 4
#: Rounds of the untangling step; the patch fitted around a folded triangle widens by a ring
#: every WIDEN_EVERY rounds it stays folded, up to MAX_RINGS.
UNTANGLE_ROUNDS = 64
WIDEN_EVERY = 8
MAX_RINGS = 6
#: Furthest (dm) the untangling moves any vertex: 3 mm.
MAX_CORRECTION = 0.03
#: ... and after head motion, in the neck's blend (:meth:`SkinGuard.after_head_motion`): a pleat
#: under an open jaw sheared by a bent neck needs a little more (6 mm: george's 27E+54E kept two
#: midline triangles under the chin inverted at 4.5 mm on some CPUs, whose solves differ in the last bits).
NECK_CORRECTION = 0.06
#: Rest triangles smaller than this (twice the area, dm²) have no reliable orientation.
DEGENERATE_AREA2 = 1e-10
#: Sliver opening: a triangle still folded after the relaxation is opened to this much more
#: than its least share (so that round-off leaves it open), in at most this many passes.
OPEN_MARGIN = 0.05
OPEN_PASSES = 200


class SkinGuard:
    """The final physical step of an engine, for one character.

    Parameters
    ----------
    head : HeadModel
        Gives the skin triangles (geometry vertices ``0 … skin_vertex_count-1``).
    rest : (N_geo, 3) array
        The character's neutral geometry.
    eye_centres : sequence of (3,) arrays
        The eyeball centres (at rest: the step runs before rigid head motion).
    eye_radius : float
    neck_below : float, optional
        Height (dm) of the jaw joint: skin triangles below it keep :data:`NECK_AREA_SHARE`.
    """

    def __init__(self, head, rest, eye_centres, eye_radius: float, neck_below: float | None = None):
        rest = np.asarray(rest, float)
        self.skin = int(head.skin_vertex_count)
        tris = np.asarray(head.triangles)
        tris = tris[(tris < self.skin).all(axis=1)]
        cross = np.cross(rest[tris[:, 1]] - rest[tris[:, 0]], rest[tris[:, 2]] - rest[tris[:, 0]])
        area2 = np.linalg.norm(cross, axis=1)
        sound = area2 > DEGENERATE_AREA2
        self.triangles = tris[sound]
        self.rest_area2 = area2[sound]
        self.rest_normal = cross[sound] / area2[sound, None]
        self.rest = rest[: self.skin]
        self.min_share = np.full(len(self.triangles), MIN_AREA_SHARE)
        if neck_below is not None:
            self.min_share[rest[self.triangles, 1].mean(axis=1) < neck_below] = NECK_AREA_SHARE
        edges = np.concatenate([self.triangles[:, [0, 1]], self.triangles[:, [1, 2]], self.triangles[:, [2, 0]]])
        n = self.skin
        adj = sp.coo_matrix((np.ones(2 * len(edges)), (np.r_[edges[:, 0], edges[:, 1]], np.r_[edges[:, 1], edges[:, 0]])),
                            shape=(n, n)).tocsr()
        adj.data[:] = 1.0  # duplicate edges (shared by two triangles) count once
        self.adjacency = adj
        self._adjacency = adj
        self._patch_cache = {}
        self.eyes = []
        for centre in eye_centres:
            centre = np.asarray(centre, float)
            dist = np.linalg.norm(self.rest - centre, axis=1)
            outside = np.flatnonzero(dist >= eye_radius)
            floor = np.minimum(dist[outside], eye_radius + LID_HEIGHT)
            self.eyes.append((centre, outside, floor))

    def __call__(self, positions: np.ndarray) -> np.ndarray:
        """A copy of ``positions`` (N_geo, 3) with the skin kept physical."""
        out = np.array(positions, dtype=np.float32, copy=True)
        skin = out[: self.skin].astype(float)
        for _ in range(ROUNDS):
            moved = self.off_eyes(skin)
            folded = self.untangle(skin)
            if not moved and not folded:
                break
        out[: self.skin] = skin
        return out

    # -- the two steps (in place on skin positions (N_skin, 3), float64)

    def off_eyes(self, skin: np.ndarray) -> int:
        """Move skin out of the eyeballs; returns how many points moved."""
        count = 0
        for centre, outside, floor in self.eyes:
            offset = skin[outside] - centre
            dist = np.linalg.norm(offset, axis=1)
            inside = dist < floor - 1e-9
            if inside.any():
                ids = outside[inside]
                skin[ids] = centre + offset[inside] * (floor[inside] / np.maximum(dist[inside], 1e-12))[:, None]
                count += int(inside.sum())
        return count

    def folded(self, skin: np.ndarray, rest_normal=None, min_share=None) -> np.ndarray:
        """Indices of skin triangles below :data:`MIN_AREA_SHARE` (:data:`NECK_AREA_SHARE` under the jaw)
        of their rest area along the rest normal (or along ``rest_normal``, against ``min_share``)."""
        t = self.triangles
        normal = self.rest_normal if rest_normal is None else rest_normal
        cross = np.cross(skin[t[:, 1]] - skin[t[:, 0]], skin[t[:, 2]] - skin[t[:, 0]])
        share = (cross * normal).sum(axis=1) / self.rest_area2
        return np.flatnonzero(share < (self.min_share if min_share is None else min_share))

    def _patches(self, bad: np.ndarray, rings: int) -> tuple[np.ndarray, np.ndarray]:
        """Patches of ``rings`` rings around triangles ``bad`` (built on first use, then kept)."""
        rings = min(rings, MAX_RINGS)
        missing = [t for t in bad if (t, rings) not in self._patch_cache]
        if missing:
            patch, weight = _patches(self.triangles[missing], self._adjacency, rings)
            for k, t in enumerate(missing):
                n = int(weight[k].sum())
                self._patch_cache[t, rings] = patch[k, :n]
        rows = [self._patch_cache[t, rings] for t in bad]
        width = max(len(r) for r in rows)
        patch = np.array([np.r_[r, np.full(width - len(r), r[0])] for r in rows])
        weight = (np.arange(width)[None, :] < np.array([len(r) for r in rows])[:, None]).astype(float)
        return patch, weight

    def after_head_motion(self, positions: np.ndarray, turn: np.ndarray, blend: np.ndarray) -> np.ndarray:
        """Untangle the neck once more after head motion (51-58) moved ``positions``.

        The head's turn fades into the neck, each point turning by its rest weight in
        the blend. An open jaw (25-27) leaves the skin under the chin and down the
        throat compressed along that fade, so a head bent forward (54) turns the upper
        edge of the pleat further than its lower edge and shears it through itself.
        Here the triangles with a corner in the blend (``blend``: (N_geo,) weights,
        strictly between 0 and 1 there) are checked against their rest normals turned
        as the head turned (``turn``, 3×3) and untangled as before; elsewhere the
        motion is rigid and nothing changes.
        """
        out = np.array(positions, dtype=np.float32, copy=True)
        t = self.triangles
        zone = ((blend[t] > 0.0) & (blend[t] < 1.0)).any(axis=1)
        skin = out[: self.skin].astype(float)
        self.untangle(skin, rest_normal=self.rest_normal @ np.asarray(turn, float).T,
                      min_share=np.where(zone, self.min_share, -np.inf), eyes=False,  # the eyes have moved
                      most=NECK_CORRECTION)
        out[: self.skin] = skin
        return out

    def untangle(self, skin: np.ndarray, *, rest_normal=None, min_share=None, eyes: bool = True,
                 most: float = MAX_CORRECTION) -> int:
        """Unfold folded triangles (in place); returns how many were folded at first.

        The corners of each folded triangle are drawn toward their rest shape,
        turned and moved as the ring of skin around them now lies (the best
        rigid fit of the rest patch, Kabsch): a rigid copy of the rest surface
        is not folded, and the fit keeps what the patch does as a whole (a
        closing lid still closes). Only the corners move, and none further
        than :data:`MAX_CORRECTION` in all.
        """
        folded = lambda: self.folded(skin, rest_normal, min_share)  # noqa: E731
        bad = folded()
        first = len(bad)
        start = skin.copy()
        for it in range(UNTANGLE_ROUNDS):
            if not len(bad):
                break
            patch, weight = self._patches(bad, 1 + it // WIDEN_EVERY)           # (B, P)
            fit = _rigid_fits(self.rest[patch], skin[patch], weight)           # (B, P, 3)
            corners = self.triangles[bad]                                      # (B, 3)
            total = np.zeros_like(skin)
            count = np.zeros(self.skin)
            np.add.at(total, corners.ravel(), fit[:, :3].reshape(-1, 3))
            np.add.at(count, corners.ravel(), 1.0)
            moved = count > 0
            skin[moved] += 0.5 * (total[moved] / count[moved, None] - skin[moved])
            self._within_reach(skin, start, most, eyes)
            bad = folded()
        if len(bad):
            self.open_slivers(skin, bad, folded, rest_normal=rest_normal, min_share=min_share)
            self._within_reach(skin, start, most, eyes)
        return first

    def _within_reach(self, skin: np.ndarray, start: np.ndarray, most: float, eyes: bool) -> None:
        """Clip each vertex's correction to ``most`` (dm) from ``start`` and keep it off the eyes (in place).

        A fold that needs more than that to undo is the target's own shape (a lid margin
        rolling under as the eye closes): leave it rather than reshape the lid.
        """
        shift = skin - start
        length = np.linalg.norm(shift, axis=1)
        far = length > most
        skin[far] = start[far] + shift[far] * (most / length[far])[:, None]
        if eyes:
            self.off_eyes(skin)

    def open_slivers(self, skin: np.ndarray, bad: np.ndarray, folded, *, rest_normal=None, min_share=None) -> None:
        """Open folded triangles ``bad`` by the least motion of their corners (in place).

        Each folded triangle's corners move along the gradient of its area along the
        rest normal, as far as restores :data:`OPEN_MARGIN` more than its least share
        (a projection onto the constraint, as in position-based dynamics); a corner
        shared by several folded triangles takes the mean of their moves. ``folded()``
        names the triangles still folded after each pass.
        """
        normal = self.rest_normal if rest_normal is None else rest_normal
        least = self.min_share if min_share is None else min_share
        for _ in range(OPEN_PASSES):
            if not len(bad):
                break
            corners = self.triangles[bad]                                      # (B, 3)
            n = normal[bad]
            x0, x1, x2 = (skin[corners[:, k]] for k in range(3))
            e1, e2 = x1 - x0, x2 - x0
            lack = (least[bad] + OPEN_MARGIN) * self.rest_area2[bad] - (np.cross(e1, e2) * n).sum(axis=1)
            g1, g2 = np.cross(e2, n), np.cross(n, e1)                          # d(area)/d(corner 1, 2)
            grads = (-(g1 + g2), g1, g2)
            step = lack / np.maximum(sum((g * g).sum(axis=1) for g in grads), 1e-20)
            total = np.zeros_like(skin)
            count = np.zeros(self.skin)
            for k, g in enumerate(grads):
                np.add.at(total, corners[:, k], step[:, None] * g)
                np.add.at(count, corners[:, k], 1.0)
            moved = count > 0
            skin[moved] += total[moved] / count[moved, None]
            bad = folded()


def _patches(triangles: np.ndarray, adjacency, rings: int) -> tuple[np.ndarray, np.ndarray]:
    """Per triangle: its corners first, then ``rings`` rings of neighbours, padded (T, P); and 1/0 weights."""
    indptr, indices = adjacency.indptr, adjacency.indices
    rows = []
    for tri in triangles:
        ring = np.asarray(tri)
        for _ in range(rings):
            ring = np.union1d(ring, np.concatenate([indices[indptr[v]:indptr[v + 1]] for v in ring]))
        rows.append(np.r_[tri, np.setdiff1d(ring, tri)])
    width = max(len(r) for r in rows)
    patch = np.zeros((len(rows), width), np.int64)
    weight = np.zeros((len(rows), width))
    for k, r in enumerate(rows):
        patch[k, :len(r)] = r
        patch[k, len(r):] = r[0]
        weight[k, :len(r)] = 1.0
    return patch, weight


def _rigid_fits(rest: np.ndarray, now: np.ndarray, weight: np.ndarray) -> np.ndarray:
    """Each patch's rest points (B, P, 3) turned and moved to fit ``now`` best (weighted; proper
    rotations, no mirroring)."""
    w = weight[..., None] / weight.sum(axis=1)[:, None, None]
    a = (w * rest).sum(axis=1, keepdims=True)
    b = (w * now).sum(axis=1, keepdims=True)
    cov = np.einsum("bpi,bpj->bij", w * (rest - a), now - b)
    u, _, vt = np.linalg.svd(cov)
    d = np.sign(np.linalg.det(u @ vt))
    u[:, :, 2] *= d[:, None]
    return np.einsum("bpi,bij->bpj", rest - a, u @ vt) + b
