"""Recorded speech → phone timings by forced alignment (pocketsphinx, BSD).

The ``pocketsphinx`` wheel ships the US-English acoustic model, the CMU
pronouncing dictionary and a language model; alignment runs offline:
``set_align_text`` → decode → ``set_alignment`` → decode → ``get_alignment``
(two passes: words, then phones within them). Audio is resampled to 16 kHz mono.

Examples
--------
>>> u = align_recording("talk.wav", "Pack my box.")       # doctest: +SKIP
>>> [p.name for p in u.speech_phones][:4]                  # doctest: +SKIP
['p', 'ae', 'k', 'm']
"""
from __future__ import annotations

import re
from functools import lru_cache
from pathlib import Path

import numpy as np

from .audio import read_wav, resample
from .utterance import SILENCE, Phone, Utterance, normalise_phone

ALIGN_RATE = 16000
#: pocketsphinx's frame rate (frames per second).
FRAMES_PER_SECOND = 100


def _words(transcript: str) -> list[str]:
    words = re.findall(r"[a-z0-9']+", transcript.lower())
    if not words:
        raise ValueError("the transcript has no words to align; give the words spoken in the recording")
    return words


@lru_cache(maxsize=1)
def _decoder():
    try:
        from pocketsphinx import Decoder, get_model_path
    except ImportError:
        raise RuntimeError("aligning a recording needs pocketsphinx: pip install 'facsim[speech]' "
                           "(pocketsphinx==5.1.1)") from None
    model = Path(get_model_path())
    return Decoder(hmm=str(model / "en-us" / "en-us"), dict=str(model / "en-us" / "cmudict-en-us.dict"),
                   samprate=ALIGN_RATE, loglevel="FATAL", lm=None)


def align_recording(path, transcript: str) -> Utterance:
    """Phone timings of the speech in WAV file ``path`` saying ``transcript``.

    Raises
    ------
    ValueError
        Unreadable audio, an empty transcript, a word the dictionary lacks, or
        audio the transcript cannot be aligned to.
    """
    samples, rate = read_wav(path)
    return align_samples(samples, rate, transcript, source=f"recording:{Path(path).name}")


def align_samples(samples: np.ndarray, rate: int, transcript: str, *, source: str = "recording") -> Utterance:
    """:func:`align_recording` on samples already in memory."""
    words = _words(transcript)
    decoder = _decoder()
    unknown = [w for w in words if decoder.lookup_word(w) is None]
    if unknown:
        raise ValueError(f"the pronouncing dictionary lacks {', '.join(map(repr, unknown))}; "
                         "spell those words out or write them as dictionary words")
    mono16 = resample(samples, rate, ALIGN_RATE)
    pcm = np.round(np.clip(mono16, -1, 1) * 32767).astype(np.int16).tobytes()
    decoder.set_align_text(" ".join(words))
    decoder.start_utt()
    decoder.process_raw(pcm, full_utt=True)
    decoder.end_utt()
    if decoder.hyp() is None:
        raise ValueError(f"{source}: could not align the transcript to the audio (is it the right recording?)")
    decoder.set_alignment()
    decoder.start_utt()
    decoder.process_raw(pcm, full_utt=True)
    decoder.end_utt()
    duration = len(samples) / rate
    phones: list[Phone] = []
    t = 0.0
    for word in decoder.get_alignment():
        for seg in word:
            start = seg.start / FRAMES_PER_SECOND
            end = min((seg.start + seg.duration) / FRAMES_PER_SECOND, duration)
            if start > t + 1e-9:
                phones.append(Phone(SILENCE, t, start))
            if end > start:
                phones.append(Phone(normalise_phone(seg.name), round(start, 6), round(end, 6)))
                t = end
    if t < duration - 1e-6:
        phones.append(Phone(SILENCE, t, duration))
    phones = _trim_to_voice(_merge_silences(phones), samples, rate)
    return Utterance(samples, rate, tuple(phones), text=" ".join(transcript.split()), source=source)


def _merge_silences(phones: list[Phone]) -> list[Phone]:
    out: list[Phone] = []
    for p in phones:
        if out and p.silent and out[-1].silent:
            out[-1] = Phone(SILENCE, out[-1].start, p.end)
        else:
            out.append(p)
    return out


#: Voice onset: the first 10-ms frame louder than this (dB below the loudest frame).
VOICE_THRESHOLD_DB = 30.0
STOPS = frozenset({"p", "b", "t", "d", "k", "g"})
#: Typical stop closure before the burst (s).
STOP_CLOSURE = 0.06


def _trim_to_voice(phones: list[Phone], samples: np.ndarray, rate: int) -> list[Phone]:
    """Give leading and trailing silence back to ``pau``.

    pocketsphinx's alignment grammar has no optional silence before the first
    word, so the first phone absorbs any silence that opens the recording (and
    the mouth would move too early). The first and last phones are cut to where
    the signal rises above the loudest 10-ms frame minus ``VOICE_THRESHOLD_DB``.
    """
    hop = max(1, rate // FRAMES_PER_SECOND)
    n = len(samples) // hop
    if n == 0 or not phones:
        return phones
    frames = np.sqrt(np.mean(np.asarray(samples[: n * hop], np.float64).reshape(n, hop) ** 2, axis=1))
    loud = np.flatnonzero(frames > frames.max() * 10 ** (-VOICE_THRESHOLD_DB / 20))
    if loud.size == 0:
        return phones
    onset, offset = float(loud[0] * hop / rate), float((loud[-1] + 1) * hop / rate)
    out = list(phones)
    first = next((i for i, p in enumerate(out) if not p.silent), None)
    if first is not None:
        # A stop's closure is silent: it starts before the burst that is heard.
        lead = STOP_CLOSURE if out[first].name in STOPS else 0.02
        if out[first].start < onset - lead < out[first].end - 0.03:
            p = out[first]
            out[first] = Phone(p.name, round(onset - lead, 6), p.end)
            out.insert(first, Phone(SILENCE, p.start, round(onset - lead, 6)))
    last = next((i for i in range(len(out) - 1, -1, -1) if not out[i].silent), None)
    if last is not None and out[last].start + 0.03 < offset + 0.02 < out[last].end:
        p = out[last]
        out[last] = Phone(p.name, p.start, round(offset + 0.02, 6))
        out.insert(last + 1, Phone(SILENCE, round(offset + 0.02, 6), p.end))
    return _merge_silences(out)
