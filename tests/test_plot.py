import sys
from pathlib import Path

import pytest

from facsim.timeline.plot import plot_timeline
from facsim.timeline.model import Blinks, Timeline
from facsim.timeline.builders import stimulus_timeline
from facsim.timeline.io import load_timeline

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


@pytest.mark.parametrize("suffix, magic", [(".png", b"\x89PNG"), (".svg", b"<?xml")])
def test_writes_png_and_svg(tmp_path, suffix, magic):
    out = plot_timeline(load_timeline(EXAMPLES / "overlapping_aus.yaml"), tmp_path / f"plot{suffix}")
    assert out == tmp_path / f"plot{suffix}"
    data = out.read_bytes()
    assert len(data) > 1000 and data.startswith(magic)
    assert [p.name for p in tmp_path.iterdir()] == [out.name]     # no temporary file left


def test_svg_has_labels(tmp_path):
    out = plot_timeline(stimulus_timeline("happiness"), tmp_path / "h.svg")
    text = out.read_text()
    assert "AU12 Lip Corner Puller" in text and "time (s)" in text


def test_fps_and_title_options(tmp_path):
    out = plot_timeline(stimulus_timeline("12"), tmp_path / "p.png", fps=10, title="Smile")
    assert out.stat().st_size > 1000


def test_timeline_without_tracks(tmp_path):
    out = plot_timeline(Timeline(duration=2.0), tmp_path / "empty.png")
    assert out.stat().st_size > 1000


def test_blinks_are_plotted(tmp_path):
    out = plot_timeline(Timeline(duration=6.0, blinks=Blinks(seed=3)), tmp_path / "b.svg")
    assert "AU45 Blink" in out.read_text()


def test_replaces_an_earlier_plot_but_not_a_file_of_another_kind(tmp_path):
    from facsim.atomic import OutputError, overwriting

    path = tmp_path / "p.png"
    plot_timeline(stimulus_timeline("12"), path)
    first = path.read_bytes()
    plot_timeline(stimulus_timeline("1+2"), path)          # a PNG replaces a PNG
    assert path.read_bytes().startswith(b"\x89PNG") and path.read_bytes() != first
    other = tmp_path / "q.png"
    other.write_bytes(b"not a picture")
    with pytest.raises(OutputError, match="overwrite"):
        plot_timeline(stimulus_timeline("12"), other)
    assert other.read_bytes() == b"not a picture"
    with overwriting(True):
        plot_timeline(stimulus_timeline("12"), other)
    assert other.read_bytes().startswith(b"\x89PNG")


def test_unsupported_suffix(tmp_path):
    with pytest.raises(ValueError, match=r"must end in \.png or \.svg, got .*plot\.jpg"):
        plot_timeline(stimulus_timeline("12"), tmp_path / "plot.jpg")


def test_does_not_switch_pyplot_backend(tmp_path):
    before = sys.modules.get("matplotlib.pyplot")
    plot_timeline(stimulus_timeline("12"), tmp_path / "p.png")
    assert sys.modules.get("matplotlib.pyplot") is before


def test_identical_curves_share_one_legend_entry(tmp_path):
    from facsim.timeline.plot import _identical_groups

    tl = load_timeline(EXAMPLES / "surprise_sequence.yaml")
    from facsim.timeline.sampling import frame_times, intensity_curves

    groups = _identical_groups(intensity_curves(tl, frame_times(tl)))
    assert groups == [["AU1", "AU2", "AU26"], ["AU5"]]
    text = plot_timeline(tl, tmp_path / "s.svg").read_text()
    assert all(name in text for name in ("Inner Brow Raiser", "Outer Brow Raiser", "Jaw Drop", "Upper Lid Raiser"))


def test_clip_shorter_than_a_frame(tmp_path):
    assert plot_timeline(Timeline.from_facs("12", end=0.01), tmp_path / "t.png").stat().st_size > 1000
