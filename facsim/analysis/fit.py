"""Landmarks → head pose, gaze and AU intensities, by fitting facsim's own face to them.

Analysis by synthesis: the register engine's displacement of each Face Mesh
landmark at full intensity of each AU — as the landmark model sees it on
facsim's renders (:mod:`.calibrate`), in the model's 3-D frame — is a basis;
a frame's landmarks are explained as

    x ≈ s · R · (X₀ + Σ_c a_c D_c) + t,     0 ≤ a_c ≤ 1

with the head pose (s, R, t) from the landmarks AUs move least (Umeyama 1991's
closed-form similarity, refined in the image plane by Gauss–Newton: the model's
depth is rough) and the intensities a by bounded least squares in the image
plane (``scipy.optimize.lsq_linear`` gives the result; the inner rounds use an
equivalent projected-Newton solver for speed), alternated a few times, with a
small ridge and a reweighted-ridge L1 so that few AUs explain a frame. A
lateral AU (one FACS lets be scored on one side) has a both-sides column and a
left-minus-right column, so one side can act alone. Gaze comes from the iris
centres against the projected eyeball centres. X₀ is the model's neutral face
plus the person's identity (:func:`fit_identity`: face-shape targets of the hm08
mesh carried to the landmarks by :mod:`.correspondence`, and the remaining
resting offset, from neutral frames) so a resting face is not read as an
expression.

Every function here is numpy/scipy only: no GL, no models.
"""
from __future__ import annotations

import hashlib
from dataclasses import dataclass, field
from functools import cached_property

import numpy as np

#: AU columns the fit solves for. Not here: head (51–58) and eyes (61–66), which come from the
#: pose and the irises; the strands of 4 (41, 42, 44) and blink/wink (45, 46), which are 4 and 43
#: again in landmarks; and codes whose landmark motion duplicates a fitted one or lies off the
#: landmarks (8, 19, 21, 29, 30, 33–35, 38, 39) — see :data:`NOT_FITTED_WHY`.
FITTED = (1, 2, 4, 5, 6, 7, 9, 10, 11, 12, 13, 14, 15, 16, 17, 18, 20, 22, 23, 24, 25, 26, 27, 28, 43)
NOT_FITTED_WHY = {
    8: "lips toward each other: in landmarks the same as 23/24 with 25",
    19: "tongue show: no landmark is on the tongue",
    21: "neck tightener: below the face mesh",
    29: "jaw thrust: a forward motion the camera sees only in depth",
    30: "jaw sideways: facsim's notation gives it no side",
    33: "cheek blow: a bulge in depth, seen only at the silhouette",
    34: "cheek puff: a bulge in depth, seen only at the silhouette",
    35: "cheek suck: a hollow in depth, seen only at the silhouette",
    38: "nostril dilate: under a millimetre at the nose-wing landmarks",
    39: "nostril compress: under a millimetre at the nose-wing landmarks",
    41: "a strand of AU4 (FACS 2002): read as 4",
    42: "a strand of AU4 (FACS 2002): read as 4",
    44: "a strand of AU4 (FACS 2002): read as 4",
    45: "blink: in one frame the same as 43; tell them apart by duration in video",
    46: "wink: read as unilateral 43",
}
#: Ridge on the AU intensities (per unit of image-plane error in mm): splits confusable AUs instead of guessing.
RIDGE = 0.02
SHAPE_RIDGE = 0.5
#: Weight of the landmark model's depth against the image plane in the AU fit (0: image plane only).
DEPTH_WEIGHT = 0.0
#: Sparsity: an L1 penalty (by reweighted ridge) in the same unit, and how many reweighting rounds.
L1 = 0.05
L1_ROUNDS = 3
#: Iris centre's distance from the eyeball centre, as a share of the eyeball radius.
IRIS_DEPTH = 0.87
#: Largest landmark displacement (mm) under which an AU counts as invisible in landmarks.
MIN_VISIBLE_MM = 0.8
#: AUs whose evidence is mostly in appearance (wrinkles, bulges, texture), not landmark motion.
APPEARANCE_AUS = {
    6: "cheek raise shows in crow's feet and the lower-lid bulge more than in landmarks; confusable with 7",
    9: "nose wrinkling is mostly skin folds on the nose bridge",
    14: "dimpling is a fold at the lip corner, little landmark motion",
    17: "chin boss wrinkling shows in the chin's texture",
    23: "lip tightening narrows the red of the lips, close to 24",
    24: "lip pressing is close to 23 in landmarks",
}
MODEL_VERSION = 5


@dataclass(frozen=True)
class FaceBasis:
    """The fit's model of one character: neutral landmarks and per-AU displacements (decimetres, facsim frame).

    Attributes
    ----------
    neutral : (468, 3)
    channels : tuple of (code, kind)
        ``kind`` "both": the AU on both sides (level 0–1); "asym": half the difference
        of its left and right actions (−1–1), so left = both + asym, right = both − asym.
    basis : (C, 468, 3)
        Landmark displacement of each channel at 1.
    shape_names : tuple of str
        Face-shape targets for the identity fit.
    shape_basis : (S, 468, 3)
    weights : (468,)
        Trust in each landmark (from its correspondence spread).
    eye_centres : (2, 3), eye_radii : (2,)
        Eyeball centre and radius, person's right eye then left eye.
    """

    neutral: np.ndarray
    channels: tuple
    basis: np.ndarray
    shape_names: tuple
    shape_basis: np.ndarray
    weights: np.ndarray
    eye_centres: np.ndarray
    eye_radii: np.ndarray

    @property
    def codes(self) -> list[int]:
        return sorted({c for c, _ in self.channels})

    @cached_property
    def lower_bounds(self) -> np.ndarray:
        return np.array([-1.0 if kind == "asym" else 0.0 for _, kind in self.channels])

    def side_levels(self, levels: np.ndarray) -> dict[tuple[int, str], float]:
        """Fitted column values → (code, "left" | "right") → level in [0, 1]."""
        both = {c: v for (c, kind), v in zip(self.channels, levels) if kind == "both"}
        asym = {c: v for (c, kind), v in zip(self.channels, levels) if kind == "asym"}
        out = {}
        for code, b in both.items():
            a = asym.get(code, 0.0)
            out[(code, "left")] = float(np.clip(b + a, 0.0, 1.0))
            out[(code, "right")] = float(np.clip(b - a, 0.0, 1.0))
        return out

    @cached_property
    def per_landmark(self) -> np.ndarray:
        """The basis as (468, C, 3), contiguous (the fit's layout)."""
        return np.ascontiguousarray(self.basis.transpose(1, 0, 2))

    @cached_property
    def rigidity(self) -> np.ndarray:
        """(468,) near 1 for landmarks no AU moves much (pose is measured on them)."""
        largest = np.abs(self.basis).max(axis=(0, 2)) * 100  # mm
        return 1.0 / (1.0 + (largest / 2.0) ** 2)

    def visibility(self) -> dict[int, str]:
        """AU code → why it cannot be read from landmarks (codes that can are absent)."""
        out = {code: "not fitted: " + why for code, why in NOT_FITTED_WHY.items()}
        flat = self.basis.reshape(len(self.channels), -1) * 100
        for code in self.codes:
            rows = [i for i, (c, _) in enumerate(self.channels) if c == code]
            largest = float(np.abs(flat[rows]).max())
            if largest < MIN_VISIBLE_MM:
                out[code] = f"moves no landmark more than {largest:.1f} mm in the register engine"
                continue
            others = [i for i, (c, _) in enumerate(self.channels) if c != code]
            col = flat[rows].sum(axis=0)
            coef, *_ = np.linalg.lstsq(flat[others].T, col, rcond=None)
            unexplained = np.linalg.norm(col - flat[others].T @ coef) / np.linalg.norm(col)
            if unexplained < 0.25:
                out[code] = f"its landmark motion is {100 * (1 - unexplained):.0f}% explained by other AUs"
        for code, why in APPEARANCE_AUS.items():
            if code in self.codes:
                out[code] = out.get(code, "weakly identifiable") + f"; {why}"
        return dict(sorted(out.items()))


@dataclass(frozen=True)
class Identity:
    """A person's resting face in model terms: face-shape target weights and what they leave over (dm)."""

    shape_weights: dict = field(default_factory=dict)
    offset: np.ndarray | None = None  # (468, 3) added to the neutral landmarks

    def sliders(self) -> dict[str, float]:
        """The shape as facsim face-shape sliders (``Character(face=...)``), each in [-1, 1]."""
        from facsim.head.character import _NEGATIVE_ENDS, _POSITIVE_ENDS

        out: dict[str, float] = {}
        for target, w in self.shape_weights.items():
            stem, _, end = target.rpartition("-")
            if end in _POSITIVE_ENDS:
                out[stem] = out.get(stem, 0.0) + w
            elif end in _NEGATIVE_ENDS:
                out[stem] = out.get(stem, 0.0) - w
            else:  # a one-ended slider
                out[target] = out.get(target, 0.0) + w
        return {k: round(float(np.clip(v, -1, 1)), 3) for k, v in sorted(out.items()) if abs(v) >= 0.01}

    def neutral(self, model: FaceBasis) -> np.ndarray:
        x0 = model.neutral.copy()
        if self.shape_weights:
            index = {n: i for i, n in enumerate(model.shape_names)}
            for name, w in self.shape_weights.items():
                x0 += w * model.shape_basis[index[name]]
        if self.offset is not None:
            x0 += self.offset
        return x0


@dataclass(frozen=True)
class FrameFit:
    """One frame's fit: intensities per channel, head pose, gaze, and how well it fits.

    ``rotvec`` is the head's rotation vector in degrees in facsim's frame
    (relative to facing the camera); ``scale`` pixels per decimetre; ``eyes``
    each eye's rotation vector in degrees (person's right, left); ``residual_px``
    the weighted RMS image distance left over.
    """

    levels: np.ndarray
    rotvec: np.ndarray
    scale: float
    translation: np.ndarray
    eyes: np.ndarray
    residual_px: float


# ------------------------------------------------------------------ building


#: The calibration's reference identity: the measured model lives in its frame.
REFERENCE_CHARACTER = "ava"


def build_basis() -> FaceBasis:
    """The fit's model: measured neutral and AU basis (:mod:`.calibrate`), face-shape targets and eyes
    from the reference identity's geometry. Built once per process, cached on disk."""
    if "model" not in _BASES:
        _BASES["model"] = _load_or_compute()
    return _BASES["model"]


_BASES: dict = {}


def _load_or_compute() -> FaceBasis:
    from importlib import resources

    from facsim.head.assets import cache_dir
    from facsim.atomic import atomic_write

    key_text = repr((MODEL_VERSION, REFERENCE_CHARACTER,
                     resources.files("facsim").joinpath("data/facemesh_au_basis.npz").read_bytes(),
                     resources.files("facsim").joinpath("data/facemesh_hm08.yaml").read_bytes()))
    key = hashlib.sha256(key_text.encode()).hexdigest()[:16]
    path = cache_dir() / "analysis" / f"basis-{key}.npz"
    try:
        with np.load(path, allow_pickle=False) as z:
            arrays = {k: z[k] for k in z.files}
        return FaceBasis(arrays["neutral"], tuple((int(c), str(s)) for c, s in arrays["channels"]),
                         arrays["basis"], tuple(str(n) for n in arrays["shape_names"]), arrays["shape_basis"],
                         arrays["weights"], arrays["eye_centres"], arrays["eye_radii"])
    except (OSError, ValueError, KeyError):
        pass
    model = _compute_basis()
    path.parent.mkdir(parents=True, exist_ok=True)

    def write(tmp):
        with open(tmp, "wb") as f:
            np.savez(f, neutral=model.neutral, channels=np.array([(c, s) for c, s in model.channels]),
                     basis=model.basis, shape_names=np.array(model.shape_names), shape_basis=model.shape_basis,
                     weights=model.weights, eye_centres=model.eye_centres, eye_radii=model.eye_radii)
    atomic_write(path, write)
    return model


def _compute_basis() -> FaceBasis:
    from facsim.head.assets import load_face_data
    from facsim.head.character import FACE_SHAPE_FOLDERS, character_positions, resolve_character
    from facsim.face import load_head

    from facsim._data import load_arrays
    from .correspondence import load_correspondence

    measured = load_arrays("facemesh_au_basis.npz")
    raw = {(int(c), side): measured["basis"][i].astype(float)
           for i, (c, side) in enumerate(x.split(":") for x in measured["channels"])}
    channels, columns = [], []
    for code in FITTED:
        channels.append((code, "both"))
        columns.append(raw[code, "both"])
        if (code, "left") in raw:  # lateral: a left-minus-right column, so one side can act alone
            channels.append((code, "asym"))
            columns.append((raw[code, "left"] - raw[code, "right"]) / 2)
    table = load_correspondence()
    head, data = load_head(), load_face_data()
    base_positions = character_positions(resolve_character(REFERENCE_CHARACTER), data)
    shape_names, shape_basis = [], []
    base = np.zeros((len(head.base_vertices), 3))
    for name in data.target_names:
        if name.split("/", 1)[0] not in FACE_SHAPE_FOLDERS or name.startswith(("neck/", "ears/")):
            continue
        idx, delta = data.target(name)
        base[:] = 0
        base[idx] = delta
        moved = np.einsum("lk,lkd->ld", table["weights"], base[table["vertices"]])
        if np.abs(moved).max() > 1e-3:
            shape_names.append(name)
            shape_basis.append(moved)
    centres, radii = [], []
    for side in ("right", "left"):
        c, r = head.eye_pivot(base_positions, side)
        centres.append(c)
        radii.append(r)
    weights = 1.0 / (1.0 + (table["spread_mm"] / 6.0) ** 2)
    return FaceBasis(measured["neutral"].astype(float), tuple(channels), np.array(columns),
                     tuple(shape_names), np.array(shape_basis), weights, np.array(centres), np.array(radii))


# ------------------------------------------------------------------ fitting


def image_to_model_axes(points: np.ndarray) -> np.ndarray:
    """Image landmarks (x right, y down, z away) → camera axes like facsim's (x right, y up, z toward us)."""
    out = np.asarray(points, float).copy()
    out[:, 1:] *= -1
    return out


def similarity(src: np.ndarray, dst: np.ndarray, w: np.ndarray):
    """Weighted Umeyama: s, R, t minimising Σ w |s R src + t − dst|²."""
    w = w / w.sum()
    mu_s, mu_d = w @ src, w @ dst
    a, b = src - mu_s, dst - mu_d
    cov = (b * w[:, None]).T @ a
    u, sig, vt = np.linalg.svd(cov)
    d = np.sign(np.linalg.det(u @ vt))
    fix = np.diag([1.0, 1.0, d])
    rot = u @ fix @ vt
    var = (w * (a ** 2).sum(axis=1)).sum()
    scale = float((sig * np.diag(fix)).sum() / var)
    return scale, rot, mu_d - scale * rot @ mu_s


def refine_pose(shape: np.ndarray, y2: np.ndarray, w: np.ndarray, scale: float, rot: np.ndarray, t: np.ndarray,
                *, steps: int = 4):
    """Weak-perspective pose from the image plane alone (the landmark model's depth is rough):
    s, R, t minimising Σ w |s (R X)_xy + t_xy − y|², by Gauss–Newton from the given pose."""
    from scipy.spatial.transform import Rotation

    sw = np.sqrt(w)
    t = np.asarray(t, float).copy()
    for _ in range(steps):
        q = shape @ rot.T                       # rotated points (L, 3)
        r = (scale * q[:, :2] + t[:2] - y2) * sw[:, None]
        # d(R X) for a small rotation δ applied after R: δ × q → x row (0, q_z, −q_y), y row (−q_z, 0, q_x)
        jac = np.zeros((len(q), 2, 6))
        jac[:, 0, 1], jac[:, 0, 2] = scale * q[:, 2], -scale * q[:, 1]
        jac[:, 1, 0], jac[:, 1, 2] = -scale * q[:, 2], scale * q[:, 0]
        jac[:, :, 3] = scale * q[:, :2]
        jac[:, 0, 4] = jac[:, 1, 5] = 1.0
        jac *= sw[:, None, None]
        a = jac.reshape(-1, 6)
        at = np.ascontiguousarray(a.T)
        step = np.linalg.solve(at @ a + 1e-9 * np.eye(6), -at @ r.ravel())
        rot = Rotation.from_rotvec(step[:3]).as_matrix() @ rot
        scale *= float(np.exp(step[3]))
        t[:2] += step[4:6]
        if np.abs(step).max() < 1e-6:
            break
    return scale, rot, t


def estimate_pose(model: FaceBasis, shape: np.ndarray, y: np.ndarray):
    """The head pose from the landmarks AUs move least: 3-D similarity, then refined in the image plane."""
    weights = model.weights * model.rigidity
    scale, rot, t = similarity(shape, y, weights)
    return refine_pose(shape, y[:, :2], weights, scale, rot, t)


def bounded_lsq(a: np.ndarray, b: np.ndarray, lower, upper=1.0, *, penalty=None) -> np.ndarray:
    """``lsq_linear`` with bounds, minimising |a x − b|² + Σ penalty_i x_i², solved on the square
    triangular system of the normal equations (same minimiser, (C, C) instead of (rows, C))."""
    at = np.ascontiguousarray(a.T)
    return bounded_normal(at @ a, at @ b, lower, upper, penalty=penalty)


def box_qp(gram: np.ndarray, atb: np.ndarray, lower, upper=1.0, *, start=None, iterations: int = 30) -> np.ndarray:
    """min ½xᵀGx − bᵀx on a box by projected Newton steps (Bertsekas 1982) — the same minimiser as
    :func:`bounded_normal` for a positive definite G, in a fraction of the time (the inner fit rounds)."""
    lower = np.broadcast_to(np.asarray(lower, float), atb.shape)
    upper = np.broadcast_to(np.asarray(upper, float), atb.shape)
    x = np.clip(np.zeros_like(atb) if start is None else start, lower, upper)

    def objective(v):
        return 0.5 * v @ gram @ v - atb @ v

    value = objective(x)
    for _ in range(iterations):
        grad = gram @ x - atb
        held = ((x <= lower + 1e-12) & (grad > 0)) | ((x >= upper - 1e-12) & (grad < 0))
        free = ~held
        target = x.copy()
        if free.any():
            rhs = atb[free] - gram[np.ix_(free, held)] @ x[held]
            target[free] = np.linalg.solve(gram[np.ix_(free, free)], rhs)
        step, moved = 1.0, False
        while step > 1e-4:
            trial = np.clip(x + step * (target - x), lower, upper)
            new = objective(trial)
            if new < value - 1e-14:
                moved = True
                break
            step *= 0.5
        if not moved:
            break
        done = np.abs(trial - x).max() < 1e-9
        x, value = trial, new
        if done:
            break
    return x


def bounded_normal(gram: np.ndarray, atb: np.ndarray, lower, upper=1.0, *, penalty=None) -> np.ndarray:
    from scipy.linalg import cho_factor, solve_triangular
    from scipy.optimize import lsq_linear

    g = gram + np.diag(penalty if penalty is not None else np.zeros(len(gram)))
    factor, _ = cho_factor(g + 1e-12 * np.trace(g) * np.eye(len(g)), lower=False)
    r = np.triu(factor)
    rhs = solve_triangular(r, atb, trans="T")
    return lsq_linear(r, rhs, bounds=(lower, upper), method="bvls").x


def fit_frame(model: FaceBasis, points: np.ndarray, irises: np.ndarray | None = None, *,
              identity: Identity | None = None, iterations: int = 3) -> FrameFit:
    """Fit one frame's landmarks (468, 3) image pixels (and irises (2, 5, 2)); see the module docstring."""
    from scipy.spatial.transform import Rotation

    y = image_to_model_axes(points)
    x0 = (identity or Identity()).neutral(model)
    w = model.weights
    c = len(model.channels)
    levels = np.zeros(c)
    shape = x0
    scale, rot, t = estimate_pose(model, shape, y)
    axes = 3 if DEPTH_WEIGHT > 0 else 2
    sw = np.sqrt(np.repeat(w, axes) * np.tile([1.0, 1.0, DEPTH_WEIGHT][:axes], len(w)))
    per_landmark = model.per_landmark
    lower = model.lower_bounds
    ridge_weights = np.where(lower < 0, 2.0, 1.0)  # prefer symmetric action
    for it in range(iterations):
        base = scale * (x0 @ rot.T) + t
        if axes == 3:  # the landmark model's depth is relative to the face: match its mean
            base[:, 2] += np.average(y[:, 2] - base[:, 2], weights=w)
        r = (y[:, :axes] - base[:, :axes]).ravel()
        m = scale * np.tensordot(per_landmark, rot[:axes], axes=([2], [1])).transpose(0, 2, 1).reshape(-1, c)
        a = m * sw[:, None]
        at = np.ascontiguousarray(a.T)  # OpenBLAS takes a slow path on a transposed view
        gram, atb = at @ a, at @ (r * sw)
        unit = (scale * 0.01) ** 2 * len(y)  # one mm of error on every landmark
        penalty = RIDGE * unit * ridge_weights
        final = it == iterations - 1
        levels = box_qp(gram + np.diag(penalty), atb, lower, start=levels)
        for k in range(L1_ROUNDS):  # reweighted ridge ≈ an L1 penalty: few AUs, each at its full level
            reweighted = penalty + L1 * unit / (np.abs(levels) + 0.05)
            if final and k == L1_ROUNDS - 1:  # the result itself: scipy's bounded least squares
                levels = bounded_normal(gram, atb, lower, penalty=reweighted)
            else:
                levels = box_qp(gram + np.diag(reweighted), atb, lower, start=levels)
        shape = x0 + (levels @ model.basis.reshape(c, -1)).reshape(-1, 3)
        if it < iterations - 1:
            scale, rot, t = refine_pose(shape, y[:, :2], w * model.rigidity, scale, rot, t)
    projected = scale * (shape @ rot.T) + t
    resid = float(np.sqrt((w * ((projected[:, :2] - y[:, :2]) ** 2).sum(axis=1)).sum() / w.sum()))
    rotvec = np.degrees(Rotation.from_matrix(rot).as_rotvec())
    eyes = gaze(model, scale, rot, t, irises) if irises is not None and np.isfinite(irises).all() else np.zeros((2, 3))
    return FrameFit(levels, rotvec, scale, t, eyes, resid)


def gaze(model: FaceBasis, scale: float, rot: np.ndarray, t: np.ndarray, irises: np.ndarray) -> np.ndarray:
    """Each eye's rotation vector (degrees, in the head's frame) from its iris centre."""
    out = np.zeros((2, 3))
    for k in range(2):
        centre = scale * rot @ model.eye_centres[k] + t
        iris = image_to_model_axes(np.c_[irises[k, :1], np.zeros(1)])[0, :2]
        g = (iris - centre[:2]) / (scale * model.eye_radii[k] * IRIS_DEPTH)
        g = g / max(1.0, float(np.linalg.norm(g)) / 0.99)
        cam = np.array([g[0], g[1], np.sqrt(1 - g @ g)])
        head = rot.T @ cam
        out[k] = [np.degrees(np.arctan2(-head[1], head[2])), np.degrees(np.arctan2(head[0], head[2])), 0.0]
    return out


def fit_identity(model: FaceBasis, frames: list[np.ndarray]) -> Identity:
    """A person's :class:`Identity` from landmarks (468, 3) of one or more neutral frames.

    The face-shape targets are fitted by bounded least squares (each target
    0–1, a slider's two ends being two targets) under the frames' mean pose;
    what they cannot explain is kept as a resting offset, so the neutral frames
    fit with no AU at all.
    """

    w = model.weights
    s_count = len(model.shape_names)
    offsets = []
    shape_rows, shape_rhs = [], []
    poses = []
    for pts in frames:
        y = image_to_model_axes(pts)
        scale, rot, t = estimate_pose(model, model.neutral, y)
        poses.append((scale, rot, t, y))
        r = (y[:, :2] - (scale * (model.neutral @ rot.T) + t)[:, :2]).ravel()
        m = scale * np.einsum("ij,slj->lis", rot[:2], model.shape_basis).reshape(-1, s_count)
        sw = np.sqrt(np.repeat(w, 2))
        shape_rows.append(m * sw[:, None])
        shape_rhs.append(r * sw)
        scale0 = scale
    a, b = np.vstack(shape_rows), np.concatenate(shape_rhs)
    penalty = SHAPE_RIDGE * (scale0 * 0.01) ** 2 * len(model.neutral) * np.ones(s_count)
    sol = bounded_lsq(a, b, 0.0, penalty=penalty)
    weights = {n: float(v) for n, v in zip(model.shape_names, sol) if v > 1e-3}
    shaped = Identity(weights).neutral(model)
    for scale, rot, t, y in poses:
        scale, rot, t = estimate_pose(model, shaped, y)
        projected = scale * (shaped @ rot.T) + t
        r2 = np.c_[(y[:, :2] - projected[:, :2]) / scale, np.zeros(len(y))]
        offsets.append(r2 @ rot)  # back into the model frame (the depth part is unseen)
    return Identity(weights, np.mean(offsets, axis=0))
