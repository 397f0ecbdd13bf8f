"""Renderer speed: median milliseconds per anti-aliased frame for a deforming mesh.

Each frame gets new vertex positions, so the timing includes everything a video frame
costs: normals in numpy, vertex upload, the draws, the anti-aliasing resolve and the
readback into an (H, W, 4) uint8 array.

    python benchmarks/bench_render.py                      # 10k and 50k triangles, 512 px
    python benchmarks/bench_render.py --size 1024 --aa msaa:4 ssaa:2 msaa:1

For the real head, call :func:`benchmark_renderer` with its topology and a sequence of
positions (e.g. from the expression pipeline).
"""
from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from facsim.render.camera import Camera, frame_camera  # noqa: E402
from facsim.render.renderer import (  # noqa: E402
    DEFAULT_COLORS, REGIONS, Appearance, Renderer, RenderTopology,
)


def benchmark_renderer(topology: RenderTopology, positions_sequence, appearance: Appearance,
                       camera: Camera, size=512, repeats: int = 5, *, antialias: int | None = None,
                       aa_method: str = "msaa", wrinkle_sequence=None, occlusion=None,
                       warmup: int = 3) -> dict:
    """Time ``Renderer.render`` over a sequence of positions.

    Parameters
    ----------
    topology, appearance, camera : as for :class:`facsim.render.Renderer`.
    positions_sequence : sequence of (N_geo, 3) arrays, one per frame
    size : int or (width, height)
    repeats : int
        Runs over the whole sequence; the result is the median of the per-run medians.
    antialias, aa_method : passed to the Renderer (``antialias=None``: its default).
    wrinkle_sequence : optional sequence of (N_geo,) arrays, parallel to the positions.
    occlusion : optional (N_geo,) array passed to every frame.
    warmup : frames rendered (and not timed) before the first run.

    Returns
    -------
    dict with ``median_ms``, ``fps`` (1000 / median_ms), ``run_medians_ms`` (one per run),
    ``frames`` (per run), ``size``, ``antialias``, ``aa_method``, ``triangles``.
    """
    frames = [np.asarray(p, dtype=np.float32) for p in positions_sequence]
    if not frames:
        raise ValueError("positions_sequence must hold at least one frame")
    wrinkles = list(wrinkle_sequence) if wrinkle_sequence is not None else [None] * len(frames)
    kwargs = {} if antialias is None else {"antialias": antialias}
    run_medians = []
    with Renderer(topology, size=size, aa_method=aa_method, **kwargs) as renderer:
        for i in range(warmup):
            renderer.render(frames[i % len(frames)], appearance=appearance, camera=camera,
                            wrinkle=wrinkles[i % len(frames)], occlusion=occlusion)
        for _ in range(max(1, repeats)):
            times = []
            for p, w in zip(frames, wrinkles):
                t0 = time.perf_counter()
                renderer.render(p, appearance=appearance, camera=camera, wrinkle=w,
                                occlusion=occlusion)
                times.append(time.perf_counter() - t0)
            run_medians.append(1000.0 * statistics.median(times))
        aa = renderer.antialias
    median_ms = statistics.median(run_medians)
    return {"median_ms": median_ms, "fps": 1000.0 / median_ms, "run_medians_ms": run_medians,
            "frames": len(frames), "size": size, "antialias": aa, "aa_method": aa_method,
            "triangles": len(topology.faces)}


# --------------------------------------------------------------------------------------------
# Synthetic head: an ellipsoid "skin" with a UV seam, two eyeballs, a mouth-interior patch
# --------------------------------------------------------------------------------------------

def _uv_sphere(n_lat: int, n_lon: int):
    theta = np.linspace(0, np.pi, n_lat + 1)
    phi = np.linspace(0, 2 * np.pi, n_lon + 1)
    t, p = np.meshgrid(theta, phi, indexing="ij")
    dirs = np.stack([np.sin(t) * np.sin(p), np.cos(t), np.sin(t) * np.cos(p)], -1).reshape(-1, 3)
    uv = np.stack([p / (2 * np.pi), 1 - t / np.pi], -1).reshape(-1, 2)
    ids = np.arange((n_lat + 1) * (n_lon + 1)).reshape(n_lat + 1, n_lon + 1)
    geo = ids.copy()
    geo[:, -1] = geo[:, 0]               # the seam column is the same geometry vertex
    geo[0, :], geo[-1, :] = geo[0, 0], geo[-1, 0]  # welded poles
    _, render_to_geo = np.unique(geo.reshape(-1), return_inverse=True)
    a, b, c, d = ids[:-1, :-1], ids[1:, :-1], ids[1:, 1:], ids[:-1, 1:]
    faces = np.concatenate([np.stack([a, b, c], -1).reshape(-1, 3),
                            np.stack([a, c, d], -1).reshape(-1, 3)])
    return dirs, uv, render_to_geo.reshape(-1), faces


def synthetic_head(n_triangles: int = 10_000):
    """(topology, rest positions) of a head-sized ellipsoid with eyeballs; ~n_triangles."""
    n_eye = max(n_triangles // 20, 200)
    n_skin = n_triangles - 2 * n_eye
    lat = max(int(round(np.sqrt(n_skin / 4))), 4)
    parts = []
    dirs, uv, r2g, faces = _uv_sphere(lat, 2 * lat)
    geo = np.zeros((r2g.max() + 1, 3))
    geo[r2g] = dirs * [0.8, 1.15, 0.95] + [0.0, 15.5, 0.0]
    region = np.zeros(len(r2g), np.uint8)
    region[(dirs[:, 2] > 0.6) & (dirs[:, 1] < -0.3) & (dirs[:, 1] > -0.45)] = REGIONS.index(
        "mouth_interior")
    parts.append((geo, faces, r2g, uv, region, np.zeros((len(r2g), 3))))
    elat = max(int(round(np.sqrt(n_eye / 4))), 4)
    for side in (-1.0, 1.0):
        dirs, _, r2g, faces = _uv_sphere(elat, 2 * elat)
        eye_dirs = dirs  # the eye's own frame is the world frame at rest: +Z = gaze
        geo = np.zeros((r2g.max() + 1, 3))
        geo[r2g] = eye_dirs * 0.12 + [0.3 * side, 15.75, 0.72]
        parts.append((geo, faces, r2g, np.zeros((len(r2g), 2)),
                      np.full(len(r2g), REGIONS.index("eyeball"), np.uint8), eye_dirs))
    pos, fcs, r2gs, uvs, regs, eyes = [], [], [], [], [], []
    n_geo = n_render = 0
    for geo, faces, r2g, uv, region, eye in parts:
        pos.append(geo), fcs.append(faces + n_render), r2gs.append(r2g + n_geo)
        uvs.append(uv), regs.append(region), eyes.append(eye)
        n_geo += len(geo)
        n_render += len(r2g)
    topology = RenderTopology(np.concatenate(fcs), np.concatenate(r2gs),
                              np.concatenate(uvs).astype(np.float32), np.concatenate(regs),
                              np.concatenate(eyes).astype(np.float32))
    return topology, np.concatenate(pos).astype(np.float32)


def deforming_sequence(rest: np.ndarray, frames: int = 30) -> list[np.ndarray]:
    """Rest positions with a travelling bulge: every frame moves every vertex."""
    centre = rest.mean(0)
    rel = rest - centre
    out = []
    for i in range(frames):
        phase = 2 * np.pi * i / frames
        bump = 0.03 * np.sin(6.0 * rel[:, 1] + phase) * np.cos(4.0 * rel[:, 0] - phase)
        out.append((rest + rel * bump[:, None]).astype(np.float32))
    return out


def synthetic_paint(size: int = 512) -> np.ndarray:
    """Paint texture (GL row order, v up) with brow, lip and cheek blobs for the sphere UVs."""
    v, u = np.meshgrid((np.arange(size) + 0.5) / size, (np.arange(size) + 0.5) / size,
                       indexing="ij")
    du = np.minimum(u, 1 - u)
    paint = np.zeros((size, size, 4), np.uint8)
    brows = np.exp(-((du - 0.07) / 0.035) ** 2 - ((v - 0.64) / 0.012) ** 2)
    lips = np.exp(-(du / 0.05) ** 2 - ((v - 0.33) / 0.015) ** 2)
    cheeks = np.exp(-((du - 0.09) / 0.04) ** 2 - ((v - 0.45) / 0.04) ** 2)
    for ch, m in enumerate((brows, lips, np.zeros_like(lips), 0.4 * cheeks)):
        paint[..., ch] = np.clip(m * 255, 0, 255).astype(np.uint8)
    return paint


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--triangles", type=int, nargs="+", default=[10_000, 50_000])
    parser.add_argument("--size", type=int, default=512)
    parser.add_argument("--aa", nargs="+", default=["msaa:4"],
                        help="anti-aliasing settings as method:factor, e.g. msaa:4 ssaa:2 msaa:1")
    parser.add_argument("--frames", type=int, default=30)
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--wrinkle", action="store_true", help="also feed a wrinkle field")
    args = parser.parse_args(argv)
    appearance = Appearance(DEFAULT_COLORS, synthetic_paint())
    print(f"{'triangles':>9} {'size':>5} {'aa':>7} {'median ms':>10} {'fps':>6}  runs (ms)")
    for n in args.triangles:
        topology, rest = synthetic_head(n)
        frames = deforming_sequence(rest, args.frames)
        wrinkles = None
        if args.wrinkle:
            wrinkles = [np.clip(np.sin(8 * f[:, 0] + i), 0, None).astype(np.float32)
                        for i, f in enumerate(frames)]
        camera = frame_camera(rest.min(0), rest.max(0), view="three-quarter-left")
        for spec in args.aa:
            method, _, factor = spec.partition(":")
            result = benchmark_renderer(topology, frames, appearance, camera, size=args.size,
                                        repeats=args.repeats, antialias=int(factor or 1),
                                        aa_method=method, wrinkle_sequence=wrinkles)
            runs = " ".join(f"{m:.1f}" for m in result["run_medians_ms"])
            print(f"{result['triangles']:>9} {args.size:>5} "
                  f"{method + ':' + str(result['antialias']):>7} {result['median_ms']:>10.1f} "
                  f"{result['fps']:>6.1f}  {runs}", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
