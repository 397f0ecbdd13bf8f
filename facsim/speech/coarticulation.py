"""Phones → AU curves over time, with coarticulation (Cohen & Massaro 1993).

Each phone is a segment whose viseme pulls every speech AU toward its target
with a dominance that is strongest over the segment's core and decays
exponentially before it (anticipation) and after it (carry-over):

.. math:: D_s(t) = \\alpha_s \\exp(-|τ| / r),\\qquad F(t) = \\frac{\\sum_s D_s(t) T_s}{\\sum_s D_s(t)}

where τ is the distance from ``t`` to the segment's core (its middle half) and
``r`` is ``rate_before`` or ``rate_after``. So consecutive sounds blend instead
of snapping, and a weak segment (k, g, h) takes on its neighbours' lip shape.

Then JALI's hard rules (Edwards et al. 2016) hold over the middle of each
constrained phone: bilabials close the lips (jaw and lip-parting AUs → 0, the
pressors at their target), labiodentals hold the lower lip at the teeth,
sibilants cap the jaw.

Pauses of at least ``rest_pause`` (300 ms) are full-strength rest segments, so
the mouth returns to rest; shorter pauses barely pull, so the mouth moves on.

The result also carries ``speaking``: 1 through each run of speech (phones not
broken by a rest pause), easing to 0 over 150 ms either side; it says how much
speech owns the lips and jaw against an emotion (see :mod:`facsim.speech.combine`).

Examples
--------
>>> from facsim.speech.utterance import Phone, Utterance
>>> u = Utterance(np.zeros(16000, np.float32), 16000,
...               (Phone("pau", 0, 0.4), Phone("m", 0.4, 0.5), Phone("aa", 0.5, 0.7), Phone("pau", 0.7, 1.0)))
>>> c = speech_curves(u, [0.1, 0.45, 0.6, 0.95])
>>> c.aus[24].round(2).tolist(), c.aus[26].round(2).tolist()
([0.01, 0.7, 0.08, 0.0], [0.0, 0.0, 0.72, 0.0])
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Mapping

import numpy as np

from .utterance import Utterance
from .visemes import viseme_table

#: Rest segments added before and after the utterance, so it starts and ends at rest.
_EDGE_REST = 0.3
#: A constraint holds at least this long either side of a phone's middle, so at 30 fps a frame always sees it.
_MIN_CORE_HALF = 1 / 60
_DECIMALS = 12


@dataclass(frozen=True, eq=False)
class SpeechCurves:
    """AU levels of speech at ``times``: ``aus[code]`` (both sides) and ``speaking``, arrays of shape (n,)."""

    times: np.ndarray
    aus: Mapping[int, np.ndarray]
    speaking: np.ndarray

    def by_side(self) -> dict[tuple[int, str], np.ndarray]:
        """The curves keyed ``(code, side)`` for both sides, as timelines key them."""
        return {(code, side): values for code, values in self.aus.items() for side in ("left", "right")}


def _segments(utterance: Utterance):
    """(start, end, viseme, dominance, is_speech) per phone, with rest before and after."""
    table = viseme_table()
    co = table.coarticulation
    rest = table.viseme_of("pau")
    segs = [(-_EDGE_REST, 0.0, rest, rest.dominance, False)]
    for p in utterance.phones:
        v = table.viseme_of(p.name)
        if p.silent or v is rest:
            alpha = rest.dominance if p.length >= co.rest_pause else co.short_pause_dominance
            segs.append((p.start, p.end, rest, alpha, False))
        else:
            segs.append((p.start, p.end, v, v.dominance, True))
    end = utterance.phones[-1].end if utterance.phones else utterance.duration
    segs.append((end, end + _EDGE_REST, rest, rest.dominance, False))
    return segs


#: Seconds over which speech takes the lips and jaw from an emotion (and gives them back).
HANDOVER = 0.15


def _speaking(utterance: Utterance, t: np.ndarray, rest_pause: float) -> np.ndarray:
    """1 through each run of speech (phones not broken by a pause of ``rest_pause`` or more),
    easing to 0 over :data:`HANDOVER` before and after it."""
    runs: list[list[float]] = []
    for p in utterance.phones:
        if p.silent:
            continue
        if runs and p.start - runs[-1][1] < rest_pause:
            runs[-1][1] = p.end
        else:
            runs.append([p.start, p.end])
    out = np.zeros_like(t)
    for start, end in runs:
        outside = np.maximum(np.maximum(start - t, t - end), 0.0)
        x = np.clip(1.0 - outside / HANDOVER, 0.0, 1.0)
        out = np.maximum(out, x * x * (3 - 2 * x))
    return out


def speech_curves(utterance: Utterance, times, *, offset: float = 0.0) -> SpeechCurves:
    """The speech AU curves of ``utterance`` at ``times`` (seconds; the utterance starts at ``offset``).

    Outside the utterance the mouth is at rest and ``speaking`` is 0.
    """
    table = viseme_table()
    co = table.coarticulation
    times = np.atleast_1d(np.asarray(times, dtype=float))
    t = times - offset
    segs = _segments(utterance)
    starts = np.array([s[0] for s in segs])
    ends = np.array([s[1] for s in segs])
    alpha = np.array([s[3] for s in segs])
    middle, quarter = 0.5 * (starts + ends), 0.25 * (ends - starts)
    core_lo, core_hi = middle - quarter, middle + quarter
    before = np.maximum(core_lo[:, None] - t[None, :], 0.0)     # t is before the core
    after = np.maximum(t[None, :] - core_hi[:, None], 0.0)      # t is after the core
    dominance = alpha[:, None] * np.exp(-before / co.rate_before - after / co.rate_after)
    total = dominance.sum(axis=0)
    weights = dominance / np.maximum(total, 1e-300)

    codes = table.codes
    targets = np.array([[s[2].aus.get(code, 0.0) for code in codes] for s in segs])   # (S, A)
    levels = targets.T @ weights                                                       # (A, n)
    speaking = _speaking(utterance, t, co.rest_pause)
    index = {code: i for i, code in enumerate(codes)}
    for start, end, viseme, _, _ in segs:
        rule = viseme.constraint
        if rule is None:
            continue
        mid = 0.5 * (start + end)
        half = max(0.5 * co.constraint_share * (end - start), _MIN_CORE_HALF)
        distance = np.maximum(np.abs(t - mid) - half, 0.0)
        window = np.clip(1.0 - distance / co.constraint_ramp, 0.0, 1.0)
        if not window.any():
            continue
        for code in rule.suppress:
            levels[index[code]] *= 1.0 - window
        for code in rule.hold:
            levels[index[code]] = np.maximum(levels[index[code]], window * viseme.aus.get(code, 0.0))
    outside = (t < -_EDGE_REST) | (t > segs[-1][1])
    levels[:, outside] = 0.0
    speaking[outside] = 0.0
    aus = {code: np.clip(np.round(levels[index[code]], _DECIMALS), 0.0, 1.0) for code in codes}
    return SpeechCurves(times, aus, np.clip(np.round(speaking, _DECIMALS), 0.0, 1.0))
