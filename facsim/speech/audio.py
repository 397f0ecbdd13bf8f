"""Audio in and out: WAV reading (any rate, channels, sample format), resampling, mixing, writing.

Examples
--------
>>> x = np.sin(np.linspace(0, 100, 48000)).astype(np.float32)
>>> resample(x, 48000, 16000).shape
(16000,)
"""
from __future__ import annotations

from math import gcd
from pathlib import Path

import numpy as np


#: Rate of audio decoded by ffmpeg (formats other than plain WAV).
DECODE_RATE = 48000


def read_wav(path) -> tuple[np.ndarray, int]:
    """Mono float32 samples in [-1, 1] and the sample rate of an audio file.

    WAV is read directly (several channels are averaged); other formats ffmpeg
    knows (MP3, M4A, FLAC, Ogg) are decoded at 48 kHz. Raises ``ValueError``
    naming the file when it cannot be read.
    """
    from scipy.io import wavfile

    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"audio file {path} does not exist")
    try:
        rate, data = wavfile.read(path)
    except (ValueError, EOFError):
        # Not a WAV scipy reads (MP3, M4A, FLAC, Ogg, 24-bit WAV...): let ffmpeg decode it.
        try:
            return decode_audio(path, DECODE_RATE), DECODE_RATE
        except ValueError:
            raise ValueError(f"{path}: not a readable audio file; give a WAV (or any format ffmpeg "
                             "reads)") from None
    data = np.asarray(data)
    if data.dtype.kind == "i":
        samples = data.astype(np.float32) / float(-np.iinfo(data.dtype).min)
    elif data.dtype.kind == "u":
        info = np.iinfo(data.dtype)
        samples = (data.astype(np.float32) - (info.max + 1) / 2) / ((info.max + 1) / 2)
    else:
        samples = data.astype(np.float32)
    if samples.ndim == 2:
        samples = samples.mean(axis=1)
    if samples.size == 0:
        raise ValueError(f"{path}: the audio file has no samples")
    return np.clip(samples, -1.0, 1.0), int(rate)


def resample(samples: np.ndarray, rate: int, target: int) -> np.ndarray:
    """``samples`` at ``rate`` resampled to ``target`` Hz (polyphase, anti-aliased)."""
    if rate == target:
        return np.asarray(samples, np.float32)
    from scipy.signal import resample_poly

    g = gcd(int(rate), int(target))
    return resample_poly(samples, target // g, rate // g).astype(np.float32)


def to_pcm16(samples: np.ndarray) -> np.ndarray:
    """Float samples → int16 (clipped, rounded)."""
    return np.round(np.clip(samples, -1.0, 1.0) * 32767.0).astype(np.int16)


def write_wav(path, samples: np.ndarray, rate: int) -> Path:
    """Write 16-bit mono PCM atomically."""
    from scipy.io import wavfile

    from facsim.atomic import atomic_write

    pcm = to_pcm16(samples)
    return atomic_write(path, lambda tmp: wavfile.write(tmp, int(rate), pcm))


def mix(placed, duration: float, rate: int) -> np.ndarray:
    """Sum ``(start_seconds, samples, samples_rate)`` clips into one track of ``duration`` seconds.

    Clips are resampled to ``rate``; anything past ``duration`` is cut; overlaps
    add (clipped to [-1, 1]).

    Examples
    --------
    >>> out = mix([(0.5, np.ones(8, np.float32), 8)], 2.0, 8)
    >>> out.tolist()
    [0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 0.0, 0.0, 0.0, 0.0]
    """
    total = int(round(duration * rate))
    out = np.zeros(total, np.float32)
    for start, samples, clip_rate in placed:
        clip = resample(samples, clip_rate, rate)
        first = int(round(start * rate))
        if first >= total:
            continue
        clip = clip[: total - first]
        out[first:first + clip.size] += clip
    return np.clip(out, -1.0, 1.0)


def rms(samples: np.ndarray) -> float:
    """Root mean square level."""
    samples = np.asarray(samples, np.float64)
    return float(np.sqrt(np.mean(samples ** 2))) if samples.size else 0.0


def decode_audio(path, rate: int = 16000) -> np.ndarray:
    """The sound track of any media file ffmpeg reads (MP4, WebM, WAV...), mono float32 at ``rate``."""
    import subprocess

    import imageio_ffmpeg

    run = subprocess.run([imageio_ffmpeg.get_ffmpeg_exe(), "-v", "error", "-i", str(path), "-vn", "-ac", "1",
                          "-ar", str(rate), "-f", "s16le", "-"], capture_output=True)
    if run.returncode != 0 or not run.stdout:
        raise ValueError(f"{path}: cannot read its audio ({run.stderr.decode(errors='replace').strip()[:200]})")
    return np.frombuffer(run.stdout, np.int16).astype(np.float32) / 32768.0


def audio_offset(signal: np.ndarray, reference: np.ndarray, rate: int, start: float = 0.0) -> float:
    """Seconds by which ``signal`` lags ``reference`` placed at ``start`` (cross-correlation peak).

    Examples
    --------
    >>> ref = np.random.default_rng(0).standard_normal(800).astype(np.float32)
    >>> round(audio_offset(np.concatenate([np.zeros(80, np.float32), ref]), ref, 8000), 4)
    0.01
    """
    from scipy.signal import correlate

    placed = np.zeros(len(signal), np.float32)
    first = int(round(start * rate))
    clip = reference[: max(0, len(signal) - first)]
    placed[first:first + len(clip)] = clip
    corr = correlate(signal, placed, mode="full", method="fft")
    return (int(np.argmax(corr)) - (len(placed) - 1)) / rate
