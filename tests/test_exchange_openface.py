"""OpenFace 2.0 CSV → timeline: AU intensities as A-E levels, at the recorded times, head and gaze as 51-64."""
from __future__ import annotations

import numpy as np
import pytest

from facsim.engines.rigid import rigid_table

from facsim.exchange import ExchangeError, load_any_timeline, read_openface_csv
from facsim.exchange.openface import intensity_levels
from facsim.timeline.sampling import activation_curves, frame_count, frame_times

OPENFACE_AUS = (1, 2, 4, 5, 6, 7, 9, 10, 12, 14, 15, 17, 20, 23, 25, 26, 45)
HEADER = (["frame", "face_id", "timestamp", "confidence", "success",
           "gaze_0_x", "gaze_0_y", "gaze_0_z", "gaze_1_x", "gaze_1_y", "gaze_1_z", "gaze_angle_x", "gaze_angle_y",
           "eye_lmk_x_0", "eye_lmk_y_0", "pose_Tx", "pose_Ty", "pose_Tz", "pose_Rx", "pose_Ry", "pose_Rz",
           "x_0", "y_0", "p_scale"] + [f"AU{c:02d}_r" for c in OPENFACE_AUS]
          + [f"AU{c:02d}_c" for c in (*OPENFACE_AUS, 28)])


def openface_csv(path, frames, *, fps=30.0):
    """Write an OpenFace-style CSV (", "-separated header); ``frames`` is a list of column → value dicts."""
    lines = [", ".join(HEADER)]
    for i, values in enumerate(frames):
        row = {"frame": i + 1, "face_id": 0, "timestamp": round(i / fps, 3), "confidence": 0.98, "success": 1,
               "pose_Tz": 500.0, **values}
        lines.append(", ".join(f"{row.get(name, 0)}" for name in HEADER))
    path.write_text("\n".join(lines) + "\n")
    return path


@pytest.fixture()
def performance(tmp_path):
    """60 frames at 30 fps: AU12 rises 0 -> 3 (C) over frames 10-20, holds, AU45 blinks, frames 30-31 lost."""
    frames = []
    for i in range(60):
        au12 = float(np.clip((i - 10) / 10, 0, 1) * 3)
        values = {"AU12_r": au12, "AU06_r": 1.0 if i >= 20 else 0.0, "AU45_r": 5.0 if 40 <= i < 43 else 0.0}
        if i in (30, 31):
            values = {"success": 0, "confidence": 0.1, "AU12_r": 0.0, "AU06_r": 4.5, "pose_Ry": 1.0}
        if i >= 50:
            values["pose_Ry"] = -np.radians(17.5)          # the person turns to their own left: AU51 at 0.5
            values["gaze_angle_x"] = np.radians(6.0)        # the gaze turns less than the head ...
        frames.append(values)
    return openface_csv(tmp_path / "perf.csv", frames)


def test_intensities_map_onto_facs_letters():
    assert intensity_levels([0, 1, 2, 3, 4, 5]).tolist() == [0.0, 0.15, 0.3, 0.55, 0.85, 1.0]
    assert intensity_levels([0.5, 2.5, 6.0, -1]).tolist() == pytest.approx([0.075, 0.425, 1.0, 0.0])
    assert intensity_levels([1, 4], "facshuman").tolist() == [0.1, 0.9]


def test_recorded_levels_and_timing(performance):
    tl = read_openface_csv(performance)
    assert tl.fps == 30 and frame_count(tl) == 60 and tl.length == pytest.approx(2.0)
    curves = activation_curves(tl, frame_times(tl))
    au12 = curves[12, "left"]
    assert au12[:11].max() == 0 and au12[20] == pytest.approx(0.55) and au12[15] == pytest.approx(0.225)   # 1.5: between A and B
    assert np.array_equal(curves[12, "left"], curves[12, "right"])
    assert curves[45, "left"][40:43].tolist() == [1.0, 1.0, 1.0] and curves[45, "left"][43] == 0
    # success = 0 holds the previous frame (its garbage values are ignored)
    assert curves[6, "left"][30:32].tolist() == [0.15, 0.15] and curves[12, "left"][30] == pytest.approx(0.55)
    assert (51, "left") not in {k for k, v in curves.items() if v[:50].any()}
    assert curves[51, "left"][55] == pytest.approx(0.5, abs=1e-3)
    assert curves[62, "left"][55] == pytest.approx(11.5 / 30, abs=1e-3)   # ... so in the head the eyes turn right


def test_pose_and_gaze_signs(tmp_path):
    frames = [{"pose_Rx": np.radians(12.5)}, {"pose_Rz": np.radians(-12.5)}, {"gaze_angle_y": np.radians(-12.5)},
              {"gaze_angle_x": np.radians(-15)}]
    tl = read_openface_csv(openface_csv(tmp_path / "signs.csv", frames))
    curves = activation_curves(tl, frame_times(tl))
    assert curves[54, "left"][0] == pytest.approx(0.5)          # pitched down in the image: head down
    assert curves[56, "left"][1] == pytest.approx(0.5)          # Rz < 0 (counter-clockwise): toward the right shoulder
    up = rigid_table()["eye_rotations"][63]["left"]              # degrees at intensity 1 (negative: about -x)
    assert curves[63, "left"][2] == pytest.approx(min(1.0, 12.5 / abs(up)))   # gaze up
    assert curves[62, "left"][3] == pytest.approx(0.5)          # gaze to the image's left: their right


def test_load_any_timeline_sniffs_openface(performance):
    assert load_any_timeline(performance) == read_openface_csv(performance)


@pytest.mark.parametrize("mangle, message", [
    (lambda rows: rows[:5] + [rows[5][:40]], r"perf\.csv:6: truncated row"),
    (lambda rows: [rows[0].replace("timestamp", "time")] + rows[1:], r"perf\.csv:1: not an OpenFace CSV: missing column timestamp"),
    (lambda rows: [", ".join(r.split(", ")[:21]) for r in rows], r"perf\.csv:1: not an OpenFace CSV: no AU intensity"),
    (lambda rows: rows[:3] + [rows[3].replace(", 0.98,", ", high,", 1)], r"perf\.csv:4: column confidence: 'high' is not a number"),
    (lambda rows: rows[:3] + [rows[1]], r"perf\.csv:4: timestamp 0 does not come after"),
])
def test_malformed_files_give_one_clear_error(tmp_path, mangle, message):
    path = openface_csv(tmp_path / "perf.csv", [{"AU12_r": 1.0}] * 5)
    path.write_text("\n".join(mangle(path.read_text().splitlines())) + "\n")
    with pytest.raises(ExchangeError, match=message) as err:
        read_openface_csv(path)
    assert "\n" not in str(err.value)


def test_a_performance_plays_on_another_character(tmp_path, performance, face_of):
    from facsim.pipeline import animate

    tl = read_openface_csv(performance)
    out = animate(tl, tmp_path / "frames", face=face_of("kwame"), fps=5, size=32, antialias=1)
    assert len(list(out.glob("*.png"))) == 10
