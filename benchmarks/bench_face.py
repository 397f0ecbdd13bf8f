"""Face pipeline benchmark: CLI cold start, warm frames, deforming sequences, videos.

Prints medians over several runs, with ratios against a baseline measured in the
same run (a 1×1-sample render of the same frame), since these machines are noisy.

    python benchmarks/bench_face.py [--repeats 5] [--size 512]
"""
from __future__ import annotations

import argparse
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path


def median_time(fn, repeats: int) -> float:
    times = []
    for _ in range(repeats):
        t = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t)
    return statistics.median(times)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--size", type=int, default=512)
    parser.add_argument("--antialias", type=int, default=4)
    parser.add_argument("--skip-video", action="store_true")
    args = parser.parse_args(argv)

    from facsim.face import Face
    from facsim.timeline.sampling import sample_frames
    from facsim.timeline.builders import stimulus_timeline
    from facsim.pipeline import animate

    tmp = Path(tempfile.mkdtemp())
    cli = [sys.executable, "-m", "facsim.cli", "render", "6+12", "-o", str(tmp / "cold.png"), "--size", str(args.size)]
    subprocess.run(cli, check=True, capture_output=True)  # warm the disk cache
    cold = median_time(lambda: subprocess.run(cli, check=True, capture_output=True), args.repeats)

    face = Face("ava")
    size = args.size
    face.render("6+12", size=size, antialias=args.antialias)
    warm = median_time(lambda: face.render("6+12", size=size, antialias=args.antialias), args.repeats * 2)
    plain = median_time(lambda: face.render("6+12", size=size, antialias=1), args.repeats * 2)

    frames = sample_frames(stimulus_timeline("happiness"))
    deformations = [face.deform(a) for a in frames]
    deform = median_time(lambda: [face.deform(a) for a in frames], args.repeats) / len(frames)

    def render_sequence(aa):
        for d in deformations:
            face.render(deformation=d, size=size, antialias=aa)
    sequence = median_time(lambda: render_sequence(args.antialias), max(2, args.repeats // 2)) / len(deformations)
    sequence_fxaa = median_time(lambda: render_sequence("fxaa"), max(2, args.repeats // 2)) / len(deformations)

    print(f"head model: {face.head.vertex_count} vertices, {len(face.head.topology.faces)} triangles "
          f"({face.head.topology.n_render} render vertices)")
    print(f"cold `facsim render` (warm cache), {size}²:      {cold:6.2f} s")
    print(f"warm frame {size}², {args.antialias}x MSAA (deform+render):   {warm * 1e3:6.1f} ms   "
          f"({warm / plain:.2f}x the 1-sample frame, {plain * 1e3:.1f} ms)")
    print(f"register engine per frame:                   {deform * 1e3:6.2f} ms")
    print(f"deforming sequence, {size}² {args.antialias}x MSAA:          {1 / sequence:6.1f} fps ({sequence * 1e3:.1f} ms/frame)")
    print(f"deforming sequence, {size}² FXAA:             {1 / sequence_fxaa:6.1f} fps ({sequence_fxaa * 1e3:.1f} ms/frame)")
    if not args.skip_video:
        timeline = stimulus_timeline("happiness")  # 3 s, 30 fps: HapFACS's stimulus
        for aa, label in (("fxaa", "FXAA (video default)"), (args.antialias, f"{args.antialias}x MSAA")):
            video = median_time(lambda: animate(timeline, tmp / "happy.mp4", face=face, size=size,
                                                antialias=aa), max(3, args.repeats // 2))
            print(f"3-s 30-fps {size}² MP4, {label}, end to end: {video:6.2f} s "
                  f"({video / timeline.length:.2f}x real time; {len(deformations) / video:.1f} fps overall)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
