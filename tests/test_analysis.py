"""The camera processor on real photographs (scikit-image, public domain) and on facsim's own renders."""
from __future__ import annotations

import re
import subprocess

import numpy as np
import pytest

skimage_data = pytest.importorskip("skimage.data")
pytest.importorskip("ai_edge_litert")

from facsim.analysis import analyse  # noqa: E402
from facsim.analysis.processor import AnalysisError  # noqa: E402

AU12 = re.compile(r"(^|\+)[LR]?12[A-E]")


@pytest.fixture(scope="module")
def astronaut():
    return skimage_data.astronaut()


@pytest.fixture(scope="module")
def astronaut_result(astronaut):
    return analyse(astronaut, landmarks=True)


@pytest.fixture(scope="module")
def detector():
    from facsim.analysis.landmarks import LandmarkDetector

    with LandmarkDetector() as d:
        yield d


def test_smiling_astronaut_reads_as_au12(astronaut_result):
    frame = astronaut_result.frames[0]
    assert frame.success and frame.confidence > 0.9
    assert AU12.search(frame.notation()), frame.notation()
    assert max(frame.levels[12, "left"], frame.levels[12, "right"]) > 0.3
    # landmarks lie on the face: eyes above the mouth, all inside the picture
    pts = frame.landmarks
    assert pts.shape == (468, 3)
    assert (pts[:, :2] > 0).all() and (pts[:, :2] < 512).all()
    assert pts[159, 1] < pts[13, 1]  # upper lid above the lips (image y grows down)


def test_result_is_frozen_and_reports_unobservable_aus(astronaut_result):
    import facsim

    assert facsim.analyse is analyse and isinstance(astronaut_result, facsim.Analysis)
    with pytest.raises(Exception):
        astronaut_result.fps = 3
    assert 19 in astronaut_result.unobservable  # the tongue: no landmark on it
    assert all(isinstance(why, str) and why for why in astronaut_result.unobservable.values())


def test_cameraman_photo_is_found(detector):
    faces = detector.faces(skimage_data.camera())
    assert len(faces) == 1


def test_no_face_is_a_row_with_success_zero_not_a_crash(tmp_path):
    result = analyse(skimage_data.chelsea())  # a cat
    assert not result.success
    assert result.frames[0].notation() == "0"
    out = result.save(tmp_path / "cat.csv")
    header, row = out.read_text().splitlines()
    values = dict(zip((h.strip() for h in header.split(",")), (v.strip() for v in row.split(","))))
    assert values["success"] == "0" and values["AU12_r"] == "0"
    with pytest.raises(AnalysisError, match="no face"):
        result.timeline()


def test_several_faces_largest_first_and_face_index(astronaut):
    from PIL import Image

    small = np.asarray(Image.fromarray(astronaut).resize((256, 256)))
    canvas = np.full((512, 768, 3), 128, np.uint8)
    canvas[:, :512] = astronaut
    canvas[128:384, 512:] = small
    first = analyse(canvas, face=0, landmarks=True).frames[0]
    second = analyse(canvas, face=1, landmarks=True).frames[0]
    assert first.success and second.success
    assert first.landmarks[:, 0].mean() < 512 < second.landmarks[:, 0].mean()
    assert not analyse(canvas, face=2).frames[0].success


def test_openface_csv_round_trips_through_the_reader(astronaut_result, tmp_path):
    from facsim.exchange.openface import openface_columns, read_openface_csv

    path = astronaut_result.save(tmp_path / "a.csv")
    header = [h.strip() for h in path.read_text().splitlines()[0].split(",")]
    assert header == openface_columns()
    timeline = read_openface_csv(path)
    assert any(track.au == 12 for track in timeline.tracks)


def test_timeline_and_notation_files(astronaut_result, tmp_path):
    from facsim.exchange import load_any_timeline

    for suffix in (".yaml", ".facs"):
        path = astronaut_result.save(tmp_path / f"a{suffix}")
        assert any(track.au == 12 for track in load_any_timeline(path).tracks)
    with pytest.raises(AnalysisError, match=r"\.csv"):
        astronaut_result.save(tmp_path / "a.txt")


# ------------------------------------------------------------------ synthetic round trips


@pytest.fixture(scope="module")
def ava_readings(detector):
    """facsim renders of known expressions, read with the neutral render as the baseline."""
    from facsim.analysis.fit import build_basis, fit_frame, fit_identity
    from facsim.face import Face

    model = build_basis()
    out = {}
    with Face("ava") as face:
        neutral = detector.faces(face.render(None, size=320)[..., :3])[0]
        identity = fit_identity(model, [neutral.points])
        out["0"] = fit_frame(model, neutral.points, neutral.irises, identity=identity)
        for expr in ("12E", "26E", "51D", "54D"):
            found = detector.faces(face.render(expr, size=320)[..., :3])[0]
            out[expr] = fit_frame(model, found.points, found.irises, identity=identity)
    return model, out


def test_round_trip_reads_the_rendered_au(ava_readings):
    model, out = ava_readings
    levels = {expr: model.side_levels(fit.levels) for expr, fit in out.items()}
    assert max(levels["0"].values()) < 0.15  # the neutral face against itself: nothing
    assert levels["12E"][12, "left"] > 0.4 and levels["12E"][12, "right"] > 0.4
    assert levels["26E"][26, "left"] >= 0.15  # read as present (27, mouth stretch, takes a share)
    assert levels["26E"][12, "left"] < 0.15


def test_round_trip_head_pose_has_the_right_direction(ava_readings):
    from facsim.engines.rigid import head_levels

    _, out = ava_readings
    turned = head_levels(out["51D"].rotvec - out["0"].rotvec)
    assert turned[51] > 0.5 and turned[52] == 0
    down = head_levels(out["54D"].rotvec - out["0"].rotvec)
    assert down[54] > 0.5 and down[53] == 0


# ------------------------------------------------------------------ video, CLI


@pytest.fixture(scope="module")
def face_video(tmp_path_factory, astronaut):
    """A 1.2 s, 10 fps clip made from the astronaut photo (moving crop) with a tone as its sound."""
    import wave

    import imageio_ffmpeg

    folder = tmp_path_factory.mktemp("video")
    tone = folder / "tone.wav"
    with wave.open(str(tone), "wb") as w:
        w.setnchannels(1)
        w.setsampwidth(2)
        w.setframerate(16000)
        w.writeframes((np.sin(np.arange(16000 * 2) * 2 * np.pi * 440 / 16000) * 8000).astype("<i2").tobytes())
    path = folder / "astronaut.mp4"
    writer = imageio_ffmpeg.write_frames(str(path), (320, 320), fps=10, macro_block_size=1, audio_path=str(tone),
                                         audio_codec="aac", output_params=["-shortest"])
    writer.send(None)
    for i in range(12):
        x, y = 60 + 4 * i, 20 + 2 * i
        writer.send(np.ascontiguousarray(astronaut[y:y + 320, x:x + 320]))
    writer.close()
    return path


def _frame_count(path) -> int:
    import imageio_ffmpeg

    return imageio_ffmpeg.count_frames_and_secs(str(path))[0]


def test_video_analysis_has_a_frame_per_frame(face_video):
    result = analyse(face_video)
    assert len(result.frames) == _frame_count(face_video) == 12
    assert result.fps == pytest.approx(10)
    assert all(f.success for f in result.frames)
    # one unchanging smile: the least active frames are its baseline, so a moving camera
    # crop must not read as expressions against it
    assert result.neutral == "video"
    sliders = result.identity.sliders()  # the performer's face shape, as a character's sliders
    assert sliders and all(-1 <= v <= 1 for v in sliders.values())
    from facsim.head.assets import load_face_data
    from facsim.head.character import face_shape_weights

    assert face_shape_weights(sliders, set(load_face_data().target_names))  # names a character accepts
    assert max(max(f.levels.values()) for f in result.frames) < 0.3


def test_cli_analyse_prints_the_facs_string(tmp_path, astronaut, capsys):
    import imageio.v2 as imageio

    from facsim.cli import main

    image = tmp_path / "astronaut.png"
    imageio.imwrite(image, astronaut)
    assert main(["analyse", str(image)]) == 0
    assert AU12.search(capsys.readouterr().out.strip())


def test_cli_analyse_bad_input_is_one_line_exit_2(tmp_path):
    import sys

    bad = tmp_path / "notes.txt"
    bad.write_text("hello")
    proc = subprocess.run([sys.executable, "-m", "facsim.cli", "analyse", str(bad)], capture_output=True, text=True)
    assert proc.returncode == 2
    assert proc.stderr.count("\n") == 1 and "not an image" in proc.stderr


def test_retarget_makes_a_character_video_of_the_same_length_with_sound(face_video, tmp_path):
    from facsim.cli.analysis import has_audio
    from facsim.cli import main

    out = tmp_path / "kwame.mp4"
    assert main(["retarget", str(face_video), "--character", "kwame", "--size", "128", "-o", str(out)]) == 0
    assert _frame_count(out) == _frame_count(face_video)
    assert has_audio(out)


def test_cli_folder_lists_each_image_and_writes_openface_rows(tmp_path, astronaut, capsys):
    import imageio.v2 as imageio

    from facsim.cli import main

    folder = tmp_path / "photos"
    folder.mkdir()
    imageio.imwrite(folder / "a_astronaut.png", astronaut)
    imageio.imwrite(folder / "b_cat.png", skimage_data.chelsea())
    assert main(["analyse", str(folder)]) == 0
    lines = capsys.readouterr().out.strip().splitlines()
    assert lines[0].startswith("a_astronaut.png\t") and AU12.search(lines[0].split("\t")[1])
    assert lines[1] == "b_cat.png\tno face found"
    assert main(["analyse", str(folder), "-o", str(tmp_path / "photos.csv")]) == 0
    rows = (tmp_path / "photos.csv").read_text().splitlines()
    assert len(rows) == 3 and [r.split(", ")[4] for r in rows[1:]] == ["1", "0"]
