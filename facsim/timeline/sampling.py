"""Sampling a timeline: per-frame times, blinks and the Activations each frame shows.

Examples
--------
>>> from facsim.timeline.model import Timeline
>>> tl = Timeline.from_facs("1+2+5B+26", start=0.2, end=1.4, onset=0.4, offset=0.4)
>>> tl.length, frame_count(tl)
(1.4, 42)
>>> act = sample(tl, 0.8)                   # at the apex
>>> act[5, "left"], act[26, "right"]
(0.3, 1.0)
>>> sample(tl, 0.4)[1, "left"]              # half-way up the onset
0.5
>>> list(intensity_curves(tl, [0.8]))
['AU1', 'AU2', 'AU5', 'AU26']
"""
from __future__ import annotations

import math
from typing import Mapping

import numpy as np

from facsim.facs.activations import Activations
from facsim.limits import check_fps, check_frames
from facsim.timeline.model import (TimelineError, BLINK_AU, BLINK_CLOSE_FRACTION, DECIMALS, SIDE_SUFFIX, Segment, Timeline, Track,
                                   positive, track_activations)


def frame_count(timeline: Timeline, fps: float | None = None) -> int:
    """Number of frames: ``round(length * fps)``, halves rounded up.

    Examples
    --------
    >>> from facsim.timeline.builders import stimulus_timeline
    >>> frame_count(stimulus_timeline("happiness"))
    90
    """
    fps = timeline.fps if fps is None else positive(fps, "fps")
    try:
        check_fps(fps)
        check_frames(timeline.length * fps, f"{timeline.length:g} s at {fps:g} fps")
    except ValueError as exc:
        raise TimelineError(str(exc)) from None
    return int(math.floor(round(timeline.length * fps, 6) + 0.5))


def frame_times(timeline: Timeline, fps: float | None = None) -> np.ndarray:
    """Time of each frame, ``i / fps`` for ``i`` in ``range(frame_count)``.

    The first frame is at 0 and the last one at ``(n - 1) / fps``, one frame
    interval before the end: frame ``i`` shows the start of its display
    interval ``[i / fps, (i + 1) / fps)``.

    Parameters
    ----------
    timeline : Timeline
    fps : float, optional
        Frame rate; default ``timeline.fps``.

    Returns
    -------
    ndarray, shape (n,)
        Seconds.

    Examples
    --------
    >>> from facsim.timeline.model import Blinks, Hold, Timeline, Track
    >>> tl = Timeline.from_facs("12", end=0.1)
    >>> frame_times(tl, fps=40).tolist()
    [0.0, 0.025, 0.05, 0.075]
    """
    fps = timeline.fps if fps is None else positive(fps, "fps")
    return np.arange(frame_count(timeline, fps)) / fps


def blink_times(timeline: Timeline, until: float | None = None) -> np.ndarray:
    """Start times of the spontaneous blinks (seconds; empty without ``blinks``).

    ``until`` (default: the timeline's length) stops the draws early: sampling
    a few frames costs blinks up to the last of them, not the whole video. The
    draws are a prefix of the same random stream, so the blinks before
    ``until`` are the same whatever it is.

    Examples
    --------
    >>> from facsim.timeline.model import Blinks, Hold, Timeline, Track
    >>> tl = Timeline(duration=10.0, blinks=Blinks(seed=1))
    >>> bool(np.all(np.diff(blink_times(tl)) >= 1.0))
    True
    >>> np.array_equal(blink_times(tl), blink_times(Timeline(duration=10.0, blinks=Blinks(seed=1))))
    True
    """
    blinks = timeline.blinks
    if blinks is None:
        return np.zeros(0)
    rng = np.random.default_rng(blinks.seed)
    mean_extra = 60.0 / blinks.rate_per_minute - blinks.min_interval
    end = timeline.length if until is None else min(float(until), timeline.length)
    # Drawn in batches (the same stream as one draw at a time), summed left to right like a running total.
    chunks, t = [], 0.0
    batch = 64
    while t < end:
        gaps = blinks.min_interval + rng.exponential(mean_extra, size=batch)
        starts = np.cumsum(np.concatenate(([t], gaps)))[1:]
        chunks.append(starts)
        t = float(starts[-1])
        batch = min(batch * 2, 1 << 16)
    times = np.concatenate(chunks) if chunks else np.zeros(0)
    return times[times < end]


def blink_track(timeline: Timeline, until: float | None = None) -> Track | None:
    """The blinks starting before ``until`` as one AU45 track of sectors (``None`` if there are none)."""
    starts = blink_times(timeline, until)
    if starts.size == 0:
        return None
    blinks = timeline.blinks
    close = blinks.duration * BLINK_CLOSE_FRACTION
    segments = []
    for t in starts:
        segments.append(Segment(t, t + close, 0.0, 1.0, "smoothstep"))
        segments.append(Segment(t + close, t + blinks.duration, 1.0, 0.0, "smoothstep"))
    return Track(au=BLINK_AU, timing=tuple(segments))


def _all_tracks(timeline: Timeline, until: float | None = None) -> tuple[Track, ...]:
    blinks = blink_track(timeline, until)
    return timeline.tracks if blinks is None else (*timeline.tracks, blinks)


def activation_curves(timeline: Timeline, times) -> dict[tuple[int, str], np.ndarray]:
    """Intensity of every (AU code, side) the timeline touches, at ``times``.

    Parameters
    ----------
    timeline : Timeline
    times : array_like, shape (n,)
        Seconds.

    Returns
    -------
    dict
        ``(code, "left" | "right")`` → ndarray of shape (n,), values in
        [0, 1]: the sum of all tracks on that key, clamped to 1. Keys in code
        order, left before right. Values are rounded to 12 decimals, which
        keeps float noise (0.49999999999999994) out of the activations.
    """
    times = np.atleast_1d(np.asarray(times, dtype=float))
    if times.ndim != 1:
        raise ValueError(f"times must be a 1-D array of seconds, got shape {times.shape}")
    totals: dict[tuple[int, str], np.ndarray] = {}
    speech = []
    # Blinks only up to the last time asked for: cost follows the frames sampled, not the duration.
    until = float(np.nextafter(times.max(), np.inf)) if times.size else 0.0
    for track in _all_tracks(timeline, until):
        if not isinstance(track, Track):   # speech: AU curves from its phones, combined below
            speech.append(track)
            continue
        base = track_activations(track, timeline.intensities)
        if not base:
            continue
        level = track.levels(times)
        for key, value in base:
            totals[key] = totals.get(key, np.zeros(times.shape)) + value * level
    curves = {key: np.clip(np.round(totals[key], DECIMALS), 0.0, 1.0) for key in sorted(totals)}
    if speech:
        from facsim.timeline.speech import with_speech

        curves = with_speech(curves, speech, times)
    return curves


def intensity_curves(timeline: Timeline, times) -> dict[str, np.ndarray]:
    """:func:`activation_curves` with readable labels, for plots and tables.

    An AU whose two sides move identically is one curve labelled ``"AU12"``;
    otherwise each side that moves is its own, ``"AU12 (L)"`` and
    ``"AU12 (R)"`` (the character's left and right).

    Examples
    --------
    >>> from facsim.timeline.model import Blinks, Hold, Timeline, Track
    >>> tl = Timeline((Track(au=12, side="left", timing=Hold(0, 1, 0.5)),
    ...                Track(au=6, timing=Hold(0, 1, 0.3))))
    >>> {k: v.tolist() for k, v in intensity_curves(tl, [0.5, 1.0]).items()}
    {'AU6': [0.3, 0.0], 'AU12 (L)': [0.5, 0.0]}
    """
    curves = activation_curves(timeline, times)
    labelled: dict[str, np.ndarray] = {}
    for code in sorted({code for code, _ in curves}):
        left, right = curves.get((code, "left")), curves.get((code, "right"))
        if left is not None and right is not None and np.array_equal(left, right):
            labelled[f"AU{code}"] = left
            continue
        for side, curve in (("left", left), ("right", right)):
            if curve is not None:
                labelled[f"AU{code} ({SIDE_SUFFIX[side]})"] = curve
    return labelled


def _activations_at(curves: Mapping[tuple[int, str], np.ndarray], i: int) -> Activations:
    return Activations({key: float(values[i]) for key, values in curves.items()})


def sample(timeline: Timeline, t: float) -> Activations:
    """The activations at time ``t`` (seconds), exactly.

    Examples
    --------
    >>> from facsim.timeline.builders import stimulus_timeline
    >>> tl = stimulus_timeline("12", intensity=0.5)
    >>> sample(tl, 1.5)[12, "left"], sample(tl, 3.0)[12, "left"]
    (0.5, 0.0)
    """
    t = float(t)
    if not math.isfinite(t):
        raise ValueError(f"t must be a finite number of seconds, got {t}")
    return _activations_at(activation_curves(timeline, [t]), 0)


def sample_frames(timeline: Timeline, fps: float | None = None) -> list[Activations]:
    """The activations of every frame, at :func:`frame_times`.

    Examples
    --------
    >>> from facsim.timeline.builders import stimulus_timeline
    >>> frames = sample_frames(stimulus_timeline("happiness"))
    >>> len(frames), frames[0][12, "left"], frames[45][12, "left"]
    (90, 0.0, 1.0)
    """
    times = frame_times(timeline, fps)
    curves = activation_curves(timeline, times)
    return [_activations_at(curves, i) for i in range(times.size)]
