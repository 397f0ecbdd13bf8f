"""Stimulus-set throughput: items per second at 1 and 2 workers, scaling efficiency, quick-set time.

For stills and for HapFACS 3-s videos (1 s onset, 1 s apex, 1 s offset, 30 fps) at HapFACS's frame size,
the same set is made in a fresh folder by ``run_batch`` with 1 worker and with 2 (process pool, spawned
workers, ``LP_NUM_THREADS`` = cores / workers), several times; the figures are medians over the runs.

* ``wall items/s``: items / wall time of the whole run (worker start-up and face loading included);
* ``steady items/s``: items after each worker's first / the time they took (start-up excluded), what a
  long set runs at;
* ``efficiency``: steady rate at 2 workers / (2 × the rate at 1 worker); 100 % is perfect scaling;
* ``worker CPU per item``: CPU seconds the workers (and their ffmpeg) spent per item. On a machine
  that other work shares, wall-clock scaling says little; the CPU time per item at 2 workers against 1
  says how much work the second worker adds (its start-up and face loading, contention), which is
  what keeps the efficiency below 100 % on free cores, with the parent's writing and hashing.

It then times ``examples/quick_set.yaml`` at 2 workers and estimates the wall time of
``examples/hapfacs_validation.yaml`` from the steady rates: start-up + videos / video rate + stills /
still rate, with the set's own numbers of videos and stills.

    python benchmarks/bench_batch.py                   # 486x480, 3 runs each
    python benchmarks/bench_batch.py --size 242x240 --runs 5 --stills 40 --videos 6
"""
from __future__ import annotations

import argparse
import os
import shutil
import statistics
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from facsim.batch.items import expand  # noqa: E402
from facsim.batch.run import run_batch  # noqa: E402
from facsim.batch.spec import load_spec, spec_from_dict  # noqa: E402

#: One character: in a real set each worker loads a few faces and then renders many items of each, so
#: the steady-state rate of one character is the rate of a long set (face loading is in the start-up).
CHARACTERS = ["ava"]
STILL_AUS = [1, 2, 4, 5, 6, 7, 9, 10, 12, 14, 15, 17, 20, 23, 25, 26]
VIDEO_AUS = [1, 2, 4, 6, 12, 15, 20, 26]


def still_spec(n: int, size) -> dict:
    levels = ["30%", "60%", "90%"]
    aus = STILL_AUS[: -(-n // (len(levels) * len(CHARACTERS)))]
    spec = {"characters": CHARACTERS, "sizes": [list(size)], "blocks": [
        {"name": "stills", "aus": aus, "outputs": {"stills": levels}}]}
    return spec


def video_spec(n: int, size) -> dict:
    aus = VIDEO_AUS[: -(-n // len(CHARACTERS))]
    return {"characters": CHARACTERS, "sizes": [list(size)], "blocks": [
        {"name": "videos", "aus": aus, "outputs": {"video": {"onset": 1, "apex": 1, "offset": 1, "fps": 30}}}]}


def one_run(spec, workers: int) -> dict:
    """Make ``spec`` in a fresh folder; wall time, and steady-state rate after each worker's first item."""
    import resource

    folder = Path(tempfile.mkdtemp(prefix="bench-batch-"))
    stamps: list[float] = []
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    try:
        start = time.perf_counter()
        result = run_batch(spec, folder, workers=workers, progress=False,
                           on_item=lambda item: stamps.append(time.perf_counter()))
        wall = time.perf_counter() - start
    finally:
        shutil.rmtree(folder, ignore_errors=True)
    # CPU time of the finished (joined) workers and their ffmpeg children: what the set costs whatever
    # else runs on the machine.
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime + after.ru_stime) - (before.ru_utime + before.ru_stime)
    warm = workers  # the first file of each worker carries its start-up
    steady = (len(stamps) - warm) / (stamps[-1] - stamps[warm - 1]) if len(stamps) > warm + 1 else float("nan")
    return {"items": result.items, "wall": wall, "wall_rate": result.items / wall, "steady_rate": steady,
            "startup": stamps[0] - start, "cpu_per_item": cpu / result.items}


def measure(spec, workers: int, runs: int) -> dict:
    results = [one_run(spec, workers) for _ in range(runs)]
    return {key: statistics.median(r[key] for r in results) for key in results[0]}


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--size", default="486x480", help="WxH (default HapFACS's 485x480, made even)")
    parser.add_argument("--runs", type=int, default=3, help="runs per figure (median)")
    parser.add_argument("--stills", type=int, default=48, help="stills per run")
    parser.add_argument("--videos", type=int, default=8, help="3-s videos per run")
    parser.add_argument("--skip-quick", action="store_true", help="do not time examples/quick_set.yaml")
    args = parser.parse_args(argv)
    size = tuple(int(v) for v in args.size.lower().split("x"))
    print(f"bench_batch: {os.cpu_count()} cores, load average {os.getloadavg()[0]:.1f} at start, "
          f"{args.size}, median of {args.runs} runs")
    rates = {}
    for kind, data in (("stills", still_spec(args.stills, size)), ("3-s videos", video_spec(args.videos, size))):
        spec = spec_from_dict(data)
        n = len(expand(spec))
        one, two = measure(spec, 1, args.runs), measure(spec, 2, args.runs)
        rates[kind] = (one, two)
        wall_eff = two["wall_rate"] / (2 * one["wall_rate"])
        steady_eff = two["steady_rate"] / (2 * one["steady_rate"])
        print(f"{kind:>10s} ({n} items): 1 worker {one['wall_rate']:6.2f} wall / {one['steady_rate']:6.2f} steady "
              f"items/s; 2 workers {two['wall_rate']:6.2f} wall / {two['steady_rate']:6.2f} steady items/s; "
              f"efficiency {100 * steady_eff:5.1f} % steady, {100 * wall_eff:5.1f} % wall; "
              f"start-up {two['startup']:.1f} s")
        print(f"{'':>10s} worker CPU per item (start-up included): {one['cpu_per_item']:.2f} s at 1 worker, "
              f"{two['cpu_per_item']:.2f} s at 2 ({100 * (two['cpu_per_item'] / one['cpu_per_item'] - 1):+.0f} % work)")
    if not args.skip_quick:
        quick = load_spec(ROOT / "examples" / "quick_set.yaml")
        times = [one_run(quick, 2)["wall"] for _ in range(args.runs)]
        print(f"examples/quick_set.yaml ({len(expand(quick))} items, 2 workers): "
              f"{statistics.median(times):.1f} s (runs: {', '.join(f'{t:.1f}' for t in times)})")
    full = expand(load_spec(ROOT / "examples" / "hapfacs_validation.yaml"))
    videos = sum(it.kind == "video" for it in full)
    stills = sum(it.kind == "still" for it in full)
    (_, still2), (_, video2) = rates["stills"], rates["3-s videos"]
    estimate = max(still2["startup"], video2["startup"]) + videos / video2["steady_rate"] + \
        stills / still2["steady_rate"]
    print(f"estimate for examples/hapfacs_validation.yaml ({videos} videos + {stills} stills at "
          f"{full[0].width}x{full[0].height}, 2 workers): {estimate / 60:.1f} min "
          f"(start-up + videos / {video2['steady_rate']:.2f} + stills / {still2['steady_rate']:.2f} items/s)")


if __name__ == "__main__":
    main()
