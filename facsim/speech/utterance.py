"""Speech as data: audio samples with the phones they say and when.

An :class:`Utterance` is what every speech source produces (flite, Piper, a
recording aligned by pocketsphinx) and what the mouth animation consumes:
mono float samples at a rate, plus a time-ordered tuple of :class:`Phone`
intervals in CMU/ARPAbet (lower case, no stress digits, silence as ``pau``).

Examples
--------
>>> u = Utterance(np.zeros(1600, np.float32), 16000, (Phone("pau", 0.0, 0.05), Phone("m", 0.05, 0.1)), text="m")
>>> u.duration, [p.name for p in u.speech_phones]
(0.1, ['m'])
"""
from __future__ import annotations

import re
from dataclasses import dataclass

import numpy as np

#: Name of the silence phone after normalisation.
SILENCE = "pau"
_SILENCE_NAMES = {"pau", "sil", "h#", "sp", "<sil>", "</s>", "<s>"}


def normalise_phone(name: str) -> str:
    """A phone name in facsim's form: lower case ARPAbet, no stress digit; silences and noises → ``pau``.

    Examples
    --------
    >>> normalise_phone("AY1"), normalise_phone("SIL"), normalise_phone("+NSN+")
    ('ay', 'pau', 'pau')
    """
    text = name.strip().lower()
    if text in _SILENCE_NAMES or text.startswith("+") or text.startswith("["):
        return SILENCE
    return re.sub(r"\d+$", "", text)


@dataclass(frozen=True)
class Phone:
    """One phone from ``start`` to ``end`` seconds."""

    name: str
    start: float
    end: float

    @property
    def middle(self) -> float:
        return 0.5 * (self.start + self.end)

    @property
    def length(self) -> float:
        return self.end - self.start

    @property
    def silent(self) -> bool:
        return self.name == SILENCE


@dataclass(frozen=True, eq=False)
class Utterance:
    """Audio and its phone timings.

    Parameters
    ----------
    samples : ndarray, shape (n,), float32
        Mono audio in [-1, 1].
    rate : int
        Samples per second.
    phones : tuple of Phone
        In time order, not overlapping, within ``[0, duration]``.
    text : str
        What is said.
    source : str
        Where it came from, e.g. ``"flite:slt"`` or ``"recording:talk.wav"``.
    """

    samples: np.ndarray
    rate: int
    phones: tuple[Phone, ...]
    text: str = ""
    source: str = ""

    def __post_init__(self):
        samples = np.ascontiguousarray(self.samples, dtype=np.float32)
        if samples.ndim != 1:
            raise ValueError(f"utterance samples must be mono (1-D), got shape {samples.shape}")
        samples.setflags(write=False)
        object.__setattr__(self, "samples", samples)
        object.__setattr__(self, "phones", tuple(self.phones))
        for before, phone in zip(self.phones, self.phones[1:]):
            if phone.start < before.end - 1e-9:
                raise ValueError(f"phones overlap: {before} and {phone}")

    @property
    def duration(self) -> float:
        """Audio length in seconds."""
        return len(self.samples) / self.rate

    @property
    def speech_phones(self) -> tuple[Phone, ...]:
        """The phones that are not silence."""
        return tuple(p for p in self.phones if not p.silent)

    def phones_named(self, *names: str) -> tuple[Phone, ...]:
        """The phones called any of ``names``."""
        return tuple(p for p in self.phones if p.name in names)


def phones_from_ends(pairs, duration: float) -> tuple[Phone, ...]:
    """Phones from ``(name, end_time)`` pairs (each starts where the previous ended).

    Synthesisers print end times; the first phone starts at 0. When the last end
    differs from the audio's ``duration`` by more than 20 ms (flite's diphone
    voices report their target durations, not the concatenated audio's), all times
    are scaled to the audio so the mouth stays in sync with what is heard.

    Examples
    --------
    >>> [(p.name, p.start, p.end) for p in phones_from_ends([("pau", 0.2), ("m", 0.3)], 0.3)]
    [('pau', 0.0, 0.2), ('m', 0.2, 0.3)]
    """
    pairs = [(normalise_phone(name), float(end)) for name, end in pairs]
    if not pairs:
        return ()
    last = pairs[-1][1]
    scale = duration / last if last > 0 and abs(last - duration) > 0.02 else 1.0
    phones, start = [], 0.0
    for name, end in pairs:
        end = min(end * scale, duration)
        if end <= start:       # zero-length phone (or clipped past the audio): skip it
            continue
        phones.append(Phone(name, round(start, 6), round(end, 6)))
        start = end
    return tuple(phones)
