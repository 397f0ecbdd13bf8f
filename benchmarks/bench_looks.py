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
import statistics
import sys
from pathlib import Path

from baseline import baseline_tree, timed

ROOT = Path(__file__).resolve().parents[1]
DEFAULT_BASELINE = "bd62f19"  # main before issue 13 (bald heads, painted brows)
VIDEO_SECONDS = 3.0


def cli_module(tree: Path) -> str:
    """``facsim.cli`` in trees where it runs as a module, else ``facsim``."""
    if (tree / "facsim" / "cli.py").exists() or (tree / "facsim" / "cli" / "__main__.py").exists():
        return "facsim.cli"
    return "facsim"


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--character", default="ava")
    parser.add_argument("--emotion", default="happiness")
    parser.add_argument("--size", type=int, default=512)
    parser.add_argument("--baseline-rev", default=DEFAULT_BASELINE)
    args = parser.parse_args(argv)

    with baseline_tree(args.baseline_rev, "bench-looks-") as (tmp, base_tree):
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
    return 0


if __name__ == "__main__":
    sys.exit(main())
