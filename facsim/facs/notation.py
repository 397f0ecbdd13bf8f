"""FACS notation: parse and format codes such as ``1+2+5B+26`` or ``R12A+L14``.

Grammar, one token per action unit, tokens joined by ``+`` (spaces around
``+`` and at the ends are ignored)::

    token     = [side] ["AU"] code [letter | "@" amount]
    side      = "L" | "R" | "U"           left / right of the character, or
                                          one side left unspecified ("unilateral")
    letter    = "A" | "B" | "C" | "D" | "E"   through an intensity table
    amount    = fraction "0.7" or percentage "70%"

Letters and ``AU`` are case-insensitive. A bare code is full intensity (1.0).
``""``, ``"0"`` and ``"neutral"`` are the neutral face (no units).

Canonical form (what :func:`format_expression` and ``str(expr)`` write):
units sorted by code, then side in the order left, right, unilateral, both;
sides written ``L``/``R``/``U`` (nothing for both); the letter when the unit
carries one, else ``@`` and the intensity with at most 3 decimals, else the
bare code for 1.0; joined with ``+``; the neutral face is ``"0"``.

Examples
--------
>>> expr = parse(" AU1 + 2 + 5b + 26@70% ")
>>> str(expr)
'1+2+5B+26@0.7'
>>> [(u.code, u.intensity, u.side) for u in parse("R12A+L14").units]
[(12, 0.15, 'right'), (14, 1.0, 'left')]
>>> parse("12C", intensities="facshuman").units[0].intensity
0.55
>>> str(parse("neutral")), bool(parse(""))
('0', False)
"""
from __future__ import annotations

import math
import re
from dataclasses import dataclass

from facsim.facs.catalogue import INTENSITY_TABLES, LETTERS, UnknownActionUnitError, info

SIDES = ("left", "right", "unilateral", "both")
_SIDE_PREFIX = {"left": "L", "right": "R", "unilateral": "U", "both": ""}
_PREFIX_SIDE = {"L": "left", "R": "right", "U": "unilateral"}
#: Which character sides a unit may occupy; two units of one code clash when
#: these overlap. A ``U`` unit could be on either side, so it clashes with any.
_COVERS = {"left": {"left"}, "right": {"right"}, "both": {"left", "right"}, "unilateral": {"left", "right"}}
_NEUTRAL = ("", "0", "neutral")
# ASCII digits only: \d would read Arabic-Indic or fullwidth digits as codes ("١٢" as AU12).
_TOKEN = re.compile(r"(?P<side>[LRU])?(?P<au>AU)?(?P<code>[0-9]+)(?:(?P<letter>[A-Z])|@(?P<amount>.*))?",
                    re.IGNORECASE | re.ASCII)
#: What an ``@`` amount may look like: a plain decimal fraction or percentage (no exponents, inf or nan).
_AMOUNT = re.compile(r"[-+]?(?:[0-9]+(?:\.[0-9]*)?|\.[0-9]+)%?", re.ASCII)
#: Longest code written with digits (FACS codes have at most 2; leading zeros allowed).
_MAX_CODE_DIGITS = 4


class NotationError(ValueError):
    """A FACS string that cannot be read, naming the token and where it is.

    Attributes
    ----------
    text : str
        The whole string given to :func:`parse`.
    position : int
        0-based index in ``text`` where the offending token starts.
    token : str
        The offending token as written.
    """

    def __init__(self, problem: str, *, text: str, position: int, token: str, hint: str = ""):
        from facsim.limits import clip, short

        self.text, self.position, self.token = text, position, token
        # The string and token are shown shortened: a 1 MB string must not make a 1 MB message.
        message = f"{problem} {short(token, 40)} at position {position} in {short(text, 60)}"
        super().__init__(clip(f"{message}: {hint}" if hint else message))

    def __reduce__(self):  # keyword-only __init__: tell pickle how to rebuild (worker processes)
        return _rebuild_notation_error, (str(self), self.text, self.position, self.token)


def _rebuild_notation_error(message: str, text: str, position: int, token: str) -> NotationError:
    error = NotationError.__new__(NotationError)
    ValueError.__init__(error, message)
    error.text, error.position, error.token = text, position, token
    return error


# ------------------------------------------------------------ intensities ---

def parse_intensity(value: float | str, *, name: str = "intensity") -> float:
    """A fraction in [0, 1] from a number, ``"0.7"`` or ``"70%"``.

    Shared by ``@`` amounts in notation and by every ``intensity=`` option.

    Parameters
    ----------
    value : float or str
        The amount.
    name : str
        What the amount is, for error messages.

    Examples
    --------
    >>> parse_intensity(0.5), parse_intensity("70%"), parse_intensity(" 0.25 ")
    (0.5, 0.7, 0.25)
    >>> parse_intensity("150%")
    Traceback (most recent call last):
    ...
    ValueError: intensity must be between 0 and 1 (0% to 100%), got '150%'
    """
    number = None
    if isinstance(value, str):
        text = value.strip()
        try:
            number = float(text[:-1]) / 100.0 if text.endswith("%") else float(text)
        except ValueError:
            number = None
    elif isinstance(value, (int, float)) and not isinstance(value, bool):
        number = float(value) if abs(value) < 1e300 else (math.inf if value > 0 else -math.inf)   # 10**400
    if number is not None:
        number += 0.0          # -0.0 -> 0.0, so '12@-0' reads and formats as 12@0
    if number is None or math.isnan(number):
        raise ValueError(f"{name} must be a number in [0, 1] or a percentage like '70%', got {value!r}")
    if not 0.0 <= number <= 1.0:
        raise ValueError(f"{name} must be between 0 and 1 (0% to 100%), got {value!r}")
    return number


def _format_amount(value: float) -> str:
    """At most 3 decimals, no trailing zeros: 0.7 → '0.7', 0.12345 → '0.123'."""
    return f"{value:.3f}".rstrip("0").rstrip(".")


# ------------------------------------------------------------ data types ---

def _letter_matches(letter: str, intensity: float) -> bool:
    return any(math.isclose(t[letter], intensity, rel_tol=0.0, abs_tol=1e-9) for t in INTENSITY_TABLES.values())


@dataclass(frozen=True)
class ActionUnit:
    """One scored action: code, intensity in [0, 1], side, and the letter if any.

    ``letter`` is kept only as written notation: it must be the letter of
    ``intensity`` in one of the intensity tables (``C`` with 0.55).

    Examples
    --------
    >>> ActionUnit(12, 0.55, "left", "C")
    ActionUnit(code=12, intensity=0.55, side='left', letter='C')
    >>> ActionUnit(26, 1.0, "left")
    Traceback (most recent call last):
    ...
    ValueError: AU26 (Jaw Drop) cannot be scored on one side; use side='both'
    """

    code: int
    intensity: float
    side: str = "both"
    letter: str | None = None

    def __post_init__(self):
        if isinstance(self.code, bool) or not isinstance(self.code, int):
            raise TypeError(f"ActionUnit code must be an int, got {self.code!r}")
        unit = info(self.code)
        object.__setattr__(self, "intensity", parse_intensity(self.intensity, name=f"intensity of AU{self.code}"))
        if self.side not in SIDES:
            raise ValueError(f"side of AU{self.code} must be one of {SIDES}, got {self.side!r}")
        if self.side != "both" and not unit.unilateral:
            raise ValueError(f"AU{self.code} ({unit.name}) cannot be scored on one side; use side='both'")
        if self.letter is not None:
            if self.letter not in LETTERS:
                raise ValueError(f"letter of AU{self.code} must be one of {LETTERS} or None, got {self.letter!r}")
            if not _letter_matches(self.letter, self.intensity):
                raise ValueError(f"letter {self.letter!r} of AU{self.code} does not match intensity "
                                 f"{self.intensity} in any intensity table; use letter=None")

    def __str__(self) -> str:
        return self.format()

    def format(self, intensities: str | None = None) -> str:
        """This unit's notation. With ``intensities``, the text reads back to exactly this
        unit under that letter table (a letter only where it means this intensity there,
        otherwise the full-precision amount); without, the canonical short form."""
        if self.letter is not None and (intensities is None or INTENSITY_TABLES[intensities][self.letter] == self.intensity):
            amount = self.letter
        else:
            written = _format_amount(self.intensity) if intensities is None else repr(self.intensity)
            amount = "" if written in ("1", "1.0") else f"@{written}"
        return f"{_SIDE_PREFIX[self.side]}{self.code}{amount}"


def _sort_key(unit: ActionUnit) -> tuple[int, int]:
    return unit.code, SIDES.index(unit.side)


@dataclass(frozen=True)
class Expression:
    """A set of scored action units; ``str(expr)`` is the canonical notation.

    Units are kept in canonical order, so two expressions that say the same
    thing compare equal. The same code twice on one side is refused.

    Examples
    --------
    >>> expr = parse("26+1+2")
    >>> str(expr), sorted(expr.codes), len(expr)
    ('1+2+26', [1, 2, 26], 3)
    >>> str(parse("1+2+5B").scaled(0.5))
    '1@0.5+2@0.5+5@0.15'
    """

    units: tuple[ActionUnit, ...] = ()

    def __post_init__(self):
        units = tuple(self.units)
        for unit in units:
            if not isinstance(unit, ActionUnit):
                raise TypeError(f"Expression units must be ActionUnit, got {unit!r}")
        for i, unit in enumerate(units):
            for other in units[:i]:
                if other.code == unit.code and _COVERS[unit.side] & _COVERS[other.side]:
                    raise ValueError(f"AU{unit.code} given twice on the same side: {other} and {unit}")
        object.__setattr__(self, "units", tuple(sorted(units, key=_sort_key)))

    def __str__(self) -> str:
        return format_expression(self)

    def __bool__(self) -> bool:
        return bool(self.units)

    def __len__(self) -> int:
        return len(self.units)

    def __iter__(self):
        return iter(self.units)

    @property
    def codes(self) -> frozenset[int]:
        """The AU codes present, on any side."""
        return frozenset(unit.code for unit in self.units)

    def scaled(self, factor: float) -> "Expression":
        """Every intensity multiplied by ``factor`` (clamped to 1).

        A unit keeps its letter only while its intensity is unchanged; units
        scaled to 0 are kept (an explicit ``@0``).
        """
        factor = float(factor)
        if not factor >= 0.0:
            raise ValueError(f"scale factor must be >= 0, got {factor}")
        units = []
        for unit in self.units:
            level = min(1.0, unit.intensity * factor)
            letter = unit.letter if level == unit.intensity else None
            units.append(ActionUnit(unit.code, level, unit.side, letter))
        return Expression(tuple(units))


# --------------------------------------------------------------- parsing ---

def _tokens(text: str):
    """Yield ``(token, position)`` per ``+``-separated piece, stripped.

    An empty piece is reported as the ``+`` that leaves it empty.
    """
    pluses = [i for i, ch in enumerate(text) if ch == "+"]
    bounds = [-1, *pluses, len(text)]
    for k in range(len(bounds) - 1):
        start, end = bounds[k] + 1, bounds[k + 1]
        piece = text[start:end]
        token = piece.strip()
        if token:
            yield token, start + len(piece) - len(piece.lstrip())
            continue
        if k == len(bounds) - 2:      # nothing after the last '+'
            raise NotationError("missing action unit after", text=text, position=bounds[k], token="+",
                                hint="remove the trailing '+' or add an action unit")
        where = "before" if k == 0 else "between"
        raise NotationError(f"missing action unit {where}", text=text, position=end, token="+",
                            hint="each '+' must join two action units, e.g. '1+2'")


def _parse_token(token: str, position: int, text: str, table: dict) -> ActionUnit:
    def error(problem: str, hint: str) -> NotationError:
        return NotationError(problem, text=text, position=position, token=token, hint=hint)

    match = _TOKEN.fullmatch(token)
    if match is None:
        raise error("malformed action unit", "write e.g. '12', 'AU12', 'L12C' or '12@0.7'")
    if len(match["code"].lstrip("0")) > _MAX_CODE_DIGITS:
        raise error("unknown action unit", "FACS codes have at most two digits")
    code = int(match["code"].lstrip("0") or "0")
    if code == 0:
        raise error("neutral code", "'0' stands for the neutral face on its own; drop it")
    try:
        unit = info(code)
    except UnknownActionUnitError as exc:
        raise error("unknown action unit", exc.reason) from None
    side = _PREFIX_SIDE[match["side"].upper()] if match["side"] else "both"
    if side != "both" and not unit.unilateral:
        raise error("one-sided action unit",
                    f"AU{code} ({unit.name}) is only scored on both sides; drop the '{match['side']}'")
    letter = match["letter"].upper() if match["letter"] else None
    if letter is not None:
        if letter not in table:
            raise error(f"bad intensity letter {match['letter']!r} in",
                        f"FACS intensities are {', '.join(LETTERS)}")
        return ActionUnit(code, table[letter], side, letter)
    if match["amount"] is not None:
        if not _AMOUNT.fullmatch(match["amount"].strip()):
            raise error("bad intensity in", "write the amount as a fraction '0.7' or a percentage '70%' "
                                            "(ASCII digits)")
        try:
            return ActionUnit(code, parse_intensity(match["amount"]), side)
        except ValueError as exc:
            problem = "intensity out of range in" if "between 0 and 1" in str(exc) else "bad intensity in"
            raise error(problem, str(exc)) from None
    return ActionUnit(code, 1.0, side)


def parse(text: str, *, intensities: str = "hapfacs") -> Expression:
    """Read FACS notation into an :class:`Expression`.

    Parameters
    ----------
    text : str
        E.g. ``"1+2+5B+26"``, ``"R12A+L14"``, ``"AU12@70%"``, ``"neutral"``.
    intensities : str
        Intensity table for letters A-E: ``"hapfacs"`` (A 0.15, B 0.30,
        C 0.55, D 0.85, E 1.0) or ``"facshuman"`` (A 0.10, B 0.20, C 0.55,
        D 0.90, E 1.0); see :data:`facsim.catalogue.INTENSITY_TABLES`.

    Raises
    ------
    NotationError
        For an unknown code, a bad letter, an amount outside [0, 1], a
        malformed token, a side on a code that cannot be one-sided, or the same
        code twice on one side (``12+L12``; ``L12+R12`` is fine).

    Examples
    --------
    >>> str(parse("r12c + 6b"))
    '6B+R12C'
    >>> parse("1+2+AU99")
    Traceback (most recent call last):
    ...
    facsim.facs.notation.NotationError: unknown action unit 'AU99' at position 4 in '1+2+AU99': FACS defines no AU99; known codes are 1-2, 4-46, 50-58, 61-66, 70-74, 80-82, 84-85, 91-92, 97-98
    """
    if intensities not in INTENSITY_TABLES:
        raise ValueError(f"unknown intensity table {intensities!r}; "
                         f"choose one of {', '.join(map(repr, INTENSITY_TABLES))}")
    if not isinstance(text, str):
        raise TypeError(f"FACS notation must be a str, got {type(text).__name__}")
    from facsim.limits import limit, override_hint

    if len(text) > limit("max_notation"):
        raise NotationError(f"notation of {len(text):,} characters is too long {override_hint('max_notation')};",
                            text=text, position=0, token=text[:10])
    if text.strip().lower() in _NEUTRAL:
        return Expression()
    table = dict(INTENSITY_TABLES[intensities])
    units: list[ActionUnit] = []
    seen: list[tuple[ActionUnit, str, int]] = []
    for token, position in _tokens(text):
        unit = _parse_token(token, position, text, table)
        for other, other_token, other_position in seen:
            if other.code == unit.code and _COVERS[other.side] & _COVERS[unit.side]:
                raise NotationError("duplicate action unit", text=text, position=position, token=token,
                                    hint=f"AU{unit.code} is already scored by {other_token!r} at position "
                                         f"{other_position}; give a code once per side (L12+R12 is fine)")
        seen.append((unit, token, position))
        units.append(unit)
    return Expression(tuple(units))


def format_expression(expr: Expression, *, intensities: str | None = None) -> str:
    """The canonical notation of an expression (see the module docstring).

    With ``intensities`` (a letter table), the text reads back to exactly ``expr``
    under that table (see :meth:`ActionUnit.format`).

    Examples
    --------
    >>> format_expression(parse("26 + 12@100% + L2@0.3 + R2B + 1E"))
    '1E+L2@0.3+R2B+12+26'
    >>> format_expression(Expression())
    '0'
    """
    return "+".join(unit.format(intensities) for unit in expr.units) or "0"
