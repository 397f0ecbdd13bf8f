"""Per-frame render time of open-mouth faces before and after the mouth work (issue 13 item 4).

Renders the same deformations (smile, surprise, a wide-open jaw, a funnel) at 512² with
FXAA in this checkout and at ``--baseline-rev`` (checked out into a temporary git
worktree), each in its own process; rounds alternate so a shared machine slows both
alike. Prints the median milliseconds per frame and the ratio after/before.

    python benchmarks/bench_mouth.py [--repeats 5] [--frames 12] [--baseline-rev REV]
"""
from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
from pathlib import Path

from baseline import baseline_tree

ROOT = Path(__file__).resolve().parents[1]
DEFAULT_BASELINE = "a14687f"  # main before the mouth work
EXPRESSIONS = ("6+12+25", "1+2+5+26", "27", "22+25")

WORKER = r"""
import json, sys, time
from facsim import Face
frames = int(sys.argv[1]); expressions = sys.argv[2].split(";")
face = Face("ava")
deformations = [face.deform(e) for e in expressions]
face.render(deformation=deformations[0], size=512, antialias="fxaa")   # compile, bake, warm up
times, cpu = [], []
for i in range(frames):
    start, start_cpu = time.perf_counter(), time.process_time()
    face.render(deformation=deformations[i % len(deformations)], size=512, antialias="fxaa")
    times.append(time.perf_counter() - start)
    cpu.append(time.process_time() - start_cpu)
print(json.dumps([times, cpu]))
"""


def frame_times(tree: Path, frames: int) -> list[list[float]]:
    """[wall seconds per frame, CPU seconds per frame (all threads: llvmpipe's rasteriser too)]."""
    env = dict(os.environ, PYTHONPATH=str(tree))
    out = subprocess.run([sys.executable, "-c", WORKER, str(frames), ";".join(EXPRESSIONS)], cwd=tree, env=env,
                         check=True, capture_output=True, text=True).stdout
    return json.loads(out.strip().splitlines()[-1])


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--frames", type=int, default=12)
    parser.add_argument("--baseline-rev", default=DEFAULT_BASELINE)
    args = parser.parse_args(argv)
    with baseline_tree(args.baseline_rev, "facsim-mouth-base-") as (_, base):
        runs = {"before": [], "after": []}
        for _ in range(args.repeats):
            for name, tree in (("before", base), ("after", ROOT)):
                wall, cpu = frame_times(tree, args.frames)
                runs[name].append((statistics.median(wall), statistics.median(cpu)))
    print(f"open-mouth frames, 512² FXAA, ava, {len(EXPRESSIONS)} expressions, "
          f"median of {args.repeats} runs × {args.frames} frames (wall / CPU of all threads)")
    for i, what in enumerate(("wall", "CPU")):
        before = statistics.median(r[i] for r in runs["before"])
        after = statistics.median(r[i] for r in runs["after"])
        print(f"  {what:4s}: before ({args.baseline_rev}) {before * 1000:6.1f} ms/frame, "
              f"after {after * 1000:6.1f} ms/frame, ratio {after / before:.3f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
