"""Property-based tests of the input side: any text in gives a result or the layer's own error, never another.

Notation → NotationError; timeline files (YAML/JSON) → TimelineError; importers
(OpenFace and ARKit CSV, .facs) → ExchangeError. Every message is one bounded
line. A timeline that loads also samples. The hypothesis profile (tests/conftest.py)
is derandomized with modest example counts; ``HYPOTHESIS_PROFILE=fuzz`` runs many more.
"""
from __future__ import annotations

import json
import signal
import string
from contextlib import contextmanager

import numpy as np
import pytest

hypothesis = pytest.importorskip("hypothesis")
from hypothesis import given, strategies as st  # noqa: E402

from facsim.exchange import ExchangeError, load_any_timeline  # noqa: E402
from facsim.facs.catalogue import info  # noqa: E402
from facsim.facs.notation import ActionUnit, Expression, NotationError, format_expression, parse  # noqa: E402
from facsim.limits import MAX_MESSAGE  # noqa: E402
from facsim.timeline.io import load_timeline  # noqa: E402
from facsim.timeline.model import TimelineError  # noqa: E402
from facsim.timeline.sampling import activation_curves, frame_times  # noqa: E402

#: An input that takes longer than this is hung (a limit is missing), not slow.
HANG_SECONDS = 60


@contextmanager
def no_hang():
    """Fail (rather than wait forever) if the body runs past HANG_SECONDS."""
    def hung(signum, frame):
        raise AssertionError(f"input took more than {HANG_SECONDS} s: a missing limit")

    previous = signal.signal(signal.SIGALRM, hung)
    signal.alarm(HANG_SECONDS)
    try:
        yield
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, previous)


def all_finite(curves) -> None:
    """An accepted input must not be misread into NaN or infinite levels."""
    import numpy as np

    for key, values in curves.items():
        assert np.all(np.isfinite(values)) and np.all((values >= 0) & (values <= 1)), (key, values)


def one_bounded_line(error: Exception) -> None:
    text = str(error)
    assert "\n" not in text and len(text) <= MAX_MESSAGE + 200, text[:300]


# ------------------------------------------------------------- notation ---

NOTATION_CHARS = "0123456789+@%. LRUAEaubcde-١٢０\t"
notation_like = st.text(alphabet=NOTATION_CHARS, max_size=40)

CODES = [c for c in (1, 2, 4, 5, 6, 7, 9, 10, 12, 14, 15, 17, 20, 23, 24, 25, 26, 27, 43, 45, 46, 51, 61)]


@st.composite
def expressions(draw) -> Expression:
    codes = draw(st.lists(st.sampled_from(CODES), unique=True, max_size=6))
    units = []
    for code in codes:
        side = draw(st.sampled_from(("both", "left", "right", "unilateral")) if info(code).unilateral
                    else st.just("both"))
        level = draw(st.integers(0, 1000)) / 1000
        units.append(ActionUnit(code, level, side))
    return Expression(tuple(units))


@given(st.one_of(st.text(max_size=80), notation_like))
def test_any_text_parses_or_raises_notation_error(text):
    with no_hang():
        try:
            expr = parse(text)
        except NotationError as exc:
            one_bounded_line(exc)
            return
    assert format_expression(parse(format_expression(expr))) == format_expression(expr)


@given(expressions())
def test_format_then_parse_gives_the_expression_back(expr):
    assert parse(format_expression(expr)) == expr


@given(st.text(alphabet="0123456789", min_size=1, max_size=6000))
def test_long_codes_are_a_notation_error(digits):
    try:
        parse(digits)
    except NotationError as exc:
        one_bounded_line(exc)


@given(st.sampled_from("٠١٢٣٤٥٦٧٨٩０１２３۱۲"), st.sampled_from("٠١٢٣٤٥٦٧٨٩０１２３۱۲"))
def test_non_ascii_digits_are_refused(a, b):
    with pytest.raises(NotationError):
        parse(a + b)
    with pytest.raises(NotationError):
        parse("12@0." + a)


# ------------------------------------------------------------ timelines ---

scalars = st.one_of(st.none(), st.booleans(), st.integers(-10**20, 10**20), st.sampled_from([10**400, -10**400]),
                    st.floats(allow_nan=True, allow_infinity=True), st.text(max_size=12),
                    st.sampled_from(["C", "55%", "E", "linear", "smoothstep", "left", "happiness", "1+2", "12"]))
KEYS = ["tracks", "au", "facs", "emotion", "start", "end", "onset", "apex", "offset", "intensity", "easing",
        "segments", "from", "to", "side", "fps", "duration", "blinks", "seed", "rate_per_minute", "table",
        "intensities", "character", "engine", "description", "say", "voice"]
values = st.recursive(scalars, lambda children: st.one_of(
    st.lists(children, max_size=4),
    st.dictionaries(st.one_of(st.sampled_from(KEYS), st.text(max_size=5), st.integers(0, 3)), children, max_size=5)),
    max_leaves=25)
track = st.fixed_dictionaries({"au": st.sampled_from([1, 12, 26, 45, 99, 0, -1, 1e300])},
                              optional={"start": scalars, "end": scalars, "onset": scalars, "apex": scalars,
                                        "offset": scalars, "intensity": scalars, "side": scalars})
timeline_dicts = st.fixed_dictionaries({"tracks": st.lists(track, max_size=4)},
                                       optional={"fps": scalars, "duration": scalars, "blinks": values,
                                                 "intensities": scalars})
YAML_CHARS = string.ascii_letters[:12] + string.digits + " :-[]{},&*!#|>'\"\n.%@?" + "\t\x00é"


def _load(tmp_path, suffix: str, text: str):
    path = tmp_path / f"timeline{suffix}"
    path.write_text(text, encoding="utf-8", errors="surrogatepass")
    with no_hang():
        try:
            timeline = load_timeline(path)
        except TimelineError as exc:
            one_bounded_line(exc)
            return None
        times = frame_times(timeline)
        all_finite(activation_curves(timeline, times[:2]))
        all_finite(activation_curves(timeline, times[-2:]))
    return timeline


@given(text=st.one_of(st.text(alphabet=YAML_CHARS, max_size=200), st.text(max_size=100)))
def test_any_yaml_text_loads_or_raises_timeline_error(tmp_path_factory, text):
    _load(tmp_path_factory.mktemp("yaml"), ".yaml", text)


@given(data=st.one_of(timeline_dicts, values))
def test_any_json_data_loads_or_raises_timeline_error(tmp_path_factory, data):
    tmp = tmp_path_factory.mktemp("json")
    _load(tmp, ".json", json.dumps(data))
    import yaml

    _load(tmp, ".yaml", yaml.safe_dump(data))


@pytest.mark.parametrize("text, problem", [
    ("a: &a [x, x]\nb: &b [*a, *a]\ntracks: *b\n", "aliases"),
    ("tracks: " + "[" * 2000 + "]" * 2000 + "\n", "nested more than"),
    ("tracks: []\nduration: 1\n1: a\nzz: b\n", "unknown field"),
    ("fps: !!int x\ntracks: [{au: 12, start: 0, end: 1}]\n", "malformed YAML"),
    ("tracks: [{au: 12, start: 1.0e+17, end: 2.0e+17}]\n", "too many for one video"),
    ("duration: 1.0e+9\nblinks: {seed: 1}\ntracks: [{au: 12, start: 0, end: 1}]\n", "FACSIM_MAX_FRAMES"),
    ("fps: 1000000\ntracks: [{au: 12, start: 0, end: 1}]\n", "FACSIM_MAX_FPS"),
    ("fps: 0\ntracks: [{au: 12, start: 0, end: 1}]\n", "fps"),
])
def test_hostile_timeline_files_are_refused_naming_the_problem(tmp_path, text, problem):
    path = tmp_path / "t.yaml"
    path.write_text(text)
    with pytest.raises(TimelineError, match=problem) as caught:
        load_timeline(path)
    assert str(path) in str(caught.value)
    one_bounded_line(caught.value)


def test_limits_can_be_raised(tmp_path, monkeypatch):
    path = tmp_path / "long.yaml"
    path.write_text("fps: 2000\ntracks: [{au: 12, start: 0, end: 1}]\n")
    with pytest.raises(TimelineError, match="FACSIM_MAX_FPS"):
        load_timeline(path)
    monkeypatch.setenv("FACSIM_MAX_FPS", "5000")
    assert load_timeline(path).fps == 2000


def test_binary_file_names_the_file(tmp_path):
    path = tmp_path / "t.yaml"
    path.write_bytes(b"tracks: [] # \xff\xfe\n")
    with pytest.raises(TimelineError, match=r"t\.yaml: not UTF-8"):
        load_timeline(path)


def test_huge_scalar_gives_a_short_message(tmp_path):
    path = tmp_path / "t.yaml"
    path.write_text("tracks: [{au: 12, start: 0, end: 1, side: " + "x" * 100_000 + "}]\n")
    with pytest.raises(TimelineError) as caught:
        load_timeline(path)
    one_bounded_line(caught.value)


# ------------------------------------------------------------ importers ---

OPENFACE_HEADER = "frame, face_id, timestamp, confidence, success, pose_Rx, pose_Ry, pose_Rz, AU01_r, AU12_r"
cells = st.one_of(st.floats(allow_nan=True, allow_infinity=True).map(repr), st.integers(-5, 5).map(str),
                  st.sampled_from(["", "x", "1e-320", "1e308", "-0", "٣", " 0.5 ", '"1"']))


@st.composite
def openface_csv(draw) -> str:
    rows = [OPENFACE_HEADER]
    stamps = draw(st.lists(st.one_of(st.floats(0, 1e6), st.sampled_from([0.0, 1e-320, 1e-9, 1e300])),
                           min_size=1, max_size=6))
    for i, stamp in enumerate(stamps):
        row = [str(i), "0", repr(stamp), "0.9", draw(st.sampled_from(["1", "0"])), "0", "0", "0",
               draw(cells), draw(cells)]
        if draw(st.booleans()):
            row[draw(st.integers(0, len(row) - 1))] = draw(cells)
        rows.append(",".join(row))
    return "\n".join(rows) + "\n"


@st.composite
def arkit_csv(draw) -> str:
    from facsim.exchange.arkit import csv_columns

    header = csv_columns()
    rows = [",".join(header)]
    for i in range(draw(st.integers(1, 4))):
        timecode = draw(st.sampled_from([f"00:00:00:{i:02d}.000", f"00:00:{i:02d}:00.5", "99:99:99:99.9", "x",
                                         f"00:00:00:{i}"]))
        values = [draw(cells) if draw(st.integers(0, 20)) == 0 else "0.5" for _ in header[2:]]
        rows.append(",".join([timecode, str(len(header) - 2), *values]))
    return "\n".join(rows) + "\n"


FACS_CHARS = "AU0123456789LR[]+-/@:>;~.% \"#\nabcdefghijklmnopqrstuvwxyz=_"
facs_files = st.text(alphabet=FACS_CHARS, max_size=120).map(lambda body: "facsim-notation 1\n" + body)


def _import(tmp_path, suffix: str, text: str):
    path = tmp_path / f"input{suffix}"
    path.write_text(text, encoding="utf-8", errors="surrogatepass")
    with no_hang():
        try:
            timeline = load_any_timeline(path)
        except ExchangeError as exc:
            one_bounded_line(exc)
            return
        all_finite(activation_curves(timeline, frame_times(timeline)[:2]))


@given(text=openface_csv())
def test_openface_csv_imports_or_raises_exchange_error(tmp_path_factory, text):
    _import(tmp_path_factory.mktemp("of"), ".csv", text)


@given(text=arkit_csv())
def test_arkit_csv_imports_or_raises_exchange_error(tmp_path_factory, text):
    _import(tmp_path_factory.mktemp("ak"), ".csv", text)


@given(text=facs_files)
def test_facs_file_imports_or_raises_exchange_error(tmp_path_factory, text):
    _import(tmp_path_factory.mktemp("facs"), ".facs", text)


def test_openface_timestamps_too_close_are_an_exchange_error(tmp_path):
    path = tmp_path / "of.csv"
    path.write_text(OPENFACE_HEADER + "\n1,0,0,1,1,0,0,0,1,1\n2,0,1e-320,1,1,0,0,0,1,1\n")
    with pytest.raises(ExchangeError, match="frames per second"):
        load_any_timeline(path)


# ---------------------------------------------------------------- blinks ---

@given(st.integers(0, 2**32), st.floats(0.0, 3000.0))
def test_blinks_up_to_a_time_are_a_prefix_of_all_blinks(seed, until):
    """Sampling early frames draws blinks only up to them, and they are the same blinks as the whole video's."""
    import numpy as np

    from facsim.timeline.model import Blinks, Timeline
    from facsim.timeline.sampling import blink_times

    timeline = Timeline(duration=3000.0, blinks=Blinks(seed=seed))
    every = blink_times(timeline)
    early = blink_times(timeline, until)
    assert np.array_equal(early, every[every < until])


# ------------------------------------------------------------------ camera processor and batch limits


@pytest.fixture(scope="module")
def tiny_video(tmp_path_factory):
    """A 5-frame 32x32 MP4 (libx264 needs even sizes)."""
    from facsim.media.video import VideoWriter

    path = tmp_path_factory.mktemp("video") / "five.mp4"
    with VideoWriter(path, fps=10) as writer:
        for k in range(5):
            writer.append(np.full((32, 32, 3), 40 * k, np.uint8))
    return path


def test_analysed_images_over_the_pixel_limit_are_refused_before_decoding(tmp_path, monkeypatch):
    import imageio.v3 as iio

    from facsim.analysis.processor import AnalysisError, iter_frames

    path = tmp_path / "frame.png"
    iio.imwrite(path, np.zeros((40, 50, 3), np.uint8))
    monkeypatch.setenv("FACSIM_MAX_IMAGE_PIXELS", "1999")
    with pytest.raises(AnalysisError, match=r"frame\.png is 50x40 pixels.*FACSIM_MAX_IMAGE_PIXELS") as caught:
        next(iter_frames(path)[0])
    one_bounded_line(caught.value)
    with pytest.raises(AnalysisError, match="FACSIM_MAX_IMAGE_PIXELS"):
        iter_frames(np.zeros((40, 50, 3), np.uint8))
    monkeypatch.setenv("FACSIM_MAX_IMAGE_PIXELS", "2000")
    assert next(iter_frames(path)[0])[1].shape == (40, 50, 3)


def test_analysed_folders_and_videos_over_the_frame_limit_are_refused(tmp_path, monkeypatch, tiny_video):
    import imageio.v3 as iio

    from facsim.analysis.processor import AnalysisError, iter_frames

    for k in range(3):
        iio.imwrite(tmp_path / f"f{k}.png", np.zeros((8, 8, 3), np.uint8))
    monkeypatch.setenv("FACSIM_MAX_FRAMES", "2")
    with pytest.raises(AnalysisError, match="makes 3 frames.*FACSIM_MAX_FRAMES"):
        iter_frames(tmp_path)
    with pytest.raises(AnalysisError, match=r"five\.mp4.*FACSIM_MAX_FRAMES") as caught:
        list(iter_frames(tiny_video)[0])
    one_bounded_line(caught.value)
    monkeypatch.setenv("FACSIM_MAX_FRAMES", "100")
    monkeypatch.setenv("FACSIM_MAX_IMAGE_PIXELS", "1000")
    with pytest.raises(AnalysisError, match=r"frame of video five\.mp4 is 32x32 pixels.*FACSIM_MAX_IMAGE_PIXELS"):
        iter_frames(tiny_video)
    monkeypatch.setenv("FACSIM_MAX_IMAGE_PIXELS", "1024")
    assert len(list(iter_frames(tiny_video)[0])) == 5
    assert len(list(iter_frames(tmp_path)[0])) == 3


def test_batch_specs_expanding_past_the_item_limit_are_refused(monkeypatch):
    from facsim.batch.items import expand
    from facsim.batch.spec import SpecError, spec_from_dict

    data = {"characters": ["ava", "liam"], "views": ["front", "profile-left"],
            "blocks": [{"name": "b", "aus": [1, 2, 4], "intensities": [0.5, 1.0],
                        "outputs": {"stills": [1], "video": True, "glb": True}}]}
    files = 2 * (3 * 2 * 2 * (1 + 1) + 3 * 2)   # characters x (conditions x (still + video) + glbs)
    assert len(expand(spec_from_dict(data))) == files
    monkeypatch.setenv("FACSIM_MAX_ITEMS", str(files - 1))
    with pytest.raises(SpecError, match=f"expands to {files} output files.*FACSIM_MAX_ITEMS") as caught:
        spec_from_dict(data)
    one_bounded_line(caught.value)
    monkeypatch.setenv("FACSIM_MAX_ITEMS", str(files))
    assert len(expand(spec_from_dict(data))) == files
