"""Fuzz facsim's input side: FACS notation, timeline files, the importers (OpenFace/ARKit CSV, .facs).

Every input must either be accepted or be rejected with the layer's documented
error (NotationError, TimelineError, ExchangeError); anything else, or an input
that takes longer than ``--slow`` seconds, is a finding. Inputs are mutations
of valid seeds plus a list of known-hostile shapes (aliases, deep nesting,
huge numbers, odd bytes). Same ``--seed`` → same inputs.

Usage::

    python3 scripts/fuzz_inputs.py [--count 3000] [--seed 0] [--slow 10]

Prints one table (inputs tried / accepted / rejected with the documented error /
anything else) per layer and the first few findings; exits 1 if there is any.
"""
from __future__ import annotations

import argparse
import random
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from facsim.exchange import ExchangeError, load_any_timeline
from facsim.facs.notation import NotationError, format_expression, parse
from facsim.timeline.model import TimelineError
from facsim.timeline.sampling import activation_curves, frame_times

NOTATION_SEEDS = ["1+2+5B+26", "R12A+L14", "AU12@70%", "neutral", "6+12", "L12C+R12@0.3", "U14E", "45", "0",
                  "12@0.5", "1E+L2@0.3+R2B+12+26", " AU1 + 2 + 5b + 26@70% "]
TIMELINE_YAML_SEEDS = [
    "fps: 30\ntracks:\n  - {au: 12, start: 0, end: 1}\n",
    "duration: 2\nblinks: {rate_per_minute: 17, duration: 0.25, seed: 0}\ntracks:\n"
    "  - au: 12\n    side: left\n    segments:\n      - {start: 0.2, end: 0.8, from: 0, to: C, easing: smoothstep}\n"
    "      - {start: 1.2, end: 1.6, to: 0}\n",
    "tracks:\n  - facs: '1+2+5B+26'\n    start: 0.2\n    onset: 0.4\n    apex: 0.4\n    offset: 0.4\n"
    "    easing: sigmoid\n  - emotion: happiness\n    start: 0.5\n    end: 1.5\n    intensity: 50%\n",
]
TIMELINE_JSON_SEEDS = ['{"fps": 25, "tracks": [{"au": 1, "start": 0, "end": 0.5, "intensity": "B"}]}',
                       '{"duration": 1, "tracks": [], "blinks": {"seed": 3}}']
HOSTILE_YAML = [
    "a: &a [x, x, x]\nb: &b [*a, *a, *a]\ntracks: *b\n",
    "tracks: " + "[" * 3000 + "]" * 3000 + "\n",
    "tracks: []\nduration: 1\n1: a\nzz: b\n",
    "fps: !!int x\ntracks: [{au: 12, start: 0, end: 1}]\n",
    "tracks: [{au: 12, start: 1.0e+17, end: 2.0e+17}]\n",
    "duration: 1.0e+9\nblinks: {seed: 1}\ntracks: [{au: 12, start: 0, end: 1}]\n",
    "fps: 1000000\ntracks: [{au: 12, start: 0, end: 1}]\n",
    "fps: 0\ntracks: [{au: 12, start: 0, end: 1}]\n",
    "fps: .nan\ntracks: [{au: 12, start: 0, end: 1}]\n",
    "tracks: [{au: 12, start: 0, end: 1, easing: " + "x" * 200_000 + "}]\n",
    "tracks: [{au: " + "9" * 5000 + ", start: 0, end: 1}]\n",
    "tracks: [{facs: '" + "1" * 4301 + "', start: 0, end: 1}]\n",
    "tracks: [{facs: '١٢', start: 0, end: 1}]\n",
    "duration: 2001-13-45\ntracks: []\n",
    "? [a, b]\n: 1\ntracks: []\n",
    "tracks:\n" + "  - {au: 12, start: 0, end: 1}\n" * 30000,
    "!!python/object:os.system 'echo hi'\n",
    "tracks: [{au: 12, start: 0, end: 1e308}]\n",
    "tracks: [{au: 12, start: 0, end: 1}]\nblinks: {rate_per_minute: 1e-300}\n",
    "tracks: [{au: 12, segments: [{start: 0, end: 1e-320, to: 1}]}]\n",
    "\ufefftracks: [{au: 12, start: 0, end: 1}]\n",
    "tracks: [{au: true, start: 0, end: 1}]\n",
]
OPENFACE_HEADER = "frame, face_id, timestamp, confidence, success, pose_Rx, pose_Ry, pose_Rz, AU01_r, AU12_r, AU45_r"
ARKIT_HEADER = None   # filled from facsim.exchange.arkit.csv_columns()


def openface_seed(rng: random.Random) -> str:
    rows = [OPENFACE_HEADER]
    for i in range(rng.randint(1, 12)):
        rows.append(f"{i + 1}, 0, {i / 30:.4f}, 0.98, 1, 0.01, -0.02, 0.0, {rng.uniform(0, 5):.2f}, "
                    f"{rng.uniform(0, 5):.2f}, {rng.uniform(0, 5):.2f}")
    return "\n".join(rows) + "\n"


def arkit_seed(rng: random.Random) -> str:
    from facsim.exchange.arkit import dumps_arkit_csv
    from facsim.timeline.model import Timeline

    return dumps_arkit_csv(Timeline.from_facs(rng.choice(["12", "1+2", "26B", "L12C"]), end=0.2, fps=30))


def facs_seed(rng: random.Random) -> str:
    return ("facsim-notation 1\nfps: 30\nduration: 3\nblinks: rate=17 duration=0.25 seed=0 min_interval=1\n"
            "[1+2+5B+26]  0.2+0.4/0.4/0.4~sigmoid\nhappiness    0.5-1.5@0.5\nsadness/emfacs 1+0.5/0/0.5\n"
            "AU12L        0:0>0.8:C~smoothstep>1.6:0;2:0.3>2.5:0\n")


ODD = ["", "0", "-0", "-1", "1e308", "1e-320", "nan", "inf", "-inf", "١٢", "１２", "\x00", "\u202e", "+", "@",
       "%", ",", ":", ";", "\n", "\r", '"', "'", "[", "]", "{", "}", "&a", "*a", "!!int", "9" * 400, "Ä", "\ufeff",
       "  ", "\t", "#", "0x10", "1_0", "12@", "AU", "L", "E", "999", "1.5", "99999999999999999999"]


def mutate(text: str, rng: random.Random) -> str:
    """A few random edits: delete, duplicate, insert odd tokens, swap bytes."""
    chars = list(text)
    for _ in range(rng.randint(1, 4)):
        op = rng.randrange(6)
        i = rng.randrange(len(chars) + 1)
        if op == 0 and chars:
            del chars[min(i, len(chars) - 1)]
        elif op == 1:
            chars[i:i] = list(rng.choice(ODD))
        elif op == 2 and chars:
            j = rng.randrange(len(chars))
            chars[i:i] = chars[j:j + rng.randint(1, 40)]
        elif op == 3 and chars:
            chars[min(i, len(chars) - 1)] = chr(rng.randrange(0x20, 0x7f))
        elif op == 4:
            chars[i:i] = list(rng.choice(ODD) * rng.randint(1, 50))
        elif op == 5 and len(chars) > 2:
            j = rng.randrange(len(chars))
            chars[i:j] = []
    return "".join(chars)


class Tally:
    def __init__(self, name: str):
        self.name, self.tried, self.accepted, self.rejected, self.other = name, 0, 0, 0, []

    def run(self, label: str, fn, expected, slow: float) -> None:
        self.tried += 1
        start = time.perf_counter()
        try:
            fn()
        except expected:
            self.rejected += 1
            outcome = "rejected"
        except BaseException as exc:  # noqa: BLE001 - anything else is exactly what we look for
            if isinstance(exc, KeyboardInterrupt):
                raise
            self.other.append(f"{label}: {type(exc).__name__}: {str(exc)[:200]}")
            return
        else:
            self.accepted += 1
            outcome = "accepted"
        took = time.perf_counter() - start
        if took > slow:
            self.other.append(f"{label}: {outcome} but took {took:.1f} s")


def check_message(exc_text: str) -> None:
    if "\n" in exc_text or len(exc_text) > 600:
        raise AssertionError(f"error message of {len(exc_text)} characters / not one line")


def notation_case(text: str):
    def run():
        try:
            expr = parse(text)
        except NotationError as exc:
            check_message(str(exc))
            raise
        again = parse(format_expression(expr))
        if format_expression(again) != format_expression(expr):
            raise AssertionError(f"format/parse round trip changed {text!r}")
    return run


def file_case(path: Path, text: str | bytes, loader, frames: bool):
    def run():
        if isinstance(text, bytes):
            path.write_bytes(text)
        else:
            path.write_text(text, encoding="utf-8", errors="surrogatepass")
        try:
            timeline = loader(path)
        except (TimelineError, ExchangeError) as exc:
            check_message(str(exc))
            raise
        if frames:    # a timeline that loads must also sample (a few frames at its start and end)
            times = frame_times(timeline)
            for curves in (activation_curves(timeline, times[:3]), activation_curves(timeline, times[-3:])):
                for key, values in curves.items():   # accepted must mean read correctly: no NaN levels
                    if not np.all(np.isfinite(values) & (values >= 0) & (values <= 1)):
                        raise AssertionError(f"levels of {key} out of 0..1 or NaN: {values}")
    return run


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--count", type=int, default=3000, help="mutated inputs per layer (default 3000)")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--slow", type=float, default=10.0, help="seconds after which an input counts as a finding")
    args = parser.parse_args(argv)
    rng = random.Random(args.seed)
    tallies = []
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        notation = Tally("notation (parse)")
        hostile = ["1" * 4301, "١٢", "12@-0", "12@1e-1", "12@inf", "AU" + "0" * 5000 + "12", "+".join(["1"] * 6000),
                   "12@" + "5" * 5000, "L" * 100000, "12\u0000", "１２", "12@٠.٥"]
        for i, text in enumerate(hostile + [mutate(rng.choice(NOTATION_SEEDS), rng) for _ in range(args.count)]):
            notation.run(f"notation #{i} {text[:40]!r}", notation_case(text), NotationError, args.slow)
        tallies.append(notation)

        timelines = Tally("timeline files (.yaml/.json)")
        cases = [(".yaml", t) for t in HOSTILE_YAML]
        cases += [(".yaml", mutate(rng.choice(TIMELINE_YAML_SEEDS), rng)) for _ in range(args.count)]
        cases += [(".json", mutate(rng.choice(TIMELINE_JSON_SEEDS), rng)) for _ in range(args.count // 3)]
        cases += [(".json", '{"tracks": ' + "[" * 200000 + "]" * 200000 + "}"),
                  (".yaml", b"tracks: [{au: 12, start: 0, end: 1}] # \xff\xfe\n")]
        from facsim.timeline.io import load_timeline

        for i, (suffix, text) in enumerate(cases):
            path = tmp / f"t{i}{suffix}"
            timelines.run(f"timeline #{i} {str(text)[:60]!r}", file_case(path, text, load_timeline, True),
                          TimelineError, args.slow)
            path.unlink(missing_ok=True)
        tallies.append(timelines)

        importers = Tally("importers (OpenFace/ARKit CSV, .facs)")
        cases = []
        for _ in range(args.count):
            kind = rng.randrange(3)
            seed = (openface_seed, arkit_seed, facs_seed)[kind](rng)
            cases.append((".csv" if kind < 2 else ".facs", mutate(seed, rng)))
        cases += [(".csv", OPENFACE_HEADER + "\n1,0,0,1,1,0,0,0,1,1,1\n2,0,1e-320,1,1,0,0,0,1,1,1\n"),
                  (".csv", OPENFACE_HEADER + "\n1,0,0,1,1,0,0,0,1,1,1\n2,0,1e300,1,1,0,0,0,1,1,1\n"),
                  (".csv", OPENFACE_HEADER + "\n1,0,0.1,1,1,0,0,0,1,1,1\n2,0,0.1000001,1,1,0,0,0,1,1,1\n"),
                  (".facs", "facsim-notation 1\nfps: 1e9\nAU12 0-1\n"),
                  (".facs", "facsim-notation 1\nAU12 0-1e17\n"),
                  (".facs", "facsim-notation 1\n[" + "1" * 4301 + "] 0-1\n"),
                  (".csv", b"\xff\xfe" + OPENFACE_HEADER.encode())]
        for i, (suffix, text) in enumerate(cases):
            path = tmp / f"x{i}{suffix}"
            importers.run(f"import #{i} {suffix} {str(text)[:60]!r}",
                          file_case(path, text, load_any_timeline, True), (ExchangeError,), args.slow)
            path.unlink(missing_ok=True)
        tallies.append(importers)

    print(f"{'layer':40s} {'tried':>7s} {'accepted':>9s} {'rejected':>9s} {'other':>6s}")
    total_other = 0
    for t in tallies:
        print(f"{t.name:40s} {t.tried:7d} {t.accepted:9d} {t.rejected:9d} {len(t.other):6d}")
        total_other += len(t.other)
    total = [sum(getattr(t, k) for t in tallies) for k in ("tried", "accepted", "rejected")]
    print(f"{'total':40s} {total[0]:7d} {total[1]:9d} {total[2]:9d} {total_other:6d}")
    for t in tallies:
        for finding in t.other[:8]:
            print("  FINDING", finding)
    return 1 if total_other else 0


if __name__ == "__main__":
    sys.exit(main())
