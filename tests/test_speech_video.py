"""Speech in timelines and videos: the track format, audio muxed in sync, exports carry the speech."""
from __future__ import annotations

import numpy as np
import pytest

from facsim.speech.audio import audio_offset, decode_audio, resample, rms
from facsim.speech.synth import synthesize
from facsim.timeline.io import load_timeline, save_timeline, timeline_from_dict, timeline_to_dict
from facsim.timeline.model import TimelineError
from facsim.timeline.sampling import frame_count, sample

TEXT = "Pack my box."
FPS = 30.0


@pytest.fixture(scope="module")
def speech_yaml(tmp_path_factory):
    folder = tmp_path_factory.mktemp("speech")
    path = folder / "talk.yaml"
    path.write_text(f"""
fps: 30
tracks:
  - emotion: happiness
    start: 0
    end: 1.2
    intensity: 70%
  - say: "{TEXT}"
    start: 0.25
    voice: slt
""")
    return path


def test_speech_track_reads_samples_and_round_trips(speech_yaml, tmp_path):
    timeline = load_timeline(speech_yaml)
    speech = timeline.tracks[1]
    u = synthesize(TEXT)
    assert timeline.length == pytest.approx(0.25 + u.duration)
    b = 0.25 + u.phones_named("b")[0].middle
    act = sample(timeline, b)
    assert act[24, "left"] >= 0.69 and act[26, "left"] < 1e-3      # speech closes the lips ...
    assert act[12, "left"] == pytest.approx(0.7)                   # ... the smile stays
    assert sample(timeline, 0.0)[25, "left"] == pytest.approx(0.7)  # before speech: the emotion's mouth
    assert timeline_from_dict(timeline_to_dict(timeline)) == timeline
    save_timeline(timeline, tmp_path / "again.json")
    assert load_timeline(tmp_path / "again.json") == timeline
    assert speech.label == f'say "{TEXT}"'


def test_recording_track_path_is_relative_to_the_timeline_file(tmp_path):
    from facsim.speech.audio import write_wav

    u = synthesize(TEXT)
    write_wav(tmp_path / "me.wav", u.samples, u.rate)
    (tmp_path / "rec.yaml").write_text(f'tracks:\n  - audio: me.wav\n    transcript: "{TEXT}"\n')
    timeline = load_timeline(tmp_path / "rec.yaml")
    b = timeline.tracks[0].utterance.phones_named("b")[0].middle
    assert sample(timeline, b)[24, "left"] >= 0.69


@pytest.mark.parametrize("track, where, message", [
    ({"say": "Hi.", "audio": "x.wav"}, "tracks[0]", "takes 'say'"),
    ({"audio": "x.wav"}, "tracks[0]", "with 'transcript'"),
    ({"say": "Hi.", "voice": "bob"}, "tracks[0].voice", "unknown voice 'bob'"),
    ({"say": "Hi.", "start": -1}, "tracks[0].start", "negative time"),
    ({"say": "Hi.", "speed": 2}, "tracks[0]", "unknown field 'speed'"),
    ({"audio": "nope.wav", "transcript": "hi"}, "tracks[0].audio", "does not exist"),
])
def test_bad_speech_tracks_are_named(track, where, message):
    with pytest.raises(TimelineError, match=message) as info:
        timeline_from_dict({"tracks": [track]})
    assert str(info.value).startswith(where)


@pytest.fixture(scope="module")
def talk_mp4(speech_yaml, tmp_path_factory, face_of):
    from facsim.pipeline import animate

    out = tmp_path_factory.mktemp("video") / "talk.mp4"
    animate(load_timeline(speech_yaml), out, face=face_of("ava"), size=(96, 96))
    return out


def test_video_has_the_speech_audio_in_sync(talk_mp4, speech_yaml):
    import imageio.v3 as iio

    frames = sum(1 for _ in iio.imiter(talk_mp4))
    timeline = load_timeline(speech_yaml)
    assert frames == frame_count(timeline)
    audio = decode_audio(talk_mp4)
    assert abs(len(audio) / 16000 - frames / FPS) <= 1 / FPS          # same length within a frame
    u = synthesize(TEXT)
    reference = resample(u.samples, u.rate, 16000)
    assert abs(audio_offset(audio, reference, 16000, start=0.25)) <= 0.005   # no offset
    assert rms(audio) == pytest.approx(rms(reference) * len(reference) ** 0.5 / len(audio) ** 0.5, rel=0.1)


def test_same_timeline_same_bytes(talk_mp4, speech_yaml, face_of, tmp_path):
    from facsim.pipeline import animate

    again = animate(load_timeline(speech_yaml), tmp_path / "again.mp4", face=face_of("ava"), size=(96, 96))
    assert again.read_bytes() == talk_mp4.read_bytes()


def test_webm_gets_opus_and_png_frames_get_a_wav_beside(speech_yaml, tmp_path, face_of):
    import imageio_ffmpeg
    import subprocess

    from facsim.speech.audio import read_wav
    from facsim.pipeline import animate

    timeline = load_timeline(speech_yaml)
    webm = animate(timeline, tmp_path / "talk.webm", face=face_of("ava"), size=(64, 64))
    probe = subprocess.run([imageio_ffmpeg.get_ffmpeg_exe(), "-i", str(webm)], capture_output=True, text=True)
    assert "Audio: opus" in probe.stderr
    frames = animate(timeline, tmp_path / "frames", face=face_of("ava"), size=(64, 64))
    samples, rate = read_wav(tmp_path / "frames.wav")
    assert len(list(frames.glob("*.png"))) == frame_count(timeline)
    assert len(samples) / rate == pytest.approx(frame_count(timeline) / FPS, abs=1 / rate)


def test_arkit_export_carries_the_speech(speech_yaml):
    import csv
    import io

    from facsim.exchange.arkit import dumps_arkit_csv

    from facsim.timeline.model import Timeline

    def jaw(timeline):
        rows = list(csv.DictReader(io.StringIO(dumps_arkit_csv(timeline))))
        return np.array([float(r["JawOpen"]) for r in rows])

    talking = load_timeline(speech_yaml)
    silent = Timeline(talking.tracks[:1], duration=talking.length)
    assert jaw(talking).max() > jaw(silent).max() + 0.1      # the jaw moves with the words
    assert np.ptp(jaw(talking)) > 0.2


def test_speak_command(tmp_path, capsys):
    from facsim.cli import main

    out = tmp_path / "s.mp4"
    assert main(["speak", "Hi, Bob.", "-o", str(out), "--emotion", "happiness", "--intensity", "70%",
                 "--size", "64", "--quiet", "--save-timeline", str(tmp_path / "s.yaml")]) == 0
    assert out.is_file() and "Audio: aac" in _probe(out)
    timeline = load_timeline(tmp_path / "s.yaml")
    assert timeline.blinks is not None and [type(t).__name__ for t in timeline.tracks] == ["SpeechTrack", "Track"]
    assert main(["speak", "-o", str(tmp_path / "x.mp4")]) == 2
    assert main(["speak", "Hi.", "--voice", "bob", "-o", str(tmp_path / "x.mp4")]) == 2
    assert "unknown voice 'bob'" in capsys.readouterr().err
    assert not (tmp_path / "x.mp4").exists()


def _probe(path) -> str:
    import subprocess

    import imageio_ffmpeg

    return subprocess.run([imageio_ffmpeg.get_ffmpeg_exe(), "-i", str(path)], capture_output=True, text=True).stderr


def test_gltf_animation_carries_the_speech(speech_yaml, face_of):
    import json
    import struct

    from facsim.exchange.gltf import glb_bytes

    timeline = load_timeline(speech_yaml)
    data = glb_bytes(face_of("ava"), timeline, aus=[24, 26], normals=False)
    length = struct.unpack_from("<I", data, 12)[0]
    doc = json.loads(data[20:20 + length])
    binary = data[20 + length + 8:]
    channel = next(c for c in doc["animations"][0]["channels"] if c["target"]["path"] == "weights")
    accessor = doc["accessors"][doc["animations"][0]["samplers"][channel["sampler"]]["output"]]
    view = doc["bufferViews"][accessor["bufferView"]]
    start = view.get("byteOffset", 0) + accessor.get("byteOffset", 0)
    weights = np.frombuffer(binary, "<f4", accessor["count"], start).reshape(frame_count(timeline), -1)
    names = doc["meshes"][doc["nodes"][4]["mesh"]]["extras"]["targetNames"]
    au24 = weights[:, [i for i, n in enumerate(names) if n.startswith("AU24")]].max(axis=1)
    b = 0.25 + synthesize(TEXT).phones_named("b")[0].middle
    assert au24[int(round(b * FPS))] >= 0.6 and au24[0] < 0.01


def test_speak_a_recording(tmp_path):
    from facsim.cli import main
    from facsim.speech.audio import write_wav

    u = synthesize(TEXT)
    write_wav(tmp_path / "me.wav", u.samples, u.rate)
    out = tmp_path / "me.webm"
    assert main(["speak", "--audio", str(tmp_path / "me.wav"), "--transcript", TEXT, "-o", str(out),
                 "--size", "64", "--quiet", "--no-blinks"]) == 0
    audio = decode_audio(out)
    assert abs(audio_offset(audio, resample(u.samples, u.rate, 16000), 16000)) <= 0.005
    assert main(["speak", "--audio", str(tmp_path / "me.wav"), "-o", str(tmp_path / "x.mp4")]) == 2
    assert main(["speak", "Hi", "--transcript", "Hi", "-o", str(tmp_path / "x.mp4")]) == 2


def test_speech_example_validates_against_the_schema():
    from pathlib import Path

    import jsonschema
    import yaml

    from facsim.timeline.io import timeline_schema

    path = Path(__file__).resolve().parents[1] / "examples" / "speech" / "talk_with_emotion.yaml"
    jsonschema.Draft202012Validator(timeline_schema()).validate(yaml.safe_load(path.read_text()))
    timeline = load_timeline(path)
    assert timeline.tracks[2].end == pytest.approx(0.9 + synthesize("Pack my box with five dozen liquor jugs.").duration)


def test_facs_notation_carries_speech_tracks(speech_yaml, tmp_path):
    from facsim.exchange.notation_file import dumps_notation, loads_notation, read_notation
    from facsim.speech.audio import write_wav

    timeline = load_timeline(speech_yaml)
    text = dumps_notation(timeline)
    assert f'say "{TEXT}" voice=slt @0.25' in text
    assert loads_notation(text) == timeline
    u = synthesize(TEXT)
    write_wav(tmp_path / "me.wav", u.samples, u.rate)
    (tmp_path / "me.facs").write_text(f'facsim-notation 1\naudio me.wav "{TEXT}" @0.5\n')
    recording = read_notation(tmp_path / "me.facs")
    assert recording.tracks[0].audio == str(tmp_path / "me.wav") and recording.length > 1.0
