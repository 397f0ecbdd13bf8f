"""Emotion presets: named emotions as FACS expressions, and blends of two.

The presets live in ``facsim/data/emotions.yaml``, one table per source:
``"hapfacs"`` (HapFACS 3.0, Table 5) and ``"emfacs"`` (the classic EMFACS
prototypes, with embarrassment after Keltner 1995 and pride after Tracy &
Robins 2004), and the default ``"facsim"``: Table 5 for every emotion but
anger and surprise, which are EMFACS's 4+5+7+23 and 1+2+5B+26 (Table 5's anger
carries disgust's 9 and 10 and was read as disgust; its surprise raises the
upper lid fully and stared as fear does). Each preset is a FACS string read by
:func:`facsim.notation.parse`.

Examples
--------
>>> str(emotion("surprise", table="emfacs"))
'1+2+5B+26'
>>> str(emotion("happiness", intensity="50%"))
'6@0.5+12@0.5+25@0.5'
>>> str(emotion("anger")), str(emotion("anger", table="hapfacs"))
('4+5+7+23', '5+7+9+10+15+17+42')
>>> str(blend("happiness", "surprise", table="emfacs"))
'1@0.5+2@0.5+5@0.15+6@0.5+12@0.5+26@0.5'
"""
from __future__ import annotations

import math
import textwrap
from dataclasses import dataclass
from functools import lru_cache
from importlib import resources
from types import MappingProxyType
from typing import Mapping

import yaml

from facsim.facs.notation import ActionUnit, Expression, NotationError, parse, parse_intensity

#: libyaml's loader when present: ten times faster than the pure-Python one.
_YAML_LOADER = getattr(yaml, "CSafeLoader", yaml.SafeLoader)
DATA_FILE = "emotions.yaml"
#: The table used when none is named (``default`` in emotions.yaml, checked when it is read).
DEFAULT_TABLE = "facsim"


@dataclass(frozen=True)
class PresetTable:
    """One source's presets: emotion name → FACS string, with provenance."""

    name: str
    title: str
    source: str
    presets: Mapping[str, str]
    notes: Mapping[str, str]


def _same_as(tables: dict, emotion_name: str, entry: dict, where: str) -> dict:
    """The entry for ``emotion_name`` in the table that ``entry`` names (``same_as``), with
    ``entry``'s own note if it gives one."""
    source = tables.get(entry["same_as"])
    if source is None or "same_as" in source["presets"].get(emotion_name, {"same_as": None}):
        raise ValueError(f"{where}: `same_as` must name a table that prints this preset, got {entry['same_as']!r}")
    return {**source["presets"][emotion_name], **{k: v for k, v in entry.items() if k == "note"}}


@lru_cache(maxsize=1)
def _load() -> tuple[tuple[str, ...], Mapping[str, PresetTable]]:
    text = (resources.files("facsim") / "data" / DATA_FILE).read_text(encoding="utf-8")
    data = yaml.load(text, Loader=_YAML_LOADER)
    names = tuple(data["emotions"])
    if data.get("default") != DEFAULT_TABLE or DEFAULT_TABLE not in data["tables"]:
        raise ValueError(f"{DATA_FILE}: `default` must name the table {DEFAULT_TABLE!r} "
                         f"(facsim.facs.emotions.DEFAULT_TABLE), got {data.get('default')!r}")
    tables = {}
    for table_name, table in data["tables"].items():
        presets, notes = {}, {}
        for emotion_name, entry in table["presets"].items():
            where = f"{DATA_FILE}, table {table_name!r}, emotion {emotion_name!r}"
            if emotion_name not in names:
                raise ValueError(f"{where}: not one of the emotions {names}")
            if "same_as" in entry:
                entry = _same_as(data["tables"], emotion_name, entry, where)
            try:
                parse(entry["facs"])
            except NotationError as exc:   # a broken data file must say where
                raise ValueError(f"{where}: {exc}") from None
            presets[emotion_name] = entry["facs"]
            if entry.get("note"):
                notes[emotion_name] = " ".join(entry["note"].split())
        missing = [n for n in names if n not in presets]
        if missing:
            raise ValueError(f"{DATA_FILE}, table {table_name!r}: no preset for {missing}")
        tables[table_name] = PresetTable(
            name=table_name, title=table["title"], source=" ".join(table["source"].split()),
            presets=MappingProxyType(presets), notes=MappingProxyType(notes),
        )
    return names, MappingProxyType(tables)


def emotion_names() -> tuple[str, ...]:
    """The emotions every preset table gives, ``"neutral"`` last.

    Examples
    --------
    >>> emotion_names()[:3], emotion_names()[-1]
    (('happiness', 'sadness', 'surprise'), 'neutral')
    """
    return _load()[0]


def preset_tables() -> Mapping[str, PresetTable]:
    """The preset tables by name (read-only); :data:`DEFAULT_TABLE` (``"facsim"``) is the default.

    Examples
    --------
    >>> list(preset_tables())
    ['facsim', 'hapfacs', 'emfacs']
    >>> preset_tables()["emfacs"].presets["contempt"]
    'R12A+R14A'
    """
    return _load()[1]


def _table(table: str) -> PresetTable:
    tables = preset_tables()
    if table not in tables:
        raise ValueError(f"unknown emotion table {table!r}; choose one of {', '.join(map(repr, tables))}")
    return tables[table]


def emotion(name: str, *, table: str = DEFAULT_TABLE, intensity: float | str = 1.0,
            intensities: str = "hapfacs") -> Expression:
    """The expression of one emotion.

    Parameters
    ----------
    name : str
        One of :func:`emotion_names` (case-insensitive).
    table : str
        Preset table, see :func:`preset_tables` (default :data:`DEFAULT_TABLE`).
    intensity : float or str
        Global intensity, ``0.5`` or ``"50%"``; multiplies every unit.
    intensities : str
        Intensity table for the letters in the preset (see
        :func:`facsim.notation.parse`).

    Examples
    --------
    >>> str(emotion("Contempt", table="emfacs"))
    'R12A+R14A'
    >>> emotion("joy")
    Traceback (most recent call last):
    ...
    ValueError: unknown emotion 'joy'; choose one of happiness, sadness, surprise, anger, fear, disgust, contempt, embarrassment, pride, neutral
    """
    presets = _table(table).presets
    key = name.strip().lower() if isinstance(name, str) else name
    if key not in presets:
        raise ValueError(f"unknown emotion {name!r}; choose one of {', '.join(emotion_names())}")
    expr = parse(presets[key], intensities=intensities)
    level = parse_intensity(intensity)
    return expr if level == 1.0 else expr.scaled(level)


def _character_sides(unit: ActionUnit) -> tuple[str, ...]:
    # Same reading as facsim.expression.activations: U acts on its default side.
    from facsim.facs.activations import UNILATERAL_DEFAULT_SIDE
    if unit.side == "both":
        return ("left", "right")
    return (UNILATERAL_DEFAULT_SIDE,) if unit.side == "unilateral" else (unit.side,)


def _mix(code: int, side: str, first: ActionUnit | None, second: ActionUnit | None,
         weight: float) -> ActionUnit | None:
    """One unit of a blend, or None where it ends at 0."""
    level = (1.0 - weight) * (first.intensity if first else 0.0) + weight * (second.intensity if second else 0.0)
    for unit in (first, second):
        # A unit the blend leaves as it was (weight 0 or 1, equal inputs) keeps its letter.
        if unit is not None and unit.letter and math.isclose(unit.intensity, level, abs_tol=1e-12):
            return ActionUnit(code, unit.intensity, side, unit.letter)
    return ActionUnit(code, level, side) if level > 0.0 else None


def _blend_code(code: int, a: Expression, b: Expression, weight: float) -> list[ActionUnit | None]:
    sides_a = {u.side: u for u in a.units if u.code == code}
    sides_b = {u.side: u for u in b.units if u.code == code}
    if not sides_a or not sides_b or sides_a.keys() == sides_b.keys():
        return [_mix(code, side, sides_a.get(side), sides_b.get(side), weight)
                for side in sides_a.keys() | sides_b.keys()]
    # The two place the code on different sides: blend each side of the face.
    left, right = (
        _mix(code, side, *(next((u for u in group.values() if side in _character_sides(u)), None)
                           for group in (sides_a, sides_b)), weight)
        for side in ("left", "right"))
    if left and right and (left.intensity, left.letter) == (right.intensity, right.letter):
        return [ActionUnit(code, left.intensity, "both", left.letter)]
    return [left, right]


def blend(first: str | Expression, second: str | Expression, weight: float | str = 0.5, *,
          table: str = DEFAULT_TABLE, intensities: str = "hapfacs") -> Expression:
    """Mix two emotions: the union of their units, intensities interpolated.

    Each unit gets ``(1 - weight) * a + weight * b``, where ``a`` and ``b`` are
    its intensities in ``first`` and ``second`` (0 where absent), so
    ``weight=0`` gives ``first``, ``weight=1`` gives ``second``; units that end
    at 0 are dropped. Where the two place one code on different sides (``12``
    and ``R12``) the blend is taken per side of the face, and a code left
    equal on both sides is written bilateral again.

    Parameters
    ----------
    first, second : str or Expression
        Emotion names (looked up in ``table``) or expressions.
    weight : float or str
        Share of ``second``, in [0, 1] (``0.3`` or ``"30%"``).
    table, intensities : str
        As for :func:`emotion`.

    Examples
    --------
    >>> str(blend("happiness", "sadness", weight=0.25, table="emfacs"))
    '1@0.25+4@0.25+6@0.75+12@0.75+15@0.25'
    >>> str(blend("happiness", "contempt", table="emfacs"))
    '6@0.5+L12@0.5+R12@0.575+R14@0.075'
    """
    weight = parse_intensity(weight, name="weight")
    a, b = (emotion(e, table=table, intensities=intensities) if isinstance(e, str) else e
            for e in (first, second))
    for label, expr in (("first", a), ("second", b)):
        if not isinstance(expr, Expression):
            raise TypeError(f"{label} must be an emotion name or an Expression, got {type(expr).__name__}")
    units = [unit for code in sorted(a.codes | b.codes) for unit in _blend_code(code, a, b, weight)]
    return Expression(tuple(u for u in units if u is not None))


def describe_emotions(table: str = DEFAULT_TABLE) -> str:
    """One preset table as plain text (for the CLI): title, source, presets, notes.

    Examples
    --------
    >>> print(describe_emotions("emfacs").splitlines()[2])
    happiness      6+12
    """
    presets = _table(table)
    width = max(len(n) for n in emotion_names()) + 2
    lines = [f"{presets.title} (table {presets.name!r})", ""]
    lines += [f"{name.ljust(width)}{presets.presets[name]}" for name in emotion_names()]
    if presets.notes:
        lines.append("")
        for name, note in presets.notes.items():
            lines += textwrap.wrap(f"{name}: {note}", width=88, subsequent_indent="  ")
    lines += ["", *textwrap.wrap(f"Source: {presets.source}", width=88, subsequent_indent="  ")]
    return "\n".join(lines)
