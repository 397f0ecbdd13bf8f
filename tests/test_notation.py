"""facsim.facs.notation: parsing, canonical formatting, errors with positions."""
import pickle
import random

import pytest

from facsim.facs.catalogue import catalogue
from facsim.facs.activations import UNILATERAL_DEFAULT_SIDE, activations
from facsim.facs.notation import (ActionUnit, Expression, NotationError, format_expression, parse,
                             parse_intensity)


def units(text, **kwargs):
    return [(u.code, u.intensity, u.side, u.letter) for u in parse(text, **kwargs).units]


# ------------------------------------------------------------- accepted ---

@pytest.mark.parametrize("text, expected", [
    ("1+2+5B+26", [(1, 1.0, "both", None), (2, 1.0, "both", None), (5, 0.30, "both", "B"),
                   (26, 1.0, "both", None)]),
    ("R12A+L14", [(12, 0.15, "right", "A"), (14, 1.0, "left", None)]),
    ("U6", [(6, 1.0, "unilateral", None)]),
    ("AU12C", [(12, 0.55, "both", "C")]),
    ("au12c", [(12, 0.55, "both", "C")]),
    ("12@0.7", [(12, 0.7, "both", None)]),
    ("12@70%", [(12, 0.7, "both", None)]),
    ("12@0", [(12, 0.0, "both", None)]),
    ("12@100%", [(12, 1.0, "both", None)]),
    ("12E", [(12, 1.0, "both", "E")]),
    (" 1 + 2 ", [(1, 1.0, "both", None), (2, 1.0, "both", None)]),
    ("R12C + 6B", [(6, 0.30, "both", "B"), (12, 0.55, "right", "C")]),
    ("L12+R12", [(12, 1.0, "left", None), (12, 1.0, "right", None)]),
    ("l12d", [(12, 0.85, "left", "D")]),
    ("RAU12", [(12, 1.0, "right", None)]),
    ("012", [(12, 1.0, "both", None)]),
    ("50+70", [(50, 1.0, "both", None), (70, 1.0, "both", None)]),   # known, not rendered
])
def test_parse_accepts(text, expected):
    assert units(text) == expected


@pytest.mark.parametrize("text", ["", "   ", "0", " 0 ", "neutral", "Neutral", " NEUTRAL "])
def test_neutral(text):
    expr = parse(text)
    assert expr == Expression() and not expr and len(expr) == 0
    assert str(expr) == "0"


@pytest.mark.parametrize("letter, hapfacs, facshuman", [
    ("A", 0.15, 0.10), ("B", 0.30, 0.20), ("C", 0.55, 0.55), ("D", 0.85, 0.90), ("E", 1.0, 1.0),
])
def test_intensity_tables(letter, hapfacs, facshuman):
    assert units(f"12{letter}") == [(12, hapfacs, "both", letter)]
    assert units(f"12{letter}", intensities="facshuman") == [(12, facshuman, "both", letter)]


def test_unknown_intensity_table():
    with pytest.raises(ValueError, match=r"unknown intensity table 'ekman'.*'hapfacs'"):
        parse("12", intensities="ekman")


# ------------------------------------------------------------ canonical ---

@pytest.mark.parametrize("text, canonical", [
    ("26+2+1", "1+2+26"),
    ("AU1 + AU2", "1+2"),
    ("R12+L12", "L12+R12"),
    ("12@0.55", "12@0.55"),            # no letter given, none invented
    ("12C", "12C"),
    ("12@100%", "12"),
    ("12@0.12345", "12@0.123"),
    ("12@0.9996", "12"),               # rounds to full intensity
    ("12@0.0001", "12@0"),
    ("12@25%", "12@0.25"),
    ("u6b", "U6B"),
    ("12E", "12E"),
    ("neutral", "0"),
])
def test_canonical_format(text, canonical):
    assert format_expression(parse(text)) == canonical == str(parse(text))


def _random_notation(rng: random.Random) -> str:
    codes = rng.sample(sorted(catalogue()), rng.randint(1, 6))
    tokens = []
    for code in codes:
        sides = ["", "L", "R", "U"] if catalogue()[code].unilateral else [""]
        side = rng.choice(sides)
        amount = rng.choice(["", "A", "B", "C", "D", "E", f"@{rng.random():.6f}", f"@{rng.randint(0, 100)}%"])
        tokens.append(f"{side}{rng.choice(['', 'AU', 'au'])}{code}{amount}")
        if side == "L" and rng.random() < 0.5:
            tokens.append(f"R{code}")
    rng.shuffle(tokens)
    return rng.choice(["+", " + "]).join(tokens)


@pytest.mark.parametrize("intensities", ["hapfacs", "facshuman"])
def test_format_parse_round_trip_is_stable(intensities):
    rng = random.Random(1234)
    for _ in range(500):
        text = _random_notation(rng)
        once = format_expression(parse(text, intensities=intensities))
        twice = format_expression(parse(once, intensities=intensities))
        assert twice == once, text
        assert parse(once, intensities=intensities) == parse(twice, intensities=intensities)


# --------------------------------------------------------------- errors ---

@pytest.mark.parametrize("text, problem, token, position", [
    ("1+2+AU99", "unknown action unit", "AU99", 4),
    ("3", "unknown action unit", "3", 0),
    ("1 + 99C", "unknown action unit", "99C", 4),
    ("12F", "bad intensity letter 'F' in", "12F", 0),
    ("1+12Z", "bad intensity letter 'Z' in", "12Z", 2),
    ("12@1.5", "intensity out of range in", "12@1.5", 0),
    ("12@150%", "intensity out of range in", "12@150%", 0),
    ("12@-0.1", "intensity out of range in", "12@-0.1", 0),
    ("12@abc", "bad intensity in", "12@abc", 0),
    ("12@", "bad intensity in", "12@", 0),
    ("12++2", "missing action unit between", "+", 3),
    ("+12", "missing action unit before", "+", 0),
    ("12+", "missing action unit after", "+", 2),
    ("1 + + 2", "missing action unit between", "+", 4),
    ("abc", "malformed action unit", "abc", 0),
    ("1+12CC", "malformed action unit", "12CC", 2),
    ("12.5", "malformed action unit", "12.5", 0),
    ("X12", "malformed action unit", "X12", 0),
    ("r 12 c", "malformed action unit", "r 12 c", 0),
    ("0+12", "neutral code", "0", 0),
    ("L26", "one-sided action unit", "L26", 0),
    ("1+R27", "one-sided action unit", "R27", 2),
    ("U29", "one-sided action unit", "U29", 0),
    ("L53", "one-sided action unit", "L53", 0),
    ("R64", "one-sided action unit", "R64", 0),
    ("12+12", "duplicate action unit", "12", 3),
    ("L12+L12", "duplicate action unit", "L12", 4),
    ("12+L12", "duplicate action unit", "L12", 3),
    ("R12+12C", "duplicate action unit", "12C", 4),
    ("U12+R12", "duplicate action unit", "R12", 4),
    ("1+AU1", "duplicate action unit", "AU1", 2),
])
def test_parse_errors_name_token_and_position(text, problem, token, position):
    with pytest.raises(NotationError, match=f"^{problem} '") as caught:
        parse(text)
    error = caught.value
    assert (error.token, error.position, error.text) == (token, position, text)
    assert f"{token!r} at position {position} in {text!r}" in str(error)
    assert isinstance(error, ValueError)


def test_unknown_code_message_lists_known_codes():
    with pytest.raises(NotationError, match=r"FACS defines no AU99; known codes are 1-2, 4-46"):
        parse("1+2+AU99")


def test_duplicate_message_points_at_first_occurrence():
    with pytest.raises(NotationError, match=r"already scored by '12' at position 0"):
        parse("12+L12")


def test_notation_error_pickles():
    with pytest.raises(NotationError) as caught:
        parse("1+2+AU99")
    copy = pickle.loads(pickle.dumps(caught.value))
    assert (str(copy), copy.text, copy.position, copy.token) == (str(caught.value), "1+2+AU99", 4, "AU99")


def test_parse_rejects_non_strings():
    with pytest.raises(TypeError, match="must be a str"):
        parse(12)


# ----------------------------------------------------- parse_intensity ---

@pytest.mark.parametrize("value, expected", [
    (0.5, 0.5), (1, 1.0), (0, 0.0), ("0.25", 0.25), ("70%", 0.7), (" 55 % ", 0.55), ("100%", 1.0),
])
def test_parse_intensity(value, expected):
    assert parse_intensity(value) == pytest.approx(expected)


@pytest.mark.parametrize("value, match", [
    (1.5, "between 0 and 1"), ("150%", "between 0 and 1"), (-0.1, "between 0 and 1"),
    ("lots", "a number in"), (True, "a number in"), (None, "a number in"), ("nan", "a number in"),
])
def test_parse_intensity_errors(value, match):
    with pytest.raises(ValueError, match=match):
        parse_intensity(value)


def test_parse_intensity_names_the_parameter():
    with pytest.raises(ValueError, match="^weight must"):
        parse_intensity(2, name="weight")


# ------------------------------------------------------ data type rules ---

def test_expression_is_canonical_and_frozen():
    a = Expression((ActionUnit(26, 1.0), ActionUnit(1, 0.5)))
    assert [u.code for u in a.units] == [1, 26]
    assert a == parse("1@0.5+26")
    with pytest.raises(AttributeError):
        a.units = ()
    assert a.codes == {1, 26}


@pytest.mark.parametrize("kwargs, match", [
    (dict(code=99, intensity=1.0), "unknown action unit 99"),
    (dict(code=12, intensity=1.2), "between 0 and 1"),
    (dict(code=12, intensity=1.0, side="top"), "side of AU12 must be one of"),
    (dict(code=26, intensity=1.0, side="left"), r"AU26 \(Jaw Drop\) cannot be scored on one side"),
    (dict(code=12, intensity=1.0, letter="F"), "letter of AU12 must be one of"),
    (dict(code=12, intensity=0.5, letter="C"), "does not match intensity 0.5"),
])
def test_action_unit_validation(kwargs, match):
    with pytest.raises(ValueError, match=match):
        ActionUnit(**kwargs)


def test_expression_refuses_duplicates():
    with pytest.raises(ValueError, match="AU12 given twice on the same side"):
        Expression((ActionUnit(12, 1.0), ActionUnit(12, 0.5, "left")))


@pytest.mark.parametrize("text, factor, expected", [
    ("1+2+5B", 0.5, "1@0.5+2@0.5+5@0.15"),
    ("12C", 1.0, "12C"),                       # unchanged: letter kept
    ("12@0.8", 2.0, "12"),                     # clamped to full
    ("6+12", 0.0, "6@0+12@0"),
    ("neutral", 0.3, "0"),
])
def test_scaled(text, factor, expected):
    assert str(parse(text).scaled(factor)) == expected


def test_scaled_rejects_negative_factor():
    with pytest.raises(ValueError, match="scale factor must be >= 0"):
        parse("12").scaled(-1)


# ------------------------------------------------ feeding activations ---

@pytest.mark.parametrize("text, expected", [
    ("12C", {(12, "left"): 0.55, (12, "right"): 0.55}),
    ("L12C", {(12, "left"): 0.55}),
    ("R12A+L14", {(12, "right"): 0.15, (14, "left"): 1.0}),
    ("U6", {(6, UNILATERAL_DEFAULT_SIDE): 1.0}),
    ("L12@0.2+R12@0.6", {(12, "left"): 0.2, (12, "right"): 0.6}),
    ("neutral", {}),
])
def test_expression_to_activations(text, expected):
    assert dict(activations(parse(text))) == pytest.approx(expected)
