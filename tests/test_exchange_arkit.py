"""ARKit-52 / Live Link Face CSV: exact layout, weights from the registers, and AU levels back."""
from __future__ import annotations

import csv

import numpy as np
import pytest

from facsim.exchange import ExchangeError, load_any_timeline, read_arkit_csv, write_arkit_csv
from facsim.exchange.arkit import arkit_weights, csv_columns, inverse_map, shape_names
from facsim.facs.activations import Activations
from facsim.engines.registers import combination_scales, register_table, response
from facsim.timeline.model import Envelope, Hold, Segment, Timeline, Track
from facsim.timeline.sampling import activation_curves, frame_times

#: The Live Link Face app's CSV header (JawRight before JawLeft, MouthRight before MouthLeft, as the app writes).
LIVE_LINK_FACE_HEADER = (
    "Timecode,BlendShapeCount,EyeBlinkLeft,EyeLookDownLeft,EyeLookInLeft,EyeLookOutLeft,EyeLookUpLeft,"
    "EyeSquintLeft,EyeWideLeft,EyeBlinkRight,EyeLookDownRight,EyeLookInRight,EyeLookOutRight,EyeLookUpRight,"
    "EyeSquintRight,EyeWideRight,JawForward,JawRight,JawLeft,JawOpen,MouthClose,MouthFunnel,MouthPucker,"
    "MouthRight,MouthLeft,MouthSmileLeft,MouthSmileRight,MouthFrownLeft,MouthFrownRight,MouthDimpleLeft,"
    "MouthDimpleRight,MouthStretchLeft,MouthStretchRight,MouthRollLower,MouthRollUpper,MouthShrugLower,"
    "MouthShrugUpper,MouthPressLeft,MouthPressRight,MouthLowerDownLeft,MouthLowerDownRight,MouthUpperUpLeft,"
    "MouthUpperUpRight,BrowDownLeft,BrowDownRight,BrowInnerUp,BrowOuterUpLeft,BrowOuterUpRight,CheekPuff,"
    "CheekSquintLeft,CheekSquintRight,NoseSneerLeft,NoseSneerRight,TongueOut,HeadYaw,HeadPitch,HeadRoll,"
    "LeftEyeYaw,LeftEyePitch,LeftEyeRoll,RightEyeYaw,RightEyePitch,RightEyeRoll").split(",")

PERFORMANCE = Timeline((
    Track(facs="1+2+26", timing=Envelope(0.1, 0.4, 0.5, 0.4, 0.85)),
    Track(au=12, side="left", timing=(Segment(0.2, 0.6, 0.0, 0.55, "smoothstep"), Segment(0.9, 1.3, 0.55, 0.0))),
    Track(au=45, timing=Envelope(0.0, 0.08, 0.0, 0.1)),  # before the smile: with 12, the 12+45 rule halves 12's cheek raise
    Track(au=4, timing=Hold(1.4, 1.5, 0.3)),       # after 1 has gone: with 1, the 1+4 rule scales 4's brow-lowering
    Track(au=51, timing=Envelope(0.0, 0.5, 0.3, 0.5, 0.6)),
    Track(au=54, timing=Hold(0.3, 0.9, 0.4)),
    Track(au=61, timing=Envelope(0.2, 0.3, 0.3, 0.3, 0.5)),
    Track(au=64, timing=Hold(1.1, 1.4, 0.5)),      # not with 45: Eq. 1 caps their shared eyeBlink at 0.25
), duration=1.5, fps=30)


def test_header_is_the_live_link_face_layout(tmp_path):
    assert csv_columns() == LIVE_LINK_FACE_HEADER and len(shape_names()) == 52
    out = write_arkit_csv(PERFORMANCE, tmp_path / "take.csv")
    rows = list(csv.reader(out.open()))
    assert rows[0] == LIVE_LINK_FACE_HEADER
    assert len(rows) == 1 + 45 and all(len(r) == 63 and r[1] == "61" for r in rows[1:])
    assert [r[0] for r in rows[1:3]] == ["00:00:00:00.000", "00:00:00:01.000"] and rows[31][0] == "00:00:01:00.000"


def test_weights_are_the_registers_faceunits_targets():
    """AU at 1 alone: each sided Face Units register gives its max (as the combination rules leave it
    for the AU alone: 26's mouthLowerDown is fear's, with 20); an unsided one the mean of its halves."""
    for code, spec in register_table()["action_units"].items():
        act = Activations({(code, "left"): 1.0, (code, "right"): 1.0})
        if spec.get("direction"):
            continue
        weights = arkit_weights(act)
        scales = combination_scales(act, code, "left")
        for reg in spec["registers"]:
            if reg["target"].startswith("faceunits/"):
                name = reg["target"][len("faceunits/"):].replace("{Side}", "Left")
                most = min(reg["max"] * scales.get(reg["target"], 1.0), 1.0)
                assert weights[name] >= most - 1e-9, (code, name)
    weights = arkit_weights(Activations({(12, "left"): 0.5}))
    half = response(0.5, 12)   # 12's concave response: half intensity moves more than half-way
    smile_max = {r["target"]: r["max"] for r in register_table()["action_units"][12]["registers"]}
    assert weights["mouthSmileLeft"] == pytest.approx(half * smile_max["faceunits/mouthSmile{Side}"])
    assert weights["mouthSmileRight"] == 0.0
    assert weights["cheekSquintLeft"] == pytest.approx(half * smile_max["faceunits/cheekSquint{Side}"])  # 12's cheek raise
    both = arkit_weights(Activations({(6, "left"): 1.0, (7, "left"): 1.0}))
    maxima = [reg["max"] for code in (6, 7) for reg in register_table()["action_units"][code]["registers"]
              if reg["target"] == "faceunits/eyeSquint{Side}"]
    # Eq. 1 clamps the sum to the smaller max, but never below the stronger AU alone (7's 1.0).
    assert len(maxima) == 2 and both["eyeSquintLeft"] == pytest.approx(max(maxima))
    weak = arkit_weights(Activations({(6, "left"): 0.4, (7, "left"): 0.2}))   # neither alone reaches 0.35
    assert weak["eyeSquintLeft"] == pytest.approx(min(response(0.4) * maxima[0] + response(0.2) * maxima[1],
                                                      min(maxima)))


def test_inverse_map_is_unambiguous():
    unknowns, matrix = inverse_map()
    assert (43, "both") not in unknowns and (12, "left") in unknowns and (26, "both") in unknowns
    single = matrix / np.linalg.norm(matrix, axis=0)
    gram = single.T @ single
    np.fill_diagonal(gram, 0)
    assert gram.max() < 0.999                                          # no two unknowns share a direction


def test_write_then_read_recovers_au_levels(tmp_path):
    path = write_arkit_csv(PERFORMANCE, tmp_path / "take.csv")
    back = read_arkit_csv(path)
    assert back.fps == 30 and back.length == pytest.approx(PERFORMANCE.length)
    times = frame_times(PERFORMANCE)
    want, got = activation_curves(PERFORMANCE, times), activation_curves(back, times)
    for key, curve in want.items():
        assert np.abs(got.get(key, 0 * times) - curve).max() < 0.01, key
    extra = {k for k, v in got.items() if k not in want and v.max() > 0.01}
    assert not extra
    assert load_any_timeline(path) == back


def test_fps_comes_from_the_timecode_frames(tmp_path):
    rows = [",".join(LIVE_LINK_FACE_HEADER)]
    for i in range(70):                                                 # 60 fps, past a second boundary
        s, f = divmod(i, 60)
        cells = [f"14:03:{52 + s:02d}:{f:02d}.{(i * 37) % 1000:03d}", "61"] + ["0"] * 61
        cells[LIVE_LINK_FACE_HEADER.index("MouthSmileLeft")] = f"{i / 70:.4f}"
        rows.append(",".join(cells))
    path = tmp_path / "take.csv"
    path.write_text("\n".join(rows) + "\n")
    tl = read_arkit_csv(path)
    assert tl.fps == 60 and tl.length == pytest.approx(70 / 60, abs=0.02)
    # Told 120 fps, frame 9.553 of the next second is (120 + 9.553) / 120 s after the first row.
    assert read_arkit_csv(path, fps=120).length == pytest.approx((120 + 9.553 + 1) / 120)


@pytest.mark.parametrize("mangle, message", [
    (lambda rows: rows[:3] + [rows[3][:len(rows[3]) // 2]], r"take\.csv:4: truncated row: \d+ cells, the header has 63"),
    (lambda rows: [rows[0].replace("JawOpen,", "")] + [r.rsplit(",", 1)[0] for r in rows[1:]],
     r"take\.csv:1: not a Live Link Face CSV: missing column JawOpen"),
    (lambda rows: rows[:2] + [rows[2].replace(",61,", ",61,abc,", 1).rsplit(",", 1)[0]],
     r"take\.csv:3: column EyeBlinkLeft: 'abc' is not a number"),
    (lambda rows: rows[:2] + ["12:00," + rows[2].split(",", 1)[1]], r"take\.csv:3: Timecode '12:00' is not HH:MM:SS:FF"),
    (lambda rows: rows[:1], r"take\.csv:1: no frames"),
    (lambda rows: [], r"take\.csv:1: empty file"),
])
def test_malformed_files_give_one_clear_error(tmp_path, mangle, message):
    short = Timeline((Track(au=12, timing=Hold(0.0, 0.1, 0.5)),), duration=0.2, fps=30)
    path = write_arkit_csv(short, tmp_path / "take.csv")
    path.write_text("\n".join(mangle(path.read_text().splitlines())) + "\n")
    with pytest.raises(ExchangeError, match=message) as err:
        read_arkit_csv(path)
    assert "\n" not in str(err.value)
