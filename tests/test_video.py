"""Videos: the right frames, sizes and rates, in every format, written atomically."""
from __future__ import annotations

import os
import subprocess
import sys

import imageio_ffmpeg
import numpy as np
import pytest
from PIL import Image

from facsim.timeline.builders import stimulus_timeline
from facsim.pipeline import animate
from facsim.media.video import VideoWriter, video_format


def _read(path):
    reader = imageio_ffmpeg.read_frames(str(path))
    meta = next(reader)
    w, h = meta["size"]
    frames = [np.frombuffer(f, np.uint8).reshape(h, w, 3) for f in reader]
    return meta, frames


@pytest.fixture(scope="module")
def short_clip():
    """0.5 s of AU 12 + 26 rising and falling at 12 fps."""
    return stimulus_timeline("12+26", onset=0.2, apex=0.1, offset=0.2, fps=12)


@pytest.mark.parametrize("suffix", [".mp4", ".webm"])
def test_video_has_the_timeline_frames_size_and_rate(tmp_path, face_of, short_clip, suffix):
    out = tmp_path / f"clip{suffix}"
    animate(short_clip, out, face=face_of("ava"), size=64)
    meta, frames = _read(out)
    assert len(frames) == 6 and meta["size"] == (64, 64) and meta["fps"] == pytest.approx(12)
    if suffix == ".mp4":
        assert meta["codec"].startswith("h264") and meta["pix_fmt"].startswith("yuv420p")
    diff = [np.abs(a.astype(int) - frames[0].astype(int)).mean() for a in frames]
    assert diff[3] > diff[1] > 0.05 and diff[3] > diff[-1]  # rises to the apex, then falls
    assert [p.name for p in tmp_path.iterdir()] == [out.name]


def test_frames_of_any_layout_encode_their_colours(tmp_path):
    """RGB frames, opaque RGBA frames and see-through RGBA frames (composited over white)."""
    red = np.zeros((32, 32, 4), np.uint8)
    red[..., 0], red[..., 3] = 220, 255
    clear = red.copy()
    clear[..., 3] = 0
    out = tmp_path / "colours.mp4"
    with VideoWriter(out, 10) as writer:
        for frame in (red[..., :3], red, clear):
            writer.append(frame)
    _, frames = _read(out)
    means = [f.reshape(-1, 3).mean(0) for f in frames]
    for rgb in means[:2]:
        assert rgb[0] > 180 and rgb[1] < 60 and rgb[2] < 60, rgb
    assert (means[2] > 235).all(), means[2]


def test_gif_and_png_sequences(tmp_path, face_of, short_clip):
    gif = animate(short_clip, tmp_path / "clip.gif", face=face_of("ava"), size=48)
    with Image.open(gif) as im:
        assert im.n_frames == 6 and im.size == (48, 48)
        total = 0
        for i in range(im.n_frames):
            im.seek(i)
            total += im.info["duration"]
        assert total == pytest.approx(500, abs=10)  # 6 frames at 12 fps, in whole centiseconds
    folder = animate(short_clip, tmp_path / "frames", face=face_of("ava"), size=48)
    names = sorted(p.name for p in folder.iterdir())
    assert names == [f"frame_{i:05d}.png" for i in range(6)]


def test_audio_track_is_muxed(tmp_path, face_of, short_clip):
    wav = tmp_path / "tone.wav"
    ffmpeg = imageio_ffmpeg.get_ffmpeg_exe()
    subprocess.run([ffmpeg, "-v", "error", "-f", "lavfi", "-i", "sine=frequency=440:duration=1", str(wav)], check=True)
    out = animate(short_clip, tmp_path / "talk.mp4", face=face_of("ava"), size=64, audio=wav)
    probe = subprocess.run([ffmpeg, "-i", str(out)], capture_output=True, text=True).stderr
    assert "Audio: aac" in probe and "Video: h264" in probe


def test_a_failed_render_leaves_nothing(tmp_path):
    with pytest.raises(ValueError, match="frames must be"):
        with VideoWriter(tmp_path / "x.mp4", 10) as writer:
            writer.append(np.zeros((8, 8), np.uint8))
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("name, message", [("x.avi", "unknown video format"), ("x.mp4", "fps must be > 0")])
def test_bad_outputs_are_refused(tmp_path, name, message):
    with pytest.raises(ValueError, match=message):
        VideoWriter(tmp_path / name, 0 if name.endswith("mp4") else 30)
    assert video_format(tmp_path / "frames") == "png"


def test_muscle_state_or_registers_reproduce_the_same_video(tmp_path, face_of, short_clip):
    a = animate(short_clip, tmp_path / "a", face=face_of("ava"), size=48)
    b = animate(short_clip, tmp_path / "b", face=face_of("ava"), size=48)
    for fa, fb in zip(sorted(a.iterdir()), sorted(b.iterdir())):
        assert np.array_equal(np.asarray(Image.open(fa)), np.asarray(Image.open(fb)))


def test_cli_emotion_and_animate(tmp_path):
    def run(*args):
        return subprocess.run([sys.executable, "-m", "facsim.cli", *args], capture_output=True, text=True, cwd=tmp_path)
    r = run("emotion", "surprise", "--intensity", "50%", "--onset", "0.2", "--apex", "0.1", "--offset", "0.2",
            "--fps", "10", "--size", "48", "-o", "s.mp4", "--quiet", "--save-timeline", "s.yaml")
    assert r.returncode == 0, r.stderr
    assert len(_read(tmp_path / "s.mp4")[1]) == 5
    r = run("animate", "s.yaml", "-o", "s.gif", "--size", "32", "--quiet")
    assert r.returncode == 0, r.stderr
    r = run("render", "--timeline", "s.yaml", "--time", "0.2", "-o", "apex.png", "--size", "32")
    assert r.returncode == 0, r.stderr
    r = run("plot", "s.yaml", "-o", "s.svg")
    assert r.returncode == 0 and (tmp_path / "s.svg").read_text().startswith("<?xml")
    (tmp_path / "bad.yaml").write_text("tracks:\n  - au: 12\n    start: 2\n    end: 1\n")
    r = run("animate", "bad.yaml", "-o", "bad.mp4")
    assert r.returncode == 2 and "tracks[0]" in r.stderr and "Traceback" not in r.stderr
    assert not (tmp_path / "bad.mp4").exists()
    r = run("render", "--timeline", "s.yaml", "--time", "9", "-o", "late.png")
    assert r.returncode == 2 and "outside the timeline" in r.stderr


def test_progress_into_a_log_writes_a_line_per_tenth(capsys):
    from facsim.cli.progress import Progress

    bar = Progress(90)
    for done in range(1, 91):
        bar.update(done)
    lines = capsys.readouterr().err.strip().splitlines()
    assert len(lines) == 10 and lines[-1].endswith("fps") and "90/90 frames" in lines[-1]
    silent = Progress(90, enabled=False)
    silent.update(90)
    assert capsys.readouterr().err == ""


# ------------------------------------------------ safety of outputs (issue 12) ---

def _cli(tmp_path, *args, **kw):
    return subprocess.run([sys.executable, "-m", "facsim", *args], capture_output=True, text=True, cwd=tmp_path, **kw)


def _one_line_error(r, code=2):
    lines = r.stderr.strip().splitlines()
    return r.returncode == code and len(lines) == 1 and lines[0].startswith("facsim: error:")


def test_cli_never_replaces_a_folder_it_did_not_make(tmp_path, short_clip):
    from facsim.timeline.io import save_timeline

    save_timeline(short_clip, tmp_path / "t.yaml")
    (tmp_path / "shots").mkdir()
    (tmp_path / "shots" / "a.jpg").write_text("a photo")
    for extra in ([], ["--overwrite"]):
        r = _cli(tmp_path, "animate", "t.yaml", "-o", "shots.png", "--size", "32", "--quiet", *extra)
        assert _one_line_error(r) and "shots is a folder holding files facsim did not write (a.jpg)" in r.stderr
    r = _cli(tmp_path, "animate", "t.yaml", "-o", ".", "--size", "32", "--quiet", "--overwrite")
    assert _one_line_error(r) and "current folder" in r.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["shots", "t.yaml"]
    assert [p.name for p in (tmp_path / "shots").iterdir()] == ["a.jpg"]


def test_frames_replace_facsims_own_frames_only_with_overwrite(tmp_path, face_of, short_clip):
    from facsim.atomic import OutputError, overwriting

    folder = animate(short_clip, tmp_path / "frames", face=face_of("ava"), size=32)
    with pytest.raises(OutputError, match="already holds 6 frames; use --overwrite"):
        animate(short_clip, folder, face=face_of("ava"), size=32)
    with overwriting():
        animate(short_clip, folder, face=face_of("ava"), size=32)
    assert len(list(folder.iterdir())) == 6 and [p.name for p in tmp_path.iterdir()] == ["frames"]


def test_audio_that_is_not_sound_fails_in_one_line_and_leaves_nothing(tmp_path, short_clip):
    from facsim.timeline.io import save_timeline

    save_timeline(short_clip, tmp_path / "t.yaml")
    (tmp_path / "not-really.wav").write_text("not sound at all\n")
    r = _cli(tmp_path, "animate", "t.yaml", "-o", "x.mp4", "--size", "32", "--quiet", "--audio", "not-really.wav")
    assert _one_line_error(r) and "not-really.wav is not sound" in r.stderr and "wrote" not in r.stdout
    assert sorted(p.name for p in tmp_path.iterdir()) == ["not-really.wav", "t.yaml"]


def test_audio_shorter_than_the_video_is_an_error_not_a_cut_video(tmp_path):
    wav = tmp_path / "short.wav"
    subprocess.run([imageio_ffmpeg.get_ffmpeg_exe(), "-v", "error", "-f", "lavfi", "-i", "sine=duration=0.2",
                    str(wav)], check=True)
    frame = np.zeros((16, 16, 3), np.uint8)
    with pytest.raises(ValueError, match="short.wav is shorter than the video"):
        with VideoWriter(tmp_path / "x.mp4", 10, audio=wav) as writer:
            for i in range(300):  # 30 s: ffmpeg stops taking frames once the sound ends
                writer.append(frame + i % 200)
    assert [p.name for p in tmp_path.iterdir()] == ["short.wav"]


def test_a_file_missing_frames_is_not_reported_as_written(tmp_path, monkeypatch):
    import facsim.media.video as video

    monkeypatch.setattr(video, "count_frames", lambda path: 2)  # as if the muxer had dropped frames
    with pytest.raises(video.VideoError, match=r"x.webm: it holds 2 of 3 frames"):
        with VideoWriter(tmp_path / "x.webm", 10) as writer:
            for _ in range(3):
                writer.append(np.zeros((16, 16, 3), np.uint8))
    assert list(tmp_path.iterdir()) == []


def test_a_signal_that_c_code_turned_into_another_error_still_reads_as_an_interruption(monkeypatch, capsys):
    """numpy turns a KeyboardInterrupt raised inside a structured-array comparison into a
    TypeError; the test below then saw 'internal error' and exit 1 once in a few dozen runs."""
    import argparse
    import os
    import signal
    import time

    import facsim.cli as cli

    def command(args):
        try:
            os.kill(os.getpid(), signal.SIGTERM)
            time.sleep(5)  # the handler raises KeyboardInterrupt here
        except KeyboardInterrupt:
            raise TypeError("Cannot compare structured arrays unless they have a common dtype") from None

    parser = argparse.ArgumentParser()
    parser.set_defaults(handler=command)
    monkeypatch.setattr(cli, "build_parser", lambda: parser)
    handlers = {signum: signal.getsignal(signum) for signum in (signal.SIGTERM, signal.SIGHUP)}
    try:
        assert cli.main([]) == 128 + signal.SIGTERM
    finally:
        for signum, handler in handlers.items():
            signal.signal(signum, handler)
    assert "interrupted (SIGTERM)" in capsys.readouterr().err


def test_a_signal_during_a_dataclass_definition_still_exits_with_its_status(tmp_path):
    """A signal that lands while a lazily imported module defines a dataclass raises its
    KeyboardInterrupt inside exec(); CPython then ended the process by SIGINT (status -2) though
    the command had caught it (the SIGHUP test below failed so once in ~20 runs under load)."""
    (tmp_path / "interrupted_cli.py").write_text(
        "import argparse, sys\n"
        "import facsim.cli as cli\n"
        "def command(args):\n"
        "    exec('raise KeyboardInterrupt')  # where dataclasses' exec() would have been\n"
        "parser = argparse.ArgumentParser()\n"
        "parser.set_defaults(handler=command)\n"
        "cli.build_parser = lambda: parser\n"
        "sys.exit(cli.main([]))\n")
    done = subprocess.run([sys.executable, "-m", "interrupted_cli"], cwd=tmp_path, capture_output=True, text=True,
                          env={**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)}, timeout=60)
    assert done.returncode == 130, done.stderr
    assert done.stderr.strip() == "facsim: interrupted (SIGINT); nothing was left half-written"


@pytest.mark.parametrize("signame, output", [("SIGTERM", "long.mp4"), ("SIGHUP", "frames")])
def test_sigterm_and_sighup_leave_no_debris(tmp_path, signame, output):
    import signal
    import time

    (tmp_path / "t.yaml").write_text("fps: 25\nduration: 120\ntracks:\n  - au: 12\n    start: 0\n    end: 120\n")
    # PYTHONFAULTHANDLER: once in ~20 runs under load the process died of SIGSEGV while unwinding
    # (session 15, not reproduced since); if it happens again, the assertion shows where.
    proc = subprocess.Popen([sys.executable, "-m", "facsim", "animate", "t.yaml", "-o", output, "--size", "16",
                             "--quiet"], cwd=tmp_path, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            env={**os.environ, "PYTHONFAULTHANDLER": "1"})
    deadline = time.monotonic() + 120
    while not any(".part" in p.name for p in tmp_path.iterdir()):
        assert proc.poll() is None and time.monotonic() < deadline, proc.communicate()
        time.sleep(0.05)
    time.sleep(0.5)  # frames are flowing
    proc.send_signal(getattr(signal, signame))
    out, err = proc.communicate(timeout=60)
    assert proc.returncode == 128 + getattr(signal, signame), err
    assert err.strip().splitlines() == [f"facsim: interrupted ({signame}); nothing was left half-written"]
    assert [p.name for p in tmp_path.iterdir()] == ["t.yaml"]


def test_gif_memory_is_flat_in_the_videos_length(tmp_path):
    import tracemalloc

    frame_bytes = 64 * 64 * 4
    frames = [np.full((64, 64, 4), (i * 7 % 256, 90, 200 - i % 150, 255), np.uint8) for i in range(8)]
    tracemalloc.start()
    try:
        with VideoWriter(tmp_path / "long.gif", 25) as writer:
            for i in range(600):  # 24 s; a GIF holding every frame would need 600 frames' worth
                writer.append(frames[i % 8].copy())  # a new array each time, as a renderer gives
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 40 * frame_bytes, peak
    with Image.open(tmp_path / "long.gif") as im:
        assert im.n_frames == 600 and im.size == (64, 64)


@pytest.mark.parametrize("suffix", [".webm", ".mp4", ".gif"])
def test_identical_frames_give_byte_identical_files(tmp_path, suffix):
    rng = np.random.default_rng(3)
    frames = [rng.integers(0, 256, (32, 32, 3), np.uint8) for _ in range(5)]
    for name in ("a", "b"):
        with VideoWriter(tmp_path / f"{name}{suffix}", 10) as writer:
            for frame in frames:
                writer.append(frame)
    assert (tmp_path / f"a{suffix}").read_bytes() == (tmp_path / f"b{suffix}").read_bytes()
