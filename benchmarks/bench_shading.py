"""Frame cost of the skin and hair shading against an earlier revision, in one run.

Times what the shading changes: ``Face.render`` of prepared frames (a happiness ramp,
deformed once up front) with the character's hair, brows and lashes, so the figures are
the renderer's per-frame cost (numpy normals, upload, the shaders, anti-aliasing,
readback) and not the engine's. Two settings: the stimulus video's (512², FXAA) and a
large still (1024², 4x MSAA, where the skin's pores are compiled in).

The baseline (``--baseline-rev``) is checked out into a temporary git worktree; each
measurement runs in a fresh process, alternating baseline and this checkout, so a shared
machine slows both alike. Medians over ``--repeats`` processes of per-frame medians.

    python benchmarks/bench_shading.py [--baseline-rev REV] [--repeats 3] [--character ava]

Set ``LP_NUM_THREADS=1`` for the steadiest CPU figures on a busy machine (llvmpipe's
worker threads otherwise spin while they wait).
"""
from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
from pathlib import Path

from baseline import baseline_tree

ROOT = Path(__file__).resolve().parents[1]
DEFAULT_BASELINE = "a14687f"  # main before the skin/hair shading work of session 10
SETTINGS = (("512² FXAA (video)", 512, "fxaa"), ("1024² 4x MSAA (still)", 1024, 4))

#: Runs in the checkout being measured: prints one median per setting (ms per frame).
CHILD = r"""
import resource, statistics, sys, time
def cpu():
    r = resource.getrusage(resource.RUSAGE_SELF)
    return r.ru_utime + r.ru_stime
from facsim.face import Face
character, frames = sys.argv[1], int(sys.argv[2])
settings = [(int(s), a if a == "fxaa" else int(a)) for s, a in (x.split(":") for x in sys.argv[3:])]
face = Face(character)
steps = ["neutral", "6A+12A", "6B+12B", "6C+12C", "6D+12D", "6E+12E"]
deformations = [face.deform(steps[i % len(steps)]) for i in range(frames)]
for size, aa in settings:
    for d in deformations[:2]:  # warm up: compile the shader variants, upload the textures
        face.render(deformation=d, size=size, antialias=aa)
    walls, cpus = [], []
    for d in deformations:
        start, start_cpu = time.perf_counter(), cpu()
        face.render(deformation=d, size=size, antialias=aa)
        walls.append(time.perf_counter() - start)
        cpus.append(cpu() - start_cpu)
    print(f"{1000 * statistics.median(walls):.2f} {1000 * statistics.median(cpus):.2f}")
"""


def measure(tree: Path, character: str, frames: int) -> list[tuple[float, float]]:
    """(wall ms, CPU ms of every thread) per frame, for each setting."""
    env = dict(os.environ, PYTHONPATH=str(tree))
    args = [f"{size}:{aa}" for _, size, aa in SETTINGS]
    out = subprocess.run([sys.executable, "-c", CHILD, character, str(frames), *args], cwd=tree, env=env,
                         check=True, capture_output=True, text=True).stdout
    return [tuple(float(x) for x in line.split()) for line in out.splitlines() if line.strip()]


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--frames", type=int, default=12)
    parser.add_argument("--character", default="ava")
    parser.add_argument("--baseline-rev", default=DEFAULT_BASELINE)
    args = parser.parse_args(argv)

    with baseline_tree(args.baseline_rev, "bench-shading-") as (tmp, base_tree):
        trees = {"before": base_tree, "after": ROOT}
        results = {name: [] for name in trees}
        for _ in range(args.repeats):
            for name, tree in trees.items():
                results[name].append(measure(tree, args.character, args.frames))
        print(f"Face.render per frame ({args.character}, hair/brows/lashes, {args.frames} frames of a 6+12 A-E ramp; "
              f"median of {args.repeats} processes; before = {args.baseline_rev}):")
        print("  (CPU = all threads, user + system: steadier than wall time on a shared machine)")
        for k, (label, _, _) in enumerate(SETTINGS):
            for j, kind in enumerate(("wall", "CPU")):
                before = statistics.median(r[k][j] for r in results["before"])
                after = statistics.median(r[k][j] for r in results["after"])
                print(f"  {label:24s} {kind:4s} before {before:7.1f} ms   after {after:7.1f} ms   "
                      f"({after / before:.2f}x)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
