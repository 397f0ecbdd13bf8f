"""Camera-processor benchmark: a 640×480 face video, time per frame in detection, landmarks and fit.

The clip is made from scikit-image's astronaut photograph (public domain) moving
across a 640×480 frame. Each run analyses the whole clip; medians over runs are
printed per stage, with frames per second overall and the share of each stage.
A baseline in the same run — decoding the video alone — shows what the machine
gives today (these machines are shared and noisy).

    python benchmarks/bench_analysis.py [--frames 90] [--repeats 3] [--threads 1]
"""
from __future__ import annotations

import argparse
import statistics
import tempfile
import time
from pathlib import Path

import numpy as np


def make_clip(path: Path, frames: int) -> Path:
    import imageio_ffmpeg
    from skimage import data

    face = data.astronaut()
    writer = imageio_ffmpeg.write_frames(str(path), (640, 480), fps=30, macro_block_size=1)
    writer.send(None)
    for i in range(frames):
        canvas = np.full((480, 640, 3), 90, np.uint8)
        x = int(64 + 60 * np.sin(i / 15))
        canvas[:, x:x + 512] = face[16:496, : min(512, 640 - x)]
        writer.send(np.ascontiguousarray(canvas))
    writer.close()
    return path


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--frames", type=int, default=90)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--threads", type=int, default=1)
    args = parser.parse_args(argv)

    try:
        from threadpoolctl import threadpool_limits

        threadpool_limits(1)
    except ImportError:
        pass
    from facsim.analysis import analyse
    from facsim.analysis.processor import iter_frames

    clip = make_clip(Path(tempfile.mkdtemp()) / "clip.mp4", args.frames)
    analyse(clip, threads=args.threads)  # warm: models loaded, basis cached
    decode, totals, stages = [], [], {"detection": [], "landmarks": [], "fit": []}
    for _ in range(args.repeats):
        t = time.perf_counter()
        for _ in iter_frames(clip)[0]:
            pass
        decode.append(time.perf_counter() - t)
        t = time.perf_counter()
        result = analyse(clip, threads=args.threads)
        totals.append(time.perf_counter() - t)
        for k in stages:
            stages[k].append(result.timings[k])
    n = len(result.frames)
    total = statistics.median(totals)
    print(f"640x480 clip, {n} frames, {args.threads} interpreter thread(s), median of {args.repeats} runs")
    print(f"  decode only (baseline)  {1000 * statistics.median(decode) / n:7.2f} ms/frame")
    for k, v in stages.items():
        ms = 1000 * statistics.median(v) / n
        print(f"  {k:<22}  {ms:7.2f} ms/frame  ({100 * statistics.median(v) / total:4.1f} % of the total)")
    print(f"  total                   {1000 * total / n:7.2f} ms/frame  = {n / total:5.1f} frames/s "
          f"(faces found in {sum(f.success for f in result.frames)}/{n})")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
