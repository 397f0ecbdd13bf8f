"""Text → speech audio with the synthesiser's own phone timings.

Default engine: Debian's ``flite`` (BSD-style licence), run as a process:
``flite -voice slt -psdur -t TEXT -o out.wav`` writes 16 kHz audio and prints
each phone's end time. Built-in voices: ``slt`` (female US), ``awb`` (male
Scottish), ``rms`` (male US), ``kal16`` (male US, diphone), ``kal`` (8 kHz).

Optional: Piper (``piper:NAME``), GPL-3.0, so it only ever runs as a separate
Python process (``piper-tts`` and a voice package must be installed by the
user); its per-phoneme alignments tile the audio exactly. facsim never imports it.

Examples
--------
>>> utterance = synthesize("Hello.", voice="slt")          # doctest: +SKIP
>>> [p.name for p in utterance.phones][:3]                 # doctest: +SKIP
['pau', 'hh', 'ax']
"""
from __future__ import annotations

import shutil
import subprocess
import tempfile
from functools import lru_cache
from pathlib import Path

from .audio import read_wav
from .utterance import Utterance, phones_from_ends

FLITE_VOICES = ("slt", "awb", "rms", "kal16", "kal")
DEFAULT_VOICE = "slt"
#: Longest text one call speaks (flite holds it all in memory; a video of it would be hours long).
MAX_TEXT = 5000


def voice_names() -> tuple[str, ...]:
    """Voices accepted by ``--voice`` (``piper:NAME`` besides)."""
    return (*FLITE_VOICES, "piper:NAME")


def check_voice(voice: str) -> str:
    """``voice`` if it names a voice, else a ``ValueError`` listing the choices."""
    if not isinstance(voice, str) or not (voice in FLITE_VOICES or (voice.startswith("piper:") and len(voice) > 6)):
        raise ValueError(f"unknown voice {voice!r}; choose one of {', '.join(voice_names())}")
    return voice


def check_text(text) -> str:
    if not isinstance(text, str) or not text.strip():
        raise ValueError("nothing to say: the text is empty")
    if len(text) > MAX_TEXT:
        raise ValueError(f"the text is {len(text)} characters long; at most {MAX_TEXT} are spoken at once")
    if any(ord(c) < 32 and c not in "\t\n\r" for c in text):
        raise ValueError("the text contains control characters")
    return " ".join(text.split())


def synthesize(text: str, voice: str = DEFAULT_VOICE) -> Utterance:
    """Speak ``text`` with ``voice``: audio plus the synthesiser's phone timings.

    The same text and voice always give the same samples (results are cached per process).

    Raises
    ------
    ValueError
        Empty or over-long text, unknown voice.
    RuntimeError
        The synthesiser is not installed or failed; the message says how to fix it.
    """
    return _synthesize(check_text(text), check_voice(voice))


@lru_cache(maxsize=64)
def _synthesize(text: str, voice: str) -> Utterance:
    if voice.startswith("piper:"):
        return _piper(text, voice[len("piper:"):])
    return _flite(text, voice)


def _flite(text: str, voice: str) -> Utterance:
    exe = shutil.which("flite")
    if exe is None:
        raise RuntimeError("flite is not installed; run install.sh (or apt-get install flite)")
    with tempfile.TemporaryDirectory(prefix="facsim-flite-") as tmp:
        wav = Path(tmp) / "speech.wav"
        # -psdur prints "phone:end" pairs; -t takes the next argument as text even if it starts with "-".
        run = subprocess.run([exe, "-voice", voice, "-psdur", "-t", text, "-o", str(wav)],
                             capture_output=True, text=True, timeout=300)
        if run.returncode != 0 or not wav.is_file():
            raise RuntimeError(f"flite failed for voice {voice!r}: {(run.stderr or run.stdout).strip()[:200]}")
        samples, rate = read_wav(wav)
    pairs = []
    for token in run.stdout.split():
        name, sep, end = token.rpartition(":")
        if not sep:
            continue
        try:
            pairs.append((name, float(end)))
        except ValueError:
            continue
    if not pairs:
        raise RuntimeError(f"flite printed no phone timings for voice {voice!r}")
    return Utterance(samples, rate, phones_from_ends(pairs, len(samples) / rate), text=text, source=f"flite:{voice}")


# Runs in a separate Python process: Piper is GPL-3.0 and must not be imported into facsim.
_PIPER_SCRIPT = r"""
import json, sys, wave
from piper import PiperVoice
voice = PiperVoice.load(sys.argv[1])
text = sys.stdin.read()
phones, rate, samples = [], voice.config.sample_rate, 0
with wave.open(sys.argv[2], "wb") as out:
    out.setnchannels(1); out.setsampwidth(2); out.setframerate(rate)
    for chunk in voice.synthesize(text, include_alignments=True):
        out.writeframes(chunk.audio_int16_bytes)
        for a in chunk.phoneme_alignments or ():
            samples += a.num_samples
            phones.append([a.phoneme, samples / rate])
print(json.dumps(phones))
"""


def _piper(text: str, name: str) -> Utterance:
    import json
    import sys

    from .utterance import Phone

    with tempfile.TemporaryDirectory(prefix="facsim-piper-") as tmp:
        wav = Path(tmp) / "speech.wav"
        try:
            run = subprocess.run([sys.executable, "-c", _PIPER_SCRIPT, name, str(wav)], input=text,
                                 capture_output=True, text=True, timeout=600)
        except OSError as exc:
            raise RuntimeError(f"could not start Piper: {exc}") from None
        if run.returncode != 0:
            if "No module named 'piper'" in run.stderr:
                raise RuntimeError("voice piper:NAME needs Piper, which is not installed (GPL-3.0, optional): "
                                   "pip install piper-tts and a voice (an .onnx model path as NAME)")
            raise RuntimeError(f"Piper failed for voice {name!r}: {run.stderr.strip().splitlines()[-1:]}")
        samples, rate = read_wav(wav)
    # Piper phonemes are IPA; they drive the mouth through the IPA column of the viseme table.
    ends = json.loads(run.stdout)
    phones, start = [], 0.0
    for phoneme, end in ends:
        if end > start:
            phones.append(Phone(_ipa_to_arpabet(phoneme), start, end))
            start = end
    return Utterance(samples, rate, tuple(phones), text=text, source=f"piper:{name}")


#: IPA (espeak-ng, as Piper emits) → ARPAbet, for the phones the viseme table knows.
_IPA = {
    "p": "p", "b": "b", "m": "m", "f": "f", "v": "v", "θ": "th", "ð": "dh", "t": "t", "d": "d",
    "k": "k", "ɡ": "g", "g": "g", "ŋ": "ng", "h": "hh", "tʃ": "ch", "dʒ": "jh", "ʃ": "sh", "ʒ": "zh",
    "s": "s", "z": "z", "n": "n", "l": "l", "ɹ": "r", "r": "r", "ɚ": "er", "ɜ": "er", "w": "w", "j": "y",
    "ɑ": "aa", "æ": "ae", "ʌ": "ah", "ə": "ax", "ɛ": "eh", "e": "ey", "ɪ": "ih", "i": "iy", "ɔ": "ao",
    "o": "ow", "ʊ": "uh", "u": "uw", "a": "aa", "ɐ": "ah", " ": "pau", "_": "pau", "^": "pau", "$": "pau",
}


def _ipa_to_arpabet(phoneme: str) -> str:
    return _IPA.get(phoneme.strip("ːˈˌ"), "pau")
