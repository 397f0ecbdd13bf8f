"""Timeline files and plain data: YAML/JSON text <-> dict <-> :class:`~facsim.timeline.Timeline`.

The file format itself (fields, timings, intensities) is described in
:mod:`facsim.timeline.model`, whose data types this module builds and takes apart.
Here live the ways in and out:

* :func:`timeline_from_dict` / :func:`timeline_to_dict`: parsed YAML/JSON
  (plain dicts and lists) to a :class:`~facsim.timeline.Timeline` and back,
  equal after the round trip;
* :func:`load_timeline` / :func:`save_timeline`: ``.yaml``/``.yml`` and
  ``.json`` files, by suffix, written atomically;
* :func:`timeline_schema`: the JSON Schema (``facsim/data/timeline.schema.json``,
  draft 2020-12) every dict is checked against first.

Whatever goes wrong (a schema violation, malformed YAML or JSON, a value the
data types refuse) comes out as one :class:`~facsim.timeline.TimelineError`
naming the file, the line where known, the field path and what is wrong.

Examples
--------
>>> tl = timeline_from_dict({"tracks": [{"au": 12, "start": 0, "end": 1}]})
>>> timeline_to_dict(tl)["tracks"]
[{'au': 12, 'side': 'both', 'start': 0, 'end': 1, 'intensity': 1}]
"""
from __future__ import annotations

import difflib
import json
import os
from functools import lru_cache
from importlib import resources
from pathlib import Path
from typing import Any, Mapping, Sequence

from facsim.atomic import atomic_write
from facsim.limits import check_file_size, limit, override_hint, short
from facsim.timeline.model import ENVELOPE_KEYS, SIDE_ONLY_FOR_AU, TABLE_ONLY_FOR_EMOTION, DEFAULT_FPS, DEFAULT_INTENSITIES, Blinks, Envelope, Hold, Segment, Timeline, TimelineError, Timing, Track, intensities_table, parse_level, source_problem

SCHEMA_FILE = "timeline.schema.json"
_SUFFIXES = {".yaml": "yaml", ".yml": "yaml", ".json": "json"}


# --------------------------------------------------------- dict <-> data ---

@lru_cache(maxsize=1)
def _schema_text() -> str:
    return resources.files("facsim").joinpath("data", SCHEMA_FILE).read_text(encoding="utf-8")


def timeline_schema() -> dict:
    """The timeline JSON Schema (draft 2020-12), as a fresh dict.

    Examples
    --------
    >>> timeline_schema()["$schema"]
    'https://json-schema.org/draft/2020-12/schema'
    """
    return json.loads(_schema_text())


@lru_cache(maxsize=1)
def _validator():
    from jsonschema import Draft202012Validator

    schema = timeline_schema()
    Draft202012Validator.check_schema(schema)
    return Draft202012Validator(schema)


_TYPE_NAMES = {"number": "a number", "integer": "an integer", "string": "a string", "object": "a mapping",
               "array": "a list", "boolean": "true or false"}


def _timing_problem(track: Mapping) -> str:
    keys = set(track)
    envelope = keys & set(ENVELOPE_KEYS)
    if "segments" in keys:
        extra = sorted(keys & {"start", "end", "onset", "apex", "offset", "intensity", "easing"})
        return (f"'segments' gives the whole timing; drop {', '.join(map(repr, extra))} "
                "(each segment has its own start, end and easing)")
    if envelope and "end" in keys:
        return "give either 'end' (a constant hold) or an envelope ('onset', 'apex', 'offset'), not both"
    if envelope:
        missing = [k for k in ENVELOPE_KEYS if k not in keys]
        return f"an envelope needs 'onset', 'apex' and 'offset'; missing {', '.join(map(repr, missing))} " \
               "(0 is allowed)"
    if "end" in keys and "easing" in keys:
        return "'easing' has no effect on a constant hold ('start' to 'end'); use an envelope or segments"
    return ("no timing: give 'segments', an envelope ('start', 'onset', 'apex', 'offset') "
            "or 'start' and 'end' for a constant hold")


def _source_problem_in(track: Mapping) -> str:
    given = [k for k in ("au", "emotion", "facs") if k in track]
    if len(given) != 1:
        return source_problem(given)
    if "side" in track and "au" not in track:
        return SIDE_ONLY_FOR_AU
    return TABLE_ONLY_FOR_EMOTION


def _intensity_problem(value: Any) -> str:
    try:
        parse_level(value, "intensity", DEFAULT_INTENSITIES)
    except TimelineError as exc:
        return exc.problem
    return f"expected an intensity (a fraction 0..1, a percentage or a letter A-E), got {value!r}"


def _schema_problem(error) -> tuple[tuple, str]:
    """Turn one jsonschema error into (field path, problem)."""
    location = tuple(error.absolute_path)
    schema = error.schema if isinstance(error.schema, dict) else {}
    marker, kind, value = schema.get("x-facsim"), error.validator, error.validator_value
    instance = error.instance
    name = next((k for k in reversed(location) if isinstance(k, str)), "value")
    if marker == "intensity":
        return location, _intensity_problem(instance)
    if marker == "track-timing":
        return location, _timing_problem(instance)
    if marker == "speech-source":
        return location, ("a speech track takes 'say' (text, with an optional 'voice') or 'audio' "
                          "(a WAV file) with 'transcript'")
    if marker == "track-source" or "dependentSchemas" in error.schema_path:
        return location, _source_problem_in(instance)
    if kind == "additionalProperties":
        allowed = list(schema.get("properties", {}))
        extra = sorted((k for k in instance if k not in allowed), key=str)[0]   # keys may mix types
        close = difflib.get_close_matches(str(extra), allowed, n=1)
        hint = f"; did you mean {close[0]!r}?" if close else f"; known fields are {', '.join(allowed)}"
        return location, f"unknown field {extra!r}{hint}"
    if kind == "required":
        missing = [k for k in value if k not in instance]
        return location, f"missing field {missing[0]!r}"
    if kind == "type":
        expected = " or ".join(_TYPE_NAMES.get(t, t) for t in ([value] if isinstance(value, str) else value))
        return location, f"expected {expected}, got {short(instance)}"
    if kind == "enum":
        return location, f"unknown {name} {short(instance)}; choose one of {', '.join(map(str, value))}"
    if kind == "minimum" and name in ("start", "end", "onset", "apex", "offset"):
        return location, (f"negative time {instance:g} s; times are seconds from the start of the video "
                          "and must be >= 0")
    if kind in ("minimum", "exclusiveMinimum", "maximum", "exclusiveMaximum"):
        sign = {"minimum": ">=", "exclusiveMinimum": ">", "maximum": "<=", "exclusiveMaximum": "<"}[kind]
        return location, f"must be {sign} {value:g}, got {short(instance)}"
    if kind in ("minItems", "minLength"):
        return location, "must not be empty"
    if kind == "maxLength":
        return location, f"{len(instance):,} characters is too long; at most {value:,}"
    return location, short(error.message, 200)


def _depth_problem(data: Any) -> str | None:
    """Why ``data`` is nested too deeply, too big or has too many tracks, else None (iterative: no recursion)."""
    tracks = data.get("tracks") if isinstance(data, Mapping) else None
    if isinstance(tracks, list) and len(tracks) > limit("max_tracks"):
        return f"{len(tracks):,} tracks is too many {override_hint('max_tracks')}"
    most, most_values, seen = limit("max_depth"), limit("max_values"), 0
    stack = [(data, 1)]
    while stack:
        value, depth = stack.pop()
        seen += 1
        if seen > most_values:       # JSON has no reader-level count (YAML does): the schema check would crawl
            return (f"more than {most_values:,} values in one timeline {override_hint('max_values')}; "
                    "long recordings are smaller and faster as .facs")
        if depth > most:
            return f"lists and mappings nested more than {most} deep {override_hint('max_depth')}"
        if isinstance(value, Mapping):
            stack.extend((v, depth + 1) for v in value.values())
        elif isinstance(value, (list, tuple)):
            stack.extend((v, depth + 1) for v in value)
    return None


def _location_key(location: tuple) -> tuple:
    return tuple((0, k, "") if isinstance(k, int) else (1, 0, str(k)) for k in location)


_FIRST = {"additionalProperties": 0, "type": 1}


def _check_schema(data: Any) -> None:
    errors = list(_validator().iter_errors(data))
    if not errors:
        return
    first = min(errors, key=lambda e: (_location_key(tuple(e.absolute_path)), _FIRST.get(e.validator, 2)))
    location, problem = _schema_problem(first)
    raise TimelineError(problem, location=location)


def _segments_from(items: Sequence[Mapping], table: str) -> tuple[Segment, ...]:
    segments, previous = [], 0.0
    for j, item in enumerate(items):
        try:
            start_level = parse_level(item["from"], "from", table) if "from" in item else previous
            seg = Segment(item["start"], item["end"], start_level, parse_level(item["to"], "to", table),
                          item.get("easing", "linear"))
        except TimelineError as exc:
            raise exc.within("segments", j) from None
        segments.append(seg)
        previous = seg.to
    return tuple(segments)


def _track_from_dict(data: Mapping, table: str, folder: Path | None = None) -> Track:
    if "say" in data or "audio" in data:
        from facsim.timeline.speech import SpeechTrack

        audio = data.get("audio")
        if audio is not None and folder is not None and not Path(audio).is_absolute():
            audio = str(folder / audio)
        return SpeechTrack(say=data.get("say"), voice=data.get("voice"), audio=audio,
                           transcript=data.get("transcript"), start=data.get("start", 0.0))
    if "segments" in data:
        timing = _segments_from(data["segments"], table)
    else:
        intensity = parse_level(data.get("intensity", 1.0), "intensity", table)
        if all(k in data for k in ENVELOPE_KEYS) and "end" not in data:
            timing = Envelope(data.get("start", 0.0), data["onset"], data["apex"], data["offset"], intensity,
                              data.get("easing", "linear"))
        elif "end" in data and not any(k in data for k in (*ENVELOPE_KEYS, "easing")):
            timing = Hold(data.get("start", 0.0), data["end"], intensity)
        else:
            raise TimelineError(_timing_problem(data))
    return Track(au=data.get("au"), side=data.get("side", "both"), facs=data.get("facs"),
                 emotion=data.get("emotion"), table=data.get("table"), timing=timing)


def timeline_from_dict(data: Mapping, *, folder=None) -> Timeline:
    """Build a :class:`Timeline` from parsed YAML/JSON (see the module docstring).

    Raises
    ------
    TimelineError
        Naming the field path and what is wrong (schema violations, unknown
        codes or emotions, reversed or overlapping times...).

    Examples
    --------
    >>> tl = timeline_from_dict({"tracks": [{"au": 12, "start": 0, "end": 1, "intensity": "C"}]})
    >>> tl.tracks[0].timing
    Hold(start=0.0, end=1.0, intensity=0.55)
    >>> timeline_from_dict({"tracks": [{"au": 12, "segments": [{"start": 1.4, "end": 0.2, "to": 1}]}]})
    Traceback (most recent call last):
    ...
    facsim.timeline.model.TimelineError: tracks[0].segments[0].end: must be after start (1.4 s), got 0.2 s
    """
    if not isinstance(data, Mapping):
        what = "nothing (the file is empty)" if data is None else type(data).__name__
        raise TimelineError(f"expected a mapping with 'tracks' at the top level, got {what}")
    problem = _depth_problem(data)         # before the schema check, which would take minutes or recurse
    if problem:
        raise TimelineError(problem)
    _check_schema(data)
    table = data.get("intensities", DEFAULT_INTENSITIES)
    intensities_table(table)
    blinks = None
    if "blinks" in data:
        try:
            blinks = Blinks(**data["blinks"])
        except TimelineError as exc:
            raise exc.within("blinks") from None
    tracks = []
    for i, item in enumerate(data.get("tracks", [])):
        try:
            tracks.append(_track_from_dict(item, table, None if folder is None else Path(folder)))
        except TimelineError as exc:
            raise exc.within("tracks", i) from None
    return Timeline(tuple(tracks), duration=data.get("duration"), fps=data.get("fps", DEFAULT_FPS),
                    character=data.get("character"), engine=data.get("engine"), blinks=blinks,
                    intensities=table, description=data.get("description"))


def _number(value: float) -> float | int:
    """Integral floats as ints, for tidy files (``30`` rather than ``30.0``)."""
    return int(value) if float(value).is_integer() else float(value)


def _timing_to_dict(timing: Timing) -> dict:
    if isinstance(timing, Envelope):
        return {"start": _number(timing.start), "onset": _number(timing.onset), "apex": _number(timing.apex),
                "offset": _number(timing.offset), "intensity": _number(timing.intensity),
                "easing": timing.easing}
    if isinstance(timing, Hold):
        return {"start": _number(timing.start), "end": _number(timing.end),
                "intensity": _number(timing.intensity)}
    return {"segments": [{"start": _number(s.start), "end": _number(s.end), "from": _number(s.from_),
                          "to": _number(s.to), "easing": s.easing} for s in timing]}


def timeline_to_dict(timeline: Timeline) -> dict:
    """The timeline as plain data for YAML/JSON; :func:`timeline_from_dict` reads it back equal.

    Intensities are written as fractions (letters read from a file become
    numbers); unset optional fields are left out.

    Examples
    --------
    >>> tl = Timeline.from_facs("12C", end=1.0)
    >>> timeline_to_dict(tl)["tracks"]
    [{'facs': '12C', 'start': 0, 'end': 1, 'intensity': 1}]
    >>> timeline_from_dict(timeline_to_dict(tl)) == tl
    True
    """
    out: dict[str, Any] = {}
    if timeline.description is not None:
        out["description"] = timeline.description
    if timeline.duration is not None:
        out["duration"] = _number(timeline.duration)
    out["fps"] = _number(timeline.fps)
    for name in ("character", "engine"):
        if getattr(timeline, name) is not None:
            out[name] = getattr(timeline, name)
    out["intensities"] = timeline.intensities
    if timeline.blinks is not None:
        b = timeline.blinks
        out["blinks"] = {"rate_per_minute": _number(b.rate_per_minute), "duration": _number(b.duration),
                         "seed": b.seed, "min_interval": _number(b.min_interval)}
    tracks = []
    for track in timeline.tracks:
        item: dict[str, Any] = {}
        if not isinstance(track, Track):          # a speech track
            tracks.append(_speech_to_dict(track))
            continue
        if track.au is not None:
            item["au"] = track.au
            item["side"] = track.side
        elif track.facs is not None:
            item["facs"] = track.facs
        else:
            item["emotion"] = track.emotion
            if track.table is not None:
                item["table"] = track.table
        item.update(_timing_to_dict(track.timing))
        tracks.append(item)
    out["tracks"] = tracks
    return out


def _speech_to_dict(track) -> dict:
    item: dict[str, Any] = {"say": track.say} if track.say is not None else {"audio": track.audio,
                                                                            "transcript": track.transcript}
    if track.voice is not None:
        item["voice"] = track.voice
    item["start"] = _number(track.start)
    return item


# ------------------------------------------------------------------ files ---

def _format_of(path: Path) -> str:
    try:
        return _SUFFIXES[path.suffix.lower()]
    except KeyError:
        raise TimelineError(f"unsupported file type {path.suffix or '(none)'!r}; use .yaml, .yml or .json",
                            file=path) from None


@lru_cache(maxsize=1)
def _guarded_loader():
    """yaml.SafeLoader that refuses aliases and nesting deeper than the depth limit.

    Aliases are how a few hundred bytes expand to gigabytes ("billion laughs");
    deep nesting is how they reach Python's recursion limit. Timeline files need neither.
    """
    import yaml

    class GuardedLoader(yaml.SafeLoader):
        def __init__(self, stream):
            super().__init__(stream)
            self._depth, self._values = 0, 0
            self._most_depth, self._most_values = limit("max_depth"), limit("max_values")
            self._most_tracks = limit("max_tracks")

        def compose_node(self, parent, index):
            if self.check_event(yaml.AliasEvent):
                event = self.peek_event()
                raise yaml.composer.ComposerError(None, None, "YAML aliases (*name) are not allowed in "
                                                  "facsim input files; write the value out", event.start_mark)
            self._depth += 1
            self._values += 1
            if self._values > self._most_values:     # checked while reading: parsing is the slow part
                raise yaml.composer.ComposerError(
                    None, None, f"more than {limit('max_values'):,} values in one file "
                    f"{override_hint('max_values')}; long recordings are smaller and faster as .facs",
                    self.peek_event().start_mark)
            # Items of a top-level list (the tracks), counted as they are read: a million of them
            # would take minutes to parse before the track limit could be checked.
            if self._depth == 3 and isinstance(parent, yaml.SequenceNode) and index >= self._most_tracks:
                self._depth -= 1
                raise yaml.composer.ComposerError(
                    None, None, f"more than {self._most_tracks:,} tracks {override_hint('max_tracks')}",
                    self.peek_event().start_mark)
            try:
                if self._depth > self._most_depth:
                    raise yaml.composer.ComposerError(
                        None, None, f"lists and mappings nested more than {limit('max_depth')} deep "
                        f"{override_hint('max_depth')}", self.peek_event().start_mark)
                return super().compose_node(parent, index)
            finally:
                self._depth -= 1

    return GuardedLoader


def _yaml_line(text: str, location: Sequence[str | int]) -> int | None:
    """1-based line of the YAML node at ``location`` (or its nearest parent)."""
    import yaml

    try:
        node = yaml.compose(text, Loader=_guarded_loader())
    except Exception:      # noqa: BLE001 - the line is only a courtesy; the error it annotates stands
        return None
    line = None
    for key in location:
        if node is None:
            break
        line = node.start_mark.line + 1
        if isinstance(node, yaml.MappingNode):
            node = next((v for k, v in node.value if k.value == str(key)), None)
        elif isinstance(node, yaml.SequenceNode) and isinstance(key, int) and key < len(node.value):
            node = node.value[key]
        else:
            node = None
    if node is not None:
        line = node.start_mark.line + 1
    return line


def read_data_file(path: Path, kind: str, error) -> tuple[str, Any]:
    """The text of a YAML or JSON file from an untrusted source, and its data, within the input limits.

    Parameters
    ----------
    path : Path
    kind : {"yaml", "json"}
    error : callable
        ``error(problem, file=..., line=...)`` makes the exception to raise
        (:class:`TimelineError`, a spec error...).

    Returns
    -------
    text : str
    data : object
        Plain dicts, lists, strings and numbers.
    """
    import yaml

    if path.is_dir():
        raise error("is a folder, not a file", file=path)
    check_file_size(path, lambda problem: error(problem, file=path))
    try:
        text = path.read_bytes().decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        raise error(f"not UTF-8 text ({exc.reason} at byte {exc.start})", file=path) from None
    if kind == "yaml":
        try:
            return text, yaml.load(text, Loader=_guarded_loader())
        except yaml.MarkedYAMLError as exc:
            mark = exc.problem_mark
            raise error(f"malformed YAML: {exc.problem or exc}", file=path,
                        line=None if mark is None else mark.line + 1) from None
        except Exception as exc:  # noqa: BLE001 - tags such as '!!int x' fail with ValueError, dates too
            raise error(f"malformed YAML: {exc}", file=path) from None
    try:
        return text, json.loads(text)
    except json.JSONDecodeError as exc:
        raise error(f"malformed JSON: {exc.msg} (column {exc.colno})", file=path, line=exc.lineno) from None
    except RecursionError:
        raise error(f"malformed JSON: lists and mappings nested too deeply {override_hint('max_depth')}",
                    file=path) from None
    except ValueError as exc:    # e.g. an integer of more than 4,300 digits
        raise error(f"malformed JSON: {exc}", file=path) from None


def load_timeline(path: str | os.PathLike) -> Timeline:
    """Read a timeline from ``.yaml``/``.yml`` or ``.json`` (by suffix).

    Raises
    ------
    TimelineError
        One line naming the file, the line where known, the field path and
        what is wrong (malformed YAML/JSON included).
    FileNotFoundError
        If there is no such file.
    """
    path = Path(path)
    kind = _format_of(path)
    text, data = read_data_file(path, kind, TimelineError)
    try:
        return timeline_from_dict(data, folder=path.parent)
    except TimelineError as exc:
        line = _yaml_line(text, exc.location) if kind == "yaml" and exc.location else None
        raise exc.in_file(path, line) from None


def save_timeline(timeline: Timeline, path: str | os.PathLike) -> Path:
    """Write a timeline as YAML or JSON (by suffix), atomically; returns the path.

    :func:`load_timeline` reads it back equal to ``timeline``.
    """
    import yaml

    path = Path(path)
    kind = _format_of(path)
    data = timeline_to_dict(timeline)
    if kind == "yaml":
        text = yaml.safe_dump(data, sort_keys=False, default_flow_style=None, allow_unicode=True, width=100)
    else:
        text = json.dumps(data, indent=2, ensure_ascii=False) + "\n"
    return atomic_write(path, lambda tmp: tmp.write_text(text, encoding="utf-8"))


__all__ = ["load_timeline", "read_data_file", "save_timeline", "timeline_from_dict", "timeline_schema", "timeline_to_dict"]
