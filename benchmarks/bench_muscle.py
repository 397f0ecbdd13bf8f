"""Benchmark: the muscle engine's solve time per frame, on one core, against the register engine.

Run::

    FACSIM_CACHE_DIR=... python benchmarks/bench_muscle.py [--character ava] [--frames 60] [--repeats 5]

Prints, for the full head (every skin point of the net, ~4.5k points with the
muscle points): the model's build time, the animation path's time per frame
(``engine.step``: one frame applies the change since the previous frame, as
Platt & Badler's simulator does), the static solve's time (``engine.deform(act)``: an
expression from rest in n increments), and the register engine's evaluation
time for the same activations, measured in the same run — medians of several
runs, and their ratios.
"""
from __future__ import annotations

import os

# One core: set before numpy/scipy load their threaded BLAS.
for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[_var] = "1"

import argparse  # noqa: E402
import statistics  # noqa: E402
import time  # noqa: E402


def _median_time(fn, repeats: int) -> float:
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        fn()
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--character", default="ava")
    parser.add_argument("--frames", type=int, default=60, help="frames of the animated sequence")
    parser.add_argument("--repeats", type=int, default=5, help="runs per measurement (the median is kept)")
    args = parser.parse_args(argv)

    from facsim.face import Face
    from facsim.facs.notation import parse
    from facsim.facs.activations import activations
    from facsim.engines.registers import RegisterEngine
    from facsim.engines.muscle.wrinkles import wrinkle_field

    face = Face(args.character, engine="muscle")
    head, data, character, base = face.head, face.data, face.character, face.base_positions
    from facsim.engines.muscle import MuscleEngine, _MODELS

    _MODELS.clear()
    start = time.perf_counter()
    engine = MuscleEngine(head, data, character, base)
    build = time.perf_counter() - start
    registers = RegisterEngine(head, data, character, base)

    # An animated sequence: a smile with brows up comes on over half the frames, then is held.
    target = activations(parse("1+2+6+12"))
    ramp = args.frames // 2
    frames = [target.scaled(min(1.0, (k + 1) / ramp)) for k in range(args.frames)]

    def animate():
        engine.reset()
        for act in frames:
            engine.step(act)

    per_frame = _median_time(animate, args.repeats) / len(frames)
    reg_frame = _median_time(lambda: [registers.deform(a) for a in frames], args.repeats) / len(frames)
    static = _median_time(lambda: engine.deform(target), args.repeats)
    reg_static = _median_time(lambda: registers.deform(target), max(args.repeats, 20))
    points = engine.model.count
    _, state, index = next(engine.static_states([target]))
    skin = state.points(index)[: engine.model.net.count]
    wrinkles = _median_time(lambda: wrinkle_field(engine.wrinkles, skin), max(args.repeats, 10))

    print(f"muscle engine, {args.character}: {points} points ({engine.model.net.count} skin), "
          f"{len(engine.model.arc_rest)} arcs, {len(engine.model.layer.names)} muscles; one core")
    print(f"  model build (net, muscles, factorisation):  {build * 1e3:8.1f} ms")
    print(f"  animation, per frame (engine.step):         {per_frame * 1e3:8.2f} ms   "
          f"register engine {reg_frame * 1e3:.2f} ms   ratio {per_frame / reg_frame:6.1f}x")
    print(f"  static expression from rest (engine.deform):  {static * 1e3:8.1f} ms   "
          f"register engine {reg_static * 1e3:.2f} ms   ratio {static / reg_static:6.1f}x")
    print(f"  wrinkle field of a frame (for the renderer): {wrinkles * 1e3:8.2f} ms")
    print(f"  medians of {args.repeats} runs; {len(frames)} frames of '1+2+6+12' coming on over {ramp}")


if __name__ == "__main__":
    main()
