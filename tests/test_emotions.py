"""facsim.facs.emotions: preset tables, intensity scaling, blends."""
import pytest

from facsim.facs.activations import activations
from facsim.facs.notation import Expression, parse
from facsim.facs.emotions import DEFAULT_TABLE, _same_as, blend, describe_emotions, emotion, emotion_names, preset_tables

EMOTIONS = ["happiness", "sadness", "surprise", "anger", "fear", "disgust", "contempt", "embarrassment",
            "pride", "neutral"]
TABLES = ["facsim", "hapfacs", "emfacs"]


def test_names_and_tables():
    assert list(emotion_names()) == EMOTIONS
    assert list(preset_tables()) == TABLES
    for table in preset_tables().values():
        assert table.title and table.source
        assert list(table.presets) == EMOTIONS


@pytest.mark.parametrize("table", TABLES)
@pytest.mark.parametrize("name", EMOTIONS)
def test_every_preset_parses(table, name):
    expr = emotion(name, table=table)
    assert isinstance(expr, Expression)
    assert bool(expr) == (name != "neutral")
    assert expr == parse(preset_tables()[table].presets[name])
    assert all(0.0 < unit.intensity <= 1.0 for unit in expr.units)


@pytest.mark.parametrize("table, name, canonical", [
    ("hapfacs", "happiness", "6+12+25"),
    ("hapfacs", "anger", "5+7+9+10+15+17+42"),
    ("hapfacs", "contempt", "12+R14"),
    ("hapfacs", "embarrassment", "12+52+62+64"),
    ("hapfacs", "pride", "12+53+58+64"),
    ("emfacs", "happiness", "6+12"),
    ("emfacs", "sadness", "1+4+15"),
    ("emfacs", "surprise", "1+2+5B+26"),
    ("emfacs", "fear", "1+2+4+5+7+20+26"),
    ("emfacs", "anger", "4+5+7+23"),
    ("emfacs", "disgust", "9+15+16"),
    ("emfacs", "contempt", "R12A+R14A"),
])
def test_known_presets(table, name, canonical):
    assert str(emotion(name, table=table)) == canonical


def test_default_table_is_table_5_with_emfacs_anger_and_surprise():
    """Session 18: HapFACS Table 5's anger (5+7+9+10+15+17+42) carries disgust's 9, 10 and 15
    and was read as disgust, and its surprise raises the lid fully (5, EMFACS 5B); the default
    set takes EMFACS's anger and surprise and Table 5 for the rest."""
    tables = preset_tables()
    assert DEFAULT_TABLE == "facsim" and next(iter(tables)) == DEFAULT_TABLE
    for name in EMOTIONS:
        source = "emfacs" if name in ("anger", "surprise") else "hapfacs"
        assert tables["facsim"].presets[name] == tables[source].presets[name]
        assert emotion(name) == emotion(name, table=source)
    assert tables["facsim"].notes["sadness"] == tables["hapfacs"].notes["sadness"]
    assert "--table hapfacs" in tables["facsim"].notes["anger"]
    assert not {9, 10, 15} & emotion("anger").codes
    assert [u.intensity for u in emotion("surprise").units if u.code == 5] == [0.30]
    text = describe_emotions()
    assert "anger          4+5+7+23" in text and "Table 5" in text


def test_same_as_must_name_a_table_that_prints_the_preset():
    tables = {"a": {"presets": {"anger": {"facs": "4+5+7+23"}}},
              "b": {"presets": {"anger": {"same_as": "a"}}}}
    assert _same_as(tables, "anger", {"same_as": "a", "note": "mine"}, "here") == {"facs": "4+5+7+23", "note": "mine"}
    with pytest.raises(ValueError, match="here: `same_as` must name a table"):
        _same_as(tables, "anger", {"same_as": "b"}, "here")
    with pytest.raises(ValueError, match="got 'c'"):
        _same_as(tables, "anger", {"same_as": "c"}, "here")


def test_head_codes_in_social_emotions():
    assert {54, 64} <= emotion("embarrassment", table="emfacs").codes
    assert {53, 58} <= emotion("pride", table="emfacs").codes


def test_letters_follow_the_chosen_intensity_table():
    hap = emotion("surprise", table="emfacs")
    fh = emotion("surprise", table="emfacs", intensities="facshuman")
    assert [u.intensity for u in hap.units if u.code == 5] == [0.30]
    assert [u.intensity for u in fh.units if u.code == 5] == [0.20]


@pytest.mark.parametrize("intensity", [0.5, "50%", "0.5"])
def test_global_intensity_scales_every_unit(intensity):
    full = emotion("surprise", table="emfacs")
    half = emotion("surprise", table="emfacs", intensity=intensity)
    assert [u.code for u in half.units] == [u.code for u in full.units]
    assert [u.intensity for u in half.units] == pytest.approx([u.intensity / 2 for u in full.units])
    assert all(u.letter is None for u in half.units)


def test_full_intensity_keeps_letters():
    assert str(emotion("contempt", table="emfacs", intensity="100%")) == "R12A+R14A"


@pytest.mark.parametrize("call, match", [
    (lambda: emotion("joy"), r"unknown emotion 'joy'; choose one of happiness, sadness"),
    (lambda: emotion("happiness", table="ekman"), r"unknown emotion table 'ekman'; choose one of 'facsim', 'hapfacs'"),
    (lambda: emotion("happiness", intensity=2), "intensity must be between 0 and 1"),
    (lambda: emotion("happiness", intensity="lots"), "intensity must be a number"),
    (lambda: blend("happiness", "sadness", weight=1.5), "weight must be between 0 and 1"),
    (lambda: blend("happiness", "joy"), "unknown emotion 'joy'"),
])
def test_errors(call, match):
    with pytest.raises(ValueError, match=match):
        call()


def test_names_are_case_insensitive():
    assert emotion(" Happiness ") == emotion("happiness")


# ---------------------------------------------------------------- blends ---

@pytest.mark.parametrize("table", TABLES)
@pytest.mark.parametrize("name", EMOTIONS)
def test_blend_endpoints(table, name):
    assert blend(name, "surprise", 0.0, table=table) == emotion(name, table=table)
    assert blend("surprise", name, 1.0, table=table) == emotion(name, table=table)


def test_blend_weights_each_unit():
    mixed = blend("happiness", "sadness", weight=0.25, table="emfacs")
    levels = {u.code: u.intensity for u in mixed.units}
    assert levels == pytest.approx({6: 0.75, 12: 0.75, 1: 0.25, 4: 0.25, 15: 0.25})


def test_blend_shared_units_interpolate():
    mixed = blend(parse("12@0.2+5B"), parse("12@0.6+5B"), weight=0.5)
    assert str(mixed) == "5B+12@0.4"           # 5B untouched keeps its letter


def test_blend_with_neutral_is_scaling():
    assert blend("surprise", "neutral", 0.4, table="emfacs") == emotion("surprise", table="emfacs",
                                                                           intensity=0.6)


def test_blend_mixed_sides_goes_per_side():
    mixed = blend("happiness", "contempt", table="emfacs")
    act = activations(mixed)
    assert act[12, "left"] == pytest.approx(0.5)
    assert act[12, "right"] == pytest.approx(0.5 + 0.5 * 0.15)
    assert act[14, "right"] == pytest.approx(0.075) and act[14, "left"] == 0.0


def test_blend_keeps_sides_as_written_when_they_agree():
    assert str(blend(parse("L12@0.4+R12@0.8"), parse("L12@0.8+R12@0.4"))) == "L12@0.6+R12@0.6"


def test_blend_mixed_sides_equal_result_becomes_bilateral():
    assert str(blend(parse("12@0.4"), parse("L12@0.4+R12@0.4"))) == "12@0.4"
    assert str(blend(parse("12@0.2"), parse("L12@0.6"))) == "L12@0.4+R12@0.1"


def test_blend_unilateral_follows_activations():
    mixed = blend(parse("U6"), parse("6"), weight=0.5)
    expected = activations(parse("U6")).scaled(0.5).combined(activations(parse("6")).scaled(0.5))
    assert dict(activations(mixed)) == pytest.approx(dict(expected))


def test_blend_rejects_other_types():
    with pytest.raises(TypeError, match="second must be an emotion name or an Expression"):
        blend("happiness", 3)


# ---------------------------------------------------------------- display ---

@pytest.mark.parametrize("table", TABLES)
def test_describe_emotions(table):
    text = describe_emotions(table)
    assert preset_tables()[table].title in text
    for name in EMOTIONS:
        assert any(line.split() == [name, preset_tables()[table].presets[name]] for line in text.splitlines())
    assert "Source:" in text
