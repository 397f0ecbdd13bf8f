"""Geometry sweep: does every expression stay physical, in each engine?

Counts, over every pair of simulated AUs at E, every single AU at E and every
emotion preset (all tables), the expressions that

* turn at least one skin triangle inside out (its normal against the rest one), and
* put at least one skin vertex inside an eyeball (any skin vertex that is
  outside the eyeball at neutral; not only the engine's own contact points).

Usage::

    python3 scripts/geometry_sweep.py                   # both engines, preset ava
    python3 scripts/geometry_sweep.py --engine registers --character noah
    python3 scripts/geometry_sweep.py --list 20         # also name the worst offenders
    python3 scripts/geometry_sweep.py --engine registers --character all --quick  # every preset, fewer pairs

Prints one line of figures per engine (and, with ``--list``, the expressions
that fail). Exit status 0 always: it measures, the tests enforce.
"""
from __future__ import annotations

import argparse
import itertools
import sys
import time


import facsim
from facsim.engines.checks import GeometryCheck


#: ``--quick``: the pairs that fold the skin around the eyes when anything does (the eye corners of
#: the East Asian presets, session 16), beside every single AU and the default table's emotions.
EYE_PAIRS = ("6E+7E", "6E+12E", "6E+64E", "7E+64E", "4E+7E", "9E+7E", "12E+7E")


def expressions(codes, *, quick: bool = False) -> list[tuple[str, facsim.Activations]]:
    """(label, activations) for singles and pairs at E plus every emotion preset of every table
    (``quick``: singles, :data:`EYE_PAIRS` and the default table's emotions)."""
    from facsim.facs.emotions import emotion, emotion_names, preset_tables

    def unit(code):  # 46 (wink) is one-sided by definition; score it on the left
        return f"L{code}E" if code == 46 else f"{code}E"

    out = [(unit(c), facsim.activations(facsim.parse(unit(c)))) for c in codes]
    pairs = EYE_PAIRS if quick else [f"{unit(a)}+{unit(b)}" for a, b in itertools.combinations(codes, 2)]
    out += [(text, facsim.activations(facsim.parse(text))) for text in pairs]
    if quick:
        return out + [(name, facsim.activations(emotion(name))) for name in emotion_names() if name != "neutral"]
    for table in preset_tables():
        for name in emotion_names():
            if name != "neutral":
                out.append((f"{table}:{name}", facsim.activations(emotion(name, table=table))))
    return out


def simulated_codes(engine_name: str) -> list[int]:
    from facsim.engines import simulated_codes as codes

    return sorted(codes(engine_name))


def sweep(engine_name: str, character: str, *, batch: int = 16, verbose: bool = False, quick: bool = False) -> dict:
    face = facsim.Face(character, engine=engine_name)
    engine = face.engine
    check = GeometryCheck(face.head, engine.neutral)
    exprs = expressions(simulated_codes(engine_name), quick=quick)
    flipped, unturned, inside, depth, worst = 0, 0, 0, 0.0, []
    start = time.perf_counter()
    for first in range(0, len(exprs), batch):
        part = exprs[first:first + batch]
        if hasattr(engine, "deform_many"):  # the muscle engine solves a batch at once
            positions = [d.positions for d in engine.deform_many([a for _, a in part])]
        else:
            positions = [engine.deform(a).positions for _, a in part]
        for (label, _), p in zip(part, positions):
            report = check(p)
            flipped += report.flipped > 0
            unturned += report.flipped_unturned > 0
            inside += report.inside > 0
            depth = max(depth, report.depth)
            if report.flipped or report.inside:
                worst.append((report.flipped + 100 * report.inside, label, report))
        if verbose:
            print(f"  {engine_name}: {first + len(part)}/{len(exprs)} done; so far {flipped} invert, "
                  f"{inside} inside an eyeball", file=sys.stderr, flush=True)
    return {"engine": engine_name, "character": character, "expressions": len(exprs),
            "flipped": int(flipped), "flipped_unturned": int(unturned), "inside": int(inside), "depth_mm": 100.0 * depth,
            "seconds": time.perf_counter() - start, "worst": sorted(worst, key=lambda w: w[0], reverse=True)}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--engine", choices=("registers", "muscle", "both"), default="both")
    parser.add_argument("--character", default="ava", help="a preset, several (comma-separated) or 'all'")
    parser.add_argument("--list", type=int, default=0, metavar="N", help="name the N worst expressions")
    parser.add_argument("--verbose", action="store_true", help="progress on stderr")
    parser.add_argument("--quick", action="store_true",
                        help="only the single AUs, the pairs around the eyes and the default emotions")
    args = parser.parse_args(argv)
    engines = ("registers", "muscle") if args.engine == "both" else (args.engine,)
    characters = args.character.split(",")
    if characters == ["all"]:
        from facsim.head.character import preset_names
        characters = list(preset_names())
    for name, character in itertools.product(engines, characters):
        r = sweep(name, character, verbose=args.verbose, quick=args.quick)
        print(f"{r['engine']:9s} {r['character']}: {r['expressions']} expressions; "
              f"{r['flipped']} invert a skin triangle ({r['flipped_unturned']} against unturned rest normals); {r['inside']} put skin inside an eyeball "
              f"(deepest {r['depth_mm']:.3f} mm); {r['seconds']:.0f} s")
        for _, label, rep in r["worst"][: args.list]:
            print(f"    {label}: {rep.flipped} triangles inverted, {rep.inside} skin points inside an eyeball "
                  f"({100 * rep.depth:.3f} mm)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
