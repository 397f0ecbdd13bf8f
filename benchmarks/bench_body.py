"""What the body under the head costs: warm frames with ``body="crewneck"`` against ``"none"``.

The two settings are timed interleaved (frame by frame, one renderer each), so a loaded,
shared machine slows both alike. Prints median wall and CPU milliseconds per frame.

    python benchmarks/bench_body.py [--character kwame] [--size 512] [--frames 12]
"""
from __future__ import annotations

import argparse
import statistics
import time


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--character", default="kwame")
    parser.add_argument("--size", type=int, default=512)
    parser.add_argument("--frames", type=int, default=12)
    parser.add_argument("--views", default="front,three-quarter-left")
    args = parser.parse_args(argv)

    from facsim.face import Face

    face = Face(args.character)
    expressions = ["12", "1+2+5B+26", "4+7+23", "51D+12"]
    views = args.views.split(",")
    settings = ("none", "crewneck")
    times = {(body, view): ([], []) for body in settings for view in views}
    for body in settings:  # build every renderer, rig and shader before timing
        for view in views:
            face.render("12", size=args.size, body=body, view=view)
    for i in range(args.frames):
        for view in views:
            for body in settings:
                deformation = face.deform(expressions[i % len(expressions)])
                wall, cpu = time.perf_counter(), time.process_time()
                face.render(deformation=deformation, size=args.size, body=body, view=view)
                times[body, view][0].append(time.perf_counter() - wall)
                times[body, view][1].append(time.process_time() - cpu)
    print(f"{args.character}, {args.size}², 4x MSAA, {args.frames} warm frames per cell (median ms per frame)")
    print(f"{'view':22s} {'body':10s} {'wall':>7s} {'CPU':>7s}")
    for view in views:
        for body in settings:
            wall, cpu = times[body, view]
            print(f"{view:22s} {body:10s} {1e3 * statistics.median(wall):7.1f} {1e3 * statistics.median(cpu):7.1f}")
    face.close()
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
