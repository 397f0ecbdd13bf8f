"""Named constructors of timelines: HapFACS stimuli and recorded samples."""
from __future__ import annotations

from typing import Mapping

import numpy as np

from facsim.timeline.model import DEFAULT_FPS, DEFAULT_INTENSITIES, TABLE_ONLY_FOR_EMOTION, Envelope, Segment, Timeline, TimelineError, Track, expression_text



def stimulus_timeline(expression_or_emotion, onset: float = 1.0, apex: float = 1.0, offset: float = 1.0,
                      fps: float = DEFAULT_FPS, *, intensity: float | str = 1.0, easing: str = "linear",
                      table: str | None = None, intensities: str = DEFAULT_INTENSITIES,
                      **settings) -> Timeline:
    """A HapFACS-style stimulus: rise from neutral, hold, return to neutral.

    The defaults are HapFACS 3.0's validation videos: 1 s onset, 1 s apex,
    1 s offset, linear, 30 fps, so a 3 s video of 90 frames that starts at 0.

    Parameters
    ----------
    expression_or_emotion : str or Expression
        An emotion name (``"happiness"``, see
        :func:`facsim.emotions.emotion_names`), FACS notation (``"1+2+5B+26"``)
        or a parsed :class:`~facsim.notation.Expression`.
    onset, apex, offset : float
        Seconds.
    fps : float
        Frames per second.
    intensity : float or str
        Peak level (HapFACS used 100 % and 50 %).
    easing : str
        For the onset and offset.
    table : str, optional
        Emotion preset table.
    intensities : str
        Letter table.
    **settings
        ``character``, ``engine``, ``blinks``, ``description``.

    Examples
    --------
    >>> tl = stimulus_timeline("surprise")
    >>> tl.length, tl.tracks[0].emotion
    (3.0, 'surprise')
    """
    from facsim.facs.emotions import emotion_names

    envelope = Envelope(0.0, onset, apex, offset, intensity, easing)
    if isinstance(expression_or_emotion, str) and expression_or_emotion.strip().lower() in emotion_names():
        track = Track(emotion=expression_or_emotion, table=table, timing=envelope)
    else:
        if isinstance(expression_or_emotion, str) and _looks_like_a_name(expression_or_emotion):
            import difflib

            name = expression_or_emotion.strip()
            close = difflib.get_close_matches(name.lower(), emotion_names(), n=1)
            hint = f"did you mean {close[0]!r}? " if close else ""
            raise TimelineError(f"unknown emotion {name[:40]!r}; {hint}choose one of {', '.join(emotion_names())} "
                                "or give FACS notation such as '1+2+5B+26'")
        if table is not None:
            raise TimelineError(TABLE_ONLY_FOR_EMOTION, location=("table",))
        text = expression_or_emotion
        if not isinstance(text, str):
            text = expression_text(expression_or_emotion, intensities)
        track = Track(facs=text, timing=envelope)
    return Timeline((track,), duration=envelope.end, fps=fps, intensities=intensities, **settings)


def _looks_like_a_name(text: str) -> bool:
    """A word, not FACS notation: letters only (every FACS unit has a digit), and not 'neutral'."""
    word = text.strip()
    return bool(word) and word.lower() != "neutral" and all(ch.isalpha() or ch in " -_" for ch in word)


def timeline_from_samples(times, curves: Mapping[tuple[int, str], np.ndarray], *, fps: float,
                          decimals: int = 4, **settings):
    """A timeline that passes through recorded levels at ``times``.

    Each (code, side) curve becomes linear segments from frame to frame
    (collinear runs merged, runs of zero left out), so sampling the timeline
    at ``times[i]`` gives ``curves[key][i]`` (rounded to ``decimals``). The
    last frame holds for one frame interval, which is where the timeline ends.

    Parameters
    ----------
    times : (n,) array
        Seconds, strictly increasing, the first >= 0.
    curves : mapping (code, "left" | "right" | "both") → (n,) array of levels
        Left and right curves of one AU that are equal become one ``both``
        track, as does an AU that cannot act on one side (from its larger
        side); otherwise each side is a track of its own.
    fps : float
        The timeline's frame rate (the last frame's length is ``1 / fps``).
    **settings
        ``character``, ``engine``, ``description``, ``intensities``.
    """
    from facsim.facs.catalogue import info

    times = np.asarray(times, dtype=float)
    if times.ndim != 1 or times.size == 0:
        raise ValueError("times must be a non-empty 1-D array of seconds")
    if times[0] < 0 or np.any(np.diff(times) <= 0):
        raise ValueError("times must start at 0 s or later and increase strictly")
    end = float(times[-1] + 1.0 / fps)
    knots = np.append(times, end)
    by_code: dict[int, dict[str, np.ndarray]] = {}
    for (code, side), values in curves.items():
        by_code.setdefault(int(code), {})[side] = np.clip(np.round(np.asarray(values, float), decimals), 0.0, 1.0)
    tracks = []
    for code in sorted(by_code):
        sides = by_code[code]
        left, right = sides.get("left"), sides.get("right")
        twins = left is not None and right is not None and np.array_equal(left, right)
        if "both" in sides or twins or not info(code).unilateral:
            parts = [s for s in (sides.get("both"), left, right) if s is not None]
            sides = {"both": np.max(parts, axis=0)}
        for side in ("both", "left", "right"):
            if side in sides:
                segments = _linear_segments(knots, np.append(sides[side], sides[side][-1]), Segment)
                if segments:
                    tracks.append(Track(au=code, side=side, timing=segments))
    return Timeline(tuple(tracks), duration=end, fps=fps, **settings)


def _linear_segments(knots: np.ndarray, levels: np.ndarray, segment) -> tuple:
    """Segments through (knots[i], levels[i]); collinear points merged, flat zero runs dropped."""
    keep = np.ones(len(knots), bool)
    if len(knots) > 2:
        t0, t1, t2 = knots[:-2], knots[1:-1], knots[2:]
        v0, v1, v2 = levels[:-2], levels[1:-1], levels[2:]
        straight = np.abs(v0 + (v2 - v0) * (t1 - t0) / (t2 - t0) - v1) <= 1e-12
        keep[1:-1] = ~straight
    idx = np.flatnonzero(keep)
    out = []
    for a, b in zip(idx[:-1], idx[1:]):
        if levels[a] == 0.0 and levels[b] == 0.0:
            continue
        out.append(segment(float(knots[a]), float(knots[b]), float(levels[a]), float(levels[b])))
    return tuple(out)
