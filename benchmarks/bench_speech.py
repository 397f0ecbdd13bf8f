"""Speech to video, end to end: a ~10-s sentence to an MP4 with AAC sound.

Times the whole `facsim speak` path in-process — flite synthesis (uncached),
visemes and coarticulation, the emotion mix, deformation, rendering, H.264 +
AAC encoding — and reports it against the clip's length (real-time factor
< 1 means faster than real time). The baseline in the same run is the same
clip without speech (the emotion alone, no audio), so the ratio is what
speech costs on top of rendering.

    python benchmarks/bench_speech.py                       # 512 px, registers engine, 3 runs
    python benchmarks/bench_speech.py --size 256 --engine muscle --runs 1
"""
from __future__ import annotations

import argparse
import statistics
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

SENTENCE = ("The quick brown fox jumps over the lazy dog, while five wizards box quickly, "
            "and a jovial mother of pearl sings about the shimmering moonlight above the quiet harbour of the old town.")


def main(argv=None) -> int:
    from facsim.face import Face
    from facsim.timeline.speech import speech_timeline
    from facsim.speech.synth import _synthesize
    from facsim.pipeline import animate
    from facsim.timeline.model import Hold, Timeline, Track

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--size", type=int, default=512)
    ap.add_argument("--engine", default="registers")
    ap.add_argument("--character", default="kwame")
    ap.add_argument("--runs", type=int, default=3)
    args = ap.parse_args(argv)

    face = Face(args.character, engine=args.engine)
    face.render(None, size=args.size, antialias="fxaa")      # warm up: GL context, occlusion bake
    speech_runs, baseline_runs, clip = [], [], None
    with tempfile.TemporaryDirectory() as tmp:
        for run in range(args.runs):
            _synthesize.cache_clear()                          # synthesis is part of the job
            t0 = time.perf_counter()
            timeline = speech_timeline(SENTENCE, emotion="happiness", intensity="70%")
            out = animate(timeline, Path(tmp) / "speech.mp4", face=face, size=args.size)
            speech_runs.append(time.perf_counter() - t0)
            clip = timeline.length
            silent = Timeline((Track(emotion="happiness", timing=Hold(0.0, clip, "70%")),),
                              blinks=timeline.blinks)
            t0 = time.perf_counter()
            animate(silent, Path(tmp) / "silent.mp4", face=face, size=args.size)
            baseline_runs.append(time.perf_counter() - t0)
            print(f"run {run + 1}: speech {speech_runs[-1]:.2f} s, baseline {baseline_runs[-1]:.2f} s "
                  f"({out.stat().st_size / 1e6:.2f} MB)", file=sys.stderr)
    speech, baseline = statistics.median(speech_runs), statistics.median(baseline_runs)
    print(f"clip: {clip:.2f} s of speech at 30 fps, {args.size} px, {args.engine} engine, {args.character}")
    print(f"speech to MP4 (synthesis + lips + render + H.264/AAC): median {speech:.2f} s over {args.runs} runs "
          f"= {speech / clip:.2f}x real time")
    print(f"same clip without speech (baseline): median {baseline:.2f} s = {baseline / clip:.2f}x real time")
    print(f"speech overhead: {speech / baseline:.2f}x the baseline")
    return 0


if __name__ == "__main__":
    sys.exit(main())
