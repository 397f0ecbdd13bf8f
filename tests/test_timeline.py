import json
import os
from pathlib import Path

import jsonschema
import numpy as np
import pytest
import yaml

from facsim.facs.activations import UNILATERAL_DEFAULT_SIDE, Activations
from facsim.facs.notation import parse
from facsim.timeline.model import BLINK_AU, Blinks, Envelope, Hold, Segment, Timeline, TimelineError, Track
from facsim.timeline.sampling import activation_curves, blink_times, frame_count, frame_times, intensity_curves, sample, sample_frames
from facsim.timeline.builders import stimulus_timeline
from facsim.timeline.io import load_timeline, save_timeline, timeline_from_dict, timeline_schema, timeline_to_dict

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
EXAMPLE_FILES = sorted(p for p in EXAMPLES.iterdir() if p.suffix in (".yaml", ".yml", ".json")
                       and "blocks" not in (yaml.safe_load(p.read_text()) or {}))  # stimulus sets: test_batch_spec


def au_track(code=12, **timing):
    return {"au": code, **timing}


def one_track(track, **top):
    return timeline_from_dict({**top, "tracks": [track]})


def level(timeline, t, code=12, side="left"):
    return sample(timeline, t)[code, side]


# ----------------------------------------------------------------- envelope ---

ENVELOPE = {"start": 0.5, "onset": 1.0, "apex": 1.0, "offset": 1.0, "intensity": 0.8}


@pytest.mark.parametrize("t, expected", [
    (0.0, 0.0),    # before start
    (0.5, 0.0),    # start
    (1.0, 0.4),    # mid-onset
    (1.5, 0.8),    # apex begins
    (2.0, 0.8),    # mid-apex
    (3.0, 0.4),    # mid-offset
    (3.5, 0.0),    # end
    (5.0, 0.0),    # after end
])
def test_envelope_values_at_key_times(t, expected):
    tl = one_track(au_track(**ENVELOPE))
    assert level(tl, t) == pytest.approx(expected)
    assert level(tl, t, side="right") == pytest.approx(expected)


def test_envelope_letter_intensity_and_easing():
    tl = one_track(au_track(start=0, onset=1, apex=1, offset=1, intensity="D", easing="ease-in"))
    assert level(tl, 1.5) == pytest.approx(0.85)
    assert level(tl, 0.5) == pytest.approx(0.85 * 0.25)        # ease-in at half-way
    assert level(tl, 2.5) == pytest.approx(0.85 * 0.75)        # falling: 1 - ease-in(0.5)


def test_envelope_with_zero_phases():
    tl = one_track(au_track(start=1, onset=0, apex=1, offset=0))
    assert [level(tl, t) for t in (0.99, 1.0, 1.99, 2.0)] == [0.0, 1.0, 1.0, 0.0]


def test_length_defaults_to_end_of_last_track():
    tl = one_track(au_track(**ENVELOPE))
    assert tl.duration is None and tl.length == pytest.approx(3.5)


# ------------------------------------------------------------------ sectors ---

SECTORS = [{"start": 0.0, "end": 1.0, "from": 0, "to": "C"},
           {"start": 2.0, "end": 3.0, "to": "100%", "easing": "smoothstep"},
           {"start": 3.0, "end": 4.0, "from": 0.5, "to": 0.0}]


@pytest.mark.parametrize("t, expected", [
    (0.0, 0.0),
    (0.5, 0.275),              # linear half-way to C (0.55)
    (1.5, 0.55),               # gap: holds the previous 'to'
    (2.5, 0.775),              # 'from' defaults to the previous 'to'; smoothstep(0.5) = 0.5
    (3.0, 0.5),                # next segment starts at its own 'from'
    (3.5, 0.25),
    (4.0, 0.0),                # end of the last segment: over
    (9.0, 0.0),
])
def test_sectors(t, expected):
    tl = one_track(au_track(segments=SECTORS), duration=10)
    assert level(tl, t) == pytest.approx(expected)


def test_sector_ending_high_drops_at_its_end():
    tl = one_track(au_track(segments=[{"start": 0, "end": 1, "from": 0, "to": 1}]), duration=2)
    assert level(tl, 0.999) == pytest.approx(0.999)
    assert level(tl, 1.0) == 0.0


def test_hold_is_constant_between_start_and_end():
    tl = one_track(au_track(start=0.5, end=1.5, intensity="B"))
    assert [level(tl, t) for t in (0.49, 0.5, 1.0, 1.49, 1.5)] == [0.0, 0.3, 0.3, 0.3, 0.0]


def test_hold_start_defaults_to_zero():
    assert one_track(au_track(end=1)).tracks[0].timing == Hold(0.0, 1.0, 1.0)


# ---------------------------------------------------------- combining tracks ---

def test_overlapping_tracks_on_same_au_sum_and_clamp():
    tl = timeline_from_dict({"tracks": [au_track(start=0, end=2, intensity=0.4),
                                        au_track(start=1, end=3, intensity=0.3),
                                        au_track(start=1.5, end=3, intensity=0.5)]})
    assert [level(tl, t) for t in (0.5, 1.2, 1.7, 2.5)] == pytest.approx([0.4, 0.7, 1.0, 0.8])


def test_sequential_tracks_do_not_add_at_the_boundary():
    tl = timeline_from_dict({"tracks": [au_track(start=0, end=1, intensity=0.6),
                                        au_track(start=1, end=2, intensity=0.6)]})
    assert level(tl, 1.0) == pytest.approx(0.6)


def test_different_aus_coexist():
    tl = timeline_from_dict({"tracks": [au_track(12, start=0, end=1, intensity=0.6),
                                        au_track(6, start=0, end=1, intensity=0.3),
                                        au_track(51, start=0, end=1, intensity=0.5)]})
    act = sample(tl, 0.5)
    assert isinstance(act, Activations)
    assert act.codes == {6, 12, 51}
    assert (act[6, "left"], act[12, "right"], act.level(51)) == pytest.approx((0.3, 0.6, 0.5))


@pytest.mark.parametrize("side, left, right", [
    ("both", 0.7, 0.7),
    ("left", 0.7, 0.0),
    ("right", 0.0, 0.7),
    ("unilateral", *((0.0, 0.7) if UNILATERAL_DEFAULT_SIDE == "right" else (0.7, 0.0))),
])
def test_sides(side, left, right):
    tl = one_track(au_track(side=side, start=0, end=1, intensity=0.7))
    act = sample(tl, 0.5)
    assert (act[12, "left"], act[12, "right"]) == (left, right)


def test_left_and_right_tracks_combine_per_side():
    tl = timeline_from_dict({"tracks": [au_track(side="left", start=0, end=1, intensity=0.7),
                                        au_track(start=0, end=1, intensity=0.5)]})
    act = sample(tl, 0.5)
    assert (act[12, "left"], act[12, "right"]) == (1.0, 0.5)


def test_facs_track_scales_its_intensities():
    tl = one_track({"facs": "1+2+5B+L12C", "start": 0, "onset": 1, "apex": 1, "offset": 1, "intensity": 0.5})
    act = sample(tl, 1.5)
    assert act[1, "left"] == pytest.approx(0.5)
    assert act[5, "right"] == pytest.approx(0.15)
    assert (act[12, "left"], act[12, "right"]) == (pytest.approx(0.275), 0.0)
    assert sample(tl, 0.5)[1, "left"] == pytest.approx(0.25)    # half-way up, times 0.5


def test_facs_letters_follow_the_intensities_table():
    track = {"facs": "5B", "end": 1}
    assert level(one_track(track), 0.5, 5) == pytest.approx(0.30)
    assert level(one_track(track, intensities="facshuman"), 0.5, 5) == pytest.approx(0.20)
    seg = {"au": 5, "segments": [{"start": 0, "end": 1, "from": "D", "to": "D"}]}
    assert level(one_track(seg, intensities="facshuman"), 0.5, 5) == pytest.approx(0.90)


@pytest.mark.parametrize("name, table, code", [("happiness", "hapfacs", 25), ("surprise", "emfacs", 5)])
def test_emotion_track_scales_its_aus(name, table, code):
    from facsim.facs.emotions import emotion

    expected = {u.code: u.intensity for u in emotion(name, table=table).units}
    tl = one_track({"emotion": name, "table": table, "start": 0, "onset": 1, "apex": 1, "offset": 1,
                    "intensity": "50%"})
    act = sample(tl, 1.5)
    assert act.codes == set(expected)
    for c, value in expected.items():
        assert act.level(c) == pytest.approx(0.5 * value)
    assert sample(tl, 0.5).level(code) == pytest.approx(0.25 * expected[code])


def test_emotion_name_is_case_insensitive():
    assert one_track({"emotion": " Happiness ", "end": 1}).tracks[0].emotion == "happiness"


def test_neutral_track_contributes_nothing():
    assert not sample(one_track({"emotion": "neutral", "end": 1}), 0.5)


def test_intensity_curves_labels_and_values():
    tl = timeline_from_dict({"tracks": [au_track(side="left", start=0, end=1, intensity=0.5),
                                        au_track(6, start=0, end=2, intensity=0.3),
                                        {"facs": "R2", "end": 1}]})
    curves = intensity_curves(tl, [0.5, 1.5])
    assert list(curves) == ["AU2 (R)", "AU6", "AU12 (L)"]
    assert curves["AU6"].tolist() == [0.3, 0.3]
    assert curves["AU12 (L)"].tolist() == [0.5, 0.0]
    keys = list(activation_curves(tl, [0.5]))
    assert keys == [(2, "right"), (6, "left"), (6, "right"), (12, "left")]


def test_tracks_run_past_duration_are_cut():
    tl = one_track(au_track(start=0, end=5), duration=2)
    assert tl.length == 2 and frame_count(tl) == 60


# ------------------------------------------------------------------- frames ---

@pytest.mark.parametrize("duration, fps, frames", [
    (3.0, 30, 90), (1.4, 30, 42), (2.0, 24, 48), (0.25, 30, 8), (10.0, 29.97, 300), (0.1, 25, 3), (1, 1, 1),
])
def test_frame_count_is_duration_times_fps_rounded(duration, fps, frames):
    tl = Timeline(duration=duration, fps=fps)
    assert frame_count(tl) == frames
    times = frame_times(tl)
    assert times.shape == (frames,)
    np.testing.assert_allclose(times, np.arange(frames) / fps)
    assert times[0] == 0.0 and times[-1] < duration


def test_fps_override():
    tl = Timeline(duration=2.0, fps=30)
    assert frame_count(tl, fps=60) == 120
    assert len(sample_frames(tl, fps=10)) == 20


def test_sample_frames_match_sample():
    tl = load_timeline(EXAMPLES / "overlapping_aus.yaml")
    times = frame_times(tl)
    frames = sample_frames(tl)
    assert len(frames) == len(times) == 90
    for i in (0, 17, 33, 45, 89):
        assert frames[i] == sample(tl, times[i])


def test_stimulus_timeline_hapfacs_defaults():
    tl = stimulus_timeline("happiness")
    assert (tl.length, tl.fps, frame_count(tl)) == (3.0, 30.0, 90)
    frames = sample_frames(tl)
    curve = [f[12, "left"] for f in frames]
    assert curve[0] == 0.0 and curve[15] == pytest.approx(0.5) and curve[30:60] == [1.0] * 30
    assert curve[75] == pytest.approx(0.5) and curve[89] == pytest.approx(1 / 30)


@pytest.mark.parametrize("what", ["1+2+5B+26", parse("1+2+5B+26")])
def test_stimulus_timeline_from_facs_or_expression(what):
    tl = stimulus_timeline(what, onset=0.5, apex=2, offset=0.5, fps=25, intensity=0.5)
    assert tl.tracks[0].facs == "1+2+5B+26"
    assert (tl.length, frame_count(tl)) == (3.0, 75)
    assert sample(tl, 1.0)[5, "left"] == pytest.approx(0.15)


def test_stimulus_timeline_keeps_expression_intensities_exact():
    expr = parse("5B+12@0.12345", intensities="facshuman")       # 5B is 0.2 in this table
    tl = stimulus_timeline(expr)
    act = sample(tl, 1.5)
    assert (act[5, "left"], act[12, "left"]) == (0.2, 0.12345)


def test_from_facs():
    tl = Timeline.from_facs("1+2+5B+26", start=0.2, end=1.4, onset=0.4, offset=0.4, easing="smoothstep")
    assert tl.tracks[0].timing == Envelope(0.2, 0.4, 0.4, 0.4, 1.0, "smoothstep")
    assert tl.length == pytest.approx(1.4)
    assert level(tl, 0.8, 26) == 1.0 and level(tl, 1.4, 26) == 0.0
    hold = Timeline.from_facs("12", start=0.2, end=1.4, intensity="50%", character="liam", engine="registers")
    assert hold.tracks[0].timing == Hold(0.2, 1.4, 0.5)
    assert (hold.character, hold.engine) == ("liam", "registers")


def test_from_facs_ramps_longer_than_span():
    with pytest.raises(TimelineError, match=r"^offset: onset \+ offset \(1 s\) is longer than end - start"):
        Timeline.from_facs("12", start=0, end=0.5, onset=0.5, offset=0.5)


# ------------------------------------------------------------------- blinks ---

def test_blinks_reproducible_with_seed():
    a = Timeline(duration=30.0, blinks=Blinks(seed=4))
    b = Timeline(duration=30.0, blinks=Blinks(seed=4))
    assert np.array_equal(blink_times(a), blink_times(b))
    assert sample_frames(a) == sample_frames(b)


def test_blinks_differ_with_another_seed():
    a = blink_times(Timeline(duration=30.0, blinks=Blinks(seed=4)))
    b = blink_times(Timeline(duration=30.0, blinks=Blinks(seed=5)))
    assert not np.array_equal(a, b)


def test_blink_rate_and_minimum_gap():
    starts = blink_times(Timeline(duration=600.0, blinks=Blinks(rate_per_minute=17, seed=0)))
    assert 17 * 10 * 0.8 < len(starts) < 17 * 10 * 1.2
    assert np.diff(starts).min() >= 1.0
    assert starts.min() >= 1.0 and starts.max() < 600.0


def test_blink_shape():
    tl = Timeline(duration=10.0, blinks=Blinks(seed=2, duration=0.25))
    t0 = blink_times(tl)[0]
    assert level(tl, t0, BLINK_AU) == 0.0
    assert level(tl, t0 + 0.1 - 1e-9, BLINK_AU) == pytest.approx(1.0)       # closed after 0.1 s
    assert level(tl, t0 + 0.175, BLINK_AU) == pytest.approx(0.5)            # half open again
    assert level(tl, t0 + 0.25, BLINK_AU) == 0.0
    assert sample(tl, t0 + 0.1).level(BLINK_AU) == pytest.approx(1.0)


def test_blinks_add_to_an_au45_track():
    tl = timeline_from_dict({"duration": 10, "blinks": {"seed": 2},
                             "tracks": [au_track(45, start=0, end=10, intensity=0.3)]})
    t0 = blink_times(tl)[0]
    assert level(tl, t0 - 0.5, 45) == pytest.approx(0.3)
    assert level(tl, t0 + 0.1, 45) == 1.0


def test_no_blinks_without_blinks_setting():
    assert blink_times(Timeline(duration=5.0)).size == 0


# -------------------------------------------------------- round trips, files ---

FULL = {
    "description": "everything",
    "duration": 4.0,
    "fps": 25,
    "character": "emma",
    "engine": "muscle",
    "intensities": "facshuman",
    "blinks": {"rate_per_minute": 20, "duration": 0.3, "seed": 9, "min_interval": 1.5},
    "tracks": [
        {"au": 12, "side": "left", "segments": SECTORS},
        {"au": 61, "start": 0.5, "onset": 0.3, "apex": 0.4, "offset": 0.3, "intensity": "C",
         "easing": "sigmoid"},
        {"facs": "1+2+5B+26", "start": 1, "end": 2, "intensity": 0.75},
        {"emotion": "contempt", "table": "emfacs", "start": 0, "onset": 1, "apex": 0, "offset": 1},
    ],
}


@pytest.mark.parametrize("data", [FULL, *(p for p in EXAMPLE_FILES)], ids=lambda d: getattr(d, "name", "full"))
def test_dict_round_trip(data):
    tl = load_timeline(data) if isinstance(data, Path) else timeline_from_dict(data)
    again = timeline_from_dict(timeline_to_dict(tl))
    assert again == tl
    assert timeline_to_dict(again) == timeline_to_dict(tl)
    assert sample_frames(again) == sample_frames(tl)


@pytest.mark.parametrize("suffix", [".yaml", ".yml", ".json"])
def test_file_round_trip(tmp_path, suffix):
    tl = timeline_from_dict(FULL)
    path = save_timeline(tl, tmp_path / f"t{suffix}")
    assert load_timeline(path) == tl
    assert [p.name for p in tmp_path.iterdir()] == [path.name]          # no temporary file left
    umask = os.umask(0)
    os.umask(umask)
    assert path.stat().st_mode & 0o777 == 0o666 & ~umask         # not mkstemp's 0o600


def test_saved_files_validate_against_the_schema(tmp_path):
    path = save_timeline(timeline_from_dict(FULL), tmp_path / "t.json")
    jsonschema.validate(json.loads(path.read_text()), timeline_schema())


def test_schema_is_valid_draft_2020_12():
    schema = timeline_schema()
    assert schema["$schema"] == "https://json-schema.org/draft/2020-12/schema"
    jsonschema.Draft202012Validator.check_schema(schema)


@pytest.mark.parametrize("path", EXAMPLE_FILES, ids=lambda p: p.name)
def test_schema_validates_examples(path):
    data = json.loads(path.read_text()) if path.suffix == ".json" else yaml.safe_load(path.read_text())
    jsonschema.Draft202012Validator(timeline_schema()).validate(data)
    assert frame_count(load_timeline(path)) > 0


def test_expected_examples_exist():
    names = {p.name for p in EXAMPLE_FILES}
    assert {"surprise_sequence.yaml", "overlapping_aus.yaml", "emotion_happiness.json", "blinks.yaml"} <= names


def test_surprise_example():
    tl = load_timeline(EXAMPLES / "surprise_sequence.yaml")
    assert tl.tracks[0].facs == "1+2+5B+26"
    assert (tl.tracks[0].start, tl.tracks[0].end) == pytest.approx((0.2, 1.4))
    assert sample(tl, 0.8)[5, "left"] == pytest.approx(0.3)


def test_module_docstring_example_loads():
    import textwrap

    import facsim.timeline.model

    block = facsim.timeline.model.__doc__.split("(read through ``intensities``)::")[1].split("Each track has")[0]
    tl = timeline_from_dict(yaml.safe_load(textwrap.dedent(block)))
    assert [t.label for t in tl.tracks] == ["AU12 (L)", "1+2+5B+26", "happiness"]


def test_blinks_example_blinks():
    assert blink_times(load_timeline(EXAMPLES / "blinks.yaml")).size > 0


# ------------------------------------------------------------------- errors ---

ERRORS = {
    "unknown au": ({"tracks": [au_track(99, end=1)]}, r"^tracks\[0\]\.au: unknown action unit 99: FACS defines no AU99"),
    "unknown code in facs": ({"tracks": [{"facs": "1+2+99", "end": 1}]},
                             r"^tracks\[0\]\.facs: unknown action unit '99' at position 4 in '1\+2\+99'"),
    "malformed facs": ({"tracks": [{"facs": "1++2", "end": 1}]}, r"^tracks\[0\]\.facs: missing action unit"),
    "unknown emotion": ({"tracks": [{"emotion": "joy", "end": 1}]},
                        r"^tracks\[0\]\.emotion: unknown emotion 'joy'; choose one of happiness"),
    "unknown emotion table": ({"tracks": [{"emotion": "happiness", "table": "x", "end": 1}]},
                              r"^tracks\[0\]\.table: unknown emotion table 'x'"),
    "negative time": ({"tracks": [au_track(start=-1, end=1)]}, r"^tracks\[0\]\.start: negative time -1 s"),
    "negative segment time": ({"tracks": [au_track(segments=[{"start": 0, "end": -0.5, "to": 1}])]},
                              r"^tracks\[0\]\.segments\[0\]\.end: negative time -0\.5 s"),
    "reversed segment": ({"tracks": [au_track(end=1), au_track(segments=[{"start": 1.4, "end": 0.2, "to": 1}])]},
                         r"^tracks\[1\]\.segments\[0\]\.end: must be after start \(1\.4 s\), got 0\.2 s"),
    "reversed hold": ({"tracks": [au_track(start=2, end=1)]}, r"^tracks\[0\]\.end: must be after start \(2 s\)"),
    "overlapping segments": ({"tracks": [au_track(segments=[{"start": 0, "end": 1, "to": 1},
                                                             {"start": 0.5, "end": 2, "to": 0}])]},
                             r"^tracks\[0\]\.segments\[1\]\.start: starts at 0\.5 s, before the previous segment"),
    "intensity above 1": ({"tracks": [au_track(end=1, intensity=1.5)]},
                          r"^tracks\[0\]\.intensity: intensity out of range: 1\.5"),
    "percent above 100": ({"tracks": [au_track(segments=[{"start": 0, "end": 1, "to": "150%"}])]},
                          r"^tracks\[0\]\.segments\[0\]\.to: intensity out of range: '150%'"),
    "bad letter": ({"tracks": [au_track(segments=[{"start": 0, "end": 1, "from": "F", "to": 1}])]},
                   r"^tracks\[0\]\.segments\[0\]\.from: not an intensity: 'F'; .* letter A-E"),
    "unknown easing": ({"tracks": [au_track(segments=[{"start": 0, "end": 1, "to": 1, "easing": "bounce"}])]},
                       r"^tracks\[0\]\.segments\[0\]\.easing: unknown easing 'bounce'; choose one of linear"),
    "missing timing": ({"tracks": [au_track()]}, r"^tracks\[0\]: no timing: give 'segments', an envelope"),
    "incomplete envelope": ({"tracks": [au_track(onset=1, apex=1)]},
                            r"^tracks\[0\]: an envelope needs 'onset', 'apex' and 'offset'; missing 'offset'"),
    "envelope and end": ({"tracks": [au_track(onset=1, apex=1, offset=1, end=3)]},
                         r"^tracks\[0\]: give either 'end' \(a constant hold\) or an envelope"),
    "segments and start": ({"tracks": [au_track(start=0, segments=[{"start": 0, "end": 1, "to": 1}])]},
                           r"^tracks\[0\]: 'segments' gives the whole timing; drop 'start'"),
    "easing on hold": ({"tracks": [au_track(end=1, easing="sigmoid")]},
                       r"^tracks\[0\]: 'easing' has no effect on a constant hold"),
    "empty segments": ({"tracks": [au_track(segments=[])]}, r"^tracks\[0\]\.segments: must not be empty"),
    "segment without to": ({"tracks": [au_track(segments=[{"start": 0, "end": 1}])]},
                           r"^tracks\[0\]\.segments\[0\]: missing field 'to'"),
    "all-zero envelope": ({"tracks": [au_track(onset=0, apex=0, offset=0)]},
                          r"^tracks\[0\]\.apex: onset, apex and offset are all 0"),
    "no source": ({"tracks": [{"end": 1}]}, r"^tracks\[0\]: a track needs one of 'au', 'emotion' or 'facs'"),
    "two sources": ({"tracks": [{"au": 12, "facs": "1", "end": 1}]},
                    r"^tracks\[0\]: a track takes one of .*, got 'au', 'facs'"),
    "side on facs": ({"tracks": [{"facs": "12", "side": "left", "end": 1}]},
                     r"^tracks\[0\]: 'side' applies only to 'au' tracks"),
    "table on au": ({"tracks": [au_track(table="emfacs", end=1)]},
                    r"^tracks\[0\]: 'table' applies only to 'emotion' tracks"),
    "one-sided jaw": ({"tracks": [au_track(26, side="left", end=1)]},
                      r"^tracks\[0\]\.side: AU26 \(Jaw Drop\) cannot act on one side"),
    "unknown side": ({"tracks": [au_track(side="top", end=1)]},
                     r"^tracks\[0\]\.side: unknown side 'top'; choose one of both, left"),
    "gross behaviour code": ({"tracks": [au_track(50, end=1)]},
                             r"^tracks\[0\]\.au: AU50 \(Speech\) is a gross-behaviour code, which facsim does not"),
    "visibility code in facs": ({"tracks": [{"facs": "12+70", "end": 1}]},
                                r"^tracks\[0\]\.facs: AU70 .* is a visibility code, which facsim does not render"),
    "wrong type": ({"tracks": [au_track(start="1s", end=2)]}, r"^tracks\[0\]\.start: expected a number, got '1s'"),
    "au as string": ({"tracks": [au_track("AU12", end=1)]}, r"^tracks\[0\]\.au: expected an integer, got 'AU12'"),
    "unknown track field": ({"tracks": [au_track(start=0, onsett=1, apex=1, offset=1)]},
                            r"^tracks\[0\]: unknown field 'onsett'; did you mean 'onset'\?"),
    "unknown top-level field": ({"fsp": 30, "tracks": []}, r"^unknown field 'fsp'; did you mean 'fps'\?"),
    "zero fps": ({"fps": 0, "tracks": [au_track(end=1)]}, r"^fps: must be > 0, got 0"),
    "tracks not a list": ({"tracks": {"au": 12}}, r"^tracks: expected a list"),
    "track after duration": ({"duration": 1, "tracks": [au_track(start=2, end=3)]},
                             r"^tracks\[0\]: starts at 2 s, at or after the end of the video \(duration 1 s\)"),
    "no tracks, no duration": ({}, r"^duration: a timeline without tracks needs a duration"),
    "blink rate too high": ({"duration": 3, "blinks": {"rate_per_minute": 120}},
                            r"^blinks\.rate_per_minute: 120 blinks a minute means 0\.5 s"),
    "blinks overlap": ({"duration": 3, "blinks": {"duration": 0.5, "min_interval": 0.3}},
                       r"^blinks\.min_interval: 0\.3 s is shorter than a blink"),
    "unknown blinks field": ({"duration": 3, "blinks": {"rate": 10}}, r"^blinks: unknown field 'rate'"),
    "unknown intensity table": ({"intensities": "foo", "tracks": []},
                                r"^intensities: unknown intensity table 'foo'; choose one of hapfacs"),
    "not a mapping": ([1, 2], r"^expected a mapping with 'tracks' at the top level, got list"),
}


@pytest.mark.parametrize("data, message", ERRORS.values(), ids=ERRORS.keys())
def test_errors_name_the_field(data, message):
    with pytest.raises(TimelineError, match=message) as info:
        timeline_from_dict(data)
    assert "\n" not in str(info.value)
    assert isinstance(info.value, ValueError)


def test_error_path_attribute():
    with pytest.raises(TimelineError) as info:
        timeline_from_dict(ERRORS["reversed segment"][0])
    assert info.value.path == "tracks[1].segments[0].end"
    assert info.value.location == ("tracks", 1, "segments", 0, "end")


def write(tmp_path, name, text):
    path = tmp_path / name
    path.write_text(text)
    return path


def test_file_errors_name_file_and_line(tmp_path):
    path = write(tmp_path, "bad.yaml", "fps: 30\ntracks:\n  - au: 12\n    end: 1\n  - au: 6\n    segments:\n"
                                       "      - {start: 0.5, end: 0.2, to: C}\n")
    with pytest.raises(TimelineError, match=r"bad\.yaml:7: tracks\[1\]\.segments\[0\]\.end: must be after start"):
        load_timeline(path)


def test_malformed_yaml(tmp_path):
    path = write(tmp_path, "broken.yaml", "tracks:\n  - au: 12\n    start: [0\n")
    with pytest.raises(TimelineError, match=r"broken\.yaml:\d+: malformed YAML: expected ','") as info:
        load_timeline(path)
    assert info.value.line is not None


def test_malformed_json(tmp_path):
    path = write(tmp_path, "broken.json", '{"tracks": [\n  {"au": 12, "start": 0,}\n]}\n')
    with pytest.raises(TimelineError, match=r"broken\.json:2: malformed JSON: Expecting property name"):
        load_timeline(path)


def test_json_semantic_error_names_file(tmp_path):
    path = write(tmp_path, "t.json", '{"tracks": [{"emotion": "joy", "end": 1}]}')
    with pytest.raises(TimelineError, match=r"t\.json: tracks\[0\]\.emotion: unknown emotion 'joy'"):
        load_timeline(path)


def test_empty_file(tmp_path):
    with pytest.raises(TimelineError, match=r"empty\.yaml: expected a mapping .*the file is empty"):
        load_timeline(write(tmp_path, "empty.yaml", ""))


def test_unsupported_suffix(tmp_path):
    with pytest.raises(TimelineError, match=r"t\.txt: unsupported file type '\.txt'; use \.yaml, \.yml or \.json"):
        load_timeline(write(tmp_path, "t.txt", "tracks: []"))
    with pytest.raises(TimelineError, match=r"unsupported file type"):
        save_timeline(Timeline(duration=1.0), tmp_path / "t.toml")


def test_missing_file(tmp_path):
    with pytest.raises(FileNotFoundError):
        load_timeline(tmp_path / "nope.yaml")


# ---------------------------------------------------- Python API validation ---

@pytest.mark.parametrize("build, message", [
    (lambda: Segment(1.4, 0.2, 0.0, 1.0), r"^end: must be after start"),
    (lambda: Segment(0, 1, 0.0, 1.0, "bounce"), r"^easing: unknown easing 'bounce'"),
    (lambda: Segment(0, 1, 0.0, 1.2), r"^to: intensity out of range: 1\.2"),
    (lambda: Envelope(start=-1), r"^start: negative time"),
    (lambda: Hold(0, 1, "C"), r"^intensity: not an intensity: 'C'"),
    (lambda: Track(timing=Hold(0, 1)), r"a track needs one of"),
    (lambda: Track(au=12, timing=[]), r"^segments: timing must be"),
    (lambda: Track(facs="12", side="left", timing=Hold(0, 1)), r"^side: 'side' applies only"),
    (lambda: Timeline((), fps=-1), r"^fps: must be a number > 0"),
    (lambda: Blinks(seed=-1), r"^seed: must be an integer >= 0"),
])
def test_dataclass_validation(build, message):
    with pytest.raises(TimelineError, match=message):
        build()


def test_dataclasses_are_frozen_and_hashable():
    track = Track(au=12, timing=[Segment(0, 1, 0, 1)])
    assert isinstance(track.timing, tuple)
    with pytest.raises(AttributeError):
        track.au = 6
    assert hash(Timeline((track,))) == hash(Timeline((track,)))


def test_sample_rejects_nan():
    with pytest.raises(ValueError, match=r"t must be a finite number"):
        sample(Timeline(duration=1.0), float("nan"))
