"""Speed of the stimulus video before and after the believable-faces work (issue 13), in one run.

The 3-s, 30-fps, 512² HapFACS stimulus video, end to end through the CLI
(``facsim emotion happiness -o x.mp4``, FXAA, the default), timed for:

- ``before``: the code at ``--baseline-rev`` (default: the commit before hair, brows,
  lashes and the new shading), checked out into a temporary git worktree;
- ``after``: this checkout, with the character's hair, brows and lashes;
- ``after, --hair none``: this checkout without the hair (brows and lashes kept).

Runs are interleaved (before, after, after-no-hair, before, ...) so a machine shared with
other work slows them alike; medians of ``--repeats`` runs, ratios against ``before``.

    python benchmarks/bench_looks.py [--repeats 5] [--character ava] [--baseline-rev REV]
"""
from __future__ import annotations

import argparse
import os
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DEFAULT_BASELINE = "bd62f19"  # main before issue 13 (bald heads, painted brows)
VIDEO_SECONDS = 3.0


def cli_module(tree: Path) -> str:
    """``facsim.cli`` in trees where it runs as a module, else ``facsim``."""
    if (tree / "facsim" / "cli.py").exists() or (tree / "facsim" / "cli" / "__main__.py").exists():
        return "facsim.cli"
    return "facsim"


def timed(command: list[str], tree: Path) -> tuple[float, float]:
    """(wall seconds, CPU seconds of the child: every thread, user + system)."""
    env = dict(os.environ, PYTHONPATH=str(tree))
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    subprocess.run(command, cwd=tree, env=env, check=True, capture_output=True)
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return wall, (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--character", default="ava")
    parser.add_argument("--emotion", default="happiness")
    parser.add_argument("--size", type=int, default=512)
    parser.add_argument("--baseline-rev", default=DEFAULT_BASELINE)
    args = parser.parse_args(argv)

    tmp = Path(tempfile.mkdtemp(prefix="bench-looks-"))
    base_tree = tmp / "before"
    subprocess.run(["git", "worktree", "add", "--detach", str(base_tree), args.baseline_rev],
                   cwd=ROOT, check=True, capture_output=True)
    try:
        def command(tree: Path, *extra: str) -> list[str]:
            return [sys.executable, "-m", cli_module(tree), "emotion", args.emotion, "-o", str(tmp / "x.mp4"),
                    "--size", str(args.size), "--character", args.character, "--quiet", *extra]

        configs = {
            "before": (base_tree, command(base_tree)),
            "after": (ROOT, command(ROOT)),
            "after, --hair none": (ROOT, command(ROOT, "--hair", "none")),
        }
        for tree, cmd in configs.values():  # warm caches (face data, occlusion bakes, proxies)
            timed(cmd, tree)
        times: dict[str, list[tuple[float, float]]] = {name: [] for name in configs}
        for _ in range(args.repeats):
            for name, (tree, cmd) in configs.items():
                times[name].append(timed(cmd, tree))
        wall0 = statistics.median(w for w, _ in times["before"])
        cpu0 = statistics.median(c for _, c in times["before"])
        print(f"3-s 30-fps {args.size}² stimulus video ({args.emotion}, {args.character}), FXAA, end to end through "
              f"the CLI; median of {args.repeats}, {os.cpu_count()} cores (CPU = all threads, user + system; "
              f"steadier than wall time on a shared machine):")
        for name, values in times.items():
            wall = statistics.median(w for w, _ in values)
            cpu = statistics.median(c for _, c in values)
            print(f"  {name:20s} wall {wall:6.2f} s ({wall / VIDEO_SECONDS:.2f}x real time; {wall / wall0:.2f}x before)"
                  f"   CPU {cpu:6.2f} s ({cpu / cpu0:.2f}x before)")
    finally:
        subprocess.run(["git", "worktree", "remove", "--force", str(base_tree)], cwd=ROOT, capture_output=True)
        shutil.rmtree(tmp, ignore_errors=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
