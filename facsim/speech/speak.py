"""``facsim speak``: a talking face from text (or a recording), with an emotion, to a video with sound.

The clip is one timeline (so ``--save-timeline`` writes what was rendered):
a speech track from 0, the emotion held for the whole clip, and seeded blinks.

Examples
--------
>>> timeline = speech_timeline("Hello.", emotion="happiness", intensity="70%")   # doctest: +SKIP
>>> [type(t).__name__ for t in timeline.tracks]                                  # doctest: +SKIP
['SpeechTrack', 'Track']
"""
from __future__ import annotations

from facsim.timeline.model import DEFAULT_FPS, Blinks, Hold, Timeline, Track

from .track import SpeechTrack

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
