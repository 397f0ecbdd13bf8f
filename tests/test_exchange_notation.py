""".facs notation files: lossless round trips with timelines, and errors that name the line and column."""
from __future__ import annotations

import random
from pathlib import Path

import pytest
import yaml

from facsim.exchange import (NotationFileError, dumps_notation, load_any_timeline, loads_notation, read_notation,
                             save_any_timeline, write_notation)
from facsim.timeline.model import Blinks, Envelope, Hold, Segment, Timeline, Track
from facsim.timeline.io import load_timeline

EXAMPLES = sorted(p for p in (Path(__file__).parents[1] / "examples").glob("*.*")
                  if "blocks" not in (yaml.safe_load(p.read_text()) or {}))  # timelines, not stimulus sets

RICH = Timeline((
    Track(facs="1+2+5B+26", timing=Envelope(0.2, 0.4, 0.4, 0.4, easing="sigmoid")),
    Track(facs=" R12A + L14 ", timing=Hold(0.1, 2.9, 0.3)),
    Track(emotion="happiness", timing=Hold(0.5, 1.5, 0.5)),
    Track(emotion="sadness", table="emfacs", timing=Envelope(1.0, 0.5, 0.0, 0.5)),
    Track(au=12, side="left", timing=(Segment(0.0, 0.8, 0.0, 0.55, "smoothstep"), Segment(0.8, 1.6, 0.55, 0.0),
                                      Segment(2.0, 2.5, 0.3, 0.1 + 0.2), Segment(2.5, 2.75, 0.7, 0.0, "ease-in"))),
    Track(au=46, side="unilateral", timing=(Segment(1e-05, 0.1, 0.0, 1.0),)),
    Track(au=51, timing=Envelope(0.3, 1 / 3, 0.2, 2 / 3, 0.123456789012345)),
    Track(au=30, side="right", timing=Hold(2.0, 2.5)),
), duration=3.0, fps=29.97, character="random:42", engine="muscle", intensities="facshuman",
    blinks=Blinks(rate_per_minute=12.5, duration=0.3, seed=7, min_interval=1.5),
    description='Quotes " and # and\nnewlines survive')


@pytest.mark.parametrize("path", EXAMPLES, ids=lambda p: p.name)
def test_examples_round_trip_losslessly(path):
    timeline = load_timeline(path)
    assert loads_notation(dumps_notation(timeline)) == timeline


def test_every_field_round_trips_losslessly():
    text = dumps_notation(RICH)
    assert loads_notation(text) == RICH
    assert dumps_notation(loads_notation(text)) == text
    assert "0:0>0.8:0.55~smoothstep>1.6:0;2:0.3>2.5:0.30000000000000004;2.5:0.7>2.75:0~ease-in\n" in text
    assert "sadness/emfacs" in text and "[ R12A + L14 ]" in text and "AU46U" in text


def _random_timeline(rng: random.Random) -> Timeline:
    tracks = []
    for _ in range(rng.randint(1, 5)):
        start = round(rng.uniform(0, 2), rng.choice([1, 3, 17]))
        kind = rng.choice(["hold", "envelope", "segments"])
        if kind == "hold":
            timing = Hold(start, start + rng.uniform(0.01, 1), rng.random())
        elif kind == "envelope":
            timing = Envelope(start, rng.random(), rng.random(), rng.random(), rng.random(),
                              rng.choice(["linear", "sigmoid", "ease-out"]))
        else:
            segs, t, level = [], start, rng.random()
            for _ in range(rng.randint(1, 4)):
                t0 = t + rng.choice([0.0, rng.random()])
                level = level if rng.random() < 0.7 else rng.random()
                t = t0 + rng.uniform(0.001, 0.5)
                nxt = rng.random()
                segs.append(Segment(t0, t, level, nxt, rng.choice(["linear", "smoothstep"])))
                level = nxt
            timing = tuple(segs)
        source = rng.choice([{"au": 12, "side": rng.choice(["both", "left", "right"])}, {"au": 26},
                             {"facs": "1+2+5B"}, {"emotion": "fear"}])
        tracks.append(Track(timing=timing, **source))
    return Timeline(tuple(tracks), fps=rng.choice([24, 30, 59.94]))


@pytest.mark.parametrize("seed", range(20))
def test_random_timelines_round_trip_losslessly(seed):
    timeline = _random_timeline(random.Random(seed))
    assert loads_notation(dumps_notation(timeline)) == timeline


def test_files_and_any_timeline(tmp_path):
    path = write_notation(RICH, tmp_path / "rich.facs")
    assert read_notation(path) == RICH == load_any_timeline(path)
    yaml_path = save_any_timeline(RICH, tmp_path / "rich.yaml")
    assert load_any_timeline(yaml_path) == RICH
    assert save_any_timeline(RICH, tmp_path / "again.facs").read_text() == path.read_text()


def test_letters_and_percentages_read_through_the_table():
    text = "facsim-notation 1\nintensities: facshuman\nAU12 0:0>1:C>2:90%;3:d>4:0  # comment\n"
    levels = [(s.from_, s.to) for s in loads_notation(text).tracks[0].timing]
    assert levels == [(0.0, 0.55), (0.55, 0.9), (0.9, 0.0)]


@pytest.mark.parametrize("body, line, column, message", [
    ("fps: x", 2, 6, "expected a number for fps, got 'x'"),
    ("AU12L 0:0>1:2", 2, 13, "level '2' is outside 0..1"),
    ("AU26L 0-1", 2, 1, "AU26 (Jaw Drop) cannot act on one side"),
    ("AU12 1-0.5", 2, 6, "must be after start (1 s), got 0.5 s"),
    ("[1+2 0-1", 2, 1, "missing ']' after the FACS string"),
    ("happy 0-1", 2, 1, "unknown emotion 'happy'"),
    ("AU12 0:0>1:0.5~bouncy", 2, 16, "unknown easing 'bouncy'"),
    ("AU12 0-1 extra", 2, 9, "unexpected text after the timing"),
    ("AU12 0:0>1:0.5;0.5:0>2:1", 2, 16, "before the previous segment ends"),
    ("AU12 0x1", 2, 7, "expected '-' (hold: START-END), '+'"),
    ("AU12", 2, 5, "expected a space and the timing"),
    ("AU12 0+1/1", 2, 11, "expected '/' and the offset duration"),
    ("foo: 1", 2, 1, "unknown setting 'foo'"),
    ("AU12 0-1\nfps: 3", 3, 1, "settings go before the tracks"),
    ("duration: 1\nAU12 2-3", 3, 1, "starts at 2 s, at or after the end of the video"),
    ("blinks: rate=100", 2, 9, "less than min_interval"),
    ("AU50 0-1", 2, 1, "AU50 (Speech) is a gross-behaviour code"),
])
def test_bad_lines_name_line_and_column(body, line, column, message):
    with pytest.raises(NotationFileError) as err:
        loads_notation("facsim-notation 1\n" + body + "\n")
    assert (err.value.line, err.value.column) == (line, column)
    assert str(err.value).startswith(f"line {line}, column {column}: ") and message in str(err.value)
    assert "\n" not in str(err.value)


@pytest.mark.parametrize("text, message", [
    ("", "empty file"),
    ("hello\n", "expected the header 'facsim-notation 1'"),
    ("facsim-notation 2\n", "unsupported facsim-notation version '2'"),
    ("facsim-notation 1\n", "a timeline without tracks needs a duration"),
])
def test_bad_files(tmp_path, text, message):
    path = tmp_path / "bad.facs"
    path.write_text(text)
    with pytest.raises(NotationFileError, match=message) as err:
        read_notation(path)
    assert str(err.value).startswith(f"{path}:1:")
