"""Speed of the 3-s, 30-fps, 512² stimulus video end to end (issue 13 item 8), with per-stage figures.

1. **End to end** through the CLI, ``python -m facsim emotion happiness -o x.mp4`` (FXAA, the
   video default), runs interleaved so a shared machine slows them alike, medians of
   ``--repeats``:

   - ``now``: this checkout (frames that repeat an earlier frame's activations written again,
     not drawn; engine in a forked child up to 64 frames ahead of the drawing; still hair kept
     as pixels);
   - ``now, serial``: this checkout with ``FACSIM_SERIAL_FRAMES=1`` (frames deformed in the
     drawing process, as before);
   - ``now, --hair none``: this checkout without hair (brows and lashes kept);
   - ``before``: the code at ``--baseline-rev`` (default: main before this work), checked out
     into a temporary git worktree;
   - with ``--muscle``, ``before, muscle`` and ``now, muscle``: the muscle engine's video (it keeps
     state between frames, so every frame is drawn), its ratios against ``before, muscle``.

   Wall seconds (and × real time: 1.0 = as long as the video), CPU seconds of every process
   and thread (facsim, llvmpipe's threads, the deformation child, ffmpeg; steadier than wall
   time on a shared machine), ratios against ``before``, and the load average.

2. **Per stage**, in a fresh process (serial, and each stage waits for the GL work it issued,
   so the stages are measured apart, not overlapped): CPU and wall milliseconds per frame
   for deformation, the face's per-frame work (proxy fitting), vertices (normals, upload),
   proxies (upload, sorting, the kept hair layer), drawing, anti-aliasing (FXAA), readback
   and encoding (the pipe to ffmpeg), plus start-up (imports, face build, first frame's
   shaders) and ffmpeg's finish.

3. **Per draw call** (``--draws``), in a fresh process with one llvmpipe thread, each draw call
   waited for: CPU milliseconds per drawn frame of each draw group (the skin's shader variant,
   each proxy kind's alpha-tested and blended passes, the head's depth pre-pass, the shadow
   map, FXAA), over the serial video's frames after the first, and in how many frames the
   still hair was kept as pixels. It tells which shader a speed-up has to make cheaper.

    python benchmarks/bench_video.py [--repeats 5] [--character ava] [--baseline-rev REV] [--muscle] [--nice -20]
    python benchmarks/bench_video.py --draws [--character ava] [--emotion happiness]
"""
from __future__ import annotations

import argparse
import json
import os
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from baseline import baseline_tree, timed

START = (time.perf_counter(), time.process_time())
ROOT = Path(__file__).resolve().parents[1]
DEFAULT_BASELINE = "a14687f"  # main before the speed work of issue 13 item 8
VIDEO_SECONDS = 3.0
FPS = 30.0


NICE = 0  # --nice: the runs' scheduling priority (negative: ahead of other work; needs root)


def stages(args) -> dict:
    """Per-stage (wall, CPU) seconds of one serial run of the video, in this (fresh) process."""
    laps: dict[str, list[float]] = {}
    mark = list(START)

    def lap(stage: str) -> None:
        now = (time.perf_counter(), time.process_time())
        w, c = laps.get(stage, (0.0, 0.0))
        laps[stage] = (w + now[0] - mark[0], c + now[1] - mark[1])
        mark[:] = now

    from facsim.face import Face
    from facsim.head.character import resolve_character
    from facsim.media.video import VideoWriter
    from facsim.pipeline import _frames_drawn, deformations, frame_sources
    from facsim.timeline.builders import stimulus_timeline
    from facsim.timeline.sampling import sample_frames
    lap("start-up: imports")
    character = resolve_character(args.character)
    if args.hair:
        character = character.with_(hair=args.hair)
    face = Face(character)
    timeline = stimulus_timeline(args.emotion, 1.0, 1.0, 1.0, FPS)
    frames = sample_frames(timeline, FPS)
    sources = frame_sources(face, frames, frame_bytes=args.size * args.size * 4)
    drawn = [act for i, act in enumerate(frames) if sources[i] == i]
    options = dict(size=args.size, antialias="fxaa")
    renderer = face.renderer(**options)
    lap("start-up: face, timeline")
    out = Path(tempfile.mkdtemp(prefix="bench-video-")) / "x.mp4"
    os.environ["FACSIM_SERIAL_FRAMES"] = "1"
    first = True
    try:
        with VideoWriter(out, FPS) as writer, deformations(face, drawn) as stream:
            lap("start-up: face, timeline")

            def draw(deformation):
                nonlocal first
                deformation.wrinkle  # noqa: B018 — an engine's lazy creases count as deformation
                lap("deformation")
                renderer.timings = {}
                image = face.render(deformation=deformation, **options)
                gl = sum(w for w, _ in renderer.timings.values()), sum(c for _, c in renderer.timings.values())
                lap("render")
                for stage, (w, c) in renderer.timings.items():
                    name = "start-up: first frame (shaders)" if first else stage
                    total = laps.get(name, (0.0, 0.0))
                    laps[name] = (total[0] + w, total[1] + c)
                rw, rc = laps.pop("render")
                laps["face: proxy fitting, per-frame"] = tuple(
                    a + b for a, b in zip(laps.get("face: proxy fitting, per-frame", (0.0, 0.0)),
                                          (rw - gl[0], rc - gl[1])))
                first = False
                return image

            for image in _frames_drawn(sources, stream, draw):  # repeated frames as the video repeats them
                writer.append(image)
                lap("encode (pipe to ffmpeg)")
            mark[:] = (time.perf_counter(), time.process_time())
        lap("ffmpeg finish")
    finally:
        shutil.rmtree(out.parent, ignore_errors=True)
    children = resource.getrusage(resource.RUSAGE_CHILDREN)
    return {"frames": len(frames), "drawn": len(drawn), "laps": laps, "ffmpeg_cpu": children.ru_utime + children.ru_stime}


def draw_calls(args) -> dict:
    """CPU seconds of each draw group over the serial video's drawn frames after the first (which
    compiles the shaders), each draw call waited for (``finish``) so its work is its own."""
    import moderngl

    from facsim.face import Face
    from facsim.head.character import resolve_character
    from facsim.pipeline import _frames_drawn, deformations, frame_sources
    from facsim.timeline.builders import stimulus_timeline
    from facsim.timeline.sampling import sample_frames

    os.environ["FACSIM_SERIAL_FRAMES"] = "1"
    face = Face(resolve_character(args.character))
    frames = sample_frames(stimulus_timeline(args.emotion, 1.0, 1.0, 1.0, FPS), FPS)
    sources = frame_sources(face, frames, frame_bytes=args.size * args.size * 4)
    drawn = [act for i, act in enumerate(frames) if sources[i] == i]
    options = dict(size=args.size, antialias="fxaa")
    renderer = face.renderer(**options)
    ctx = renderer._ctx
    names: dict[int, str] = {}
    cpu: dict[str, float] = {}
    timing = [False]
    render = moderngl.VertexArray.render

    def timed_render(vao, *a, **k):
        if not timing[0]:
            return render(vao, *a, **k)
        ctx.finish()
        start = time.process_time()
        render(vao, *a, **k)
        ctx.finish()
        if id(vao) not in names:  # a variant compiled in this frame's render
            name_vertex_arrays()
        name = names.get(id(vao), "other")
        cpu[name] = cpu.get(name, 0.0) + time.process_time() - start

    def name_vertex_arrays():  # (variants compile as frames need them: named when first drawn)
        names.update({id(vao): f"face: {name}" for name, vao in renderer._vaos.items()})
        if renderer._depth_vao is not None:
            names[id(renderer._depth_vao)] = "head depth pre-pass"
        for mesh, layer in renderer._proxy_layers.items():
            names.update({id(vao): f"{mesh.kind}: {stage}" for stage, vao in layer.vaos.items()})
        if renderer._downsample is not None:
            names[id(renderer._downsample)] = "anti-aliasing (FXAA)"
        shadow = renderer._key_shadow
        if shadow is not None:
            names[id(shadow._vao)] = "shadow map: head"
            names.update({id(vao): "shadow map: hair cards" for vao in shadow._card_vaos.values()})

    moderngl.VertexArray.render = timed_render
    count, kept = 0, 0
    try:
        with renderer.sequence(), deformations(face, drawn) as stream:
            def draw(deformation):
                nonlocal count, kept
                timing[0] = count > 0
                image = face.render(deformation=deformation, **options)
                kept += count > 0 and renderer._hair_moving is not None
                count += 1
                return image

            for _ in _frames_drawn(sources, stream, draw):
                pass
    finally:
        moderngl.VertexArray.render = render
    return {"frames": count - 1, "kept": kept, "cpu": cpu}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--character", default="ava")
    parser.add_argument("--emotion", default="happiness")
    parser.add_argument("--size", type=int, default=512)
    parser.add_argument("--hair", help=argparse.SUPPRESS)
    parser.add_argument("--baseline-rev", default=DEFAULT_BASELINE)
    parser.add_argument("--nice", type=int, default=0,
                        help="run the videos at this niceness (e.g. -20 as root: a shared machine's other work "
                             "then yields, and wall times approach an idle machine's)")
    parser.add_argument("--muscle", action="store_true",
                        help="also the muscle engine's video, before and now (its ratio is against its own before)")
    parser.add_argument("--stages-only", action="store_true", help="only the per-stage figures (JSON; internal)")
    parser.add_argument("--no-stages", action="store_true", help="only the end-to-end figures")
    parser.add_argument("--draws", action="store_true",
                        help="only the CPU per draw group, one llvmpipe thread (a fresh process; see 3. above)")
    parser.add_argument("--draws-only", action="store_true", help=argparse.SUPPRESS)  # (JSON; internal)
    args = parser.parse_args(argv)
    global NICE
    NICE = args.nice
    if args.stages_only:
        print(json.dumps(stages(args)))
        return 0
    if args.draws_only:
        print(json.dumps(draw_calls(args)))
        return 0
    if args.draws:
        cmd = [sys.executable, __file__, "--draws-only", "--character", args.character, "--emotion", args.emotion,
               "--size", str(args.size)]
        done = subprocess.run(cmd, cwd=ROOT, env=dict(os.environ, PYTHONPATH=str(ROOT), LP_NUM_THREADS="1"),
                              check=True, capture_output=True, text=True)
        result = json.loads(done.stdout.strip().splitlines()[-1])
        n = max(result["frames"], 1)
        print(f"CPU per draw group, {args.emotion} on {args.character}, {args.size}² FXAA, one llvmpipe thread, "
              f"each draw call waited for; over the {result['frames']} drawn frames after the first "
              f"(still hair kept as pixels in {result['kept']} of them):")
        for name, seconds in sorted(result["cpu"].items(), key=lambda item: -item[1]):
            print(f"  {name:32s} {seconds / n * 1000:7.1f} ms/frame")
        print(f"  {'all draw calls':32s} {sum(result['cpu'].values()) / n * 1000:7.1f} ms/frame")
        return 0

    with baseline_tree(args.baseline_rev, "bench-video-") as (tmp, base_tree):
        def command(tree: Path, *extra: str) -> list[str]:
            return [sys.executable, "-m", "facsim", "emotion", args.emotion, "-o", str(tmp / "x.mp4"), "--overwrite",
                    "--size", str(args.size), "--character", args.character, "--quiet", *extra]

        configs = {
            "before": (base_tree, command(base_tree), None),
            "now": (ROOT, command(ROOT), None),
            "now, serial": (ROOT, command(ROOT), {"FACSIM_SERIAL_FRAMES": "1"}),
            "now, --hair none": (ROOT, command(ROOT, "--hair", "none"), None),
        }
        if args.muscle:
            configs["before, muscle"] = (base_tree, command(base_tree, "--engine", "muscle"), None)
            configs["now, muscle"] = (ROOT, command(ROOT, "--engine", "muscle"), None)
        for tree, cmd, env in configs.values():  # warm caches (face data, occlusion bakes, proxies)
            timed(cmd, tree, env, nice=NICE)
        loads = [os.getloadavg()[0]]
        times: dict[str, list[tuple[float, float]]] = {name: [] for name in configs}
        for _ in range(args.repeats):
            for name, (tree, cmd, env) in configs.items():
                times[name].append(timed(cmd, tree, env, nice=NICE))
            loads.append(os.getloadavg()[0])
        wall0 = statistics.median(w for w, _ in times["before"])
        cpu0 = statistics.median(c for _, c in times["before"])
        print(f"3-s {FPS:g}-fps {args.size}² stimulus video ({args.emotion}, {args.character}), FXAA, end to end "
              f"through the CLI; median of {args.repeats}, {os.cpu_count()} cores, load average "
              f"{min(loads):.1f}-{max(loads):.1f} during the runs{f', nice {NICE}' if NICE else ''} "
              f"(CPU = every process and thread, user + system):")
        for name, values in times.items():
            if name == "before, muscle":
                wall0 = statistics.median(w for w, _ in values)
                cpu0 = statistics.median(c for _, c in values)
            wall = statistics.median(w for w, _ in values)
            cpu = statistics.median(c for _, c in values)
            print(f"  {name:18s} wall {wall:6.2f} s ({wall / VIDEO_SECONDS:4.2f}x real time; {wall / wall0:.2f}x before)"
                  f"   CPU {cpu:6.2f} s ({cpu / VIDEO_SECONDS:4.2f} CPU-s per video-s; {cpu / cpu0:.2f}x before)")

    if args.no_stages:
        return 0
    runs = []
    for _ in range(max(1, min(args.repeats, 3))):
        cmd = [sys.executable, __file__, "--stages-only", "--character", args.character, "--emotion", args.emotion,
               "--size", str(args.size)]
        done = subprocess.run(cmd, cwd=ROOT, env=dict(os.environ, PYTHONPATH=str(ROOT)), check=True,
                              capture_output=True, text=True)
        runs.append(json.loads(done.stdout.strip().splitlines()[-1]))
    frames, drawn = runs[0]["frames"], runs[0]["drawn"]
    print(f"Per stage, serial, each stage waiting for its GL work (median of {len(runs)} fresh processes; "
          f"{drawn} of the {frames} frames drawn, the others repeat them; per drawn frame, encoding per "
          f"written frame, start-up and finish in total):")
    for stage in runs[0]["laps"]:
        wall = statistics.median(r["laps"][stage][0] for r in runs)
        cpu = statistics.median(r["laps"][stage][1] for r in runs)
        if stage.startswith("start-up") or stage == "ffmpeg finish":
            print(f"  {stage:34s} CPU {cpu * 1000:7.0f} ms        wall {wall * 1000:7.0f} ms")
        else:
            n = frames if stage.startswith("encode") else drawn
            print(f"  {stage:34s} CPU {cpu / n * 1000:7.1f} ms/frame  wall {wall / n * 1000:7.1f} ms/frame")
    total = statistics.median(sum(c for _, c in r["laps"].values()) for r in runs)
    ffmpeg = statistics.median(r["ffmpeg_cpu"] for r in runs)
    print(f"  {'ffmpeg (its own process)':34s} CPU {ffmpeg * 1000:7.0f} ms")
    print(f"  {'total':34s} CPU {(total + ffmpeg) * 1000:7.0f} ms")
    return 0


if __name__ == "__main__":
    sys.exit(main())
