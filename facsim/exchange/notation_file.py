"""``.facs``: FACS notation over time, a compact text that round-trips timelines losslessly.

The notation is the "tie point" between coders, stimuli and simulators: AUs
and when they act, small enough to mail or keep beside a video. A ``.facs``
file holds exactly what a :class:`~facsim.timeline.Timeline` holds, so
``loads_notation(dumps_notation(tl)) == tl`` for every timeline (numbers are
written as Python's shortest round-tripping decimals).

Example
-------
::

    facsim-notation 1
    # Surprise, then a one-sided smile.          <- '#' starts a comment
    fps: 30
    duration: 3
    description: "Surprise, then a smirk"
    blinks: rate=17 duration=0.25 seed=0 min_interval=1

    [1+2+5B+26]  0.2+0.4/0.4/0.4~sigmoid          <- FACS string, envelope
    happiness    0.5-1.5@0.5                      <- emotion preset, hold at 50 %
    sadness/emfacs 1+0.5/0/0.5                    <- preset from a named table
    AU12L        0:0>0.8:C~smoothstep>1.6:0;2:0.3>2.5:0   <- AU track, segments
    say "Pack my box." voice=slt @0.5             <- speech (facsim.timeline.speech)

Grammar
-------
One setting or track per line; blank lines and comments are ignored; settings
come before the first track::

    file      = "facsim-notation 1" NL { line NL }
    setting   = key ":" SP value
        fps: NUMBER                      duration: NUMBER
        intensities: hapfacs|facshuman   (letter table for levels and FACS strings)
        character: STRING                engine: STRING
        description: STRING
        blinks: {name "=" NUMBER}        rate, duration, seed, min_interval (defaults as Blinks)
    STRING    = bare word without spaces, '"' or '#'  |  a JSON string "..."
    track     = source SP timing  |  speech
    speech    = "say" SP JSON-STRING [ SP "voice=" STRING ] SP "@" TIME     synthesised text from TIME
              | "audio" SP STRING SP JSON-STRING SP "@" TIME           a recording and its transcript
    source    = "AU" CODE [ "L" | "R" | "U" ]    one AU: both sides, left, right, unilateral
              | "[" FACS "]"  |  JSON string     a FACS string (its intensities times the level)
              | NAME [ "/" TABLE ]               an emotion preset (and its table)
    timing    = hold | envelope | segments       (no spaces inside)
    hold      = TIME "-" TIME [ "@" LEVEL ]                          constant from start to end
    envelope  = TIME "+" TIME "/" TIME "/" TIME [ "@" LEVEL ] [ "~" EASING ]
                                                 start + onset / apex / offset
    segments  = chain { ";" chain }              a new chain after a gap or a jump
    chain     = point { ">" point [ "~" EASING ] }
                                                 each link is one segment; its easing follows its end point
    point     = TIME ":" LEVEL
    LEVEL     = NUMBER (0..1) | NUMBER "%" | letter A-E (read with `intensities`)
    TIME      = NUMBER (seconds >= 0)

Every error names the line and the column, e.g.
``timeline.facs:7:14: expected a level (0..1, 55% or A-E) after ':'``.
"""
from __future__ import annotations

import json
import re
from pathlib import Path

from facsim.exchange import ExchangeError, write_file

HEADER = "facsim-notation"
VERSION = "1"
SETTINGS = ("fps", "duration", "intensities", "character", "engine", "description", "blinks")
BLINK_FIELDS = ("rate", "duration", "seed", "min_interval")
_BLINK_ATTR = {"rate": "rate_per_minute"}
_SIDE_SUFFIX = {"both": "", "left": "L", "right": "R", "unilateral": "U"}
_SUFFIX_SIDE = {v: k for k, v in _SIDE_SUFFIX.items()}

# ASCII digits only (\d alone would read '١٢' as 12); codes of at most 4 digits (int() of 5,000 digits raises).
_NUMBER = re.compile(r"(?:\d+(?:\.\d*)?|\.\d+)(?:[eE][-+]?\d+)?", re.ASCII)
_WORD = re.compile(r"[A-Za-z][A-Za-z0-9_-]*")
_BARE = re.compile(r"[^\s\"#]+")
_AU = re.compile(r"AU(\d{1,4})([LRU]?)(?=\s|$)", re.ASCII)
_KEY = re.compile(r"([a-z_]+):(?=\s|$)")
_SPEECH = re.compile(r"(say|audio)[ \t]+")


class NotationFileError(ExchangeError):
    """A ``.facs`` text that cannot be read: ``file:line:column: problem``."""


# ------------------------------------------------------------------ write ---

def _num(value: float) -> str:
    value = float(value)
    return str(int(value)) if value.is_integer() and abs(value) < 1e15 else repr(value)


def _string(text: str) -> str:
    return text if _BARE.fullmatch(text) else json.dumps(text, ensure_ascii=False)


def _source_text(track) -> str:
    if track.au is not None:
        return f"AU{track.au}{_SIDE_SUFFIX[track.side]}"
    if track.facs is not None:
        text = track.facs
        return f"[{text}]" if not set(text) & set("]\n\r\"") else json.dumps(text, ensure_ascii=False)
    return track.emotion + (f"/{track.table}" if track.table is not None else "")


def _is_speech(track) -> bool:
    return hasattr(track, "say")


def _speech_text(track) -> str:
    if track.say is not None:
        voice = "" if track.voice is None else f" voice={_string(track.voice)}"
        return f"say {json.dumps(track.say, ensure_ascii=False)}{voice} @{_num(track.start)}"
    return f"audio {_string(track.audio)} {json.dumps(track.transcript, ensure_ascii=False)} @{_num(track.start)}"


def _ends(level: float, easing: str = "linear") -> str:
    return ("" if level == 1.0 else f"@{_num(level)}") + ("" if easing == "linear" else f"~{easing}")


def _timing_text(timing) -> str:
    from facsim.timeline.model import Envelope, Hold

    if isinstance(timing, Hold):
        return f"{_num(timing.start)}-{_num(timing.end)}{_ends(timing.intensity)}"
    if isinstance(timing, Envelope):
        t = timing
        return f"{_num(t.start)}+{_num(t.onset)}/{_num(t.apex)}/{_num(t.offset)}{_ends(t.intensity, t.easing)}"
    chains, previous = [], None
    for seg in timing:
        link = f">{_num(seg.end)}:{_num(seg.to)}" + ("" if seg.easing == "linear" else f"~{seg.easing}")
        if previous is not None and seg.start == previous.end and seg.from_ == previous.to:
            chains[-1] += link
        else:
            chains.append(f"{_num(seg.start)}:{_num(seg.from_)}{link}")
        previous = seg
    return ";".join(chains)


def dumps_notation(timeline) -> str:
    """The timeline as ``.facs`` text (see the module docstring); :func:`loads_notation` reads it back equal."""
    lines = [f"{HEADER} {VERSION}", f"fps: {_num(timeline.fps)}"]
    if timeline.duration is not None:
        lines.append(f"duration: {_num(timeline.duration)}")
    lines.append(f"intensities: {timeline.intensities}")
    for name in ("character", "engine", "description"):
        if getattr(timeline, name) is not None:
            lines.append(f"{name}: {_string(getattr(timeline, name))}")
    if timeline.blinks is not None:
        b = timeline.blinks
        lines.append(f"blinks: rate={_num(b.rate_per_minute)} duration={_num(b.duration)} seed={b.seed} "
                     f"min_interval={_num(b.min_interval)}")
    if timeline.tracks:
        lines.append("")
    timed = [track for track in timeline.tracks if not _is_speech(track)]
    sources = {id(track): _source_text(track) for track in timed}
    width = max(map(len, sources.values()), default=0)
    for track in timeline.tracks:
        if _is_speech(track):
            lines.append(_speech_text(track))
        else:
            lines.append(f"{sources[id(track)].ljust(width)}  {_timing_text(track.timing)}")
    return "\n".join(lines) + "\n"


def write_notation(timeline, path) -> Path:
    """Write ``timeline`` as a ``.facs`` file, atomically; returns the path."""
    return write_file(path, dumps_notation(timeline))


# ------------------------------------------------------------------- read ---

class _Line:
    """A cursor over one line; errors carry its line number and the cursor's column."""

    def __init__(self, text: str, number: int):
        self.text, self.lineno, self.pos = text, number, 0
        self.segment_starts: list[int] = []

    def error(self, problem: str, pos: int | None = None) -> NotationFileError:
        return NotationFileError(problem, line=self.lineno, column=(self.pos if pos is None else pos) + 1)

    def peek(self) -> str:
        return self.text[self.pos] if self.pos < len(self.text) else ""

    def at_end(self) -> bool:
        return self.pos >= len(self.text)

    def skip_space(self) -> None:
        while self.peek() in (" ", "\t"):
            self.pos += 1

    def match(self, pattern: re.Pattern, what: str) -> re.Match:
        found = pattern.match(self.text, self.pos)
        if not found:
            got = "the end of the line" if self.at_end() else repr(self.text[self.pos:].split(None, 1)[0][:20])
            raise self.error(f"expected {what}, got {got}")
        self.pos = found.end()
        return found

    def accept(self, char: str) -> bool:
        if self.peek() == char:
            self.pos += 1
            return True
        return False

    def number(self, what: str) -> float:
        return float(self.match(_NUMBER, what).group())

    def json_string(self) -> str:
        try:
            value, end = json.JSONDecoder().raw_decode(self.text, self.pos)
        except json.JSONDecodeError as exc:
            raise self.error(f"malformed quoted string: {exc.msg}", exc.pos) from None
        if not isinstance(value, str):
            raise self.error("expected a quoted string")
        self.pos = end
        return value


def _strip_comment(text: str) -> str:
    """The line without its comment ('#' outside quotes and brackets) and trailing space."""
    quoted, depth, escape = False, 0, False
    for i, char in enumerate(text):
        if quoted:
            if escape:
                escape = False
            elif char == "\\":
                escape = True
            elif char == '"':
                quoted = False
        elif char == '"':
            quoted = True
        elif char == "[":
            depth += 1
        elif char == "]":
            depth = max(0, depth - 1)
        elif char == "#" and depth == 0:
            return text[:i].rstrip()
    return text.rstrip()


def _level(line: _Line, table: str) -> float:
    from facsim.facs.catalogue import intensity_of

    start = line.pos
    letter = re.compile(r"[A-Ea-e](?![A-Za-z0-9])").match(line.text, line.pos)
    if letter:
        line.pos = letter.end()
        return intensity_of(letter.group(), table)
    found = _NUMBER.match(line.text, line.pos)
    if not found:
        raise line.error("expected a level (a fraction 0..1, a percentage like 55% or a letter A-E)")
    line.pos = found.end()
    value = float(found.group()) / (100.0 if line.accept("%") else 1.0)
    if not 0.0 <= value <= 1.0:
        raise line.error(f"level {line.text[start:line.pos]!r} is outside 0..1 (0% to 100%)", start)
    return value


def _easing(line: _Line) -> str:
    from facsim.timeline.easing import EASINGS

    start = line.pos
    name = line.match(_WORD, "an easing name").group()
    if name not in EASINGS:
        raise line.error(f"unknown easing {name!r}; choose one of {', '.join(sorted(EASINGS))}", start)
    return name


def _segments(line: _Line, table: str) -> tuple:
    from facsim.timeline.model import Segment, TimelineError

    segments = []
    line.segment_starts = []                 # where each segment's start point is, for Track's errors
    while True:
        t0_at = line.pos
        t0 = line.number("a time in seconds")
        if not line.accept(":"):
            raise line.error("expected ':' and a level after the time")
        v0 = _level(line, table)
        if line.peek() != ">":
            raise line.error("expected '>' and the next point (TIME:LEVEL)")
        while line.accept(">"):
            start = line.pos
            t1 = line.number("a time in seconds")
            if not line.accept(":"):
                raise line.error("expected ':' and a level after the time")
            v1 = _level(line, table)
            easing = _easing(line) if line.accept("~") else "linear"
            try:
                segments.append(Segment(t0, t1, v0, v1, easing))
            except TimelineError as exc:
                raise line.error(f"segment {t0:g}-{t1:g} s: {exc.problem}", start) from None
            line.segment_starts.append(t0_at)
            t0, v0, t0_at = t1, v1, start
        if not line.accept(";"):
            return tuple(segments)


def _timing(line: _Line, table: str):
    from facsim.timeline.model import Envelope, Hold, TimelineError

    start = line.pos
    first = line.number("a timing: START-END, START+ONSET/APEX/OFFSET or TIME:LEVEL>TIME:LEVEL")
    kind = line.peek()
    if kind == ":":
        line.pos = start
        return _segments(line, table)
    if kind not in ("-", "+"):
        raise line.error("expected '-' (hold: START-END), '+' (envelope: START+ONSET/APEX/OFFSET) or ':' "
                         "(segments: TIME:LEVEL>TIME:LEVEL) after the start time")
    line.pos += 1
    if kind == "-":
        end = line.number("the end time")
        level = _level(line, table) if line.accept("@") else 1.0
        if line.peek() == "~":
            raise line.error("a hold has no easing (it steps on and off); use an envelope or segments")
        build = lambda: Hold(first, end, level)  # noqa: E731
    else:
        onset = line.number("the onset duration")
        parts = []
        for name in ("apex", "offset"):
            if not line.accept("/"):
                raise line.error(f"expected '/' and the {name} duration (START+ONSET/APEX/OFFSET)")
            parts.append(line.number(f"the {name} duration"))
        level = _level(line, table) if line.accept("@") else 1.0
        easing = _easing(line) if line.accept("~") else "linear"
        build = lambda: Envelope(first, onset, parts[0], parts[1], level, easing)  # noqa: E731
    try:
        return build()
    except TimelineError as exc:
        raise line.error(exc.problem, start) from None


def _track(line: _Line, table: str, folder=None):
    from facsim.timeline.model import Track, TimelineError

    start = line.pos
    source: dict = {}
    if _SPEECH.match(line.text, start):
        return _speech_track(line, folder)
    if line.text.startswith("AU", start) and _AU.match(line.text, start):
        found = line.match(_AU, "an AU")
        source = {"au": int(found.group(1)), "side": _SUFFIX_SIDE[found.group(2)]}
    elif line.accept("["):
        close = line.text.find("]", line.pos)
        if close < 0:
            raise line.error("missing ']' after the FACS string", start)
        source = {"facs": line.text[line.pos:close]}
        line.pos = close + 1
    elif line.peek() == '"':
        source = {"facs": line.json_string()}
    else:
        name = line.match(_WORD, "a track: an AU (AU12, AU12L), a [FACS string] or an emotion name").group()
        source = {"emotion": name}
        if line.accept("/"):
            source["table"] = line.match(_WORD, "an emotion table name after '/'").group()
    if line.peek() not in (" ", "\t"):
        raise line.error("expected a space and the timing after the source")
    line.skip_space()
    timing_at = line.pos
    timing = _timing(line, table)
    if not line.at_end():
        raise line.error("unexpected text after the timing (no spaces inside a timing; '#' starts a comment)")
    try:
        return Track(timing=timing, **source)
    except TimelineError as exc:
        where = start
        if exc.location[:1] == ("segments",):
            index = exc.location[1] if len(exc.location) > 1 else 0
            where = line.segment_starts[index] if index < len(line.segment_starts) else timing_at
        raise line.error(exc.problem, where) from None


def _speech_track(line: _Line, folder=None):
    from facsim.timeline.speech import SpeechTrack
    from facsim.timeline.model import TimelineError

    start = line.pos
    kind = line.match(_SPEECH, "say or audio").group(1)
    fields: dict = {}
    if kind == "say":
        if line.peek() != '"':
            raise line.error('expected the text to say in double quotes, e.g. say "Hello." @0')
        fields["say"] = line.json_string()
        line.skip_space()
        if line.text.startswith("voice=", line.pos):
            line.pos += len("voice=")
            fields["voice"] = line.json_string() if line.peek() == '"' else line.match(_BARE, "a voice name").group()
            line.skip_space()
    else:
        audio = line.json_string() if line.peek() == '"' else line.match(_BARE, "an audio file").group()
        fields["audio"] = audio if folder is None or Path(audio).is_absolute() else str(Path(folder) / audio)
        line.skip_space()
        if line.peek() != '"':
            raise line.error('expected the transcript in double quotes after the audio file')
        fields["transcript"] = line.json_string()
        line.skip_space()
    if not line.accept("@"):
        raise line.error("expected '@' and the start time, e.g. @0.5")
    fields["start"] = line.number("a start time in seconds")
    if not line.at_end():
        raise line.error("unexpected text after the speech track's start time")
    try:
        return SpeechTrack(**fields)
    except TimelineError as exc:
        raise line.error(exc.problem, start) from None


def _setting_value(line: _Line, key: str, settings: dict):
    from facsim.facs.catalogue import INTENSITY_TABLES
    from facsim.timeline.model import Blinks, TimelineError

    start = line.pos
    if key in ("fps", "duration"):
        value = line.number(f"a number for {key}")
    elif key == "intensities":
        value = line.match(_WORD, "an intensity table name").group()
        if value not in INTENSITY_TABLES:
            raise line.error(f"unknown intensity table {value!r}; choose one of {', '.join(INTENSITY_TABLES)}", start)
    elif key == "blinks":
        fields: dict = {}
        while not line.at_end():
            at = line.pos
            name = line.match(_WORD, "a blinks field (rate=, duration=, seed=, min_interval=)").group()
            if name not in BLINK_FIELDS:
                raise line.error(f"unknown blinks field {name!r}; use {', '.join(BLINK_FIELDS)}", at)
            if name in fields:
                raise line.error(f"blinks field {name!r} given twice", at)
            if not line.accept("="):
                raise line.error(f"expected '=' and a number after {name!r}")
            number = line.number(f"a number for {name}")
            fields[_BLINK_ATTR.get(name, name)] = int(number) if name == "seed" and number.is_integer() else number
            line.skip_space()
        try:
            value = Blinks(**fields)
        except TimelineError as exc:
            raise line.error(f"blinks {exc.path}: {exc.problem}" if exc.path else exc.problem, start) from None
    else:
        value = line.json_string() if line.peek() == '"' else line.match(_BARE, f"a value for {key}").group()
    if not line.at_end():
        raise line.error(f"unexpected text after the {key} value (quote values with spaces: \"...\")")
    return value


def loads_notation(text: str, *, folder=None):
    """Read ``.facs`` text into a :class:`~facsim.timeline.Timeline` (grammar in the module docstring).

    Relative audio files of speech tracks are read from ``folder`` (default: the working folder).

    Raises
    ------
    NotationFileError
        Naming the line and column and what is wrong.
    """
    from facsim.timeline.model import DEFAULT_FPS, DEFAULT_INTENSITIES, Timeline, TimelineError

    rows = text.splitlines()
    first = next((i for i, row in enumerate(rows) if _strip_comment(row).strip()), None)
    if first is None:
        raise NotationFileError(f"empty file; a .facs file starts with '{HEADER} {VERSION}'", line=1, column=1)
    header = _strip_comment(rows[first]).split()
    if header[:1] != [HEADER]:
        raise NotationFileError(f"expected the header '{HEADER} {VERSION}', got {rows[first].strip()[:40]!r}",
                                line=first + 1, column=1)
    if header[1:] != [VERSION]:
        raise NotationFileError(f"unsupported {HEADER} version {' '.join(header[1:]) or '(none)'!r}; this facsim "
                                f"reads version {VERSION}", line=first + 1, column=len(HEADER) + 2)
    settings: dict = {}
    setting_lines: dict = {}
    tracks, track_lines = [], []
    for index in range(first + 1, len(rows)):
        line = _Line(_strip_comment(rows[index]), index + 1)
        line.skip_space()
        if line.at_end():
            continue
        key = _KEY.match(line.text, line.pos)
        if key:
            name = key.group(1)
            if name not in SETTINGS:
                raise line.error(f"unknown setting {name!r}; settings are {', '.join(SETTINGS)}")
            if tracks:
                raise line.error(f"setting {name!r} after the first track (line {track_lines[0]}); "
                                 "settings go before the tracks")
            if name in settings:
                raise line.error(f"{name!r} given twice (first on line {setting_lines[name]})")
            line.pos = key.end()
            line.skip_space()
            settings[name] = _setting_value(line, name, settings)
            setting_lines[name] = line.lineno
            continue
        tracks.append(_track(line, settings.get("intensities", DEFAULT_INTENSITIES), folder))
        track_lines.append(line.lineno)
    try:
        return Timeline(tuple(tracks), duration=settings.get("duration"), fps=settings.get("fps", DEFAULT_FPS),
                        character=settings.get("character"), engine=settings.get("engine"),
                        blinks=settings.get("blinks"), description=settings.get("description"),
                        intensities=settings.get("intensities", DEFAULT_INTENSITIES))
    except TimelineError as exc:
        loc = exc.location
        if loc[:1] == ("tracks",) and len(loc) > 1:
            line_no, problem = track_lines[loc[1]], exc.problem
        else:
            line_no = setting_lines.get(loc[0] if loc else "duration", first + 1)
            problem = exc.problem if not loc or loc[0] in setting_lines else f"{exc.path}: {exc.problem}"
        raise NotationFileError(problem, line=line_no, column=1) from None


def read_notation(path):
    """Read a ``.facs`` file (see :func:`loads_notation`); errors name the file."""
    from facsim.exchange import check_input_size

    path = Path(path)
    check_input_size(path)
    try:
        return loads_notation(path.read_text(encoding="utf-8"), folder=path.parent)
    except NotationFileError as exc:
        raise exc.in_file(path) from None
    except UnicodeDecodeError as exc:
        raise NotationFileError(f"not UTF-8 text ({exc.reason} at byte {exc.start})", file=path) from None
