"""Timelines: action units over time, as data (frozen dataclasses checked as they are built).

A timeline is what a facsim video shows: a list of tracks, each an action unit
(or an emotion preset, or a FACS string) with a level that changes over time.
Sampling it per frame is :mod:`facsim.timeline.sampling`'s job; named
constructors live in :mod:`facsim.timeline.builders`; files and dicts in
:mod:`facsim.timeline.io`.

File format
-----------
YAML or JSON (by suffix), checked against ``facsim/data/timeline.schema.json``
(JSON Schema draft 2020-12, see :func:`~facsim.timeline_io.timeline_schema`).
Times are seconds from the start of the video; intensities are fractions
``0.55``, percentages ``"55%"`` or FACS letters ``A``-``E`` (read through ``intensities``)::

    description: Surprise, rising and falling   # optional free text
    duration: 2.0            # optional; default: the end of the last track
    fps: 30                  # default 30
    character: ava           # optional, passed through to the renderer
    engine: registers        # optional, passed through to the renderer
    intensities: hapfacs     # letter table: hapfacs (default) or facshuman
    blinks: {rate_per_minute: 17, duration: 0.25, seed: 0}   # optional
    tracks:
      - au: 12               # one code; head 51-58 and eyes 61-66 too
        side: left           # both (default), left, right, unilateral
        segments:            # HapFACS sectors
          - {start: 0.2, end: 0.8, from: 0, to: C, easing: smoothstep}
          - {start: 1.2, end: 1.6, to: 0}     # 'from' defaults to the last 'to'
      - facs: "1+2+5B+26"    # the string's intensities times the envelope
        start: 0.2           # envelope: rise, hold, fall
        onset: 0.4
        apex: 0.4
        offset: 0.4
        intensity: 1.0       # peak level (default 1)
        easing: sigmoid      # for the rise and the fall (default linear)
      - emotion: happiness   # a preset of facsim.emotions
        table: hapfacs       # preset table (default facsim: HapFACS Table 5, anger and surprise from EMFACS)
        start: 0.5           # constant hold from start (default 0) to end
        end: 1.5
        intensity: 50%

Each track has exactly one source (``au``, ``facs`` or ``emotion``) and one
timing:

* ``segments``: HapFACS sectors, in time order, not overlapping. Each moves the
  level from ``from`` at ``start`` to ``to`` at ``end`` along its easing.
  Between two segments the level stays at the earlier one's ``to``; before the
  first segment and from the end of the last one it is 0.
* an envelope (``start``, ``onset``, ``apex``, ``offset``, all three durations
  required, 0 allowed): 0 at ``start``, rising to ``intensity`` over
  ``onset``, held for ``apex``, falling to 0 over ``offset``.
* a hold (``start``, ``end``): the level is ``intensity`` from ``start`` to
  ``end``, with no ramps (a step on and off; use an envelope for ramps).

Speech tracks (:mod:`facsim.timeline.speech`) say synthesised text or play a recording::

      - say: "Pack my box."  # synthesised text ...
        voice: slt           # slt (default), awb, rms, kal16, kal, piper:MODEL
        start: 0.5
      - audio: me.wav        # ... or a recording (relative to the file) and its words
        transcript: "Pack my box."
        start: 2.0

Their phones become AU curves when the timeline is sampled, so they mix with the
other tracks (while speaking they own the lips and jaw, see
:mod:`facsim.speech.combine`); each lasts as long as its audio; videos carry the audio.

Every track is active on the half-open interval ``[start, end)``: a track
contributes 0 at its end time, so a track that ends at 1 s and one that starts
at 1 s on the same AU never add up. An ``au`` track's level is the AU's
intensity; ``facs`` and ``emotion`` tracks multiply each unit of the string
by the level. Tracks acting on the same AU and side add up, clamped to 1
(:meth:`Activations.merge <facsim.expression.Activations.merge>`); different
AUs simply coexist and the engines apply their own rules. Gross-behaviour and
visibility codes (such as 50 Speech or 70 Brows Not Visible) are
refused: facsim does not render them.

Frames
------
A video of ``duration`` seconds at ``fps`` has ``round(duration * fps)``
frames (halves rounded up), frame ``i`` showing the face at ``t = i / fps``:
the first frame is at 0, the last at ``(n - 1) / fps``, before ``duration``
(a 3 s clip at 30 fps: 90 frames, the last at 2.967 s). Each frame shows the start of its display interval
``[i / fps, (i + 1) / fps)``, which matches the half-open tracks above.

Blinks
------
``blinks`` adds spontaneous AU45 blinks. Intervals between blink starts are
``min_interval`` plus an exponential draw whose mean makes the average rate
``rate_per_minute``; draws come from ``numpy.random.default_rng(seed)``, so
the same seed (and duration) gives the same blinks. Each blink closes over
40 % of ``duration`` (0.1 s of 0.25 s) and opens over the rest. Blinks add to
any AU45 track like any other track.

Examples
--------
>>> tl = Timeline.from_facs("1+2+5B+26", start=0.2, end=1.4, onset=0.4, offset=0.4)
>>> tl.length, [track.facs for track in tl.tracks]
(1.4, ['1+2+5B+26'])
"""
from __future__ import annotations

import math
import os
from dataclasses import dataclass
from functools import lru_cache
from typing import Any, Sequence

import numpy as np

from facsim.limits import check_fps, check_frames, limit, override_hint, short
from facsim.facs.catalogue import INTENSITY_TABLES, LETTERS, UnknownActionUnitError, info, intensity_of
from facsim.timeline.easing import get_easing
from facsim.facs.activations import Activations, activations

#: Sides an ``au`` track may name (as in :class:`facsim.notation.ActionUnit`).
TRACK_SIDES = ("both", "left", "right", "unilateral")
DEFAULT_FPS = 30.0
DEFAULT_INTENSITIES = "hapfacs"
#: Code of the spontaneous blink action.
BLINK_AU = 45
#: Share of a blink's duration spent closing the lids (the rest re-opens them).
BLINK_CLOSE_FRACTION = 0.4
SIDE_SUFFIX = {"left": "L", "right": "R"}
ENVELOPE_KEYS = ("onset", "apex", "offset")
#: Levels are rounded to this many decimals (float noise from time arithmetic).
DECIMALS = 12


# ---------------------------------------------------------------- errors ---

def _path_text(location: Sequence[str | int]) -> str:
    text = ""
    for key in location:
        text += f"[{key}]" if isinstance(key, int) else (f".{key}" if text else str(key))
    return text


class TimelineError(ValueError):
    """A timeline that cannot be read or built, in one line.

    The message names the file (and line, where known), the field path such
    as ``tracks[2].segments[0].end``, and what is wrong.

    Attributes
    ----------
    problem : str
        What is wrong, without the file and path.
    location : tuple of str and int
        The field path as keys and list indices (empty for the whole timeline).
    file : str or None
        The file it came from, if any.
    line : int or None
        1-based line in ``file``, if known.

    Examples
    --------
    >>> err = TimelineError("must be after start (1.4 s), got 0.2", location=("end",))
    >>> print(err.within("tracks", 2, "segments", 0))
    tracks[2].segments[0].end: must be after start (1.4 s), got 0.2
    """

    def __init__(self, problem: str, *, location: Sequence[str | int] = (),
                 file: str | os.PathLike | None = None, line: int | None = None):
        self.problem = problem
        self.location = tuple(location)
        self.file = None if file is None else str(file)
        self.line = line
        where = self.file or ""
        if where and line is not None:
            where += f":{line}"
        parts = [p for p in (where, self.path) if p]
        from facsim.limits import clip

        # One line, bounded: a hostile file must not make a megabyte-long message.
        super().__init__(clip(": ".join([*parts, str(problem)])))

    @property
    def path(self) -> str:
        """The field path as text, e.g. ``"tracks[2].segments[0].end"``."""
        return _path_text(self.location)

    def within(self, *prefix: str | int) -> "TimelineError":
        """The same error, its field path placed under ``prefix``."""
        return TimelineError(self.problem, location=(*prefix, *self.location), file=self.file, line=self.line)

    def in_file(self, file: str | os.PathLike, line: int | None = None) -> "TimelineError":
        """The same error, naming the file (and line) it came from."""
        return TimelineError(self.problem, location=self.location, file=file,
                             line=self.line if line is None else line)


# ------------------------------------------------------------ validation ---

def seconds(value: Any, name: str) -> float:
    """A finite time or duration >= 0, else a TimelineError at ``name``."""
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise TimelineError(f"expected a number of seconds, got {short(value)}", location=(name,))
    value = _float(value)
    if not math.isfinite(value):
        raise TimelineError(f"expected a finite number of seconds, got {value}", location=(name,))
    if value < 0:
        raise TimelineError(f"negative time {value:g} s; times are seconds from the start of the video "
                            "and must be >= 0", location=(name,))
    return value


def _set_interval(item) -> None:
    """Check a frozen ``item``'s ``start`` and ``end`` (seconds, start before end); store them as floats."""
    start, end = seconds(item.start, "start"), seconds(item.end, "end")
    if end <= start:
        raise TimelineError(f"must be after start ({start:g} s), got {end:g} s", location=("end",))
    object.__setattr__(item, "start", start)
    object.__setattr__(item, "end", end)


def _float(value) -> float:
    """``float(value)``, infinite for integers too big for a float (JSON and YAML allow 10**400)."""
    try:
        return float(value)
    except OverflowError:
        return math.inf if value > 0 else -math.inf


def positive(value: Any, name: str, unit: str = "") -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)) \
            or not math.isfinite(_float(value)) or _float(value) <= 0:
        raise TimelineError(f"must be a number > 0{unit}, got {short(value)}", location=(name,))
    return float(value)


def parse_level(value: Any, name: str, table: str | None = None) -> float:
    """An intensity in [0, 1] from a number, ``"55%"`` or (with ``table``) a letter."""
    from facsim.facs.notation import parse_intensity

    if table is not None and isinstance(value, str) and value.strip().upper() in LETTERS:
        return intensity_of(value.strip().upper(), table)
    try:
        return parse_intensity(value, name="intensity")
    except ValueError as exc:
        problem = "intensity out of range" if "between 0 and 1" in str(exc) else "not an intensity"
        letters = " or a letter A-E" if table is not None else ""
        raise TimelineError(f"{problem}: {short(value)}; use a fraction 0..1, a percentage '0%'..'100%'{letters}",
                            location=(name,)) from None


def _easing(value: Any, name: str = "easing") -> str:
    try:
        get_easing(value)
    except ValueError as exc:
        raise TimelineError(str(exc), location=(name,)) from None
    return value


def intensities_table(value: Any) -> str:
    if not isinstance(value, str) or value not in INTENSITY_TABLES:
        raise TimelineError(f"unknown intensity table {value!r}; choose one of "
                            f"{', '.join(INTENSITY_TABLES)}", location=("intensities",))
    return value


def _check_rendered(code: int, where: str) -> None:
    unit = info(code)
    if not unit.rendered:
        kind = {"gross": "a gross-behaviour code", "visibility": "a visibility code"}.get(unit.kind, unit.kind)
        raise TimelineError(f"AU{code} ({unit.name}) is {kind}, which facsim does not render; "
                            "remove it from the timeline", location=(where,))


# ------------------------------------------------------------ data types ---

@dataclass(frozen=True)
class Segment:
    """One HapFACS sector: the level goes from ``from_`` at ``start`` to ``to`` at ``end``.

    Parameters
    ----------
    start, end : float
        Seconds, ``0 <= start < end``.
    from_, to : float
        Levels in [0, 1] (``"55%"`` is accepted too); ``from_`` is written
        ``from`` in files.
    easing : str
        A name in :data:`facsim.easing.EASINGS`.

    Examples
    --------
    >>> seg = Segment(0.0, 1.0, 0.0, 0.55, "smoothstep")
    >>> seg.values([0.0, 0.5, 1.0]).tolist()
    [0.0, 0.275, 0.55]
    >>> Segment(1.4, 0.2, 0.0, 1.0)
    Traceback (most recent call last):
    ...
    facsim.timeline.model.TimelineError: end: must be after start (1.4 s), got 0.2 s
    """

    start: float
    end: float
    from_: float
    to: float
    easing: str = "linear"

    def __post_init__(self):
        _set_interval(self)
        object.__setattr__(self, "from_", parse_level(self.from_, "from"))
        object.__setattr__(self, "to", parse_level(self.to, "to"))
        _easing(self.easing)

    @property
    def length(self) -> float:
        """``end - start`` in seconds."""
        return self.end - self.start

    def values(self, times) -> np.ndarray:
        """The segment's level at ``times`` (clamped to its ends outside it)."""
        progress = (np.asarray(times, dtype=float) - self.start) / (self.end - self.start)
        return self.from_ + (self.to - self.from_) * get_easing(self.easing)(progress)


@dataclass(frozen=True)
class Envelope:
    """Onset, apex, offset: 0 at ``start``, up to ``intensity``, held, back to 0.

    HapFACS stimuli use ``Envelope(0, 1, 1, 1)``: one second each.

    Examples
    --------
    >>> env = Envelope(start=0.2, onset=1.0, apex=1.0, offset=1.0, intensity=0.85)
    >>> env.end
    3.2
    >>> [(s.start, s.end, s.from_, s.to) for s in env.segments]
    [(0.2, 1.2, 0.0, 0.85), (1.2, 2.2, 0.85, 0.85), (2.2, 3.2, 0.85, 0.0)]
    """

    start: float = 0.0
    onset: float = 1.0
    apex: float = 1.0
    offset: float = 1.0
    intensity: float = 1.0
    easing: str = "linear"

    def __post_init__(self):
        for name in ("start", *ENVELOPE_KEYS):
            object.__setattr__(self, name, seconds(getattr(self, name), name))
        if self.onset + self.apex + self.offset <= 0:
            raise TimelineError("onset, apex and offset are all 0; the envelope would never show",
                                location=("apex",))
        object.__setattr__(self, "intensity", parse_level(self.intensity, "intensity"))
        _easing(self.easing)

    @property
    def end(self) -> float:
        """When the offset is over: ``start + onset + apex + offset``."""
        return self.start + self.onset + self.apex + self.offset

    @property
    def segments(self) -> tuple[Segment, ...]:
        """Rise, hold and fall as sectors (zero-length phases left out)."""
        peak = self.intensity
        t0 = self.start
        t1 = t0 + self.onset
        t2 = t1 + self.apex
        t3 = t2 + self.offset
        phases = ((t0, t1, 0.0, peak, self.easing), (t1, t2, peak, peak, "linear"),
                  (t2, t3, peak, 0.0, self.easing))
        return tuple(Segment(*phase) for phase in phases if phase[1] > phase[0])


@dataclass(frozen=True)
class Hold:
    """A constant level from ``start`` to ``end``: a step on and a step off.

    Examples
    --------
    >>> Hold(0.5, 1.5, 0.3).segments
    (Segment(start=0.5, end=1.5, from_=0.3, to=0.3, easing='linear'),)
    """

    start: float
    end: float
    intensity: float = 1.0

    def __post_init__(self):
        _set_interval(self)
        object.__setattr__(self, "intensity", parse_level(self.intensity, "intensity"))

    @property
    def segments(self) -> tuple[Segment, ...]:
        """The hold as one flat sector."""
        return (Segment(self.start, self.end, self.intensity, self.intensity),)


Timing = Envelope | Hold | tuple[Segment, ...]


@dataclass(frozen=True, kw_only=True)
class Track:
    """One thing that moves: an AU, a FACS string or an emotion, with its timing.

    Give exactly one of ``au``, ``facs`` and ``emotion``.

    Parameters
    ----------
    timing : Envelope, Hold or sequence of Segment
        The track's level over time, 0..1. Segments must be in time order and
        must not overlap.
    au : int, optional
        One FACS code; its level is the AU's intensity.
    side : str
        For ``au`` only: ``"both"``, ``"left"``, ``"right"`` or
        ``"unilateral"`` (FACS ``U``, see
        :data:`facsim.expression.UNILATERAL_DEFAULT_SIDE`).
    facs : str, optional
        FACS notation; each unit's intensity is multiplied by the level.
    emotion : str, optional
        A preset name of :mod:`facsim.facs.emotions`; scaled like ``facs``.
    table : str, optional
        For ``emotion`` only: the preset table (``None`` means the default, ``"facsim"``).

    Examples
    --------
    >>> Track(au=12, side="left", timing=Hold(0.0, 1.0)).label
    'AU12 (L)'
    >>> Track(au=26, side="left", timing=Hold(0.0, 1.0))
    Traceback (most recent call last):
    ...
    facsim.timeline.model.TimelineError: side: AU26 (Jaw Drop) cannot act on one side; use side 'both'
    """

    timing: Timing
    au: int | None = None
    side: str = "both"
    facs: str | None = None
    emotion: str | None = None
    table: str | None = None

    def __post_init__(self):
        given = [name for name in ("au", "facs", "emotion") if getattr(self, name) is not None]
        if len(given) != 1:
            raise TimelineError(source_problem(given))
        if self.side not in TRACK_SIDES:
            raise TimelineError(f"unknown side {self.side!r}; choose one of {', '.join(TRACK_SIDES)}",
                                location=("side",))
        if self.side != "both" and self.au is None:
            raise TimelineError(SIDE_ONLY_FOR_AU, location=("side",))
        if self.table is not None and self.emotion is None:
            raise TimelineError(TABLE_ONLY_FOR_EMOTION, location=("table",))
        self._check_source()
        timing = self.timing
        if not isinstance(timing, (Envelope, Hold)):
            timing = tuple(timing) if isinstance(timing, (list, tuple)) else timing
            if not isinstance(timing, tuple) or not timing or \
                    not all(isinstance(s, Segment) for s in timing):
                raise TimelineError("timing must be an Envelope, a Hold or a non-empty sequence of "
                                    f"Segment, got {self.timing!r}", location=("segments",))
            for i in range(1, len(timing)):
                before, seg = timing[i - 1], timing[i]
                if seg.start < before.end:
                    raise TimelineError(
                        f"starts at {seg.start:g} s, before the previous segment ends ({before.end:g} s); "
                        "segments must be in time order without overlap", location=("segments", i, "start"))
            object.__setattr__(self, "timing", timing)

    def _check_source(self) -> None:
        from facsim.facs.notation import NotationError, parse

        if self.au is not None:
            if isinstance(self.au, bool) or not isinstance(self.au, (int, np.integer)):
                raise TimelineError(f"expected an integer FACS code, got {self.au!r}", location=("au",))
            object.__setattr__(self, "au", int(self.au))
            try:
                unit = info(self.au)
            except UnknownActionUnitError as exc:
                raise TimelineError(str(exc), location=("au",)) from None
            _check_rendered(self.au, "au")
            if self.side != "both" and not unit.unilateral:
                raise TimelineError(f"AU{self.au} ({unit.name}) cannot act on one side; use side 'both'",
                                    location=("side",))
        elif self.facs is not None:
            if not isinstance(self.facs, str):
                raise TimelineError(f"expected FACS notation as a string, got {self.facs!r}",
                                    location=("facs",))
            try:
                expr = parse(self.facs)
            except NotationError as exc:
                raise TimelineError(str(exc), location=("facs",)) from None
            for unit in expr.units:
                _check_rendered(unit.code, "facs")
        else:
            from facsim.facs.emotions import emotion

            if not isinstance(self.emotion, str):
                raise TimelineError(f"expected an emotion name, got {self.emotion!r}", location=("emotion",))
            object.__setattr__(self, "emotion", self.emotion.strip().lower())
            try:
                expr = emotion(self.emotion, **({"table": self.table} if self.table else {}))
            except ValueError as exc:
                where = "table" if str(exc).startswith("unknown emotion table") else "emotion"
                raise TimelineError(str(exc), location=(where,)) from None
            for unit in expr.units:
                _check_rendered(unit.code, "emotion")

    @property
    def segments(self) -> tuple[Segment, ...]:
        """The timing as sectors, whatever form it was given in."""
        return self.timing if isinstance(self.timing, tuple) else self.timing.segments

    @property
    def start(self) -> float:
        """When the track begins, seconds."""
        return self.segments[0].start

    @property
    def end(self) -> float:
        """When the track is over (it contributes 0 from then on), seconds."""
        return self.segments[-1].end

    @property
    def label(self) -> str:
        """A short name: ``"AU12 (L)"``, ``"1+2+5B+26"``, ``"happiness"``."""
        if self.au is not None:
            side = {"both": "", "left": " (L)", "right": " (R)", "unilateral": " (U)"}[self.side]
            return f"AU{self.au}{side}"
        return self.facs if self.facs is not None else self.emotion

    def levels(self, times) -> np.ndarray:
        """The track's level (0..1) at each of ``times`` (seconds), vectorised.

        Examples
        --------
        >>> track = Track(au=12, timing=Envelope(0.0, 1.0, 1.0, 1.0))
        >>> track.levels([0.0, 0.5, 1.5, 2.5, 3.0]).tolist()
        [0.0, 0.5, 1.0, 0.5, 0.0]
        """
        times = np.asarray(times, dtype=float)
        out = np.zeros(times.shape)
        segments = self.segments
        for i, seg in enumerate(segments):
            inside = (times >= seg.start) & (times < seg.end)
            out[inside] = seg.values(times[inside])
            if i + 1 < len(segments):      # a gap holds the level reached
                gap = (times >= seg.end) & (times < segments[i + 1].start)
                out[gap] = seg.to
        return np.clip(np.round(out, DECIMALS), 0.0, 1.0)


@dataclass(frozen=True)
class Blinks:
    """Seeded spontaneous blinks (AU45), see the module docstring.

    Examples
    --------
    >>> Blinks(rate_per_minute=90)
    Traceback (most recent call last):
    ...
    facsim.timeline.model.TimelineError: rate_per_minute: 90 blinks a minute means 0.667 s between blinks on average, less than min_interval (1 s); lower the rate or min_interval
    """

    rate_per_minute: float = 17.0
    duration: float = 0.25
    seed: int = 0
    min_interval: float = 1.0

    def __post_init__(self):
        rate = positive(self.rate_per_minute, "rate_per_minute")
        length = positive(self.duration, "duration", " s")
        gap = positive(self.min_interval, "min_interval", " s")
        if isinstance(self.seed, bool) or not isinstance(self.seed, (int, np.integer)) or self.seed < 0:
            raise TimelineError(f"must be an integer >= 0, got {self.seed!r}", location=("seed",))
        if gap < length:
            raise TimelineError(f"{gap:g} s is shorter than a blink ({length:g} s); blinks would overlap",
                                location=("min_interval",))
        if 60.0 / rate < gap:
            raise TimelineError(f"{rate:g} blinks a minute means {60.0 / rate:.3g} s between blinks on average, "
                                f"less than min_interval ({gap:g} s); lower the rate or min_interval",
                                location=("rate_per_minute",))
        object.__setattr__(self, "rate_per_minute", rate)
        object.__setattr__(self, "duration", length)
        object.__setattr__(self, "min_interval", gap)
        object.__setattr__(self, "seed", int(self.seed))


class SoundTrack:
    """Base of tracks that carry sound and make their own AU curves (speech: :mod:`facsim.timeline.speech`).

    A subclass gives ``start``, ``end``, ``label`` and ``curves(times)``; sampling
    adds its curves to the AU tracks' by the subclass's own rule.
    """


@dataclass(frozen=True)
class Timeline:
    """Everything a video shows: tracks, length, frame rate and pass-through settings.

    Parameters
    ----------
    tracks : sequence of Track
        May overlap; order does not matter for sampling.
    duration : float, optional
        Video length in seconds; ``None`` means the end of the last track
        (see :attr:`length`).
    fps : float
        Frames per second (default 30).
    character, engine : str, optional
        Passed through to the renderer untouched.
    blinks : Blinks, optional
        Spontaneous blinks.
    intensities : str
        Table for letters A-E in FACS strings (``"hapfacs"`` or ``"facshuman"``).
    description : str, optional
        Free text; the plot's title.
    """

    tracks: tuple[Track, ...] = ()
    duration: float | None = None
    fps: float = DEFAULT_FPS
    character: str | None = None
    engine: str | None = None
    blinks: Blinks | None = None
    intensities: str = DEFAULT_INTENSITIES
    description: str | None = None

    def __post_init__(self):
        tracks = tuple(self.tracks)
        for i, track in enumerate(tracks):
            if not isinstance(track, (Track, SoundTrack)):
                raise TimelineError(f"expected a Track, got {type(track).__name__}", location=("tracks", i))
        object.__setattr__(self, "tracks", tracks)
        if len(tracks) > limit("max_tracks"):
            raise TimelineError(f"{len(tracks):,} tracks is too many {override_hint('max_tracks')}",
                                location=("tracks",))
        object.__setattr__(self, "fps", positive(self.fps, "fps"))
        try:
            check_fps(self.fps)
        except ValueError as exc:
            raise TimelineError(str(exc).removeprefix("fps "), location=("fps",)) from None
        if self.duration is None:
            if not tracks:
                raise TimelineError("a timeline without tracks needs a duration", location=("duration",))
        else:
            object.__setattr__(self, "duration", positive(self.duration, "duration", " s"))
            for i, track in enumerate(tracks):
                if track.start >= self.duration:
                    raise TimelineError(
                        f"starts at {track.start:g} s, at or after the end of the video (duration "
                        f"{self.duration:g} s), so it would never show", location=("tracks", i))
        for name in ("character", "engine", "description"):
            value = getattr(self, name)
            if value is not None and not isinstance(value, str):
                raise TimelineError(f"expected a string, got {value!r}", location=(name,))
        if self.blinks is not None and not isinstance(self.blinks, Blinks):
            raise TimelineError(f"expected Blinks, got {self.blinks!r}", location=("blinks",))
        intensities_table(self.intensities)
        ends = [track.end for track in tracks if isinstance(track, Track)]   # speech: known once synthesised
        length = self.duration if self.duration is not None else max(ends, default=0.0)
        try:
            check_frames(length * self.fps, f"{length:g} s at {self.fps:g} fps")
        except ValueError as exc:
            raise TimelineError(str(exc), location=("duration",) if self.duration is not None else ()) from None
        for i, track in enumerate(tracks):     # letters must read in this table too
            if isinstance(track, SoundTrack):
                continue
            try:
                track_activations(track, self.intensities)
            except TimelineError as exc:
                raise exc.within("tracks", i) from None

    @property
    def length(self) -> float:
        """The video length in seconds: ``duration``, else the end of the last track."""
        if self.duration is not None:
            return self.duration
        return max(track.end for track in self.tracks)

    @classmethod
    def from_facs(cls, facs, *, start: float = 0.0, end: float, onset: float = 0.0, offset: float = 0.0,
                  intensity: float | str = 1.0, easing: str = "linear", fps: float = DEFAULT_FPS,
                  duration: float | None = None, intensities: str = DEFAULT_INTENSITIES,
                  **settings) -> "Timeline":
        """One FACS string active from ``start`` to ``end``.

        With ``onset``/``offset`` (seconds) the level ramps up after ``start``
        and down before ``end`` (an :class:`Envelope` whose apex fills the
        rest); without them it is a :class:`Hold`.

        Parameters
        ----------
        facs : str or Expression
            FACS notation such as ``"1+2+5B+26"``, or a parsed expression.
        start, end, onset, offset : float
            Seconds.
        intensity : float or str
            Peak level multiplying the string's own intensities.
        easing : str
            For the ramps.
        fps, duration, intensities
            As for :class:`Timeline`; other keywords (``character``,
            ``engine``, ``blinks``, ``description``) too.

        Examples
        --------
        >>> tl = Timeline.from_facs("1+2+5B+26", start=0.2, end=1.4, onset=0.4, offset=0.4)
        >>> tl.tracks[0].timing
        Envelope(start=0.2, onset=0.4, apex=0.4, offset=0.4, intensity=1.0, easing='linear')
        >>> Timeline.from_facs("12", end=1.0).tracks[0].timing
        Hold(start=0.0, end=1.0, intensity=1.0)
        """
        text = facs if isinstance(facs, str) else expression_text(facs, intensities)
        start, end = seconds(start, "start"), seconds(end, "end")
        onset, offset = seconds(onset, "onset"), seconds(offset, "offset")
        if end <= start:
            raise TimelineError(f"must be after start ({start:g} s), got {end:g} s", location=("end",))
        if onset == 0 and offset == 0:
            timing = Hold(start, end, intensity)
        else:
            apex = round(end - start - onset - offset, 9)
            if apex < 0:
                raise TimelineError(f"onset + offset ({onset + offset:g} s) is longer than end - start "
                                    f"({end - start:g} s)", location=("offset",))
            timing = Envelope(start, onset, apex, offset, intensity, easing)
        return cls((Track(facs=text, timing=timing),), duration=duration, fps=fps,
                   intensities=intensities, **settings)


def source_problem(given: Sequence[str]) -> str:
    if not given:
        return "a track needs one of 'au', 'emotion' or 'facs' (what moves)"
    return (f"a track takes one of 'au', 'emotion' or 'facs', got {', '.join(map(repr, given))}; "
            "put each in a track of its own")


SIDE_ONLY_FOR_AU = ("'side' applies only to 'au' tracks; write sides into the FACS string instead "
                     "(e.g. 'L12+L14')")
TABLE_ONLY_FOR_EMOTION = "'table' applies only to 'emotion' tracks (it names the preset table)"


def expression_text(expr, intensities: str) -> str:
    """FACS notation that reads back to ``expr`` exactly under ``intensities``."""
    from facsim.facs.notation import Expression, format_expression

    if not isinstance(expr, Expression):
        raise TypeError(f"expected FACS notation (str) or an Expression, got {type(expr).__name__}")
    return format_expression(expr, intensities=intensities)


@lru_cache(maxsize=1024)
def track_activations(track: Track, intensities: str) -> Activations:
    """The track's activations at level 1 (its intensities before the envelope)."""
    from facsim.facs.notation import ActionUnit, Expression, NotationError, parse

    if track.au is not None:
        expr = Expression((ActionUnit(track.au, 1.0, track.side),))
    elif track.facs is not None:
        try:
            expr = parse(track.facs, intensities=intensities)
        except NotationError as exc:
            raise TimelineError(str(exc), location=("facs",)) from None
    else:
        from facsim.facs.emotions import emotion

        expr = emotion(track.emotion, **({"table": track.table} if track.table else {}), intensities=intensities)
    return activations(expr)


# -------------------------------------------------------------- sampling ---
