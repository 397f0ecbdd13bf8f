"""The AU basis as the landmark model sees it: measured on facsim's renders, triangulated over views.

The register engine's AU displacements, carried to the landmarks through the
surface correspondence alone, disagree with what Face Mesh reports on the
same faces: the model places lip and brow contours by appearance (the red of
the lips, the brow strokes), so a smile that rolls the lower lip reads as the
lip rising more than its skin does. The fit is far better when its basis is
the engine's AU motion *as measured by the landmark model*:

for several identities and three yaw views, render the neutral face and each
AU channel at full intensity, detect landmarks, and solve per landmark for the
3-D displacement whose projections (through each render's known camera,
linearised at the surface point) best match the measured 2-D displacements
in all views. The neutral landmarks are triangulated the same way. The
results of all identities, aligned by a similarity transform, are averaged.

Run ``python -m facsim.analysis.calibrate`` to rebuild
``facsim/data/facemesh_au_basis.npz`` (about three minutes).
"""
from __future__ import annotations

import numpy as np

DATA_FILE = "data/facemesh_au_basis.npz"
CHARACTERS = ("ava", "kwame", "mei", "george")
VIEWS = (-30.0, 0.0, 30.0)
SIZE = 384
#: Ridge (px² per dm²) holding an unseen direction of a displacement at zero.
RIDGE = 1e-2


def _jacobians(camera, points: np.ndarray, size: int) -> np.ndarray:
    """d(pixel)/d(world) (L, 2, 3) by central differences, in image axes (y down)."""
    from facsim.render.camera import project

    eps = 1e-3
    out = np.empty((len(points), 2, 3))
    for k in range(3):
        step = np.zeros(3)
        step[k] = eps
        hi, _ = project(camera, points + step, size)
        lo, _ = project(camera, points - step, size)
        out[:, :, k] = (hi - lo) / (2 * eps)
    return out


def _solve(jacobians: list[np.ndarray], deltas: list[np.ndarray]) -> np.ndarray:
    """Per landmark, the 3-D vector whose projections best match the 2-D deltas of all views."""
    a = np.concatenate(jacobians, axis=1)            # (L, 2V, 3)
    b = np.concatenate(deltas, axis=1)               # (L, 2V)
    ata = np.einsum("lij,lik->ljk", a, a) + RIDGE * np.eye(3)
    atb = np.einsum("lij,li->lj", a, b)
    return np.linalg.solve(ata, atb[..., None])[..., 0]


def measure_character(name: str, channels, detector, *, views=VIEWS, size: int = SIZE):
    """Triangulated neutral (468, 3) and channel displacements (C, 468, 3) for one character."""
    from facsim.facs.activations import Activations
    from facsim.face import Face

    from .correspondence import surface_points

    from facsim.head.character import resolve_character

    face = Face(resolve_character(name).with_(symmetric=True))   # the AUs' own motion, mirror-exact
    surface = surface_points(face.base_positions)
    cams, jac, neutral_px = [], [], []
    for yaw in views:
        cam = face.camera(yaw=yaw, size=(size, size))
        found = detector.faces(face.render(None, yaw=yaw, size=size)[..., :3])
        if not found:
            raise RuntimeError(f"no face found on the neutral render of {name} at yaw {yaw}")
        cams.append(cam)
        jac.append(_jacobians(cam, surface, size))
        neutral_px.append(found[0].points[:, :2])
    from facsim.render.camera import project

    offsets = [n - project(c, surface, size)[0] for n, c in zip(neutral_px, cams)]
    neutral = surface + _solve(jac, offsets)
    basis = []
    for code, side in channels:
        sides = ("left", "right") if side == "both" else (side,)
        act = Activations({(code, s): 1.0 for s in sides})
        deltas = []
        for yaw, n_px in zip(views, neutral_px):
            found = detector.faces(face.render(act, yaw=yaw, size=size)[..., :3])
            deltas.append(found[0].points[:, :2] - n_px if found else np.zeros_like(n_px))
        basis.append(_solve(jac, deltas))
    face.close()
    return neutral, np.array(basis)


def build(characters=CHARACTERS, *, progress: bool = True) -> dict[str, np.ndarray]:
    """Measure every character and average them in the first one's frame."""
    import sys

    from .fit import FITTED, similarity
    from .landmarks import LandmarkDetector
    from facsim.facs.catalogue import info

    channels = [(code, side) for code in FITTED
                for side in (("both", "left", "right") if info(code).unilateral else ("both",))]
    neutrals, bases = [], []
    with LandmarkDetector(irises=False) as detector:
        for i, name in enumerate(characters):
            neutral, basis = measure_character(name, channels, detector)
            if neutrals:
                s, r, t = similarity(neutral, neutrals[0], np.ones(len(neutral)))
                neutral = s * neutral @ r.T + t
                basis = s * basis @ r.T
            neutrals.append(neutral)
            bases.append(basis)
            if progress:
                sys.stderr.write(f"\rAU basis: {i + 1}/{len(characters)} identities")
    if progress:
        sys.stderr.write("\n")
    return {
        "neutral": np.mean(neutrals, axis=0).astype(np.float32),
        "basis": np.mean(bases, axis=0).astype(np.float32),
        "channels": np.array([f"{c}:{s}" for c, s in channels]),
        "characters": np.array(characters),
        "views": np.array(VIEWS),
    }


def load_measured() -> dict[str, np.ndarray]:
    """The measured basis (read-only arrays), as :mod:`.fit` uses it."""
    from facsim._data import load_arrays

    return load_arrays(DATA_FILE.removeprefix("data/"))


def main(argv=None) -> None:
    """Rebuild the shipped basis (``--help`` says so and does nothing else)."""
    import argparse
    from importlib import resources

    from facsim.atomic import atomic_write

    parser = argparse.ArgumentParser(
        prog="python -m facsim.analysis.calibrate",
        description=f"Re-measure the AU basis the camera processor fits ({DATA_FILE}) on facsim's own "
                    f"renders: {', '.join(CHARACTERS)} (symmetric), yaws {', '.join(f'{v:g}' for v in VIEWS)}, "
                    f"{SIZE}². Run it after changing how the register engine moves an AU "
                    "(facsim/data/registers.yaml) or the faces' looks; a few minutes.")
    parser.parse_args(argv)
    arrays = build()
    path = resources.files("facsim").joinpath(DATA_FILE)

    def write(tmp):
        with open(tmp, "wb") as f:
            np.savez_compressed(f, **arrays)
    atomic_write(path, write)
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
