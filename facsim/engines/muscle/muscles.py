"""Muscles on the tension net, and the AU parser (AU → muscles → loads).

Platt & Badler's structures, bottom up:

* a **fiber** joins a *bone point* (its fixed base) to a *muscle point* that is
  tied by arcs to one or more *skin heads*. Contracting it pulls the muscle
  point toward the bone. Where the fiber bends over bone (zygomaticus major over
  the cheekbone, frontalis over the forehead) it passes through intermediate
  muscle points that ride the bone sheet: the paper's "improved muscle". A
  fiber under tension ``T`` has the potential ``T × (length of its path)``, so
  its force on each muscle point is ``T`` along the path on either side.
* a **sphincter** is a chain (or ring) of muscle points under tension; it
  straightens and shrinks toward its centre (orbicularis oculi and oris).
* a **muscle** is a set of fibers with a maximal force; an **AU** is a set of
  muscles with relative magnitudes (``muscle_aus.yaml``). Negative magnitudes
  relax a muscle's resting tone (the jaw drops when the masseter relaxes).
* **jaw muscles** act on the mandible, a rigid bone (see :func:`jaw_pose`).

Air pressure in the mouth (cheek blow, puff and suck) and the tongue are the
other loads; :func:`loads` turns activations into all of them at once.
"""
from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from importlib import resources

import numpy as np
import yaml
from scipy.spatial import cKDTree

from facsim.engines.muscle.net import LID, MOUTH, OUTER, SIDES, SOCKET, Anatomy, Arcs, TensionNet, carry_points, patch, resolve_vertex

AU_FILE = "muscle_aus.yaml"
#: Depth (in tissue depths below the skin) of an insertion's muscle point.
INSERTION_DEPTH = 0.5


@lru_cache(maxsize=1)
def au_table() -> dict:
    """The parsed ``facsim/data/muscle_aus.yaml``."""
    text = resources.files("facsim").joinpath("data", AU_FILE).read_text(encoding="utf-8")
    return yaml.load(text, Loader=getattr(yaml, "CSafeLoader", yaml.SafeLoader))


# ------------------------------------------------------------ the layer ---

@dataclass(frozen=True, eq=False)
class MuscleLayer:
    """The muscles of one character, as arrays (frozen; see :func:`build_muscles`).

    Node numbering is global: skin points ``0 … N_skin-1``, then this layer's
    muscle points. Chain segments join two points; a negative end ``-1 - b``
    names bone point ``b`` instead (fixed to the skull or riding the jaw).

    Attributes
    ----------
    names : tuple of str
        One per muscle and side, e.g. ``"zygomaticus_major_left"``;
        midline muscles carry no side.
    muscle, side : per-muscle base name and side ("left", "right", "both").
    force, tone : (M,) float
        Maximal tension and resting tone (a fraction of ``force``).
    node_rest : (Q, 3) float
        Rest positions of the muscle points.
    node_parent : (Q,) int
        The skin point each muscle point lies beneath (its bone and eye contacts).
    node_floor : (Q,) float
        Least height of the muscle point above bone.
    arcs : Arcs
        Insertion arcs (muscle point ↔ skin heads), guide couplings, passive bellies.
    seg_a, seg_b, seg_muscle, seg_weight : (S,) chain segments and their muscle/fiber share.
    seg_fiber : (S,) int
        The fiber each segment belongs to (a linear muscle's fiber, or a sphincter's whole chain):
        a fiber's force-length relation is read on its whole path's length.
    head_ids, head_weight : (H,) skin heads of the linear muscles' insertions into the skin and their
        weight in the insertion's patch (1 at its centre); the skin is stiffer there.
    bone_points, bone_on_jaw : (P, 3), (P,) bool.
    relax_node, relax_dir, relax_muscle, relax_weight : where a relaxing muscle's tone is released.
    jaw_action : (M, 3)
        Generalised force of each muscle on the jaw pose (opening, protrusion, lateral) at full force.
    bulge_ids, bulge_vec, bulge_muscle : outward push of a contracting belly (masseter).
    """

    names: tuple
    muscle: tuple
    side: tuple
    kind: tuple
    force: np.ndarray
    tone: np.ndarray
    node_rest: np.ndarray
    node_parent: np.ndarray
    node_floor: np.ndarray
    arcs: Arcs
    seg_a: np.ndarray
    seg_b: np.ndarray
    seg_muscle: np.ndarray
    seg_weight: np.ndarray
    bone_points: np.ndarray
    bone_on_jaw: np.ndarray
    relax_node: np.ndarray
    relax_dir: np.ndarray
    relax_muscle: np.ndarray
    relax_weight: np.ndarray
    jaw_action: np.ndarray
    bulge_ids: np.ndarray
    bulge_vec: np.ndarray
    bulge_muscle: np.ndarray
    clench: np.ndarray = None    # (M,) bool: contracting it presses the teeth together
    seg_fiber: np.ndarray = None
    head_ids: np.ndarray = None
    head_weight: np.ndarray = None

    def index(self, name: str, side: str) -> int:
        """Index of muscle ``name`` on ``side`` (midline muscles answer for both sides)."""
        for k, (m, s) in enumerate(zip(self.muscle, self.side)):
            if m == name and s in (side, "both"):
                return k
        raise KeyError(f"no muscle {name!r} on side {side!r}; muscles are {sorted(set(self.muscle))}")


class _Builder:
    """Accumulates muscle points, arcs, chain segments and bone points while reading the spec."""

    def __init__(self, anat: Anatomy, net: TensionNet, constants: dict):
        self.anat, self.net, self.c = anat, net, constants
        self.n_skin = net.count
        self.nodes, self.parent, self.floor = [], [], []
        self.arcs = {k: [] for k in ("i", "j", "rest", "k", "beta", "compress")}
        self.seg = {k: [] for k in ("a", "b", "muscle", "weight", "fiber")}
        self.fibers = 0
        self.heads, self.head_weight = [], []
        self.bones, self.bone_jaw = [], []
        self.relax = {k: [] for k in ("node", "dir", "muscle", "weight")}
        self._outer_tree = cKDTree(net.rest[anat.outer])

    # -- points
    def bone(self, position, on_jaw: bool) -> int:
        self.bones.append(np.asarray(position, float))
        self.bone_jaw.append(bool(on_jaw))
        return -len(self.bones)  # -1 - index

    def node(self, position, parent: int, floor: float) -> int:
        self.nodes.append(np.asarray(position, float))
        self.parent.append(int(parent))
        self.floor.append(float(floor))
        return self.n_skin + len(self.nodes) - 1

    def arc(self, i: int, j: int, k: float, beta: float = 0.0, compress: float = 1.0):
        pi, pj = self.position(i), self.position(j)
        for key, v in zip(("i", "j", "rest", "k", "beta", "compress"),
                          (i, j, np.linalg.norm(pi - pj), k, beta, compress)):
            self.arcs[key].append(v)

    def position(self, ref: int) -> np.ndarray:
        if ref < 0:
            return self.bones[-1 - ref]
        if ref < self.n_skin:
            return self.net.rest[ref]
        return self.nodes[ref - self.n_skin]

    def new_fiber(self) -> int:
        self.fibers += 1
        return self.fibers - 1

    def segment(self, a: int, b: int, muscle: int, weight: float, fiber: int):
        for key, v in zip(("a", "b", "muscle", "weight", "fiber"), (a, b, muscle, weight, fiber)):
            self.seg[key].append(v)

    # -- selectors on the character
    def skin_point(self, sel: dict, side: str) -> tuple[int, np.ndarray]:
        """Vertex and position of a skin selector, moved ``depth`` tissue depths inward (and by
        ``offset``, base-mesh dm, mirrored on the right)."""
        vid = resolve_vertex(self.anat, sel, side)
        depth = sel.get("depth", 0.0) * self.net.depth[vid]
        offset = np.asarray(sel.get("offset", (0.0, 0.0, 0.0)), float) * self.net.scale
        if side == "right":
            offset = offset * [-1.0, 1.0, 1.0]
        return vid, self.net.rest[vid] - depth * self.net.normal[vid] + offset

    def point(self, sel: dict, side: str) -> tuple[int, np.ndarray]:
        """Any selector → (nearest skin vertex, position on this character)."""
        mirror = np.array([-1.0 if side == "right" else 1.0, 1.0, 1.0])
        if "at" in sel:
            p = carry_points(self.anat, self.net.rest, np.asarray(sel["at"], float) * mirror)[0]
        elif "eye" in sel:
            centre = self.net.eye_centre[SIDES.index(side)]
            p = centre + self.net.scale * np.asarray(sel["eye"], float) * mirror
        else:
            return self.skin_point(sel, side)
        return self._nearest(p, side)[0], p

    def _nearest(self, p, side: str, k: int = 1) -> list[int]:
        """The ``k`` outer-skin vertices nearest to ``p``, chosen on the left and mirrored for the
        right (so that ties break alike on both sides)."""
        left = np.asarray(p, float) * ([-1.0, 1.0, 1.0] if side == "right" else 1.0)
        _, j = self._outer_tree.query(left, k=k)
        ids = self.anat.outer[np.atleast_1d(j)]
        return [int(self.anat.mirror[v]) if side == "right" else int(v) for v in ids]

    def insertion(self, sel: dict, side: str, force: float = 0.0) -> tuple[int, np.ndarray, np.ndarray]:
        """A muscle point beneath a patch of skin heads: (node, heads, weights).

        A fiber of a muscle of maximal ``force`` ties it with ``tendon × force`` more (a
        stronger muscle has a thicker tendon)."""
        vid, _ = self.skin_point({k: v for k, v in sel.items() if k != "depth"}, side)
        kinds = (LID, SOCKET) if self.anat.kind[vid] in (LID, SOCKET) else (OUTER, LID)
        radius = sel.get("radius", 0.04)
        heads, w = patch(self.anat, vid, radius, kinds=kinds)
        centre = (w[:, None] * self.net.rest[heads]).sum(axis=0)
        normal = (w[:, None] * self.net.normal[heads]).sum(axis=0)
        normal /= np.linalg.norm(normal)
        on_eye = self.anat.kind[vid] in (LID, SOCKET)
        # Lid muscles lie on the tarsus, right under the skin; elsewhere half a tissue depth down.
        depth = 0.0 if on_eye else INSERTION_DEPTH * (w * self.net.depth[heads]).sum()
        node = self.node(centre - depth * normal, vid, 0.1 * self.net.depth[vid])
        # `stiffness` (relative) ties a strong muscle's point more firmly to its skin: through the
        # default arcs a tension T stretches them T / insertion, and zygomaticus major reached its
        # pulley (the fiber fully shortened) with the lip corner only 10 mm up (issue 13).
        k = self.c["insertion"] * float(sel.get("stiffness", 1.0)) + self.c.get("tendon", 0.0) * force
        for h, wh in zip(heads, w):
            self.arc(node, int(h), k * wh)
        return node, heads, w

    def guide(self, sel: dict, side: str, on_jaw: bool) -> int:
        """An intermediate point of an improved muscle: a muscle point over the bone sheet,
        or a fixed pulley (``fixed: true``, e.g. Whitnall's ligament for the levator)."""
        vid, p = self.point(sel, side)
        if sel.get("fixed"):
            return self.bone(p, on_jaw)
        node = self.node(p, vid, 0.1 * self.net.depth[vid])
        # Coupled to the skin above it (the muscle lies in the superficial fascia).
        for h in self._nearest(p, side, k=3):
            self.arc(node, h, self.c["guide_coupling"] / 3.0)
        return node


def _fan(spec: dict) -> list[dict]:
    """Fibers interpolated between the two end fibers of a ``fan`` (numeric selector fields)."""
    count, a, b = spec["count"], spec["from"], spec["to"]

    def lerp(x, y, t):
        if isinstance(x, dict):
            if set(x) != set(y):  # different kinds of selector: take the nearer end's
                return x if t < 0.5 else y
            return {k: lerp(x[k], y[k], t) for k in x}
        if isinstance(x, list):
            return [lerp(u, v, t) for u, v in zip(x, y)]
        if isinstance(x, (int, float)) and not isinstance(x, bool):
            return (1 - t) * x + t * y
        return x

    return [lerp(a, b, t) for t in np.linspace(0.0, 1.0, count)]


def build_muscles(anat: Anatomy, net: TensionNet, spec: dict) -> MuscleLayer:
    """Read the muscles of ``spec`` (muscles.yaml) onto a character's net."""
    b = _Builder(anat, net, spec["net"])
    names, muscle_of, side_of, kinds, force, tone, clench = [], [], [], [], [], [], []
    jaw_action, bulges = [], []
    for name, m in spec["muscles"].items():
        sides = ("both",) if m.get("midline") else SIDES
        for side in sides:
            geo_side = "left" if side == "both" else side
            index = len(names)
            names.append(name if side == "both" else f"{name}_{side}")
            muscle_of.append(name)
            side_of.append(side)
            kinds.append(m["kind"])
            force.append(float(m["force"]))
            tone.append(float(m.get("tone", 0.0)))
            clench.append(bool(m.get("clench", False)))
            action = np.zeros(3)
            if m["kind"] == "linear":
                _linear(b, m, index, geo_side)
            elif m["kind"] == "sphincter":
                _sphincter(b, m, index, geo_side, midline=side == "both")
            elif m["kind"] == "jaw":
                action = _jaw_action(b, m, geo_side, net)
            else:
                raise ValueError(f"muscles.yaml, {name}: unknown kind {m['kind']!r} (linear, sphincter, jaw)")
            if "belly" in m:  # a contracting belly thickens (its volume is kept) and pushes the skin out
                bulges.append((index, m["belly"], geo_side))
            jaw_action.append(action)

    bulge_ids, bulge_vec, bulge_muscle = [], [], []
    for index, belly, side in bulges:
        vid = resolve_vertex(anat, belly, side)
        ids, w = patch(anat, vid, belly["radius"])
        bulge_ids.append(ids)
        bulge_vec.append(belly["bulge"] * w[:, None] * net.normal[ids])
        bulge_muscle.append(np.full(len(ids), index))

    arr = lambda key, d=b.arcs: np.asarray(d[key], float)  # noqa: E731
    return MuscleLayer(
        names=tuple(names), muscle=tuple(muscle_of), side=tuple(side_of), kind=tuple(kinds),
        force=np.asarray(force), tone=np.asarray(tone),
        node_rest=np.asarray(b.nodes, float).reshape(-1, 3), node_parent=np.asarray(b.parent, np.int64),
        node_floor=np.asarray(b.floor, float),
        arcs=Arcs(np.asarray(b.arcs["i"], np.int64), np.asarray(b.arcs["j"], np.int64), arr("rest"),
                  arr("k"), arr("beta"), arr("compress")),
        seg_a=np.asarray(b.seg["a"], np.int64), seg_b=np.asarray(b.seg["b"], np.int64),
        seg_muscle=np.asarray(b.seg["muscle"], np.int64), seg_weight=np.asarray(b.seg["weight"], float),
        seg_fiber=np.asarray(b.seg["fiber"], np.int64),
        head_ids=np.concatenate(b.heads) if b.heads else np.zeros(0, np.int64),
        head_weight=np.concatenate(b.head_weight) if b.head_weight else np.zeros(0),
        bone_points=np.asarray(b.bones, float).reshape(-1, 3), bone_on_jaw=np.asarray(b.bone_jaw, bool),
        relax_node=np.asarray(b.relax["node"], np.int64),
        relax_dir=np.asarray(b.relax["dir"], float).reshape(-1, 3),
        relax_muscle=np.asarray(b.relax["muscle"], np.int64), relax_weight=np.asarray(b.relax["weight"], float),
        jaw_action=np.asarray(jaw_action, float).reshape(-1, 3),
        bulge_ids=np.concatenate(bulge_ids) if bulge_ids else np.zeros(0, np.int64),
        bulge_vec=np.concatenate(bulge_vec) if bulge_vec else np.zeros((0, 3)),
        bulge_muscle=np.concatenate(bulge_muscle) if bulge_muscle else np.zeros(0, np.int64),
        clench=np.asarray(clench, bool),
    )


def _linear(b: _Builder, m: dict, index: int, side: str):
    """Fibers bone → (guides) → muscle point; tone released along the last segment."""
    fibers = _fan(m["fan"]) if "fan" in m else m["fibers"]
    on_jaw = m.get("bone", "skull") == "jaw"
    total = sum(f.get("weight", 1.0) for f in fibers)
    for fiber in fibers:
        weight = fiber.get("weight", 1.0) / total
        _, origin_pos = b.point(fiber["origin"], side)
        chain = [b.bone(origin_pos, on_jaw)]
        chain += [b.guide(g, side, on_jaw) for g in fiber.get("path", [])]
        node, heads, w = b.insertion(fiber["insertion"], side, force=float(m["force"]))
        # A fiber's insertion into the skin (not a lid's tarsus), on its own side of the midline (a
        # patch reaching across it - procerus - stiffened there dragged the other brow along).
        skin = b.anat.kind[heads] == OUTER
        if not m.get("midline"):
            skin &= b.net.rest[heads, 0] * (1.0 if side == "left" else -1.0) > 0.0
        b.heads.append(np.asarray(heads, np.int64)[skin])
        b.head_weight.append(np.asarray(w, float)[skin] / max(float(np.max(w)), 1e-12))
        chain.append(node)
        fiber_id = b.new_fiber()
        for p, q in zip(chain[:-1], chain[1:]):
            b.segment(p, q, index, weight, fiber_id)
            if p >= 0 and q >= 0:  # passive belly between muscle points
                b.arc(p, q, b.c["muscle_passive"], beta=0.0, compress=1.0)
        direction = b.position(chain[-2]) - b.position(node)
        b.relax["node"].append(node)
        b.relax["dir"].append(direction / np.linalg.norm(direction))
        b.relax["muscle"].append(index)
        b.relax["weight"].append(weight)


def _sphincter(b: _Builder, m: dict, index: int, side: str, midline: bool):
    """A ring or an anchored chain of muscle points under tension. ``rings`` (concentric arcs of
    one muscle, e.g. the inner and outer fibres of orbicularis oculi's orbital part) gives a chain
    per arc, each shortening as a fiber of its own under the muscle's tension."""
    if "rings" in m:
        for ring in m["rings"]:
            _sphincter_chain(b, m, index, side, *_ring_selectors(ring))
    elif "ring" in m:
        _sphincter_chain(b, m, index, side, *_ring_selectors(m["ring"]))
    else:
        _sphincter_chain(b, m, index, side, m["chain"], m.get("radius", 0.03), False)


def _ring_selectors(ring: dict) -> tuple[list[dict], float, bool]:
    """A ring's (or an arc's) skin selectors, the radius of their heads, and whether it closes."""
    cx, cy = ring["centre"]
    a, r = ring["radii"]
    count = ring["count"]
    if "arc" in ring:  # part of the ellipse, from one angle to another (degrees, 0 = lateral, 90 = up)
        angles = np.radians(np.linspace(*ring["arc"], count))
        closed = False
    else:
        angles = 2 * np.pi * np.arange(count) / count
        closed = ring.get("closed", True)
    sels = [{"front": [cx + a * np.cos(t), cy + r * np.sin(t)]} for t in angles]
    return sels, ring.get("radius", 0.04), closed


def _sphincter_chain(b: _Builder, m: dict, index: int, side: str, sels: list[dict], radius: float, closed: bool):
    """One chain of a sphincter's muscle points; its anchored ends are bone points."""
    anchors = m.get("anchors", [])
    fixed = set()
    if "first" in anchors:
        fixed.add(0)
    if "last" in anchors:
        fixed.add(len(sels) - 1)
    if "medial" in anchors:
        xs = [abs(b.anat.base[resolve_vertex(b.anat, s, "left")][0]) for s in sels]
        fixed.add(int(np.argmin(xs)))
    chain = []
    for k, sel in enumerate(sels):
        if k in fixed:
            vid, p = b.skin_point({**sel, "depth": sel.get("depth", 1.0)}, side)
            chain.append(b.bone(p, False))
        else:
            node, _, _ = b.insertion({**sel, "radius": radius}, side)
            chain.append(node)
    pairs = list(zip(chain[:-1], chain[1:])) + ([(chain[-1], chain[0])] if closed else [])
    bias = m.get("bias")
    centre_y = np.mean([b.position(r)[1] for r in chain])
    fiber_id = b.new_fiber()  # the chain shortens as one
    for p, q in pairs:
        weight = 1.0
        if bias:  # segments below the ring's centre pull with `below`, above with `above`
            t = np.clip((0.5 * (b.position(p)[1] + b.position(q)[1]) - centre_y) / (0.2 * b.net.scale), -1.0, 1.0)
            weight = bias["below"] + (bias["above"] - bias["below"]) * 0.5 * (1.0 + t)
        b.segment(p, q, index, weight, fiber_id)
        if p >= 0 and q >= 0:
            b.arc(p, q, b.c["muscle_passive"], beta=0.0, compress=0.2)
    if m.get("tone"):
        # The tone a ring holds pulls its points in toward its centre (seen from the front); relaxed,
        # it is released as an outward push: orbicularis oris letting go parts the lips (FACS 25).
        nodes = [r for r in chain if r >= 0]
        centre = np.mean([b.position(r) for r in chain], axis=0)
        for node in nodes:
            inward = centre - b.position(node)
            inward[2] = 0.0
            b.relax["node"].append(node)
            b.relax["dir"].append(inward / max(np.linalg.norm(inward), 1e-12))
            b.relax["muscle"].append(index)
            b.relax["weight"].append(1.0 / len(nodes))


def _jaw_action(b: _Builder, m: dict, side: str, net: TensionNet) -> np.ndarray:
    """Generalised force of a jaw muscle at full force: (opening torque, protrusion, lateral)."""
    _, origin = b.point(m["origin"], side)
    _, insertion = b.point(m["insertion"], side)
    pull = origin - insertion
    pull /= np.linalg.norm(pull)
    arm = insertion - net.hinge
    torque_x = arm[1] * pull[2] - arm[2] * pull[1]  # about +X: positive opens the mouth
    return np.array([torque_x, pull[2], pull[0]])


# ------------------------------------------------------------ AU parser ---

@dataclass(frozen=True)
class Drive:
    """What a set of activations asks of the face, per configuration (leading axis B).

    Attributes
    ----------
    muscle : (B, M) float in [-1, 1]
        Muscle activations (negative: resting tone released).
    pressure : (B, 2) float
        Air pressure (relative) behind the left and right cheek; negative sucks.
    lip_pressure : (B,) float
        Air pressure behind the lips.
    tongue : (B, 3) float
        Tongue protrusion (0..1), sideways turn (-1 right … +1 left), lift (0..1).
    """

    muscle: np.ndarray
    pressure: np.ndarray
    lip_pressure: np.ndarray
    tongue: np.ndarray


def drive(layer: MuscleLayer, activations_list) -> Drive:
    """The AU parser: activations (one or a list) → muscle levels, pressures, tongue.

    Each AU lists muscles with relative magnitudes (``muscle_aus.yaml``); an AU
    on one side drives that side's muscles. Contributions to one muscle add up,
    clamped to [-1, 1].
    """
    if not isinstance(activations_list, (list, tuple)):
        activations_list = [activations_list]
    table = au_table()["action_units"]
    B, M = len(activations_list), len(layer.names)
    muscle = np.zeros((B, M))
    pressure, lip_pressure, tongue = np.zeros((B, 2)), np.zeros(B), np.zeros((B, 3))
    for bi, act in enumerate(activations_list):
        for (code, side), level in act:
            entry = table.get(code)
            if not entry:
                continue
            scale = _combination_scales(act, code, side)
            for name, value in (entry.get("muscles") or {}).items():
                magnitude, target = _muscle_entry(value, side)
                magnitude *= scale.get(name, 1.0)
                k = layer.index(name, target)
                share = 0.5 if layer.side[k] == "both" else 1.0  # midline muscles: mean of the sides
                muscle[bi, k] += share * magnitude * level
            air = entry.get("pressure") or {}
            pressure[bi, SIDES.index(side)] += air.get("cheek", 0.0) * level
            lip_pressure[bi] += 0.5 * air.get("lips", 0.0) * level
            tongue_spec = entry.get("tongue") or {}
            tongue[bi, 0] = max(tongue[bi, 0], tongue_spec.get("protrude", 0.0) * level)
            # One tongue: it turns toward the side scored (toward the left when both are).
            if side == "left" or act[code, "left"] == 0:
                tongue[bi, 1] += tongue_spec.get("sweep", 0.0) * level * (1 if side == "left" else -1)
            tongue[bi, 2] = max(tongue[bi, 2], tongue_spec.get("lift", 0.0) * level)
    return Drive(np.clip(muscle, -1, 1), np.clip(pressure, -1, 1), np.clip(lip_pressure, -1, 1),
                 np.clip(tongue, -1, 1))


def _combination_scales(act, code: int, side: str) -> dict[str, float]:
    """Muscle → factor on AU ``code``'s magnitudes on ``side`` (``combinations`` in muscle_aus.yaml).

    A rule applies when every AU it names acts on that side, as the register engine's do
    (:func:`facsim.engines.registers.combination_scales`): in full while the other AUs of the
    rule act at least as strongly as ``code``, fading with their share of ``code``'s intensity.
    So a whole emotion at half intensity keeps its combinations' look (session 16: scaled by the
    weakest AU's intensity instead, anger at 50 % kept only half of the 5+7 rule and its eyes
    squeezed as at rest the lower palpebral chain does).

    >>> from facsim.facs.activations import Activations
    >>> glare = Activations({(5, "left"): 0.5, (7, "left"): 0.5})
    >>> round(_combination_scales(glare, 7, "left")["orbicularis_oculi_palpebral_lower"], 6)
    0.1
    >>> _combination_scales(Activations({(7, "left"): 1.0}), 7, "left")
    {}
    """
    out: dict[str, float] = {}
    level = act[code, side]
    if level <= 0.0:
        return out
    for rule in au_table().get("combinations") or []:
        scale = rule["scale"]
        if scale["au"] != code:
            continue
        partners = [act[c, side] for c in rule["when"] if c != code]
        share = min(1.0, min(partners, default=level) / level)
        if share <= 0.0:
            continue
        factor = 1.0 - share * (1.0 - float(scale["by"]))
        for name in scale["muscles"]:
            out[name] = out.get(name, 1.0) * factor
    return out


def _muscle_entry(value, side: str) -> tuple[float, str]:
    """An AU's muscle entry: a magnitude (on the AU's side) or ``{level, side}`` with side one of
    same, opposite, left, right."""
    if not isinstance(value, dict):
        return float(value), side
    where = value.get("side", "same")
    if where == "same":
        return float(value["level"]), side
    if where == "opposite":
        return float(value["level"]), SIDES[1 - SIDES.index(side)]
    return float(value["level"]), where


def jaw_pose(layer: MuscleLayer, muscle: np.ndarray, jaw_spec: dict, *, clench_floor: float = 0.0) -> np.ndarray:
    """Quasi-static pose of the mandible (B, 3) under its muscles.

    The jaw muscles' generalised forces are summed (a relaxed elevator
    releases its tone, which was holding the jaw shut against gravity) and met
    by the passive joint: compliance with a soft limit (tanh) for each degree of
    freedom. The teeth stop the jaw closing past occlusion, so clenching leaves
    it shut (and bulges the masseter instead).
    """
    tension = np.where(muscle >= 0, muscle, muscle * layer.tone) * layer.force
    gen = tension @ layer.jaw_action  # (B, 3)
    o, p, lat = jaw_spec["opening"], jaw_spec["protrusion"], jaw_spec["lateral"]
    max_open = np.radians(o["max_degrees"])
    opening = max_open * np.tanh(np.maximum(gen[:, 0], 0.0) * o["compliance"] / max_open)
    # Clenched teeth interlock: a jaw pressed shut by its clenchers (masseter) does not slide.
    clench = np.clip(np.max(np.where(layer.clench, muscle, 0.0), axis=1, keepdims=True) / 0.5, 0.0, 1.0)
    free = 1.0 - clench * clench * (3.0 - 2.0 * clench)
    gen = np.c_[gen[:, :1], gen[:, 1:] * free]
    forward = np.where(gen[:, 1] >= 0,
                       p["max"] * np.tanh(gen[:, 1] * p["compliance"] / p["max"]),
                       p["retrusion"] * np.tanh(gen[:, 1] * p["compliance"] / p["retrusion"]))
    lateral = lat["max"] * np.tanh(gen[:, 2] * lat["compliance"] / lat["max"])
    # Beyond the first degrees of opening the condyles glide forward down the articular eminence,
    # so a wide-open jaw swings its chin less far back than a pure hinge would.
    glide = jaw_spec.get("glide")
    if glide:
        forward = forward + glide["forward_per_degree"] * np.maximum(np.degrees(opening) - glide["onset_degrees"], 0.0)
    return np.stack([opening, forward, lateral], axis=1)


# ---------------------------------------------------- air and the tongue ---

def pressure_patches(anat: Anatomy, net: TensionNet, spec: dict) -> dict:
    """Where air in the mouth pushes: per cheek (left, right) and on the lips.

    Each patch gives points and their force per unit pressure: the patch's
    total ``force`` spread over area × outward normal with a soft fall-off.
    """
    def blob(zone, side_sign):
        centre = np.asarray(zone["centre"], float) * [side_sign, 1, 1]
        rel = (anat.base[: anat.skin_count] - centre) / np.asarray(zone["radii"], float)
        w = np.clip(1.0 - (rel ** 2).sum(1), 0.0, 1.0) ** 2
        w[anat.kind != OUTER] = 0.0
        ids = np.flatnonzero(w > 0)
        vec = (w[ids] * net.area[ids])[:, None] * net.normal[ids]
        return ids, zone["force"] * vec / (w[ids] * net.area[ids]).sum()

    cheek = [blob(spec["pressure"]["cheek"], +1.0), blob(spec["pressure"]["cheek"], -1.0)]
    return {"cheek": cheek, "lips": blob(spec["pressure"]["lips"], 1.0)}


@dataclass(frozen=True, eq=False)
class TongueModel:
    """The tongue as a rigid body on the jaw: its root, tip sphere, reach, and what it pushes."""

    ids: np.ndarray             # geometry ids of the tongue's vertices
    rest: np.ndarray            # their rest positions
    root: np.ndarray
    tip: np.ndarray
    radius: float
    reach: float
    sweep: float
    contact_ids: np.ndarray     # skin points the tip sphere pushes ...
    contact_offset: np.ndarray  # ... each kept this far beyond the sphere (tissue in between)
    contact_k: np.ndarray


def build_tongue(head, anat: Anatomy, net: TensionNet, spec: dict, positions: np.ndarray) -> TongueModel:
    """The tongue of a character (positions: its neutral geometry, (N_geo, 3))."""
    from facsim.head.mesh import REGIONS

    t = spec["tongue"]
    ids = np.flatnonzero(head.region == REGIONS.index("tongue"))
    rest = positions[ids].astype(float)
    tip = rest[np.argmax(rest[:, 2])] * [0.0, 1.0, 1.0]  # on the midline (the tongue is symmetric)
    root = carry_points(anat, net.rest, [t["root"]["at"]])[0]
    radius = t["tip_radius"] * net.scale
    reach = t["reach"] * net.scale
    # Points the tip can meet: the lining, and the lips and cheeks (through their thickness).
    d = np.linalg.norm(net.rest - tip, axis=1)
    lining = (anat.kind == MOUTH) & (d < reach + 0.3 * net.scale)
    outer = (anat.kind == OUTER) & (d < reach + 0.25 * net.scale) & (net.rest[:, 1] < tip[1] + 0.25 * net.scale)
    contact = np.flatnonzero(lining | outer)
    offset = np.where(anat.kind[contact] == OUTER, 0.6 * net.depth[contact], 0.0)
    # Nothing is pushed at rest: the allowed distance never exceeds the rest one.
    offset = np.minimum(offset, np.linalg.norm(net.rest[contact] - tip, axis=1) - radius)
    k = net.constants["contact"] * net.area[contact] / (0.05 * net.scale)
    return TongueModel(ids=ids, rest=rest, root=root, tip=tip, radius=radius, reach=reach,
                       sweep=float(t["sweep_degrees"]), contact_ids=contact, contact_offset=offset, contact_k=k)
