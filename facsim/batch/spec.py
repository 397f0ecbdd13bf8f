"""Stimulus-set specs: YAML/JSON text → checked, frozen :class:`StimulusSet`.

A spec names *blocks* of expressions (single AUs × sides, FACS strings, AU
combinations, emotions × preset tables, timeline files), each with the
intensities it is shown at and its outputs (stills at levels relative to the
peak, a HapFACS-timed video, a glb), crossed with characters, engines, views
and sizes. :func:`facsim.batch.items.expand` turns the set into the list of
files to make.

Errors reuse the timeline loader's machinery (:mod:`facsim.timeline_io`): the
JSON Schema (``facsim/data/stimulus_set.schema.json``) is checked first and
the first problem is reported as one :class:`SpecError` naming the file, the
line, the field path and what is wrong; then every name is resolved (AU codes,
sides, FACS strings, emotions, tables, characters, views, timeline files)
through the same data types the timeline uses.

Examples
--------
>>> s = spec_from_dict({"characters": ["ava"], "blocks": [
...     {"name": "smiles", "aus": [12], "sides": ["both", "left"], "outputs": {"stills": [1]}}]})
>>> [stim.label for stim in s.blocks[0].stimuli]
['AU12', 'AU12L']
>>> spec_from_dict({"blocks": [{"name": "x", "aus": [3], "outputs": {"stills": [1]}}]})
Traceback (most recent call last):
...
facsim.batch.spec.SpecError: blocks[0].aus[0]: unknown action unit 3: FACS defines no AU3; known codes are 1-2, 4-46, 50-58, 61-66, 70-74, 80-82, 84-85, 91-92, 97-98
"""
from __future__ import annotations

import hashlib
import json
import os
from dataclasses import dataclass
from functools import lru_cache
from importlib import resources
from pathlib import Path
from typing import Any, Mapping, Sequence

import numpy as np

import facsim
from facsim.facs.stimuli import hapfacs_stimuli
from facsim.render.options import DEFAULT_BODY
from facsim.timeline import io as timeline_io
from facsim.timeline.model import Hold, TimelineError, Track, parse_level

SCHEMA_FILE = "stimulus_set.schema.json"
SIDE_SUFFIX = {"both": "", "left": "L", "right": "R"}
SIDE_PREFIX = {"both": "", "left": "L", "right": "R"}
VIDEO_FORMATS = ("mp4", "webm", "gif")
DEFAULT_SIZE = (512, 512)


class SpecError(TimelineError):
    """A stimulus-set spec that cannot be read, in one line: ``file:line: field.path: problem``.

    The same machinery as :class:`facsim.timeline.TimelineError` (field path,
    file, line), under its own name.
    """

    def within(self, *prefix: str | int) -> "SpecError":
        return SpecError(self.problem, location=(*prefix, *self.location), file=self.file, line=self.line)

    def in_file(self, file: str | os.PathLike, line: int | None = None) -> "SpecError":
        return SpecError(self.problem, location=self.location, file=file, line=self.line if line is None else line)


# ------------------------------------------------------------- data types ---

@dataclass(frozen=True)
class Stimulus:
    """One expression of a block, before intensities, characters and outputs are crossed with it.

    ``kind`` is ``"au"`` (``au`` and ``side``), ``"facs"`` (``facs``),
    ``"emotion"`` (``emotion`` and ``table``) or ``"timeline"``
    (``timeline``: the timeline as canonical JSON, so an item carries
    everything a remote worker needs).
    """

    kind: str
    label: str
    facs: str = ""
    au: int | None = None
    side: str = "both"
    emotion: str | None = None
    table: str | None = None
    timeline: str | None = None


@dataclass(frozen=True)
class VideoOutput:
    """HapFACS timing: neutral → peak in ``onset`` s, held ``apex`` s, back in ``offset`` s."""

    onset: float = 1.0
    apex: float = 1.0
    offset: float = 1.0
    fps: float = 30.0
    easing: str = "linear"
    format: str = "mp4"


@dataclass(frozen=True)
class Outputs:
    """What each condition becomes: stills at ``stills`` × its peak, a video, a glb."""

    stills: tuple[float, ...] = ()
    video: VideoOutput | None = None
    glb: bool = False


@dataclass(frozen=True)
class Block:
    """A named group of stimuli with their intensities, outputs and crossing factors."""

    name: str
    stimuli: tuple[Stimulus, ...]
    intensities: tuple[float, ...]
    outputs: Outputs
    characters: tuple[str, ...]
    engines: tuple[str, ...]
    views: tuple[str, ...]
    sizes: tuple[tuple[int, int], ...]


@dataclass(frozen=True)
class StimulusSet:
    """A checked spec. ``spec_json`` is the spec as read (canonical JSON); ``spec_hash``
    identifies it together with the timeline files it names and facsim's version."""

    blocks: tuple[Block, ...]
    name: str = ""
    description: str = ""
    seed: int = 0
    counterbalance: str = "full"
    lists: int = 1
    naming: str = "readable"
    key_file: str = "key.csv"
    intensities: str = "hapfacs"
    background: tuple[float, float, float] = (1.0, 1.0, 1.0)
    body: str = DEFAULT_BODY
    antialias: int | str = 4
    spec_json: str = "{}"
    spec_hash: str = ""


# ---------------------------------------------------------------- schema ---

@lru_cache(maxsize=1)
def _schema_text() -> str:
    return resources.files("facsim").joinpath("data", SCHEMA_FILE).read_text(encoding="utf-8")


def stimulus_set_schema() -> dict:
    """The stimulus-set JSON Schema (draft 2020-12), as a fresh dict.

    Examples
    --------
    >>> stimulus_set_schema()["title"]
    'facsim stimulus set'
    """
    return json.loads(_schema_text())


@lru_cache(maxsize=1)
def _validator():
    from jsonschema import Draft202012Validator

    schema = stimulus_set_schema()
    Draft202012Validator.check_schema(schema)
    return Draft202012Validator(schema)


_SOURCES = ("aus", "facs", "combinations", "emotions", "timelines")
#: What a value must look like, for the schema nodes whose alternatives jsonschema cannot explain well.
_EXPECTED = {
    "characters": "expected 'all', a list of character names or {random: {n: N, seed: S}}",
    "size": "expected N or [width, height] in pixels, each 16..8192",
    "counterbalance": "expected 'full', 'latin_square' or {latin_square: {lists: N}}",
    "naming": "expected 'readable', 'blind' or {style: blind, key: NAME.csv}",
    "aus": "expected 'hapfacs' or a list of FACS codes",
    "combinations": "expected 'hapfacs' or a list of FACS strings",
    "emotions": "expected 'all' or a list of emotion names (see `facsim emotions`)",
    "video": "expected true/false or {onset, apex, offset, fps, easing, format}",
    "antialias": "expected MSAA samples 1..16 or 'fxaa'",
}

_PATTERNS = {"key": "expected a file name ending in .csv (no folders)",
             "name": "expected a folder name: letters, digits, '_', '.' or '-', starting with a letter or digit"}


def _block_source_problem(block: Mapping) -> str:
    given = [k for k in _SOURCES if k in block]
    if len(given) != 1:
        said = f"got {', '.join(map(repr, given))}" if given else "got none"
        return f"a block needs exactly one of {', '.join(map(repr, _SOURCES))}; {said}"
    if "sides" in block:
        return "'sides' applies only to 'aus' blocks"
    return "'tables' applies only to 'emotions' blocks"


def _schema_problem(error) -> tuple[tuple, str]:
    schema = error.schema if isinstance(error.schema, dict) else {}
    marker = schema.get("x-facsim")
    location = tuple(error.absolute_path)
    if (marker == "block-source" and error.validator == "oneOf") or "dependentSchemas" in error.schema_path:
        return location, _block_source_problem(error.instance)
    if error.validator == "minProperties" and location and location[-1] == "outputs":
        return location, "no outputs: give 'stills', 'video' or 'glb: true'"
    if error.validator in ("anyOf", "oneOf"):
        # The branch of the right type that failed inside says more ('onset: must be >= 0').
        inner = [e for e in error.context if e.validator not in ("type", "enum", "const")]
        if inner and isinstance(error.instance, (Mapping, list)):
            return _schema_problem(min(inner, key=lambda e: (-len(e.absolute_path), str(e.schema_path))))
    if error.validator == "pattern" and location and location[-1] in _PATTERNS:
        return location, f"{_PATTERNS[location[-1]]}, got {error.instance!r}"
    if marker in _EXPECTED and error.validator in ("anyOf", "oneOf"):
        return location, f"{_EXPECTED[marker]}, got {error.instance!r}"
    location, problem = timeline_io._schema_problem(error)  # the timeline's wording: fields, types, ranges
    if error.validator == "additionalProperties":  # point at the unknown key itself (its line)
        allowed = schema.get("properties", {})
        location = (*location, sorted(k for k in error.instance if k not in allowed)[0])
    return location, problem


def _check_schema(data: Any) -> None:
    errors = list(_validator().iter_errors(data))
    if not errors:
        return
    first = min(errors, key=lambda e: (timeline_io._location_key(tuple(e.absolute_path)),
                                       timeline_io._FIRST.get(e.validator, 2)))
    location, problem = _schema_problem(first)
    raise SpecError(problem, location=location)


# ------------------------------------------------------------ resolving ---

@lru_cache(maxsize=1)
def _checked_track(where: tuple, **source) -> Track:
    """A Track (the timeline's own checks of codes, sides, FACS strings, emotions and tables)."""
    try:
        return Track(timing=Hold(0.0, 1.0), **source)
    except TimelineError as exc:
        # Track names the failing field ('au', 'side', 'facs', ...); the spec's field is ``where``.
        raise SpecError(exc.problem, location=where) from None


def _au_stimuli(block: Mapping, where: tuple) -> list[Stimulus]:
    codes = hapfacs_stimuli()["single_aus"] if block["aus"] == "hapfacs" else block["aus"]
    sides = block.get("sides", ["both"])
    out = []
    for j, code in enumerate(codes):
        _checked_track((*where, "aus", j), au=code)
        for k, side in enumerate(sides):
            if side != "both":
                try:
                    Track(timing=Hold(0.0, 1.0), au=code, side=side)
                except TimelineError as exc:
                    raise SpecError(f"{exc.problem} (listed in 'sides')", location=(*where, "sides", k)) from None
            out.append(Stimulus("au", f"AU{code:02d}{SIDE_SUFFIX[side]}", facs=f"{SIDE_PREFIX[side]}{code}",
                                au=code, side=side))
    return out


def _facs_label(text: str) -> str:
    """A file-name-safe label for a FACS string: '1+2+5B+26' → 'AU1_2_5B_26'."""
    keep = "".join(ch if ch.isalnum() else "_" for ch in text.replace(" ", ""))
    return "AU" + "_".join(part for part in keep.split("_") if part)


def _facs_stimuli(block: Mapping, field: str, where: tuple) -> list[Stimulus]:
    texts = hapfacs_stimuli()["combinations"] if block[field] == "hapfacs" else block[field]
    out = []
    for j, text in enumerate(texts):
        _checked_track((*where, field, j), facs=text)
        out.append(Stimulus("facs", _facs_label(text), facs=" ".join(text.split())))
    return out


def _emotion_stimuli(block: Mapping, where: tuple) -> list[Stimulus]:
    from facsim.facs.emotions import DEFAULT_TABLE, emotion, emotion_names, preset_tables
    from facsim.facs.notation import format_expression

    names = list(emotion_names()) if block["emotions"] == "all" else block["emotions"]
    tables = block.get("tables", [DEFAULT_TABLE])
    for k, table in enumerate(tables):
        if table not in preset_tables():
            raise SpecError(f"unknown emotion table {table!r}; choose one of {', '.join(preset_tables())}",
                            location=(*where, "tables", k))
    out = []
    for table in tables:
        for j, name in enumerate(names):
            track = _checked_track((*where, "emotions", j), emotion=name, table=table)
            label = track.emotion if len(tables) == 1 else f"{track.emotion}-{table}"
            out.append(Stimulus("emotion", label, facs=format_expression(emotion(track.emotion, table=table)),
                                emotion=track.emotion, table=table))
    return out


def _timeline_stimuli(block: Mapping, where: tuple, base_dir: Path | None) -> list[Stimulus]:
    out = []
    for j, name in enumerate(block["timelines"]):
        path = Path(name) if base_dir is None else base_dir / name
        try:
            timeline = timeline_io.load_timeline(path)
        except FileNotFoundError:
            raise SpecError(f"no timeline file {str(path)!r}", location=(*where, "timelines", j)) from None
        except TimelineError as exc:
            raise SpecError(f"timeline {name!r}: {exc}", location=(*where, "timelines", j)) from None
        text = json.dumps(timeline_io.timeline_to_dict(timeline), sort_keys=True, separators=(",", ":"))
        out.append(Stimulus("timeline", Path(name).stem, timeline=text))
    return out


def _characters(value: Any, seed: int, where: tuple) -> tuple[str, ...]:
    from facsim.head.character import CharacterError, preset_names, resolve_character

    if value == "all":
        return tuple(preset_names())
    if isinstance(value, Mapping):
        spec = value["random"]
        rng = np.random.default_rng(spec.get("seed", seed))
        seeds: list[int] = []
        while len(seeds) < spec["n"]:  # distinct seeds, drawn in order: same seed → same people
            s = int(rng.integers(0, 1_000_000))
            if s not in seeds:
                seeds.append(s)
        return tuple(f"random:{s}" for s in seeds)
    for j, name in enumerate(value):
        try:
            resolve_character(name)
        except CharacterError as exc:
            raise SpecError(str(exc), location=(*where, j)) from None
    if len(set(value)) != len(value):
        dup = next(n for n in value if value.count(n) > 1)
        raise SpecError(f"character {dup!r} is listed twice", location=(*where, value.index(dup, value.index(dup) + 1)))
    return tuple(value)


def _views(value: Sequence[str], where: tuple) -> tuple[str, ...]:
    from facsim.render.camera import VIEWS

    for j, view in enumerate(value):
        if view not in VIEWS:
            raise SpecError(f"unknown view {view!r}; choose one of {', '.join(VIEWS)}", location=(*where, j))
    return tuple(dict.fromkeys(value))


def _sizes(value: Sequence, where: tuple) -> tuple[tuple[int, int], ...]:
    return tuple(dict.fromkeys((v, v) if isinstance(v, int) else (v[0], v[1]) for v in value))


def _outputs(data: Mapping, table: str, where: tuple) -> Outputs:
    stills = tuple(_intensity(v, table, (*where, "stills", j)) for j, v in enumerate(data.get("stills", [])))
    video = data.get("video", False)
    if video is True:
        video = {}
    if isinstance(video, Mapping):
        video = VideoOutput(**{k: (float(v) if isinstance(v, (int, float)) else v) for k, v in video.items()})
        if video.onset + video.apex + video.offset <= 0:
            raise SpecError("a video needs onset + apex + offset > 0 seconds", location=(*where, "video"))
    else:
        video = None
    if not stills and video is None and not data.get("glb", False):
        raise SpecError("no outputs: give 'stills', 'video' or 'glb: true'", location=where)
    return Outputs(stills=stills, video=video, glb=bool(data.get("glb", False)))


def _intensity(value: Any, table: str, where: tuple) -> float:
    try:
        return parse_level(value, "intensity", table)
    except TimelineError as exc:
        raise SpecError(exc.problem, location=where) from None


def _block(data: Mapping, i: int, top: Mapping, base_dir: Path | None) -> Block:
    where = ("blocks", i)
    table = top["intensities"]
    if "aus" in data:
        stimuli = _au_stimuli(data, where)
    elif "facs" in data or "combinations" in data:
        stimuli = _facs_stimuli(data, "facs" if "facs" in data else "combinations", where)
    elif "emotions" in data:
        stimuli = _emotion_stimuli(data, where)
    else:
        stimuli = _timeline_stimuli(data, where, base_dir)
        if "intensities" in data:
            raise SpecError("timelines carry their own intensities; drop 'intensities'",
                            location=(*where, "intensities"))
    labels = [s.label for s in stimuli]
    if len(set(labels)) != len(labels):
        dup = next(x for x in labels if labels.count(x) > 1)
        raise SpecError(f"{dup!r} is listed twice", location=(*where, next(k for k in _SOURCES if k in data)))
    intensities = tuple(_intensity(v, table, (*where, "intensities", j))
                        for j, v in enumerate(data.get("intensities", [1.0])))
    if len(set(intensities)) != len(intensities):
        raise SpecError("an intensity is listed twice", location=(*where, "intensities"))
    outputs = _outputs(data["outputs"], table, (*where, "outputs"))
    if stimuli[0].kind == "timeline" and outputs.stills:
        raise SpecError("timelines make videos and glb files, not stills; drop 'stills'",
                        location=(*where, "outputs", "stills"))

    def factor(name, parse, default):
        if name in data:
            return parse(data[name], (*where, name))
        return top[name] if name in top else default

    characters = factor("characters", lambda v, w: _characters(v, top["seed"], w), ("ava",))
    engines = factor("engines", lambda v, w: tuple(dict.fromkeys(v)), ("registers",))
    views = factor("views", _views, ("front",))
    sizes = factor("sizes", _sizes, (DEFAULT_SIZE,))
    if outputs.video is not None and outputs.video.format in ("mp4", "webm"):
        for j, (w, h) in enumerate(sizes):
            if w % 2 or h % 2:
                field = (*where, "sizes", j) if "sizes" in data else ("sizes", j)
                raise SpecError(f"{w}x{h}: {outputs.video.format} videos need even widths and heights "
                                f"(H.264/VP9 with yuv420p); use {w + w % 2}x{h + h % 2}", location=field)
    return Block(data["name"], tuple(stimuli), intensities, outputs, characters, engines, views, sizes)


def _background(value: str) -> tuple[float, float, float]:
    from facsim.head.appearance import hex_to_rgb

    try:
        return tuple(hex_to_rgb(value))
    except ValueError as exc:
        raise SpecError(str(exc), location=("background",)) from None


def _body(value: str) -> str:
    from facsim.head.body import check_body_style

    try:
        return check_body_style(value)
    except ValueError as exc:
        raise SpecError(str(exc), location=("body",)) from None


def _check_item_count(blocks: Sequence[Block], counterbalance: str, lists: int) -> None:
    """Refuse a spec that expands to more output files than the limit, before expanding it:
    a few lines of YAML can cross factors into millions of files."""
    from facsim.limits import limit, override_hint

    total = 0
    for block in blocks:
        glbs = len(block.stimuli) * len(block.intensities) * len(block.engines) * bool(block.outputs.glb)
        conds = len(block.stimuli) * len(block.intensities) * len(block.engines) * len(block.views) * len(block.sizes)
        files = conds * (len(block.outputs.stills) + (block.outputs.video is not None)) + glbs  # one glb per view and size
        total += files * (len(block.characters) if counterbalance == "full" else lists)
    if total > limit("max_items"):
        raise SpecError(f"the spec expands to {total:,} output files, too many for one set "
                        f"{override_hint('max_items')}", location=("blocks",))


def spec_from_dict(data: Any, *, base_dir: str | os.PathLike | None = None) -> StimulusSet:
    """Check parsed YAML/JSON and build the :class:`StimulusSet`.

    Parameters
    ----------
    data : mapping
        The spec, as :func:`yaml.safe_load` returns it.
    base_dir : path, optional
        Folder that timeline file names are relative to (the spec's folder).

    Raises
    ------
    SpecError
        Naming the field path and what is wrong.
    """
    if not isinstance(data, Mapping):
        what = "nothing (the file is empty)" if data is None else type(data).__name__
        raise SpecError(f"expected a mapping with 'blocks' at the top level, got {what}")
    _check_schema(data)
    from facsim.timeline.model import intensities_table

    try:
        table = intensities_table(data.get("intensities", "hapfacs"))
    except TimelineError as exc:
        raise SpecError(exc.problem, location=exc.location) from None
    top: dict[str, Any] = {"intensities": table, "seed": data.get("seed", 0)}
    if "characters" in data:
        top["characters"] = _characters(data["characters"], top["seed"], ("characters",))
    if "engines" in data:
        top["engines"] = tuple(dict.fromkeys(data["engines"]))
    if "views" in data:
        top["views"] = _views(data["views"], ("views",))
    if "sizes" in data:
        top["sizes"] = _sizes(data["sizes"], ("sizes",))
    base = None if base_dir is None else Path(base_dir)
    blocks = [_block(b, i, top, base) for i, b in enumerate(data["blocks"])]
    names = [b.name for b in blocks]
    for i, name in enumerate(names):
        if names.index(name) != i:
            raise SpecError(f"block name {name!r} is used twice", location=("blocks", i, "name"))

    counterbalance, lists = data.get("counterbalance", "full"), 1
    if isinstance(counterbalance, Mapping):
        lists = counterbalance["latin_square"].get("lists", 1)
        counterbalance = "latin_square"
    if counterbalance == "latin_square":
        fewest = min(len(b.characters) for b in blocks)
        if lists > fewest:
            raise SpecError(f"{lists} lists need at least {lists} characters in every block, "
                            f"but a block has {fewest}", location=("counterbalance", "latin_square", "lists"))
    _check_item_count(blocks, counterbalance, lists)
    naming = data.get("naming", "readable")
    key_file = "key.csv"
    if isinstance(naming, Mapping):
        key_file = naming.get("key", key_file)
        naming = naming["style"]
    if key_file in ("manifest.csv",):
        raise SpecError("the key file cannot be called manifest.csv", location=("naming", "key"))

    spec_json = json.dumps(data, sort_keys=True, separators=(",", ":"), ensure_ascii=False, default=str)
    digest = hashlib.sha256()
    digest.update(f"facsim {facsim.__version__}\n".encode())
    digest.update(spec_json.encode())
    for block in blocks:  # a timeline file edited between runs is a changed spec
        for stim in block.stimuli:
            if stim.timeline is not None:
                digest.update(stim.timeline.encode())
    return StimulusSet(
        blocks=tuple(blocks), name=data.get("name", ""), description=data.get("description", ""),
        seed=top["seed"], counterbalance=counterbalance, lists=lists, naming=naming, key_file=key_file,
        intensities=table, background=_background(data.get("background", "#ffffff")),
        body=_body(data.get("body", DEFAULT_BODY)),
        antialias=data.get("antialias", 4), spec_json=spec_json, spec_hash=digest.hexdigest(),
    )


def load_spec(path: str | os.PathLike) -> StimulusSet:
    """Read a stimulus-set spec from ``.yaml``/``.yml`` or ``.json``.

    Raises
    ------
    SpecError
        One line: the file, the line where known, the field path, what is wrong.
    FileNotFoundError
        If there is no such file.
    """
    path = Path(path)
    if path.suffix.lower() not in (".yaml", ".yml", ".json"):
        raise SpecError(f"unsupported file type {path.suffix or '(none)'!r}; use .yaml, .yml or .json", file=path)
    # JSON is YAML; one reader for both keeps the line numbers. Limits as for timelines (aliases, depth, size).
    text, data = timeline_io.read_data_file(path, "yaml", SpecError)
    try:
        return spec_from_dict(data, base_dir=path.parent)
    except SpecError as exc:
        line = timeline_io._yaml_line(text, exc.location) if exc.location else None
        raise exc.in_file(path, line) from None


__all__ = ["Block", "Outputs", "SpecError", "StimulusSet", "Stimulus", "VideoOutput", "load_spec",
           "spec_from_dict", "stimulus_set_schema", "hapfacs_stimuli"]
