"""The FACS catalogue: every code facsim knows, and the intensity tables.

Both come from one data file, ``facsim/data/action_units.yaml``; this module
only loads, checks and looks up. Engines are not described here: each engine
reports the codes it simulates, and :func:`describe_table` lays those beside
the catalogue.

Examples
--------
>>> info(12).name
'Lip Corner Puller'
>>> info("AU26").unilateral
False
>>> intensity_of("C"), intensity_of("D", table="facshuman")
(0.55, 0.9)
>>> letter_of(0.3)
'B'
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache
from importlib import resources
from types import MappingProxyType
from typing import Iterable, Mapping

import yaml

#: libyaml's loader when present: ten times faster than the pure-Python one.
_YAML_LOADER = getattr(yaml, "CSafeLoader", yaml.SafeLoader)
DATA_FILE = "action_units.yaml"
REGIONS = ("upper face", "lower face", "head", "eyes", "gross behaviour", "visibility")
KINDS = ("action", "head", "eye", "gross", "visibility")
#: Kinds that are known and accepted but never rendered.
UNRENDERED_KINDS = ("gross", "visibility")
LETTERS = ("A", "B", "C", "D", "E")


class UnknownActionUnitError(KeyError, ValueError):
    """A code that FACS (as listed in the catalogue) does not define.

    A ``KeyError`` for mapping-style lookups and a ``ValueError`` for callers
    validating user input. ``.code`` is what was asked for, ``.reason`` says
    why it is unknown and lists the known codes.
    """

    def __init__(self, code, reason: str):
        super().__init__(code, reason)
        self.code, self.reason = code, reason

    def __str__(self) -> str:  # KeyError would show the repr of the args
        return f"unknown action unit {self.code!r}: {self.reason}"


@dataclass(frozen=True)
class ActionUnitInfo:
    """One FACS code as described in the catalogue.

    Attributes
    ----------
    code : int
        FACS number, e.g. ``12``.
    name : str
        FACS name, e.g. ``"Lip Corner Puller"``.
    muscles : tuple of str
        Muscular basis; empty where FACS names none.
    region : str
        One of :data:`REGIONS`.
    kind : str
        One of :data:`KINDS`.
    unilateral : bool
        Whether the code may be scored on one side (``L12``).
    rendered : bool
        False for gross-behaviour and visibility codes.
    description : str
        The change of appearance in a sentence.
    note : str
        Optional remark (history, ambiguity); ``""`` if none.
    """

    code: int
    name: str
    muscles: tuple[str, ...]
    region: str
    kind: str
    unilateral: bool
    rendered: bool
    description: str
    note: str = ""

    @property
    def label(self) -> str:
        """``"AU12"``-style label."""
        return f"AU{self.code}"


# ---------------------------------------------------------------- loading ---

def _fail(where: str, problem: str):
    raise ValueError(f"{DATA_FILE}, {where}: {problem}")


@lru_cache(maxsize=1)
def _raw() -> dict:
    text = (resources.files("facsim") / "data" / DATA_FILE).read_text(encoding="utf-8")
    data = yaml.load(text, Loader=_YAML_LOADER)
    if not isinstance(data, dict) or "action_units" not in data or "intensity_tables" not in data:
        _fail("top level", "expected the keys 'intensity_tables' and 'action_units'")
    return data


def _entry_to_info(entry: dict) -> ActionUnitInfo:
    code = entry.get("code")
    where = f"entry with code {code!r}"
    if not isinstance(code, int) or isinstance(code, bool) or code <= 0:
        _fail(where, "'code' must be a positive integer")
    required = {"code", "name", "muscles", "region", "kind", "unilateral", "rendered", "description"}
    missing = required - entry.keys()
    unknown = entry.keys() - required - {"note"}
    if missing or unknown:
        _fail(where, f"missing fields {sorted(missing)}, unknown fields {sorted(unknown)}")
    if entry["region"] not in REGIONS:
        _fail(where, f"region {entry['region']!r} is not one of {REGIONS}")
    if entry["kind"] not in KINDS:
        _fail(where, f"kind {entry['kind']!r} is not one of {KINDS}")
    if not isinstance(entry["muscles"], list) or not all(isinstance(m, str) for m in entry["muscles"]):
        _fail(where, "'muscles' must be a list of strings")
    for flag in ("unilateral", "rendered"):
        if not isinstance(entry[flag], bool):
            _fail(where, f"{flag!r} must be true or false")
    if entry["rendered"] == (entry["kind"] in UNRENDERED_KINDS):
        _fail(where, f"'rendered' must be {entry['kind'] not in UNRENDERED_KINDS} for kind {entry['kind']!r}")
    return ActionUnitInfo(
        code=code,
        name=str(entry["name"]),
        muscles=tuple(entry["muscles"]),
        region=entry["region"],
        kind=entry["kind"],
        unilateral=entry["unilateral"],
        rendered=entry["rendered"],
        description=str(entry["description"]).strip(),
        note=str(entry.get("note", "")).strip(),
    )


@lru_cache(maxsize=1)
def catalogue() -> Mapping[int, ActionUnitInfo]:
    """Every FACS code facsim knows, by code, in ascending order (read-only).

    Examples
    --------
    >>> cat = catalogue()
    >>> cat[1].name, 3 in cat
    ('Inner Brow Raiser', False)
    >>> sorted(code for code, unit in cat.items() if unit.kind == "visibility")
    [70, 71, 72, 73, 74]
    """
    table: dict[int, ActionUnitInfo] = {}
    for entry in _raw()["action_units"]:
        unit = _entry_to_info(entry)
        if unit.code in table:
            _fail(f"entry with code {unit.code}", "the code is listed twice")
        table[unit.code] = unit
    return MappingProxyType(dict(sorted(table.items())))


def _load_intensity_tables() -> Mapping[str, Mapping[str, float]]:
    tables = {}
    for name, table in _raw()["intensity_tables"].items():
        letters = table.get("letters", {}) if isinstance(table, dict) else {}
        if sorted(letters) != list(LETTERS):
            _fail(f"intensity table {name!r}", f"'letters' must give exactly {LETTERS}")
        values = [float(letters[letter]) for letter in LETTERS]
        if values != sorted(values) or not 0.0 < values[0] or values[-1] != 1.0:
            _fail(f"intensity table {name!r}", "values must rise from above 0 to exactly 1.0 at E")
        tables[name] = MappingProxyType(dict(zip(LETTERS, values)))
    return MappingProxyType(tables)


#: Intensity letter → fraction of the AU's full action, per named table
#: (``"hapfacs"``, ``"facshuman"``), from ``action_units.yaml``.
INTENSITY_TABLES: Mapping[str, Mapping[str, float]] = _load_intensity_tables()


# ---------------------------------------------------------------- lookups ---

def _ranges(codes: Iterable[int]) -> str:
    """``[1, 2, 4, 5, 6]`` → ``"1-2, 4-6"`` for compact error messages."""
    spans: list[list[int]] = []
    for code in sorted(codes):
        if spans and code == spans[-1][1] + 1:
            spans[-1][1] = code
        else:
            spans.append([code, code])
    return ", ".join(str(a) if a == b else f"{a}-{b}" for a, b in spans)


def info(code: int | str) -> ActionUnitInfo:
    """The catalogue entry of one FACS code.

    Parameters
    ----------
    code : int or str
        ``12``, ``"12"`` or ``"AU12"``.

    Raises
    ------
    UnknownActionUnitError
        (a ``KeyError`` and a ``ValueError``) if FACS defines no such code.

    Examples
    --------
    >>> info("au4").muscles
    ('depressor glabellae', 'depressor supercilii', 'corrugator supercilii')
    >>> info(3)
    Traceback (most recent call last):
    ...
    facsim.facs.catalogue.UnknownActionUnitError: unknown action unit 3: FACS defines no AU3; known codes are 1-2, 4-46, 50-58, 61-66, 70-74, 80-82, 84-85, 91-92, 97-98
    """
    number = code
    if isinstance(code, str):
        text = code.strip()
        digits = text[2:] if text[:2].upper() == "AU" else text
        number = int(digits) if digits.isdigit() else None
    elif isinstance(code, bool) or not isinstance(code, int):
        number = None
    table = catalogue()
    if number not in table:
        known = _ranges(table)
        what = f"FACS defines no AU{number}" if number is not None else "expected an integer code or 'AU<n>'"
        raise UnknownActionUnitError(code, f"{what}; known codes are {known}")
    return table[number]


def _table(table: str) -> Mapping[str, float]:
    try:
        return INTENSITY_TABLES[table]
    except (KeyError, TypeError):
        raise ValueError(
            f"unknown intensity table {table!r}; choose one of {', '.join(map(repr, INTENSITY_TABLES))}"
        ) from None


def intensity_of(letter: str, table: str = "hapfacs") -> float:
    """The fraction of full action that an intensity letter stands for.

    Examples
    --------
    >>> intensity_of("a"), intensity_of("A", table="facshuman")
    (0.15, 0.1)
    >>> intensity_of("F")
    Traceback (most recent call last):
    ...
    ValueError: unknown intensity letter 'F'; FACS intensities are A, B, C, D, E
    """
    values = _table(table)
    key = letter.upper() if isinstance(letter, str) else letter
    if key not in values:
        raise ValueError(f"unknown intensity letter {letter!r}; FACS intensities are {', '.join(LETTERS)}")
    return values[key]


def letter_of(value: float, table: str = "hapfacs") -> str | None:
    """The letter whose table value equals ``value`` exactly, else ``None``.

    Examples
    --------
    >>> letter_of(0.85), letter_of(0.9, table="facshuman"), letter_of(0.5)
    ('D', 'D', None)
    """
    for letter, level in _table(table).items():
        if math.isclose(level, value, rel_tol=0.0, abs_tol=1e-9):
            return letter
    return None


# ---------------------------------------------------------------- display ---

def describe_table(
    engines: Mapping[str, Iterable[int]] | None = None,
    *,
    kinds: Iterable[str] | None = None,
) -> str:
    """The catalogue as a plain-text table (for ``facsim aus``).

    Parameters
    ----------
    engines : mapping of str to iterable of int, optional
        Engine name → codes that engine simulates; one column per engine,
        ``x`` where the engine simulates the code.
    kinds : iterable of str, optional
        Only list codes of these kinds (see :data:`KINDS`); default all.

    Examples
    --------
    >>> print(describe_table({"register": {1, 2}}, kinds=["visibility"]))
    AU  name                            region      L/R  rendered  register
    70  Brows and Forehead Not Visible  visibility  -    no
    71  Eyes Not Visible                visibility  -    no
    72  Lower Face Not Visible          visibility  -    no
    73  Entire Face Not Visible         visibility  -    no
    74  Unscorable                      visibility  -    no
    """
    engines = {name: set(codes) for name, codes in (engines or {}).items()}
    wanted = set(KINDS if kinds is None else kinds)
    if not wanted <= set(KINDS):
        raise ValueError(f"kinds must be among {KINDS}, got {sorted(wanted - set(KINDS))}")
    header = ["AU", "name", "region", "L/R", "rendered", *engines]
    rows = [header]
    for unit in catalogue().values():
        if unit.kind not in wanted:
            continue
        rows.append([
            str(unit.code), unit.name, unit.region,
            "yes" if unit.unilateral else "-",
            "yes" if unit.rendered else "no",
            *("x" if unit.code in codes else "" for codes in engines.values()),
        ])
    widths = [max(len(row[i]) for row in rows) for i in range(len(header))]
    return "\n".join("  ".join(cell.ljust(w) for cell, w in zip(row, widths)).rstrip() for row in rows)
