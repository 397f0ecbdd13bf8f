"""Characters: presets, macro weighting, and differences their parameters cause."""
from __future__ import annotations

import numpy as np
import pytest

from facsim.head.assets import load_face_data
from facsim.head.character import (Character, CharacterError, character_positions, macro_weights, preset,
                              preset_names, random_character, resolve_character)


def test_macro_weights_are_products_of_partitions_of_unity():
    w = macro_weights(Character(gender=0.3, age=40, african=0.2, caucasian=0.8, muscle=0.7, weight=0.2))
    race = sum(v for k, v in w.items() if not k.startswith("universal"))
    universal = sum(v for k, v in w.items() if k.startswith("universal"))
    assert race == pytest.approx(1.0) and universal == pytest.approx(1.0)
    assert w["african-female-young"] == pytest.approx(0.2 * 0.7 * (1 - (40 - 25) / 65))


def test_presets_cover_sex_ethnicity_and_age():
    chars = [preset(n) for n in preset_names()]
    assert len(chars) >= 10
    for sex in (0, 1):
        for eth in ("african", "asian", "caucasian"):
            ages = [c.age for c in chars if round(c.gender) == sex and c.ethnicity[eth] > 0.8]
            assert min(ages) < 40 and max(ages) > 60, (sex, eth)


@pytest.mark.parametrize("name", preset_names())
def test_every_preset_builds(name, head):
    base = character_positions(preset(name), load_face_data())
    p = head.positions(base)
    assert np.isfinite(p).all() and p.shape == (head.vertex_count, 3)


def _marks_positions(character, head, marks):
    return head.positions(character_positions(character, load_face_data()))


def test_older_characters_have_deeper_nasolabial_folds(head, marks):
    def fold_depth(age):
        p = _marks_positions(Character(age=age), head, marks)
        fold, cheek, corner = (p[marks[n + "_left"]] for n in ("nasolabial_fold", "cheek", "lip_corner"))
        return 0.5 * (cheek[2] + corner[2]) - fold[2]  # how far the fold sits behind its neighbours
    assert fold_depth(75) > fold_depth(25)


def test_men_have_wider_jaws(head, marks):
    def jaw_width(gender):
        p = _marks_positions(Character(gender=gender), head, marks)
        return p[marks["jaw_angle_left"], 0] - p[marks["jaw_angle_right"], 0]
    assert jaw_width(1.0) > jaw_width(0.0) + 0.02


def test_face_sliders_move_their_region(head, marks):
    data = load_face_data()
    a = head.positions(character_positions(Character(), data))
    b = head.positions(character_positions(Character(face={"nose/nose-scale-horiz": 1.0}), data))
    moved = np.linalg.norm(a - b, axis=1)
    assert moved[marks["nose_wing_left"]] > 0.01 and moved[marks["inner_brow_left"]] < 1e-3


def test_random_characters_are_reproducible():
    assert random_character(7) == random_character(7)
    assert random_character(7) != random_character(8)
    assert resolve_character("random:7") == random_character(7)


@pytest.mark.parametrize("spec, message", [
    ("nobody", "unknown character 'nobody'"),
    ("random:x", "integer seed"),
    ({"age": 200}, "age"),
    ({"gender": 2}, "gender"),
    ({"height": 1}, "unknown character parameter"),
    ({"face": {"nose/nonsense": 0.5}}, None),
    ({"colors": {"fur": "#000000"}}, "unknown colour 'fur'"),
])
def test_bad_characters_are_refused(spec, message):
    with pytest.raises(CharacterError, match=message):
        c = resolve_character(spec)
        character_positions(c, load_face_data())
