"""The photo-trained panel (scripts/panel): preprocessing as fer does it, the tallies, the CLI, a real photo."""
from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

import numpy as np
import pytest

PANEL = Path(__file__).resolve().parents[1] / "scripts" / "panel"


def _load(name):
    # unique module names: scripts/blind_review has a score.py too
    spec = importlib.util.spec_from_file_location(f"panel_{name}", PANEL / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


sys.path.insert(0, str(PANEL))   # score.py imports its sibling as `rater`
score = _load("score")
rater = sys.modules["rater"]


def test_resize_matches_opencv_bilinear_rule():
    # At exactly 2x down, OpenCV's INTER_LINEAR samples at 2i + 0.5: the mean of each pixel pair, no wider blur.
    ramp = np.tile(np.arange(128, dtype=np.float32), (128, 1))
    small = rater.resize_bilinear(ramp, 64)
    assert small.shape == (64, 64)
    np.testing.assert_allclose(small[0], np.arange(64) * 2 + 0.5)
    np.testing.assert_allclose(rater.resize_bilinear(np.full((90, 70), 7.0, np.float32), 64), 7.0)


def test_face_tensor_is_the_offset_square_crop_scaled_to_unit_range():
    gray = np.zeros((200, 200), np.float32)
    gray[50:150, 50:150] = 255.0          # a white "face" box
    tensor = rater.face_tensor(gray, (50, 50, 100, 100))
    assert tensor.shape == (64, 64) and tensor.min() >= -1 and tensor.max() <= 1
    # fer grows the box by 10 px each side: 10 of 120 px around the face stay dark
    assert tensor[32, 0] == pytest.approx(-1) and tensor[32, 32] == pytest.approx(1)
    # a box past the image edge reads the padding (the bottom rows' mean), it does not fail
    assert rater.face_tensor(gray, (-20, -20, 60, 60)).shape == (64, 64)


def test_haar_like_box_is_square_and_moved_up():
    _, y, w, h = rater.haar_like_box((100, 100, 200, 180))
    assert w == h == 100
    assert y < 100 - 10 + 5          # centre moved up by 12 % of the side (the box was 80 tall, squared to 100)


def test_to_rgb_composites_transparent_pixels_over_white():
    rgba = np.zeros((2, 2, 4), np.uint8)
    rgba[0, 0] = (10, 20, 30, 255)
    rgb = rater.to_rgb(rgba)
    assert tuple(rgb[0, 0]) == (10, 20, 30) and tuple(rgb[1, 1]) == (255, 255, 255)
    with pytest.raises(ValueError, match="uint8"):
        rater.to_rgb(np.zeros((4, 4, 3), np.float32))


def _row(emotion, intensity, said, p=0.9):
    reading = None if said is None else {"label": said, "scores": {label: (p if label == said else 0.0)
                                                                   for label in rater.LABELS}}
    return {"character": "ava", "emotion": emotion, "intensity": intensity, "engine": "registers",
            "reading": reading}


def test_summary_counts_hits_misses_and_faces_not_found():
    rows = [_row("happiness", 1.0, "happy"), _row("happiness", 1.0, "neutral"), _row("anger", 1.0, None),
            _row("fear", 0.5, "fear"), _row("contempt", 1.0, "disgust"), _row("neutral", 0.0, "neutral")]
    s = score.summarise(rows)
    assert s["cells"][("happiness", 1.0)]["rate"] == 0.5
    assert s["overall"] == {1.0: pytest.approx(1 / 3), 0.5: 1.0}     # contempt has no FER label: not counted
    assert s["no_face"] == 1 and s["confusion"][("anger", 1.0)] == {"no face": 1}
    failed = score.summarise([{**_row("fear", 1.0, None), "error": "positions contain NaN"}])
    assert failed["failed"] == 1 and failed["no_face"] == 0 and failed["overall"] == {1.0: 0.0}
    assert s["confusion"][("contempt", 1.0)] == {"disgust": 1}
    grid = [_row("happiness", 1.0, "happy"), _row("happiness", 1.0, "happy")]
    grid[0]["reading"]["grid_labels"] = ["happy", "neutral", "neutral", "neutral"]
    assert score.summarise(grid)["overall_grid"] == {1.0: pytest.approx((0.25 + 1.0) / 2)}
    text = score.format_report("registers", "fer", s, ["happiness", "anger", "fear", "contempt"], [1.0, 0.5])
    assert "emotions at 100%: 33.3% recognised" in text and "neutral: 100.0% read as neutral" in text


@pytest.mark.parametrize("argv, message", [
    (["--engine", "springs"], "--engine: unknown engine 'springs'"),
    (["--characters", "nobody"], "--characters: unknown character 'nobody'"),
    (["--emotions", "joy"], "--emotions: unknown emotion 'joy'"),
    (["--intensities", "0,1"], "--intensities: each must lie in (0, 1]"),
    (["--raters", "crowd"], "--raters: unknown rater 'crowd'"),
])
def test_bad_arguments_exit_2_with_one_line(argv, message, capsys):
    assert score.main(argv) == 2
    err = capsys.readouterr().err
    assert message in err and err.count("\n") == 1


def test_missing_model_without_fetch_says_how_to_get_it(tmp_path, monkeypatch):
    monkeypatch.setenv("FACSIM_CACHE_DIR", str(tmp_path))
    with pytest.raises(rater.RaterError, match="rater.py"):
        rater.model_path(fetch=False)


def test_faceapi_network_matches_face_api_js_on_a_fixed_input():
    # Reference: face-api.js 0.22.2 on tfjs-core 1.7.0 (node), FaceExpressionNet.forwardInput on this same
    # input (uniform noise, numpy seed 0, 112x112x3 in 0..255) with the weights of @vladmandic/face-api 1.7.15.
    faceapi = sys.modules.get("faceapi") or __import__("faceapi")
    try:
        weights = faceapi.load_weights(fetch=False)
    except rater.RaterError as exc:
        pytest.skip(str(exc))
    noise = np.random.default_rng(0).uniform(0, 255, (112, 112, 3)).astype(np.float32)
    np.testing.assert_allclose(faceapi.forward(noise, weights),
                               [0.1528, 0.0235, 0.6247, 0.1550, 0.0065, 0.0048, 0.0328], atol=2e-4)


@pytest.fixture(scope="module")
def panel():
    try:
        p = rater.Panel(fetch=False)
    except rater.RaterError as exc:
        pytest.skip(str(exc))
    yield p
    p.close()


def test_real_smiling_photo_reads_happy_and_a_facsim_face_is_found(panel, face_of):
    from skimage import data

    readings = panel.rate(data.astronaut())
    assert {name: r.label for name, r in readings.items()} == {"fer": "happy", "faceapi": "happy"}
    assert min(r.confidence for r in readings.values()) > 0.9
    readings = panel.rate(face_of("ava").render(None, size=256), grid=True)
    for reading in readings.values():
        assert set(reading.scores) == set(rater.LABELS) and abs(sum(reading.scores.values()) - 1) < 1e-3
        assert len(reading.grid_labels) == len(rater.CROP_GRID)
