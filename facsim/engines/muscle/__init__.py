"""The muscle engine: Platt & Badler's tension net, with their unsolved problems solved.

Activations → the AU parser (``muscle_aus.yaml``: AU → muscles with relative
magnitudes) → loads (muscle tensions, released tone, air pressure, the
tongue, the jaw's pose) → quasi-static equilibrium of the net
(:mod:`.solver`) → geometry (skin, teeth and tongue on the jaw, eyeballs,
lashes on the lids) → wrinkles from skin compression (:mod:`.wrinkles`).

Examples
--------
>>> from facsim.face import Face                          # doctest: +SKIP
>>> face = Face("ava", engine="muscle")                   # doctest: +SKIP
>>> face.save("/tmp/m46.png", "4+6")                      # doctest: +SKIP
>>> engine = face.engine                                  # doctest: +SKIP
>>> engine.reset()                                        # doctest: +SKIP
>>> frames = [engine.step(a) for a in timeline_frames]    # doctest: +SKIP
>>> frames[-1].wrinkle                                    # doctest: +SKIP
"""
from __future__ import annotations

from functools import cached_property

import numpy as np
from scipy.spatial import cKDTree

from facsim.engines.base import Deformation
from facsim.engines.rigid import RigidMotion
from facsim.engines.guard import SkinGuard
from facsim.engines.lids import meet_amount
from facsim.facs.activations import Activations
from facsim.engines.muscle import solver
from facsim.engines.muscle.muscles import au_table, build_muscles, build_tongue, drive, jaw_pose, pressure_patches
from facsim.engines.muscle.net import LID, SIDES, anatomy, build_net, jaw_transform, load_spec, move_with_jaw
from facsim.engines.muscle.wrinkles import build_wrinkles, wrinkle_field

__all__ = ["MuscleEngine", "simulated_codes", "coverage"]

#: Increments of a static solve (Platt & Badler's n) and iterations per increment at most ...
#: (at 30, 12 alone stopped 2.4 mm short of the lip corner's settled rise on noah, so 6 after 12
#: seemed to lift the corner 1.3 mm more, 4x 6 alone; at 60 it adds nothing, as FACS's masking has it)
STATIC_STEPS = 2
STATIC_ITERATIONS = 60
#: Iterations per increment at which a static solve has settled (tests that compare expressions use it):
#: 60 stop short, and where they stop depends on the batch and on any change to the net - on session
#: 23's main anger (4+5+7+23) raised ava's lower lids 0.6 mm at 60 where 5+7 raised them 2.1; settled
#: (200 and 600 alike) 2.4 and 2.7. Session 21: noah's corner went 8.7 mm out in 12 in one batch,
#: 10.3 in another, 11.1 settled.
SETTLED_ITERATIONS = 200
#: ... an increment ends when the net force left on the points is below this share of what it added.
STATIC_RESIDUAL = 0.02
#: A static solve takes one more increment per this many degrees of jaw opening.
JAW_DEGREES_PER_STEP = 10.0
#: At most this many extra rounds of iterations for a static solve that ends with folded skin.
POLISH_ROUNDS = 5
#: Expressions solved together by :meth:`MuscleEngine.solve_many`.
BATCH = 4
#: Iterations per animation frame (the state carries over, so frames converge over time; at 2 a
#: held 1+2+12 on noah stayed 0.29 mm on average from the static solve of 60 iterations, at 3 0.15).
FRAME_ITERATIONS = 3


def simulated_codes() -> set[int]:
    """AU codes this engine renders."""
    return set(au_table()["action_units"])


def coverage() -> dict[int, str]:
    """AU code → one line on how this engine produces it, or why it cannot."""
    table = au_table()
    out = {code: spec["how"] for code, spec in table["action_units"].items()}
    out.update({code: "not simulated: " + why for code, why in (table.get("not_simulated") or {}).items()})
    return dict(sorted(out.items()))


class _Parts:
    """How the rigid and attached parts follow the net: teeth, tongue, eyes, lashes, neck cap."""

    def __init__(self, head, data, neutral, net):
        self.lower_teeth = head.group_geometry(data, "helper-lower-teeth")
        self.neutral = neutral
        # Lashes ride the lid vertex nearest their root, turning with its local frame.
        lids = np.flatnonzero(anatomy(head).kind == LID)
        _, near = cKDTree(neutral[lids]).query(neutral[head.lashes], k=12)
        frame = _spanning_triples(neutral, lids[near])                  # (L, 3) vertices spanning a frame
        # The right lashes take the mirror image of their left twins' frames (symmetric faces stay so).
        mirror = np.asarray(head.mirror)
        twin = {int(v): k for k, v in enumerate(head.lashes)}
        for k, v in enumerate(head.lashes):
            if neutral[v, 0] < 0 and int(mirror[v]) in twin:
                frame[k] = mirror[frame[twin[int(mirror[v])]]]
        self.lashes = head.lashes
        self.lash_frame = frame
        self.lash_offset = np.einsum("lij,lj->li", _frames(neutral, self.lash_frame),
                                     neutral[head.lashes] - neutral[self.lash_frame[:, 0]])
        self.eye = {s: head.eye_vertices[s] for s in SIDES}
        self.eye_local = head.eye_local.astype(float)
        self.eye_centre = {s: net.eye_centre[i] for i, s in enumerate(SIDES)}
        self.eye_radius = net.eye_radius
        self.cap, self.loop = head.cap_vertex, head.neck_loop

    def place(self, skin, jaw_rot, jaw_shift, hinge, tongue_rt, tongue, eye_rotations) -> np.ndarray:
        out = self.neutral.astype(float).copy()
        out[: len(skin)] = skin
        out[self.lower_teeth] = move_with_jaw(self.neutral[self.lower_teeth], jaw_rot[None], jaw_shift[None], hinge)[0]
        r, t = tongue_rt
        out[tongue.ids] = tongue.rest @ r.T + t
        for side in SIDES:
            rot = eye_rotations[side]
            out[self.eye[side]] = self.eye_centre[side] + self.eye_radius * (self.eye_local @ rot.T)
        frames = _frames(out, self.lash_frame)
        out[self.lashes] = out[self.lash_frame[:, 0]] + np.einsum("lji,lj->li", frames, self.lash_offset)
        out[self.cap] = out[self.loop].mean(axis=0)
        return out


#: A lash's frame is spanned by lid points whose two edges from its root make at least this sine
#: (30 degrees): on noah the nearest three lay 3 degrees off a line, and under 4 the lid's
#: sub-millimetre motion turned that frame so far that a lash tip jumped 3.6 mm between frames.
LASH_FRAME_SINE = 0.5


def _spanning_triples(positions, candidates) -> np.ndarray:
    """Three of each row of ``candidates`` (L, K, nearest first) spanning a well-shaped frame.

    The row's first point and the nearest pair (in the row's order) whose edges from it
    make at least :data:`LASH_FRAME_SINE`; failing that, the pair that comes closest.
    Some face shapes squeeze lid vertices onto a line (three with the same x and y on
    ngozi), whose frame would be undefined, and a nearly straight triple turns wildly
    with small motions of the lid.
    """
    triples = candidates[:, :3].copy()
    for k, row in enumerate(candidates):
        p = positions[row]
        edge = p[1:] - p[0]
        length = np.linalg.norm(edge, axis=1)
        scale = max(float(length.max()), 1e-12)
        unit = edge / np.maximum(length, 1e-3 * scale)[:, None]
        sine = np.linalg.norm(np.cross(unit[:, None, :], unit[None, :, :]), axis=-1)
        sine[length < 1e-3 * scale] = 0.0
        sine[:, length < 1e-3 * scale] = 0.0
        pairs = [(i, j) for j in range(len(edge)) for i in range(j)]   # nearest pairs first
        good = [pair for pair in pairs if sine[pair] >= LASH_FRAME_SINE]
        best = good[0] if good else max(pairs, key=lambda pair: sine[pair])
        if sine[best] > 0.0:
            triples[k] = row[[0, best[0] + 1, best[1] + 1]]
    return triples


def _frames(positions, triples) -> np.ndarray:
    """Orthonormal frames (L, 3, 3) (rows = axes) spanned by vertex triples (L, 3)."""
    p = positions[triples[:, 0]]
    a = positions[triples[:, 1]] - p
    b = positions[triples[:, 2]] - p
    e1 = a / np.linalg.norm(a, axis=1, keepdims=True)
    n = np.cross(a, b)
    e3 = n / np.linalg.norm(n, axis=1, keepdims=True)
    e2 = np.cross(e3, e1)
    return np.stack([e1, e2, e3], axis=1)


class MuscleEngine:
    """The muscle engine (an :class:`~facsim.engines.base.Engine`): Activations → :class:`Deformation`.

    :meth:`deform` solves an expression from rest (n increments); :meth:`step`
    is the animation path: it keeps the face's state between calls and applies
    only the change from the previous frame's activations. Each result carries
    the skin's creases (computed when a renderer first asks for them).

    Built once per character from ``(head, data, character, base_positions)``, as every
    :class:`~facsim.engines.base.Engine` is.
    """

    name = "muscle"

    def __init__(self, head, data, character, base_positions):
        self.head = head
        self.data = data
        base_positions = np.asarray(base_positions, np.float32)
        self.base_positions = base_positions
        self.model, self.wrinkles, sculpted = _built(head, data, base_positions)
        # The net rests on the sculpted face (MakeHuman's staring lids); the face at rest,
        # :attr:`neutral`, carries relaxed lids on top (facsim.engines.lids.RestLids).
        self.sculpted = sculpted.astype(np.float32)
        self.parts = _Parts(head, data, sculpted, self.model.net)
        self.rigid = RigidMotion(head, base_positions)
        self.rest_lids = self._measure_rest_lids()
        self.state = solver.rest_state(self.model)
        # The solver keeps its contact points off the eyes; this last step checks every skin point.
        self.guard = SkinGuard(head, self.sculpted, list(self.model.net.eye_centre), self.model.net.eye_radius,
                               neck_below=float(head.joint(base_positions, "joint-jaw")[1]))

    @cached_property
    def _closing_columns(self) -> dict:
        """Side -> the closing target's motion of the net's skin points (``lids.yaml``'s target)."""
        from facsim.engines.lids import closing_column, rest_table

        return {side: closing_column(self.head, self.data, self.base_positions, rest_table()["target"], side)
                [: self.model.net.count] for side in SIDES}

    def _margin(self, side: str) -> np.ndarray:
        from facsim.engines.lids import lid_margin

        net = self.model.net
        return lid_margin(self.head, self.sculpted, net.eye_centre[SIDES.index(side)], net.eye_radius)

    def _measure_rest_lids(self):
        """The relaxed lids (:class:`~facsim.engines.lids.RestLids`) measured on the sculpted skin."""
        from facsim.engines.lids import RestLids, closing_column, rest_table

        net = self.model.net
        lower = rest_table()["lower"]["target"]
        return RestLids.measure(self.sculpted[:net.count], self._closing_columns.__getitem__,
                                lambda side: (net.eye_centre[SIDES.index(side)], net.eye_radius), self._margin,
                                lambda side: closing_column(self.head, self.data, self.base_positions, lower, side)
                                [: net.count])

    @cached_property
    def eyelids(self) -> dict:
        """Side -> :class:`~facsim.engines.lids.EyeLids` on the sculpted skin."""
        from facsim.engines.lids import EyeLids

        net = self.model.net
        return {side: EyeLids(self.sculpted[:net.count], self._closing_columns[side], centre, net.eye_radius,
                              self._margin(side))
                for side, centre in zip(SIDES, net.eye_centre)}

    @cached_property
    def neutral(self) -> np.ndarray:
        """The face at rest (N_geo, 3) float32: the net at rest with the relaxed lids."""
        return self.geometry(solver.rest_state(self.model), Activations())

    # -- the Engine protocol
    def deform(self, act: Activations) -> Deformation:
        """Static solve: the expression ``act`` reached from rest in n increments."""
        return self.deform_many([act])[0]

    def reset(self) -> None:
        """Back to the neutral face (the next :meth:`step` starts from rest)."""
        self.state = solver.rest_state(self.model)

    def step(self, act: Activations, *, iterations: int = FRAME_ITERATIONS) -> Deformation:
        """One animation frame: apply the change since the previous frame and relax the net.

        The state (positions, applied activations and the minimiser's memory)
        carries over between calls, so a held expression keeps converging.
        """
        self.state = solver.solve(self.model, self.state, drive(self.model.layer, act), steps=1,
                                  iterations=iterations, settle=False)
        return self._deformation(self.state, act, 0)

    # -- batches
    def deform_many(self, acts, *, steps: int = STATIC_STEPS, iterations: int = STATIC_ITERATIONS) -> list[Deformation]:
        """Static solves of several expressions at once (batched), in order."""
        acts = list(acts)
        out = [None] * len(acts)
        for k, state, b in self.static_states(acts, steps=steps, iterations=iterations):
            out[k] = self._deformation(state, acts[k], b)
        return out

    def solve_many(self, acts, **options) -> np.ndarray:
        """Positions (B, N_geo, 3) float32 of :meth:`deform_many`."""
        return np.stack([d.positions for d in self.deform_many(acts, **options)])

    def static_states(self, acts, *, steps: int = STATIC_STEPS, iterations: int = STATIC_ITERATIONS):
        """Yield ``(k, state, b)``: expression ``k`` of ``acts`` solved from rest is configuration
        ``b`` of ``state``.

        Expressions needing the same number of increments are solved together, a
        few at a time (beyond that the arrays leave the cache); each solves as it
        would alone (to round-off: the batch's width changes the last bits of the
        sparse solves).
        """
        acts = list(acts)
        extra = [self._extra_steps(drive(self.model.layer, act)) for act in acts]
        for more in sorted(set(extra)):
            group = [k for k, e in enumerate(extra) if e == more]
            for start in range(0, len(group), BATCH):
                part = group[start:start + BATCH]
                target = drive(self.model.layer, [acts[k] for k in part])
                state = solve_static(self.model, target, steps=steps + more, iterations=iterations)
                for b, k in enumerate(part):
                    yield k, state, b

    def _extra_steps(self, target) -> int:
        """More increments for big jaw motions: the face then moves far, and the net is followed
        more safely in smaller steps (the paper's n-step contraction as a continuation method)."""
        pose = jaw_pose(self.model.layer, target.muscle, self.model.jaw_spec)
        return int(np.degrees(pose[:, 0]).max() // JAW_DEGREES_PER_STEP)

    # -- geometry
    def _deformation(self, state: solver.State, act: Activations, index: int) -> Deformation:
        return Deformation(self.geometry(state, act, index), creases=lambda: self._creases(state, index))

    def _creases(self, state: solver.State, index: int) -> tuple[np.ndarray, np.ndarray]:
        """Skin compression (N_geo,) ≥ 0 and furrow phase (N_geo,) of configuration ``index``."""
        skin = state.points(index)[: self.model.net.count]
        strength, phase = wrinkle_field(self.wrinkles, skin)
        wrinkle, crease_phase = (np.zeros(self.head.vertex_count, np.float32) for _ in range(2))
        wrinkle[: len(skin)] = strength
        crease_phase[: len(skin)] = phase
        return wrinkle, crease_phase

    def geometry(self, state: solver.State, act: Activations, index: int = 0) -> np.ndarray:
        """Geometry positions (N_geo, 3) float32 of configuration ``index`` of a state."""
        model = self.model
        net = model.net
        rot, shift = jaw_transform(state.jaw[index:index + 1], net.hinge, model.jaw_spec["yaw_per_lateral"])
        control = state.drive.tongue[index:index + 1]
        r, t = solver.tongue_frame(model.tongue, control, rot, shift, net.hinge)
        skin = state.points(index)[: net.count] + self.rest_lids.offsets(act, net.count)
        for side, lids in self.eyelids.items():   # closing lids meet (the net leaves the corners open)
            amount = meet_amount(act, side)
            if amount > 0.0:
                lids.meet_lower(skin, amount)
        skin = self.guard(skin)
        out = self.parts.place(skin, rot[0], shift[0], net.hinge, (r[0], t[0]), model.tongue,
                               self.rigid.eye_rotations(act))
        out = out.astype(np.float32, copy=False)
        # The neck's blend read where the expression put each point: the net moves skin far from
        # its rest place (an open jaw presses the lower lip together), and a smooth blend over
        # space keeps what lies together turning together.
        weight = self.rigid.weight_at(out)
        moved = self.rigid.move_head(out, act, weight)
        if moved is out:   # no head motion
            return out
        return self.guard.after_head_motion(moved, self.rigid.head_turn(act), weight[:, 0])


def solve_static(model, target, *, steps: int, iterations: int) -> solver.State:
    """An expression from rest in ``steps`` increments; where the skin is still folded through
    itself at the end (a big change not yet relaxed), keep relaxing, a few rounds at most."""
    state = solver.solve(model, solver.rest_state(model, target.muscle.shape[0]), target, steps=steps,
                         iterations=iterations, residual=STATIC_RESIDUAL)
    for _ in range(POLISH_ROUNDS):
        folded = solver.folded(model, state.x) > 0
        if not folded.any():
            break
        more = solver.solve(model, state, target, steps=1, iterations=iterations, residual=STATIC_RESIDUAL)
        # Only the folded ones take the extra round (so a batch solves each alike to alone).
        state = solver.State(np.where(folded[None, :, None], more.x, state.x), target,
                             np.where(folded[:, None], more.jaw, state.jaw))
    # Not at rest after these rounds (issue 13: anger's brows stood at 60 % of their settled depth);
    # relaxing until settled cost 2.4x the CPU and the animation path then lagged it: not done.
    return state


_MODELS: dict = {}


def _built(head, data, base_positions):
    """The model of a character, built once per process (about a second) and reused."""
    key = (id(head), hash(base_positions.tobytes()))
    if key not in _MODELS:
        _MODELS[key] = _build_all(head, data, base_positions)
        while len(_MODELS) > 8:
            _MODELS.pop(next(iter(_MODELS)))
    return _MODELS[key]


def _build_all(head, data, base_positions):
    spec = load_spec()
    anat = anatomy(head)
    net = build_net(head, base_positions, anat=anat, spec=spec)
    layer = build_muscles(anat, net, spec)
    neutral = head.positions(base_positions).astype(float)
    tongue = build_tongue(head, anat, net, spec, neutral)
    model = solver.build_model(net, layer, spec, tongue, pressure_patches(anat, net, spec),
                               teeth=_teeth_rows(head, data, neutral), mirror=np.asarray(head.mirror)[: net.count])
    return model, build_wrinkles(anat, net, spec), neutral


def _teeth_rows(head, data, neutral) -> dict:
    """Rest positions of the upper and lower tooth rows (geometry vertices of hm08's teeth helpers)."""
    return {name: neutral[head.group_geometry(data, group)]
            for name, group in (("upper", "helper-upper-teeth"), ("lower", "helper-lower-teeth"))}
