"""Check a `facsim speak` video: frames at chosen phones, audio length, loudness and sync.

    python scripts/check_speech_video.py s.mp4 "Pack my box with five dozen liquor jugs." --phones p b m

Prints each chosen phone's middle time and frame, the video's frame count and
length, the decoded audio's length and RMS, and the audio offset found by
cross-correlating the decoded track with the synthesised speech (0 = in sync).
Writes a contact sheet of the mouth at those frames beside the video.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))


def video_frames(path) -> tuple[list, float]:
    import imageio.v3 as iio

    frames = list(iio.imiter(path))
    fps = float(iio.immeta(path).get("fps", 30.0))
    return frames, fps


def main(argv=None) -> int:
    from PIL import Image

    from facsim.speech.audio import audio_offset, decode_audio, resample, rms
    from facsim.speech.synth import synthesize

    ap = argparse.ArgumentParser()
    ap.add_argument("video")
    ap.add_argument("text")
    ap.add_argument("--voice", default="slt")
    ap.add_argument("--start", type=float, default=0.0, help="when the speech starts in the video")
    ap.add_argument("--phones", nargs="+", default=["p", "b", "m"])
    args = ap.parse_args(argv)

    utterance = synthesize(args.text, args.voice)
    frames, fps = video_frames(args.video)
    audio = decode_audio(args.video)
    video_seconds = len(frames) / fps
    print(f"video: {len(frames)} frames at {fps:g} fps = {video_seconds:.4f} s")
    print(f"audio: {len(audio) / 16000:.4f} s decoded, RMS {rms(audio):.4f} "
          f"(synthesised: {utterance.duration:.4f} s, RMS {rms(utterance.samples):.4f})")
    print(f"audio - video length: {(len(audio) / 16000 - video_seconds) * 1000:+.1f} ms (one frame = {1000 / fps:.1f} ms)")
    offset = audio_offset(audio, resample(utterance.samples, utterance.rate, 16000), 16000, args.start)
    print(f"audio offset against the synthesised speech: {offset * 1000:+.1f} ms")
    h, w = frames[0].shape[:2]
    tiles = []
    for p in utterance.phones:
        if p.name not in args.phones:
            continue
        t = args.start + p.middle
        i = min(int(round(t * fps)), len(frames) - 1)
        print(f"/{p.name}/ {args.start + p.start:.3f}-{args.start + p.end:.3f} s, middle {t:.3f} s -> frame {i} ({i / fps:.3f} s)")
        tiles.append(frames[i][int(h * 0.55):int(h * 0.92), int(w * 0.25):int(w * 0.75), :3])
    if tiles:
        sheet = Path(args.video).with_suffix(".phones.png")
        Image.fromarray(np.concatenate(tiles, axis=1)).save(sheet)
        print(f"wrote {sheet}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
