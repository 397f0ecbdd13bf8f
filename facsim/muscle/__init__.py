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
>>> frames = [engine.step(a) for a in timeline_frames]    # doctest: +SKIP
"""
from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

from ..expression import Activations
from . import solver
from .muscles import au_table, build_muscles, build_tongue, drive, pressure_patches
from .net import LID, SIDES, anatomy, build_net, load_spec, move_with_jaw
from .wrinkles import WrinkleModel, build_wrinkles, wrinkle_field

__all__ = ["MuscleEngine", "simulated_codes", "coverage"]

#: Increments of a static solve (Platt & Badler's n) and iterations per increment.
STATIC_STEPS = 3
STATIC_ITERATIONS = 14
#: Iterations per animation frame (the state carries over, so frames converge over time).
FRAME_ITERATIONS = 5


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
        geo_of_base = np.full(len(head.base_vertices), -1, np.int64)
        geo_of_base[head.base_index] = np.arange(len(head.base_index))
        lower = geo_of_base[data.group_vertices("helper-lower-teeth")]
        self.lower_teeth = lower[lower >= 0]
        self.neutral = neutral
        # Lashes ride the lid vertex nearest their root, turning with its local frame.
        lids = np.flatnonzero(anatomy(head).kind == LID)
        _, near = cKDTree(neutral[lids]).query(neutral[head.lashes], k=3)
        self.lashes = head.lashes
        self.lash_frame = lids[near]                                    # (L, 3) vertices spanning a frame
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
    """Callable engine: :class:`Activations` → geometry positions (N_geo, 3) float32.

    ``engine(act)`` solves from rest (a static expression); ``engine.step(act)``
    is the animation path: it keeps the face's state between calls and applies
    only the change from the previous frame's activations. ``last_wrinkle``
    holds the skin compression (N_geo,) of the last result, for the renderer.

    Parameters
    ----------
    head : HeadModel
    data : FaceData
    character : Character
    base_positions : (19158, 3) array
        The character's neutral base mesh.
    """

    name = "muscle"

    def __init__(self, head, data, character, base_positions):
        from ..registers import RegisterEngine

        self.head = head
        base_positions = np.asarray(base_positions, np.float32)
        self.model, self.wrinkles, neutral = _built(head, base_positions)
        self.neutral = neutral.astype(np.float32)
        self.parts = _Parts(head, data, neutral, self.model.net)
        # Rigid head (51–58) and eye (61–66) motions are the register engine's, shared by both engines.
        self.rigid = RegisterEngine(head, data, character, base_positions)
        self.state = solver.rest_state(self.model)
        self.last_wrinkle = np.zeros(head.vertex_count, np.float32)
        self.last_state = self.state

    # -- public API
    def __call__(self, act: Activations) -> np.ndarray:
        """Static solve: the expression ``act`` reached from rest in n increments."""
        state = solver.solve(self.model, solver.rest_state(self.model), drive(self.model.layer, act),
                             steps=STATIC_STEPS, iterations=STATIC_ITERATIONS)
        return self._finish(state, act)

    def step(self, act: Activations, *, iterations: int = FRAME_ITERATIONS) -> np.ndarray:
        """One animation frame: apply the change since the previous frame and relax the net."""
        self.state = solver.solve(self.model, self.state, drive(self.model.layer, act), steps=1,
                                  iterations=iterations)
        return self._finish(self.state, act)

    def animate(self, frames):
        """Yield positions for each Activations in ``frames`` (the stateful path, from rest)."""
        self.reset()
        for act in frames:
            yield self.step(act)

    def reset(self) -> None:
        """Back to the neutral face (the next ``step`` starts from rest)."""
        self.state = solver.rest_state(self.model)

    # -- geometry
    def _finish(self, state: solver.State, act: Activations) -> np.ndarray:
        self.last_state = state
        positions = self.geometry(state, act)
        skin = state.points(0)[: self.model.net.count]
        wrinkle = np.zeros(self.head.vertex_count, np.float32)
        wrinkle[: len(skin)] = wrinkle_field(self.wrinkles, skin)
        self.last_wrinkle = wrinkle
        return positions

    def geometry(self, state: solver.State, act: Activations, index: int = 0) -> np.ndarray:
        """Geometry positions (N_geo, 3) float32 of configuration ``index`` of a state."""
        from .net import jaw_transform
        model = self.model
        net = model.net
        rot, shift = jaw_transform(state.jaw[index:index + 1], net.hinge, model.jaw_spec["yaw_per_lateral"])
        control = state.drive.tongue[index:index + 1]
        r, t = solver.tongue_frame(model.tongue, control, rot, shift, net.hinge)
        out = self.parts.place(state.points(index)[: net.count], rot[0], shift[0], net.hinge, (r[0], t[0]),
                               model.tongue, self.rigid.eye_rotations(act))
        return self.rigid.move_head(out.astype(np.float32), act).astype(np.float32)


_MODELS: dict = {}


def _built(head, base_positions):
    """The model of a character, built once per process (about a second) and reused."""
    key = (id(head), hash(base_positions.tobytes()))
    if key not in _MODELS:
        _MODELS[key] = _build_all(head, base_positions)
        while len(_MODELS) > 8:
            _MODELS.pop(next(iter(_MODELS)))
    return _MODELS[key]


def _build_all(head, base_positions):
    spec = load_spec()
    anat = anatomy(head)
    net = build_net(head, base_positions, anat=anat, spec=spec)
    layer = build_muscles(anat, net, spec)
    neutral = head.positions(base_positions).astype(float)
    tongue = build_tongue(head, anat, net, spec, neutral)
    model = solver.build_model(net, layer, spec, tongue, pressure_patches(anat, net, spec))
    return model, build_wrinkles(anat, net, spec), neutral
