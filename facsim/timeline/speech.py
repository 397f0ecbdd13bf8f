"""The speech track of a timeline: ``{say: "...", start: 1.0, voice: slt}`` or ``{audio: f.wav, transcript: "..."}``.

A speech track resolves to AU curves when the timeline is sampled (see
:func:`facsim.timeline.sampling.activation_curves`), so every consumer of
sampled activations (videos, stills, plots, glTF and ARKit exports) gets the
speech animation; videos also get its audio (:func:`timeline_audio`).

Examples
--------
>>> track = SpeechTrack(say="Hello there.", start=0.5)
>>> track.label, round(track.end, 3) > 0.5              # doctest: +SKIP
('say "Hello there."', True)
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from facsim.speech.coarticulation import SpeechCurves, speech_curves
from facsim.speech.utterance import Utterance
from facsim.timeline.model import DEFAULT_FPS, Blinks, Hold, SoundTrack, Timeline, TimelineError, Track, seconds

def _error(problem: str, where: str):
    return TimelineError(problem, location=(where,))


@dataclass(frozen=True, kw_only=True)
class SpeechTrack(SoundTrack):
    """Speech that starts at ``start`` seconds: synthesised text, or a recording with its transcript.

    Parameters
    ----------
    say : str, optional
        Text to synthesise with ``voice``.
    audio : str, optional
        A WAV recording (any rate, mono or stereo) ...
    transcript : str, optional
        ... and the words it says, for forced alignment.
    voice : str, optional
        For ``say``: ``slt`` (default), ``awb``, ``rms``, ``kal16`` or ``piper:NAME``.
    start : float
        Seconds from the start of the video.
    """

    say: str | None = None
    audio: str | None = None
    transcript: str | None = None
    voice: str | None = None
    start: float = 0.0

    def __post_init__(self):
        if (self.say is None) == (self.audio is None):
            raise _error("a speech track takes either 'say' (text) or 'audio' (a WAV file) with 'transcript'",
                         "say")
        object.__setattr__(self, "start", seconds(self.start, "start"))
        if self.say is not None:
            from facsim.speech.synth import check_text, check_voice

            if self.transcript is not None:
                raise _error("'transcript' goes with 'audio'; 'say' is its own transcript", "transcript")
            try:
                check_text(self.say)
            except ValueError as exc:
                raise _error(str(exc), "say") from None
            try:
                check_voice(self.voice or "slt")
            except ValueError as exc:
                raise _error(str(exc), "voice") from None
        else:
            if self.voice is not None:
                raise _error("'voice' applies to 'say' tracks; a recording has its own voice", "voice")
            if not isinstance(self.audio, (str, Path)) or not Path(self.audio).is_file():
                raise _error(f"audio file {self.audio} does not exist", "audio")
            object.__setattr__(self, "audio", str(self.audio))
            if not isinstance(self.transcript, str) or not self.transcript.strip():
                raise _error("a recording needs 'transcript': the words it says", "transcript")

    @property
    def utterance(self) -> Utterance:
        """The audio and phone timings (synthesised or aligned once per process)."""
        if self.say is not None:
            from facsim.speech.synth import synthesize

            return synthesize(self.say, self.voice or "slt")
        return _aligned(self.audio, Path(self.audio).stat().st_mtime_ns, self.transcript)

    @property
    def end(self) -> float:
        """When the speech is over, seconds."""
        return self.start + self.utterance.duration

    @property
    def label(self) -> str:
        text = self.say if self.say is not None else self.transcript
        short = text if len(text) <= 32 else text[:31] + "…"
        return f'say "{short}"' if self.say is not None else f'audio "{short}"'

    def curves(self, times) -> SpeechCurves:
        """Speech AU curves at ``times`` (seconds from the start of the video)."""
        return speech_curves(self.utterance, times, offset=self.start)


_ALIGNED: dict = {}


def _aligned(path: str, mtime: int, transcript: str) -> Utterance:
    key = (path, mtime, transcript)
    if key not in _ALIGNED:
        from facsim.speech.align import align_recording

        try:
            _ALIGNED[key] = align_recording(path, transcript)
        except ValueError as exc:
            raise _error(str(exc), "transcript") from None
    return _ALIGNED[key]


def speech_tracks(timeline) -> tuple[SpeechTrack, ...]:
    return tuple(t for t in timeline.tracks if isinstance(t, SpeechTrack))


def timeline_audio(timeline, duration: float, rate: int | None = None) -> tuple[np.ndarray, int] | None:
    """The timeline's speech mixed into one mono track as long as its video, and its sample rate
    (``None`` without speech).

    The track lasts ``duration`` seconds (the video's: frame count / fps), so audio and video end together.
    ``rate`` defaults to the highest rate among the clips (flite's 16 kHz needs no resampling).
    """
    from facsim.speech.audio import mix

    tracks = speech_tracks(timeline)
    if not tracks:
        return None
    clips = [(t.start, t.utterance.samples, t.utterance.rate) for t in tracks]
    rate = rate or max(clip[2] for clip in clips)
    out = mix(clips, duration, rate)
    assert math.isclose(len(out) / rate, duration, abs_tol=1 / rate)
    return out, rate


def with_speech(curves, tracks, times) -> dict:
    """Timeline ``curves`` (``(code, side)`` → levels at ``times``) with speech ``tracks`` combined in.

    Overlapping speech tracks add (clamped to 1) and speak while any of them does.
    """
    from facsim.speech.combine import combine_curves

    speech: dict = {}
    speaking = np.zeros(len(times))
    for track in tracks:
        part = track.curves(times)
        speaking = np.maximum(speaking, part.speaking)
        for key, values in part.by_side().items():
            speech[key] = speech[key] + values if key in speech else values
    combined = combine_curves(curves, speech, speaking)
    return {key: np.round(values, 12) for key, values in combined.items()}


# ------------------------------------------------------ speaking timelines ---

#: Blinks a minute while talking: people blink more in conversation (about 26) than at rest
#: (about 17; Bentivoglio et al. 1997, Movement Disorders 12(6)).
TALKING_BLINK_RATE = 26.0


def speech_timeline(text: str | None = None, *, audio=None, transcript: str | None = None, voice: str | None = None,
                    emotion: str | None = None, intensity="100%", table: str | None = None, blinks: bool = True,
                    seed: int = 0, fps: float = DEFAULT_FPS, intensities: str = "hapfacs", **settings) -> Timeline:
    """The timeline of a speaking character.

    Parameters
    ----------
    text : str, optional
        What to say (synthesised with ``voice``); or give ``audio`` and ``transcript``.
    emotion, intensity, table
        An emotion preset held for the whole clip at ``intensity`` (its lips and jaw
        yield to speech while talking, see :mod:`facsim.speech.combine`).
    blinks, seed
        Spontaneous blinks (seeded, so the same inputs give the same video).
    **settings
        ``character``, ``engine``, ``description`` as for :class:`~facsim.timeline.model.Timeline`.
    """
    if text is not None and audio is not None:
        raise ValueError("give text to say or --audio with --transcript, not both")
    if audio is None and text is None:
        raise ValueError("nothing to say: give the text, or --audio FILE.wav with --transcript")
    if audio is not None:
        speech = SpeechTrack(audio=str(audio), transcript=transcript)
    else:
        if transcript is not None:
            raise ValueError("--transcript goes with --audio")
        speech = SpeechTrack(say=text, voice=voice)
    tracks = [speech]
    if emotion:
        tracks.append(Track(emotion=emotion, table=table, timing=Hold(0.0, speech.end, intensity)))
    return Timeline(tuple(tracks), fps=fps, intensities=intensities,
                    blinks=Blinks(rate_per_minute=TALKING_BLINK_RATE, seed=seed) if blinks else None, **settings)
