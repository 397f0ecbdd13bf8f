"""The register engine: each simulated AU moves the face where and how FACS says."""
from __future__ import annotations

import numpy as np
import pytest

from facsim.facs.catalogue import catalogue
from facsim.facs.activations import Activations, activations
from facsim.facs.notation import parse
from facsim.engines.registers import (combine_registers, register_table, register_weights, response,
                                     response_inverse, simulated_codes)
from facsim.engines.rigid import rigid_table

X, Y, Z = 0, 1, 2
#: AU → checks (landmark on the character's left, axis, sign): the FACS manual's appearance changes.
DIRECTIONS = {
    1: [("inner_brow", Y, +1)],
    2: [("outer_brow", Y, +1)],
    4: [("inner_brow", Y, -1), ("inner_brow", X, -1)],  # lowered and drawn together
    5: [("upper_lid", Y, +1)],
    6: [("cheek", Y, +1), ("lower_lid", Y, +1)],
    7: [("lower_lid", Y, +1)],
    9: [("nose_wing", Y, +1), ("inner_brow", Y, -1)],
    10: [("upper_lip", Y, +1)],
    11: [("nasolabial_fold", Z, -1)],
    12: [("lip_corner", Y, +1), ("lip_corner", X, +1)],
    13: [("lip_corner", Y, +1)],
    14: [("lip_corner", Z, -1)],
    15: [("lip_corner", Y, -1)],
    16: [("lower_lip", Y, -1)],
    17: [("lower_lip", Y, +1)],
    18: [("upper_lip", Z, +1), ("lip_corner", X, -1)],
    19: [("lower_lip", Y, -1)],
    20: [("lip_corner", X, +1)],
    22: [("upper_lip", Z, +1)],
    24: [("lower_lip", Y, +1), ("upper_lip", Y, -1)],  # pressed together
    25: [("lower_lip", Y, -1)],
    26: [("chin", Y, -1)],
    27: [("chin", Y, -1)],
    28: [("lower_lip", Z, -1)],
    29: [("chin", Z, +1)],
    33: [("cheek", Z, +1)],
    35: [("cheek", X, -1)],
    38: [("nose_wing", X, +1)],
    39: [("nose_wing", X, -1)],
    41: [("inner_brow", Y, -1)],
    42: [("inner_brow", Y, -1)],
    43: [("upper_lid", Y, -1)],
    44: [("inner_brow", X, -1)],
    45: [("upper_lid", Y, -1)],
    46: [("upper_lid", Y, -1)],
    51: [("nose_tip", X, +1)],  # the head turns to the character's left
    52: [("nose_tip", X, -1)],
    53: [("nose_tip", Y, +1)],
    54: [("nose_tip", Y, -1)],
    55: [("glabella", X, +1)],  # top of the head toward the left shoulder
    56: [("glabella", X, -1)],
    57: [("nose_tip", Z, +1)],
    58: [("nose_tip", Z, -1)],
    63: [("upper_lid", Y, +1)],
    64: [("upper_lid", Y, -1)],
}


@pytest.fixture(scope="module")
def engine(face_of):
    return face_of("noah").engine


def _moved(engine, text):
    return engine.deform(activations(parse(text))).positions - engine.neutral


def test_every_simulated_au_is_checked_or_is_an_eye_rotation():
    eye = set(rigid_table()["eye_rotations"])
    assert simulated_codes() - eye - set(DIRECTIONS) <= {8, 21, 23, 30, 32, 34, 36, 37}  # checked below


@pytest.mark.parametrize("code", sorted(DIRECTIONS))
def test_au_moves_landmarks_the_way_facs_says(engine, marks, code):
    delta = _moved(engine, f"{code}")
    for name, axis, sign in DIRECTIONS[code]:
        key = name if name in marks else name + "_left"
        assert sign * delta[marks[key], axis] > 0.002, (code, name, axis, delta[marks[key]])


@pytest.mark.parametrize("code", [8, 21, 23, 30, 34])
def test_other_simulated_aus_move_the_lower_face(engine, marks, code):
    delta = np.linalg.norm(_moved(engine, f"{code}"), axis=1)
    assert delta.max() > 0.01
    assert delta[marks["inner_brow_left"]] < 0.005  # and leave the brows alone


@pytest.mark.parametrize("code", sorted(set(DIRECTIONS) - {30, 46} - set(range(51, 59))))
def test_bilateral_aus_are_symmetric(engine, head, code):
    p = engine.deform(activations(parse(f"{code}"))).positions
    assert np.allclose(p[head.mirror] * [-1, 1, 1], p, atol=1e-4)


@pytest.mark.parametrize("code", [1, 2, 4, 6, 12, 15, 20, 46])
def test_unilateral_aus_move_only_their_side(engine, head, code):
    delta = np.linalg.norm(_moved(engine, f"L{code}"), axis=1)
    x = engine.neutral[:, 0]
    assert delta[x > 0.05].max() > 0.01
    assert delta[x < -0.15].max() < 0.1 * delta[x > 0.05].max()  # the lips are one piece: spill stops by 1.5 cm


def test_eyes_turn_left_on_61(engine, head):
    p = engine.deform(activations(parse("61"))).positions
    for side in ("left", "right"):
        eye = head.eye_vertices[side]
        pupil = eye[np.argmax(head.eye_local[:, 2])]
        assert p[pupil, 0] - engine.neutral[pupil, 0] > 0.03


def test_eq1_sums_shared_registers_and_clamps_to_the_smallest_max():
    assert combine_registers([(0.2, 0.6), (0.3, 1.0)]) == pytest.approx(0.42)
    assert combine_registers([(0.5, 0.6), (0.4, 0.8)]) == pytest.approx(0.6)  # 0.62 clamped to 0.6
    weights = register_weights(Activations({(42, "left"): 0.2, (4, "left"): 0.2}))
    shared = [w for c, w in weights.items() if c.target == "faceunits/browDownLeft"]
    assert len(weights) == 3  # browDown shared, eyebrows-down summed as well; 4's push on the lid (eyeBlink)
    # each AU at the engine's response to 0.2: r·1.0 + r·0.6, under min(1.0, 0.6)
    assert shared == [pytest.approx(1.6 * response(0.2))] and 1.6 * response(0.2) < 0.6


def test_response_is_concave_from_rest_to_e():
    """Issue 13: an AU at intensity x moves its targets by more than x of the way (skin stiffens),
    rising steadily from rest (0) to E (1); the inverse reads the intensity back."""
    levels = np.linspace(0.0, 1.0, 21)
    weights = np.array([response(x) for x in levels])
    assert weights[0] == 0.0 and weights[-1] == pytest.approx(1.0)
    assert np.all(np.diff(weights) > 0) and np.all(np.diff(weights, 2) < 0)   # rising, concave
    assert 0.55 < response(0.5) < 0.7                                         # HapFACS's 50 % is over half-way
    assert [response_inverse(w) for w in weights] == pytest.approx(levels)
    half = register_weights(Activations({(12, "left"): 0.5}))
    smile_max = next(float(reg["max"]) for reg in register_table()["action_units"][12]["registers"]
                     if reg["target"] == "faceunits/mouthSmile{Side}")
    # 12 takes its own stiffening (session 23): its registers follow its own curve, read back alike
    assert {c.target: w for c, w in half.items()}["faceunits/mouthSmileLeft"] == pytest.approx(smile_max * response(0.5, 12))
    assert response(0.5, 12) > response(0.5) and response_inverse(response(0.3, 12), 12) == pytest.approx(0.3)


def test_eq1_never_undoes_the_strongest_au():
    # Literal Eq. 1 would clamp 4's brow lowering to 9's max (0.35) and 26's jaw drop to 25's.
    assert combine_registers([(1.0, 0.6), (1.0, 1.0)]) == pytest.approx(1.0)
    for combo, alone, target in (("4+9", "4", "faceunits/browDown"), ("25+26", "26", "faceunits/jawOpen")):
        both = register_weights(activations(parse(combo)))
        single = register_weights(activations(parse(alone)))
        for column, weight in single.items():
            if column.target.startswith(target):
                assert both[column] >= weight - 1e-12, (combo, column)


def test_every_register_names_a_real_target(face_of):
    from facsim.facs.activations import SIDES
    engine = face_of("sofia").engine
    for code in register_table()["action_units"]:
        for side in SIDES:
            for column in register_weights(Activations({(code, side): 1.0})):
                assert np.abs(engine.column(column)).max() > 0, (code, column)


def test_every_catalogue_action_is_simulated_or_explained():
    table = register_table()
    for code, info in catalogue().items():
        if info.rendered:
            assert code in simulated_codes() or code in table["not_simulated"], code


def test_emotions_differ_from_neutral_where_their_aus_act(face_of):
    from facsim.facs.emotions import emotion, emotion_names
    face = face_of("amara")
    neutral = face.render(size=128).astype(int)
    for name in emotion_names():
        if name == "neutral":
            continue
        img = face.render(emotion(name), size=128).astype(int)
        assert np.abs(img - neutral).sum(-1).max() > 100, name


#: The all-pairs sweep is shared out over this many tests, so ``pytest -n`` runs them side by side.
PAIR_PARTS = 3


def _pairs():
    import itertools

    def unit(code):  # the wink is one-sided by definition
        return f"L{code}E" if code == 46 else f"{code}E"

    codes = sorted(simulated_codes())
    return [unit(c) for c in codes] + [f"{unit(a)}+{unit(b)}" for a, b in itertools.combinations(codes, 2)]


@pytest.fixture(scope="module")
def geometry_check(engine, head):
    from facsim.engines.checks import GeometryCheck

    return GeometryCheck(head, engine.neutral)


@pytest.mark.parametrize("part", range(PAIR_PARTS))
def test_every_au_and_pair_at_e_stays_physical(engine, head, marks, geometry_check, part):
    """Every single AU and pair of AUs at E, checked on EVERY skin vertex and triangle (the lids,
    their corners and the skin around the eyes included): finite, no skin inside an eyeball, no
    skin triangle turned inside out — no exceptions (issue 12)."""
    problems = []
    for text in _pairs()[part::PAIR_PARTS]:
        problems += _geometry_problems(engine, geometry_check, text)
    assert not problems, "\n".join(problems)


def _geometry_problems(engine, check, text) -> list[str]:
    p = engine.deform(activations(parse(text))).positions
    if not np.isfinite(p).all():
        return [f"{text}: not finite"]
    report = check(p)
    out = []
    if report.inside:
        out.append(f"{text}: {report.inside} skin points {report.depth * 100:.2f} mm inside an eyeball")
    if report.flipped:
        out.append(f"{text}: {report.flipped} skin triangles turned inside out")
    return out


#: What closes or narrows the eyes, and what moves the lids or the skin around them.
CLOSING = ("43E", "45E", "L46E", "64E")
AROUND_EYES = ("1E", "2E", "4E", "5E", "6E", "7E", "9E", "12E", "41E", "42E", "44E", "61E", "62E", "63E", "65E", "66E")


@pytest.mark.parametrize("character", ["ava", "kwame", "george"])
def test_lids_lips_and_neck_stay_physical_on_other_characters(face_of, head, character):
    """The lid, lip and neck expressions that used to fold, on a young woman (larger eyes), a man
    and an older man: closing AUs with everything around the eyes, 8 with the lip AUs, an open jaw
    with head motion."""
    from facsim.engines.checks import GeometryCheck

    engine = face_of(character).engine
    check = GeometryCheck(head, engine.neutral)
    texts = list(CLOSING) + [f"{a}+{b}" for a in CLOSING for b in AROUND_EYES + CLOSING if a < b or b not in CLOSING]
    texts += [f"8E+{b}E" for b in (23, 24, 25, 26, 27, 28)] + ["27E+57E", "27E+58E", "26E+58E"]
    problems = [q for text in texts for q in _geometry_problems(engine, check, text)]
    assert not problems, "\n".join(problems)


def test_fear_and_closed_eye_smiles_stay_physical_on_amara(face_of, head):
    """Amara's lids are the tightest of the presets: anger's glare rule (5 raised 1.5x under
    lowered brows) folded her upper lid in fear's 1+2+4+5, and 12's raised cheek with closed
    eyes her outer corner; the rule now yields to 1/2, and 12 halves its cheek raise there."""
    from facsim.engines.checks import GeometryCheck

    engine = face_of("amara").engine
    check = GeometryCheck(head, engine.neutral)
    texts = ["1+2+4+5+20+26", "1+2+4+5", "1+2+4+5+7+20+26", "12E+43E", "12E+45E", "12E+L46E"]
    problems = [q for text in texts for q in _geometry_problems(engine, check, text)]
    assert not problems, "\n".join(problems)


#: The lid AUs and pairs that folded slivers at the outer eye corners of mei (and hiro, lin, kenji,
#: whose character morphs draw the corner together to 0.13-0.3 mm) and george (6+7, 6+12, 9+7).
EYE_CORNER = ("6E+7E", "6E+12E", "6E+64E", "7E+64E", "4E+7E", "9E+7E", "12E+7E")


@pytest.mark.parametrize("character", ["mei", "george"])
def test_singles_eye_pairs_and_emotions_stay_physical_on_mei_and_george(face_of, head, character):
    """Every AU at E, the pairs around the eye corners and every emotion at 100 % keep every skin
    triangle the right way out on an East Asian and an older preset (mei's 7E inverted 8
    slivers at the outer corners, 6E+64E 21; george's 6E+12E 7 and happiness 6)."""
    from facsim.engines.checks import GeometryCheck
    from facsim.facs.emotions import emotion, emotion_names

    engine = face_of(character).engine
    check = GeometryCheck(head, engine.neutral)
    texts = [f"L{c}E" if c == 46 else f"{c}E" for c in sorted(simulated_codes())] + list(EYE_CORNER)
    problems = [q for text in texts for q in _geometry_problems(engine, check, text)]
    for name in emotion_names():
        report = check(engine.deform(activations(emotion(name))).positions)
        if report.flipped or report.inside:
            problems.append(f"{name}: {report.flipped} skin triangles turned inside out, {report.inside} skin points in an eye")
    assert not problems, "\n".join(problems)


def _eye_seen(head, positions, side, within=None) -> int:
    """How many of the eyeball's points (its front within 40 degrees of its gaze, or the local
    points ``within`` selects) are seen from straight ahead: no skin triangle between them and the
    viewer (rays toward +Z, Moller-Trumbore)."""
    eye = head.eye_vertices[side]
    pick = head.eye_local[:, 2] > np.cos(np.radians(40)) if within is None else within(head.eye_local)
    points = positions[eye[pick]].astype(float)
    centre = positions[eye].mean(axis=0)
    tris = np.asarray(head.triangles)
    tris = tris[(tris < head.skin_vertex_count).all(axis=1)]
    # Skin in front of the eyeball: the lids' inner faces lie inside it, hidden by the eye itself.
    radius = np.linalg.norm(positions[eye] - centre, axis=1).mean()
    distance = np.linalg.norm(positions[tris].mean(axis=1) - centre, axis=1)
    tris = tris[(distance < 0.4) & (distance > radius)]
    a, b, c = (positions[tris[:, k]].astype(float) for k in range(3))
    e1, e2, ray = b - a, c - a, np.array([0.0, 0.0, 1.0])
    h = np.cross(ray, e2)
    det = (e1 * h).sum(1)
    ok = np.abs(det) > 1e-12
    s_ = points[:, None, :] - a[None]
    u = (s_ * h[None]).sum(-1) / np.where(ok, det, 1.0)
    q = np.cross(s_, e1[None])
    v = (q @ ray) / np.where(ok, det, 1.0)
    t = (q * e2[None]).sum(-1) / np.where(ok, det, 1.0)
    hit = ok & (u >= 0) & (v >= 0) & (u + v <= 1) & (t > 1e-5)
    return int((~hit.any(axis=1)).sum())


@pytest.mark.parametrize("character", ["noah", "ava", "george"])
def test_closed_lids_cover_the_eye(face_of, head, character):
    """43 and 45 close both eyes and 46 the left one fully: no point of the eyeball's front shows
    from straight ahead (the lids meet, no gap); at rest and under 5 the eye shows."""
    engine = face_of(character).engine
    seen = {text: {side: _eye_seen(head, engine.deform(activations(parse(text))).positions, side)
                   for side in ("left", "right")} for text in ("43E", "45E", "L46E", "5E")}
    rest = {side: _eye_seen(head, engine.neutral, side) for side in ("left", "right")}
    assert seen["43E"] == seen["45E"] == {"left": 0, "right": 0}, seen
    assert seen["L46E"]["left"] == 0 and seen["L46E"]["right"] > 0, seen
    assert min(rest.values()) > 0 and seen["5E"]["left"] > rest["left"], (rest, seen)


def test_skin_guard_unfolds_a_fold_and_lifts_skin_off_the_eye(engine, head, marks, geometry_check):
    """The guard itself: a lid point pushed into the eyeball and a folded triangle are repaired."""
    p = engine.neutral.copy()
    centre, radius = head.eye_pivot(engine.base_positions, "left")
    # the skin point nearest the cornea's front among those outside the eye at rest (the lid's
    # inner surface lies just inside it; lifted at rest, a hooded lid brings one nearest)
    outside = geometry_check.outside[0]
    lid = outside[np.argmin(np.linalg.norm(p[outside] - (centre + [0, 0, radius]), axis=1))]
    p[lid] = centre + 0.5 * (p[lid] - centre)          # halfway to the eye's centre
    centroid = p[geometry_check.triangles].mean(axis=1)
    a, b, c = geometry_check.triangles[np.argmin(np.linalg.norm(centroid - p[marks["cheek_left"]], axis=1))]
    edge = (p[c] - p[b]) / np.linalg.norm(p[c] - p[b])
    foot = p[b] + np.dot(p[a] - p[b], edge) * edge
    p[a] = p[a] + 1.3 * (foot - p[a])                  # push one corner just across the opposite edge
    before = geometry_check(p)
    assert before.inside >= 1 and before.flipped >= 1
    after = geometry_check(engine.guard(p))
    assert after.ok, after


@pytest.mark.parametrize("level", [1.0, 0.5])
@pytest.mark.parametrize("name", ["sadness", "fear"])
def test_sad_and_fearful_inner_brows_are_raised(engine, marks, name, level):
    """Issue 13: in 1+4 the inner brows rise and are drawn together (a combination rule),
    at half intensity by half as much (the rule holds while 1 and 4 keep their ratio)."""
    from facsim.facs.emotions import emotion

    delta = engine.deform(activations(emotion(name, intensity=level))).positions - engine.neutral
    assert delta[marks["inner_brow_left"], 1] > 0.03 * level
    both = _moved(engine, "1+4")[marks["inner_brow_left"]]
    assert both[1] > 0.03 and both[0] < -0.005


def test_pressed_lips_keep_their_corners(engine, marks):
    """Issue 13: 24 presses the lips together without the smile mouthPress alone gives."""
    delta = _moved(engine, "24")
    assert abs(delta[marks["lip_corner_left"], 1]) < 0.015
    assert delta[marks["upper_lip"], 1] < -0.02 and delta[marks["lower_lip"], 1] > 0.02


def test_tightened_lips_keep_their_corners(engine, marks):
    """FACS 23 narrows the red of the lips without raising their corners: with mouthPress alone
    the corners rose 4 mm and EMFACS anger (4+5+7+23) wore a faint smile (session 16)."""
    delta = _moved(engine, "23")
    assert abs(delta[marks["lip_corner_left"], 1]) < 0.02
    assert delta[marks["upper_lip"], 1] - delta[marks["lower_lip"], 1] < -0.04     # red narrowed >= 4 mm


@pytest.mark.parametrize("code", ["23", "24"])
@pytest.mark.parametrize("preset", ["ava", "kwame", "george"])
def test_tightened_and_pressed_lips_do_not_widen_the_mouth(face_of, marks, preset, code):
    """FACS 23 tightens and thins the red, 24 presses the lips together; neither stretches the mouth
    as 20 does. With ARKit's mouthPress the corners moved 7.7 mm apart at 23E (0.6) and 4.2 mm at 24E
    (0.25), and anger (4+5+7+23) wore a stretched slot (session 20)."""
    engine = face_of(preset).engine
    corners = [marks["lip_corner_left"], marks["lip_corner_right"]]

    def width(positions):
        return float(np.linalg.norm(positions[corners[0]] - positions[corners[1]]))

    assert width(engine.deform(activations(parse(code))).positions) - width(engine.neutral) < 0.01   # 1 mm


def test_16_pulls_the_lower_lip_down_not_the_chin(engine, marks):
    """Depressor labii inferioris runs from the lower lip to the mandible: 16 moves the lip down off
    the lower teeth and leaves the chin boss. ARKit's mouthLowerDown past 1.0 dragged the chin
    6.2 mm down with a 4.0 mm drop of the lip, the lip a flat-bottomed slab (session 20)."""
    delta = _moved(engine, "16")
    lip, chin = -delta[marks["lower_lip"], 1], -delta[marks["chin"], 1]
    assert lip > 0.04 and chin < 0.5 * lip


def test_15_lowers_the_corners_without_pushing_the_lower_lip_up(engine, marks):
    """Depressor anguli oris pulls the corners down; pushing the lower lip and the chin boss up is
    mentalis's (17). MakeHuman's mouth-depression unit in 15 raised the lower lip 1.0 mm and the
    chin 0.6 mm, the thick boxed lower lip over a chin bulge of the sad faces (session 20)."""
    delta = _moved(engine, "15")
    assert delta[marks["lip_corner_left"], 1] < -0.04
    assert delta[marks["lower_lip"], 1] < 0.003 and delta[marks["chin"], 1] < 0.003


def _emotion_moved(engine, name, level=1.0, table="facsim"):
    from facsim.facs.emotions import emotion

    return engine.deform(activations(emotion(name, intensity=level, table=table))).positions - engine.neutral


@pytest.mark.parametrize("table", ["facsim", "hapfacs"])
@pytest.mark.parametrize("level", [1.0, 0.5])
def test_anger_glares_under_knitted_brows(engine, marks, level, table):
    """Issue 13 (HapFACS anger read as disgust): the eyes of 5+7 under lowered brows are not
    narrower than at rest, and the brows are drawn together more than in disgust (9 without 4),
    in the default anger (EMFACS 4+5+7+23) and in HapFACS's (5+7+9+10+15+17+42, the glare rules).
    (Session 26: disgust's brows are lowered but not drawn together - 9 does not gather them, 4
    does - where until then 9 drew them 5.2 mm together on ava; the test asked for some knit.)"""
    anger = _emotion_moved(engine, "anger", level, table)
    aperture = anger[marks["upper_lid_left"], 1] - anger[marks["lower_lid_left"], 1]
    assert aperture >= 0.0
    disgust = _emotion_moved(engine, "disgust", level)

    def knit(delta):
        return delta[marks["inner_brow_left"], 0] - delta[marks["inner_brow_right"], 0]

    assert knit(anger) < knit(disgust) - 0.02 * level


@pytest.mark.parametrize("character", ["ava", "mei", "george"])
def test_9_narrows_the_eye_from_above_as_well_as_below(face_of, marks, character):
    """FACS 9 lowers the brows' inner part and raises the infraorbital triangle: the eye narrows
    from below AND the lowered brow pushes the upper lid down, as 4's does (lids.yaml `brow_push`).
    Until session 24 9's upper lid stayed where it rests (0.1 mm down) while 9's lower lid rose
    2.3 mm, so disgust's eyes kept the wide stare of anger's glare (FER2013 named disgust anger).
    The push is fitted like 4's: an open eye (ava, mei) narrows from above, a hooded one (george),
    whose lid rests low over the iris already, is not pushed further."""
    engine = face_of(character).engine
    moved = engine.deform(activations(parse("9"))).positions - engine.neutral
    upper, lower = moved[marks["upper_lid_left"], Y], moved[marks["lower_lid_left"], Y]
    assert lower > 0.015
    if character == "george":
        assert upper > -0.005
    else:
        assert upper < -0.01, upper
    # With 5 (HapFACS anger's 5+7+9+...) the levator holds the lid up against the push. (george's
    # lid, lifted at rest to 3.7 mm since session 26, takes 9's push to brow_push's 4 mm: 0.35 mm.)
    glare = engine.deform(activations(parse("5+9"))).positions - engine.deform(activations(parse("5"))).positions
    assert glare[marks["upper_lid_left"], Y] > (-0.004 if character == "george" else -0.003)


def test_9_raises_the_upper_lip_in_an_inverted_u(engine, marks):
    """FACS 9 and 10 raise the upper lip's centre most and its outer parts less, an inverted U.
    ARKit's mouthUpperUp (9's 0.45 until session 24) lifts the lip evenly over the canines: halfway
    to the corner it rose 0.70 of the middle's 3.7 mm, a flat-topped box of upper teeth over the lower
    that read as anger's clenched snarl in disgust (9+15+16). Now 0.52 of 3.1 mm."""
    moved = _moved(engine, "9")
    rest = engine.neutral
    skin = rest[: engine.head.skin_vertex_count]
    middle, corner = rest[marks["upper_lip"]], rest[marks["lip_corner_left"]]
    halfway = int(np.argmin(((skin - (middle + corner) / 2) ** 2).sum(1)))
    assert moved[marks["upper_lip"], Y] > 0.025
    assert moved[halfway, Y] < 0.6 * moved[marks["upper_lip"], Y]


@pytest.mark.parametrize("level", [1.0, 0.5])
def test_default_anger_has_none_of_disgusts_lower_face(engine, marks, level):
    """Session 18 (HapFACS anger named disgust 5 times in 12 by a blind reviewer, for its nose
    wrinkle, raised upper lip and lowered corners): the default anger presses its lips - the red
    narrowed, the upper lip down, the corners not pulled down as disgust's are - and does not lift
    the nose wing, while disgust lifts it (6.2 mm on noah; HapFACS's anger 7.3) and the upper lip."""
    anger, disgust = _emotion_moved(engine, "anger", level), _emotion_moved(engine, "disgust", level)
    assert anger[marks["upper_lip"], 1] - anger[marks["lower_lip"], 1] < -0.02 * level     # red narrowed
    assert anger[marks["upper_lip"], 1] < 0.0 < disgust[marks["upper_lip"], 1]
    assert anger[marks["nose_wing_left"], 1] < 0.001 and disgust[marks["nose_wing_left"], 1] > 0.02 * level
    assert anger[marks["lip_corner_left"], 1] > disgust[marks["lip_corner_left"], 1] + 0.01 * level


@pytest.mark.parametrize("level", [1.0, 0.5])
def test_sad_upper_lids_droop_where_fear_and_anger_keep_theirs_up(face_of, marks, level):
    """FACS 2002: 4 pushes down on the upper eyelid, 1+2 counteracts it and 1 alone does not; with 5
    the levator holds it up. Session 18: sadness (1+4+15) kept the open lids of rest (the margin
    0.4 mm lower on ava) where the manual's sad face has its upper lids drooping slightly. Hooded
    lids that already cover 4 mm of the iris (george) are not pushed further (lids.yaml)."""
    ava, george = face_of("ava").engine, face_of("george").engine

    def lid(engine, delta):
        return delta[marks["upper_lid_left"], 1]

    assert lid(ava, _emotion_moved(ava, "sadness", level)) < -0.012 * level
    assert lid(ava, _emotion_moved(ava, "fear", level)) > -0.005
    assert lid(ava, _moved(ava, "1+2+4")) > -0.006
    assert lid(ava, _emotion_moved(ava, "anger", level)) > 0.0
    # The brows alone: 0.6 mm; since session 26 george's lid rests lifted to 3.7 mm over the iris
    # (lids.yaml most_cover_mm), and 4's push takes it to brow_push's 4 mm: 0.3 mm more.
    assert lid(george, _emotion_moved(george, "sadness", level)) > -0.0095


@pytest.mark.parametrize("level", [1.0, 0.5])
def test_surprise_is_not_fear(engine, marks, level):
    """Session 12 (surprise named fear 5 times in 12): surprise's brows rise high in an even arch,
    barely drawn together; fear's are drawn together, lower and straightened, inner ends as
    high as the outer (session 15: surprise's outer ends no longer rise above its inner ends -
    the slanted brow read as anger). Surprise's relaxed jaw hangs open in a tall oval narrower than at rest;
    fear's lips are stretched wider than at rest."""
    surprise, fear = (_emotion_moved(engine, name, level) for name in ("surprise", "fear"))

    def knit(delta):
        return delta[marks["inner_brow_left"], 0] - delta[marks["inner_brow_right"], 0]

    def tilt(delta):   # inner end of the brow over its outer end, from rest
        return delta[marks["inner_brow_left"], 1] - delta[marks["outer_brow_left"], 1]

    def lift(delta):   # both ends of the brow, from rest
        return (delta[marks["inner_brow_left"], 1] + delta[marks["outer_brow_left"], 1]) / 2

    def widening(delta):
        return delta[marks["lip_corner_left"], 0] - delta[marks["lip_corner_right"], 0]

    assert knit(fear) < knit(surprise) - 0.02 * level
    assert lift(surprise) > lift(fear) + 0.02 * level and tilt(fear) > -0.005
    assert widening(surprise) < 0.0 < 0.05 * level < widening(fear)
    opening = surprise[marks["upper_lip"], 1] - surprise[marks["lower_lip"], 1]
    assert opening > 0.12 * level


def test_half_an_emotion_shows_more_than_half_its_movement(engine, marks):
    """Session 12 (50 % smiles read as neutral, 50 % sadness as neutral): at half intensity each
    AU goes 0.62 of the way (the concave response; 12 0.84 since session 23), so a half smile lifts its corners over 6 mm
    and half sadness still tilts the brows up at their inner ends by over 5 mm."""
    full, half = (_emotion_moved(engine, "happiness", level)[marks["lip_corner_left"], 1] for level in (1.0, 0.5))
    assert half > 0.06 and half > 0.6 * full
    sad = _emotion_moved(engine, "sadness", 0.5)
    assert sad[marks["inner_brow_left"], 1] - sad[marks["outer_brow_left"], 1] > 0.05


def test_a_character_s_natural_asymmetry_moves_one_side_more(face_of):
    """Session 14: unless symmetric, a character's AUs act a little more strongly on one side
    (its seeded gain), every register alike; the symmetric faces the other tests use have none."""
    engine = face_of("liam", symmetric=False).engine
    gain = engine.side_gain
    assert 0.01 < abs(gain["left"] - gain["right"]) < 0.2
    weights = engine.weights(activations(parse("12")))
    smile = {c.side: w for c, w in weights.items() if c.target.startswith("faceunits/mouthSmile")}
    assert smile["left"] / smile["right"] == pytest.approx(gain["left"] / gain["right"])
    assert face_of("liam").engine.side_gain == {"left": 1.0, "right": 1.0}
    # Session 17: the mandible is one bone - 26 drops both halves of the jaw alike (a blind reviewer
    # saw liam's and george's surprise with the mouth skewed and the chin shifted sideways).
    jaw = {c.side: w for c, w in engine.weights(activations(parse("26"))).items() if c.target == "faceunits/jawOpen"}
    assert jaw["left"] == jaw["right"] > 0


def test_a_half_smile_narrows_the_eye_from_below(engine, marks):
    """Session 15 (half smiles read as surprise or neutral by FER2013 4 times in 6): 6 raises the
    cheek and pushes the lower lid up, narrowing the eye from below, not by lowering the upper
    lid; at half intensity (6+12+25 at 50 %) the lower lid still rises over 1.5 mm (2.4 until session
    22, whose fit of 6's lower lid to the eye's aperture, ``lids.yaml`` ``squint``, leaves noah 1.9)."""
    half = _emotion_moved(engine, "happiness", 0.5)
    assert half[marks["lower_lid_left"], 1] > 0.015
    assert abs(half[marks["upper_lid_left"], 1]) < 0.005


def test_14_sinks_a_dimple_beyond_the_corner(engine, marks):
    """Session 15 (14 hardly showed on dark skin or unilaterally): the buccinator pulls the corner
    back and the skin just beyond it into a dimple, a pit deeper than the corner itself goes:
    at E over 3.5 mm deeper, where the lips stretched by 20 sink that skin under 3 mm."""
    from facsim.head.assets import load_face_data

    base, _ = load_face_data(progress=False).target("mouth/mouth-dimples-in")
    pit_skin = engine.head.geo_of_base[base]
    pit_skin = pit_skin[(pit_skin >= 0) & (engine.neutral[np.maximum(pit_skin, 0), X] > 0)]  # the left pit

    def pit(text):
        moved = _moved(engine, text)
        return moved[marks["lip_corner_left"], Z] - moved[pit_skin, Z].min()

    assert pit("14") > 0.035
    assert pit("20") < 0.03


@pytest.mark.parametrize("name", ["amara", "mei", "noah", "ava", "george", "margaret", "kwame"])
def test_surprise_raises_the_whole_brow_in_an_arch(face_of, name):
    """Session 15 (amara's surprise read as anger): in 1+2 the whole brow rises, curved and
    high, its inner end about as much as its outer, its middle highest - not a low, heavy
    head under a raised tail. Measured on the drawn brow (one preset per brow style and
    ethnicity), in thirds along it. Session 23: arched - the middle third rose 3.6-4.9 mm more
    than the mean of the inner and outer thirds (1.7-2.7 mm on main 98c87e1, where the brow rose
    as a straight bar and FER2013 named surprise fear). Session 25: bowed, not arched high - a
    blind reviewer saw "eyebrows distorted into high arches"; 2.0-3.1 mm now, still over 1.5."""
    from facsim.head.proxies import along_brow

    face = face_of(name)
    brow = next(b for b in face.proxies if b.proxy.kind == "eyebrows")
    rest = brow.binding.positions(face.neutral)
    rise = brow.binding.positions(face.engine.deform(activations(parse("1+2"))).positions)[:, 1] - rest[:, 1]
    along, left = along_brow(rest), rest[:, 0] > 0
    inner, middle, outer = (rise[left & (along >= lo) & (along <= hi)].mean()
                            for lo, hi in ((0.0, 1 / 3), (1 / 3, 2 / 3), (2 / 3, 1.0)))
    assert inner > 0.04 and inner >= 0.7 * outer, (name, inner, middle, outer)
    assert middle >= 0.9 * max(inner, outer), (name, inner, middle, outer)
    assert middle - (inner + outer) / 2 > 0.015, (name, inner, middle, outer)



@pytest.mark.parametrize("name", ["amara", "mei", "ava", "george", "kwame"])
def test_surprise_lifts_the_brow_as_far_as_photographs_show(face_of, name):
    """In photographs of surprise (1+2 at E) the brows rise about 6-9 mm, the whole brow lifted
    and bowed a little, keeping its shape. Session 23's arch lifted the drawn brow's middle third
    12.5 mm on every preset, its ends 7-10 mm: the reviewer's "eyebrows distorted into high
    arches" (session 24). Now the middle third rises 9.6-9.7 mm and no third rises over 10 mm,
    nor under 5 (1+2 still shows)."""
    from facsim.head.proxies import along_brow

    face = face_of(name)
    brow = next(b for b in face.proxies if b.proxy.kind == "eyebrows")
    rest = brow.binding.positions(face.neutral)
    rise = brow.binding.positions(face.engine.deform(activations(parse("1+2"))).positions)[:, 1] - rest[:, 1]
    along, left = along_brow(rest), rest[:, 0] > 0
    thirds = [rise[left & (along >= lo) & (along <= hi)].mean() for lo, hi in ((0.0, 1 / 3), (1 / 3, 2 / 3), (2 / 3, 1.0))]
    assert max(thirds) < 0.1 and min(thirds) > 0.05, (name, thirds)

def _nose_and_glabella(head):
    """Skin vertex masks on the base mesh: the nose's bridge from its root between the eyes
    down the dorsum, and the glabella between the brow heads."""
    skin = head.base_vertices[head.base_index[: head.skin_vertex_count]]
    x, y, front = np.abs(skin[:, 0]), skin[:, 1], skin[:, 2] > 1.3
    return skin, (x < 0.05) & (y > 7.04) & (y < 7.32) & front, (x < 0.08) & (y > 7.36) & (y < 7.46) & front


@pytest.mark.parametrize("character", ["noah", "ava", "kwame", "george"])
def test_4_furrows_the_glabella_upright_and_leaves_the_nose_to_9(face_of, head, character):
    """FACS 4: brows lowered and drawn together, vertical furrows between the brows, at most one
    horizontal line at the root of the nose; the nose wrinkles only with 9. Session 15's blind
    reviewer read anger as disgust for a "sculpted nose wrinkle": 4's glabella drew horizontal
    lines and the root of the nose creased as deeply under 4+5+7+23 as under 9 (90th percentile
    0.33 vs 0.35 on ava). (Session 26 doubled the root's crease gain, 3 -> 6, for 9's lines under the
    higher key: both fields doubled, anger's bridge 0.17-0.20 -> 0.31-0.35 and 9's 0.34-0.36 -> 0.65-0.71
    on these four, so anger's bound is its share of 9's, 0.6 - 0.50-0.54 on main, 0.94 in session 15.)"""
    engine = face_of(character).engine
    skin, bridge, glabella = _nose_and_glabella(head)

    def creases(text):
        deformation = engine.deform(activations(parse(text)))
        return deformation.wrinkle[: len(skin)], deformation.crease_phase[: len(skin)]

    anger, phase = creases("4+5+7+23")
    nose_wrinkler, _ = creases("9")
    assert np.percentile(nose_wrinkler[bridge], 90) > 0.24
    assert np.percentile(anger[bridge], 90) < 0.6 * np.percentile(nose_wrinkler[bridge], 90)
    assert anger[glabella].max() > 0.5   # the glabellar furrows themselves
    # The renderer draws a furrow at each whole phase: it climbs more sideways than upward, so the
    # furrows run up or obliquely (on session 15's main it climbed 2.5 times as fast upward).
    design = np.c_[skin[glabella, :2], np.ones(glabella.sum())]
    (per_x, per_y, _), *_ = np.linalg.lstsq(design, phase[glabella], rcond=None)
    assert abs(per_x) > 1.2 * abs(per_y), (per_x, per_y)


@pytest.mark.parametrize("name", ["ava", "kwame"])
def test_15_lowers_the_corners_without_furrowing_the_chin_boss(face_of, name):
    """FACS 15 pulls the lip corners down, with some pouching below them; wrinkling the chin boss
    is 17's. Session 19: mouthFrown past its authored 1.0 (1.3) dragged the skin under the corners
    and the chin's top down onto its lower half, and the crease field drew rows of furrows across
    the chin (mean crease strength there 0.055 on ava, 0.049 on kwame): a blind reviewer saw a
    swollen, rubbery chin boss in every strong sad face (1+4+15). Now 0.037 and 0.030, the corners
    still 6 mm down."""
    from facsim.head.landmarks import landmarks

    face = face_of(name)
    marks = landmarks(face.head)
    rest = np.asarray(face.neutral)
    deformation = face.deform("15E")
    moved = np.asarray(deformation.positions)
    strength = np.asarray(deformation.creases()[0])
    skin = rest[: face.head.skin_vertex_count]
    lower_lip, chin = rest[marks["lower_lip"]], rest[marks["chin"]]
    half_width = 1.1 * abs(rest[marks["lip_corner_left"], X])
    boss = np.flatnonzero((skin[:, Y] < lower_lip[Y] - 0.03) & (skin[:, Y] > chin[Y] - 0.05)
                          & (np.abs(skin[:, X]) < half_width) & (skin[:, Z] > chin[Z] - 0.25))
    assert len(boss) > 50
    corner = marks["lip_corner_left"]
    assert moved[corner, Y] - rest[corner, Y] < -0.05            # the corners come down over 5 mm
    assert strength[boss].mean() < 0.045, strength[boss].mean()


@pytest.mark.parametrize("code", ["10", "9"])
def test_the_raised_upper_lip_bends_up_at_its_centre(face_of, code):
    """FACS 10 (and 9's raise of the upper lip): the upper lip's centre is drawn straight up and
    its outer parts less, an angular bend. Session 18's lip rose evenly over the canines (ARKit's
    mouthUpperUp), its centre 4.8 mm and halfway to the corners 5.1 mm on noah: a flat-topped,
    squared mouth (a blind reviewer). Now the centre rises most (6.1 / 5.6 mm in 10)."""
    face = face_of("noah")
    rim = face._mouth_rim.upper
    rest = np.asarray(face.neutral, float)
    rise = np.asarray(face.deform(code).positions, float)[rim, 1] - rest[rim, 1]
    x = rest[rim, 0]
    order = np.argsort(x)
    half = np.abs(x).max()

    def at(share):
        return 0.5 * sum(np.interp(sign * share * half, x[order], rise[order]) for sign in (-1, 1))

    assert at(0.0) > at(0.5) + 0.0025 > at(0.8) + 0.01     # 0.25 mm above halfway, 1 mm above the ends


PRESETS = ["ava", "emma", "liam", "noah", "amara", "zola", "kwame", "tunde", "mei", "hiro", "margaret", "george",
           "ngozi", "kofi", "lin", "kenji", "sofia", "arjun"]


@pytest.mark.parametrize("character", PRESETS)
def test_the_lower_lip_drops_with_the_chin(face_of, marks, character):
    """Session 20: the lower lip rests on the mandible, so when the jaw drops (26, 27) it turns about
    the jaw's hinge with the chin. The authored jawOpen turned it 5-12 % further (george 15.1 degrees
    to the chin's 13.5 at 26E): the lip slid off the teeth into a sagging ring, its inner edge 3.8 mm
    further down than the chin on every preset (a blind reviewer: "lower face warped and sagging")."""
    import sys
    from pathlib import Path

    from facsim.speech.mouth import MouthGauge

    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "scripts"))
    from engine_amplitudes import bone_motion

    face = face_of(character)
    rest = np.asarray(face.neutral, np.float64)
    hinge = face.head.joint(face.engine.base_positions, "joint-mouth")
    lip = MouthGauge(face.head, rest).lower_lip
    for text in ("26E", "27E"):
        moved = np.asarray(face.deform(text).positions, np.float64)
        _, glide, _ = bone_motion(face, moved, marks)   # the turn about the hinge, less the condyles' glide

        def turn(i):
            before, after = rest[i, 1:] - hinge[1:], moved[i, 1:] - glide - hinge[1:]
            return np.arctan2(before[0], before[1]) - np.arctan2(after[0], after[1])

        assert turn(marks["chin"]) > np.radians(10), text
        assert turn(lip) < 1.03 * turn(marks["chin"]), text


@pytest.mark.parametrize("character", ["ava", "george", "kwame"])
def test_the_dropped_jaw_leaves_the_skin_over_the_maxilla(face_of, marks, character):
    """Session 21: the upper lip and the cheeks beside the nose lie on the maxilla, which does not move
    when the mandible drops (26, 27). The authored jawOpen dragged them with it: the nasolabial fold
    came down 5.7 mm at 26E and 9.1 mm at 27E on george, long folds of skin beside the open mouth
    ("rubbery mouth and neck", a blind reviewer, fear and surprise at 100 %)."""
    face = face_of(character)
    rest = np.asarray(face.neutral, np.float64)
    for text in ("26E", "27E"):
        moved = np.asarray(face.deform(text).positions, np.float64) - rest
        assert -moved[marks["chin"], 1] > 0.15, text    # the jaw still drops (15 mm at least)
        for side in ("left", "right"):
            assert abs(moved[marks[f"nasolabial_fold_{side}"], 1]) < 0.015, (text, side)


@pytest.mark.parametrize("character", ["ava", "george", "kwame"])
def test_the_skin_over_the_mandible_turns_with_the_bone(face_of, marks, character):
    """Session 22: the chin and the skin over the mandible's body are bound to the bone and turn with it
    about the jaw's hinge, nearly rigidly. The authored jawOpen dropped the chin's midline but fell off
    toward the mandible's sides (george at 27E: 12 mm down at 30 mm beside the midline where the bone
    takes it 23 mm), a V of sheared skin from the corners to the chin and a band under the lower lip
    (george's fear at 100 % rated 1 of 5, "warped lower face", a blind reviewer). Measured against the
    chin's own turn and shift, over the muscle engine's jaw attachment 12 mm or more below the lip corners:
    main's mean was 5.6-6.0 mm (26E) and 8.3-9.0 (27E), its 95th percentile 15-21 mm."""
    import sys
    from pathlib import Path

    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "scripts"))
    from engine_amplitudes import off_the_bone

    face = face_of(character)
    for text in ("26E", "27E"):
        angle, off = off_the_bone(face, face.deform(text).positions, marks)
        assert angle > np.radians(10), text
        assert off.mean() < 0.04 and np.percentile(off, 95) < 0.10, (text, off.mean(), np.percentile(off, 95))


def _cheek_stretch(face, marks, text):
    """Stretch (deformed / rest length) of the skin's edges beside the mouth in ``text``: 3 mm or more
    lateral of the lip corners, from 10 mm below to 30 mm above them, in front of the jaw's angle."""
    from facsim.engines.muscle.net import OUTER, anatomy, mask_per_vertex

    anat = anatomy(face.head)
    skin = anat.skin_count
    rest = np.asarray(face.neutral, np.float64)[:skin]
    moved = np.asarray(face.deform(text).positions, np.float64)[:skin]
    lips = mask_per_vertex(face.head, "lips")[:skin]
    corner = rest[marks["lip_corner_left"]]
    cheek = ((anat.kind == OUTER) & (lips < 0.05) & (np.abs(rest[:, 0]) > corner[0] + 0.03)
             & (rest[:, 1] > corner[1] - 0.10) & (rest[:, 1] < corner[1] + 0.30)
             & (rest[:, 2] > rest[marks["jaw_angle_left"], 2]))
    tri = np.asarray(face.head.triangles)
    tri = tri[(tri < skin).all(axis=1)]
    edges = np.unique(np.sort(np.concatenate([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]]), axis=1), axis=0)
    edges = edges[cheek[edges].all(axis=1)]

    def length(p):
        return np.linalg.norm(p[edges[:, 0]] - p[edges[:, 1]], axis=1)

    return length(moved) / length(rest)


@pytest.mark.parametrize("character", ["ava", "george", "kwame", "mei"])
def test_the_cheeks_lengthen_smoothly_when_the_jaw_drops(face_of, marks, character):
    """Session 24: beside the mouth the cheek hangs between the zygoma and the mandible, and when the jaw
    drops it lengthens over its whole height. The jaw's target kept the skin over the maxilla still down
    to 8 mm above the corners' line across the whole face, so the cheeks beside the mouth took the drop in
    one narrow band and stretched 2-3 times their length (1 % of the edges 2.5-3.1 at 27E, 2.0-2.4 at
    26E; george, amara, liam and kwame's fear and surprise, "jaw and cheeks distorted", "face geometry
    warped", session 23's blind reviewer); with the band growing taller beside the mouth, 1.5-1.8 and 1.3-1.6."""
    face = face_of(character)
    for text, most in (("26E", 1.9), ("27E", 2.2)):
        stretch = _cheek_stretch(face, marks, text)
        assert len(stretch) > 100
        assert np.percentile(stretch, 99) < most, (text, np.percentile(stretch, 99))


@pytest.mark.parametrize("character", ["ava", "george", "kwame"])
def test_the_jaws_angle_stays_near_its_place_and_the_neck_behind_it_smooth(face_of, marks, character):
    """Session 24: opening wide, the condyles glide forward as the mandible turns, and its angle stays
    nearly in place. Turned about the hinge alone, the jaw's angle went 13-14 mm back into the neck at
    27E and the skin behind the ramus bunched into vertical cords below the ear (crease strength there
    0.13-0.17 on average; "jaw and neck distorted", "neck stretch", session 23's blind reviewer)."""
    face = face_of(character)
    skin = face.head.skin_vertex_count
    rest = np.asarray(face.neutral, np.float64)
    deformation = face.deform("27E")
    moved = np.asarray(deformation.positions, np.float64)
    for side in ("left", "right"):
        assert np.linalg.norm(moved[marks[f"jaw_angle_{side}"]] - rest[marks[f"jaw_angle_{side}"]]) < 0.09, side
    angle, r = rest[marks["jaw_angle_left"]], rest[:skin]
    behind = ((np.abs(r[:, 0]) > 0.3) & (r[:, 2] < angle[2]) & (r[:, 1] < angle[1] + 0.05)
              & (r[:, 1] > rest[marks["chin"], 1] - 0.3))
    assert behind.sum() > 50
    strength, _ = deformation.creases()
    assert strength[:skin][behind].mean() < 0.11, strength[:skin][behind].mean()


@pytest.mark.parametrize("character", ["ava", "george", "kwame"])
def test_no_crease_band_between_the_dropped_lower_lip_and_the_chin(face_of, marks, character):
    """Session 22: the skin from the lower lip to the chin lies on the mandible and turns with it; a jaw
    drop stretches it, if anything, and draws no furrows. Where jawOpen fell off toward the mandible's
    sides that skin was squeezed, and the crease field drew a band of lines under the lower lip (george's
    fear at 100 %, "a chin band", a blind reviewer): mean crease strength there on main 0.11-0.14 at 26E
    and 0.13-0.17 at 27E, 0.04-0.05 and 0.06-0.07 with the skin turning with the bone."""
    from facsim.engines.muscle.net import OUTER, anatomy, mask_per_vertex

    face = face_of(character)
    anat = anatomy(face.head)
    count = anat.skin_count
    rest = np.asarray(face.neutral, np.float64)[:count]
    lips = mask_per_vertex(face.head, "lips")[:count]
    chin, lip = rest[marks["chin"]], rest[marks["lower_lip"]]
    below_the_lip = ((anat.kind == OUTER) & (lips < 0.05) & (rest[:, 1] < lip[1]) & (rest[:, 1] > chin[1])
                     & (np.abs(rest[:, 0]) < 0.25) & (rest[:, 2] > chin[2] - 0.15))
    assert below_the_lip.sum() > 20
    for text in ("26E", "27E"):
        strength, _ = face.deform(text).creases()
        assert strength[:count][below_the_lip].mean() < 0.09, (text, strength[:count][below_the_lip].mean())


@pytest.mark.parametrize("character", ["ava", "george", "kwame"])
def test_15_pulls_the_corners_down_not_the_cheeks_and_jowls(face_of, marks, character):
    """Session 21: depressor anguli oris pulls the lip corner down toward its origin on the mandible;
    the skin around the corner follows less with distance. ARKit's mouthFrown moved a slab of cheek and
    jowl from the nasolabial fold (3.9 mm down on liam) to the jaw line as one piece, with a U-shaped
    pouch under the mouth where it met the still chin ("rubbery chin", a blind reviewer, liam's sadness)."""
    face = face_of(character)
    rest = np.asarray(face.neutral, np.float64)
    skin = face.head.skin_vertex_count
    moved = np.asarray(face.deform("15E").positions, np.float64)[:skin] - rest[:skin]
    corners = rest[[marks["lip_corner_left"], marks["lip_corner_right"]]]
    assert -moved[[marks["lip_corner_left"], marks["lip_corner_right"]], 1].min() > 0.04   # corners 4 mm down
    distance = np.linalg.norm(rest[:skin, None] - corners[None], axis=2).min(axis=1)
    far = distance > 0.25
    assert np.linalg.norm(moved[far], axis=1).max() < 0.01   # nothing 25 mm from the corners moves 1 mm
    for side in ("left", "right"):
        assert abs(moved[marks[f"nasolabial_fold_{side}"], 1]) < 0.015, side


@pytest.mark.parametrize("character", ["ava", "george", "kwame"])
def test_20_stretches_the_lips_not_the_cheeks(face_of, marks, character):
    """Session 21: risorius stretches the lip corners out; ARKit's mouthStretch slid the cheeks beside the
    mouth out with them down to the jaw line, a stretch a blind reviewer called exaggerated on ava, amara
    and mei's fear (and with the dropped jaw, rubbery columns beside george's mouth)."""
    face = face_of(character)
    rest = np.asarray(face.neutral, np.float64)
    skin = face.head.skin_vertex_count
    moved = np.asarray(face.deform("20E").positions, np.float64)[:skin] - rest[:skin]
    corner_ids = [marks["lip_corner_left"], marks["lip_corner_right"]]
    assert moved[corner_ids[0], 0] - moved[corner_ids[1], 0] > 0.08    # the mouth 8 mm wider
    distance = np.linalg.norm(rest[:skin, None] - rest[corner_ids][None], axis=2).min(axis=1)
    cheeks = (distance > 0.3) & (np.abs(rest[:skin, 0]) > rest[corner_ids[0], 0])   # beyond the corners
    assert np.linalg.norm(moved[cheeks], axis=1).max() < 0.01   # nothing 30 mm out moves 1 mm


def _strain_beyond_the_corner(face, marks, text, band_mm):
    """Strain (deformed / rest length - 1) of the skin's edges beyond the left lip corner (lateral
    of it) whose midpoints lie ``band_mm`` from the corner, in ``text``."""
    skin = face.head.skin_vertex_count
    rest = np.asarray(face.neutral, np.float64)[:skin]
    moved = np.asarray(face.deform(text).positions, np.float64)[:skin]
    tri = np.asarray(face.head.triangles)
    tri = tri[(tri < skin).all(axis=1)]
    edges = np.unique(np.sort(np.concatenate([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]]), axis=1), axis=0)
    corner = rest[marks["lip_corner_left"]]
    mid = (rest[edges[:, 0]] + rest[edges[:, 1]]) / 2 - corner
    distance = np.linalg.norm(mid, axis=1) * 100.0
    band = (mid[:, 0] > 0.02) & (distance >= band_mm[0]) & (distance < band_mm[1])

    def length(p):
        return np.linalg.norm(p[edges[band, 0]] - p[edges[band, 1]], axis=1)

    return length(moved) / length(rest) - 1.0


@pytest.mark.parametrize("character", ["ava", "george", "kwame", "mei"])
def test_20_bunches_the_skin_beyond_the_corners_mildly(face_of, marks, character):
    """FACS 20: risorius stretches the lips and pulls the corners out; the skin beyond the corners,
    between the corner and the muscle's origin, bunches mildly. ARKit's mouthStretch, held within
    28 mm of the corner (session 21), squeezed the skin 14-28 mm beyond it by 30-37 % (the 5th
    percentile of its edges' strain) and creased it in a line from the corner toward the jaw (george's
    fear, "collapsed rubbery lower face", the worst image of session 22's blind review); smoothed between
    the corner and the still skin (``corner_reach`` ``smoothing_passes``), 16-21 %."""
    squeezed = np.percentile(_strain_beyond_the_corner(face_of(character), marks, "20E", (14.0, 28.0)), 5)
    assert squeezed > -0.27, (character, squeezed)


@pytest.mark.parametrize("character", ["ava", "george", "kwame"])
def test_12_lifts_the_corners_not_the_jaw_line(face_of, marks, character):
    """Session 21: zygomaticus major pulls the lip corners up and back, and the skin below them follows
    less with depth; ARKit's mouthSmile lifted the skin over the mandible with them (12 mm at 20 mm below
    ava's corners), widening the jowls into "rubbery cheeks" (a blind reviewer, broad smiles)."""
    face = face_of(character)
    rest = np.asarray(face.neutral, np.float64)
    skin = face.head.skin_vertex_count
    moved = np.asarray(face.deform("12E").positions, np.float64)[:skin] - rest[:skin]
    corner_ids = [marks["lip_corner_left"], marks["lip_corner_right"]]
    assert moved[corner_ids, 1].min() > 0.1                       # the corners 10 mm up
    jaw = rest[:skin, 1] < rest[corner_ids, 1].mean() - 0.3        # 30 mm below the corners or more
    assert np.abs(moved[jaw, 1]).max() < 0.01


@pytest.mark.parametrize("character", ["ava", "mei", "kwame", "george"])
def test_12_draws_the_corners_up_and_back_more_than_out(face_of, marks, character):
    """Session 22: zygomaticus major pulls the corners obliquely up and back toward the cheekbone; a
    maximal smile moves them 10-14 mm and widens the mouth some 10-20 %. ARKit's mouthSmile at full weight
    moved them 19-22 mm (10 mm out on each side, 16 up), the mouth 38-45 % wider: a thin crescent
    stretched across the face ("Joker", a blind reviewer)."""
    from facsim.speech.mouth import mouth_shape

    face = face_of(character)
    rest = np.asarray(face.neutral, np.float64)
    smile = np.asarray(face.deform("12E").positions, np.float64)
    corner = marks["lip_corner_left"]
    out, up, back = (smile[corner] - rest[corner]) * np.array([100.0, 100.0, -100.0])   # mm
    assert 10.0 < np.linalg.norm([out, up, back]) < 15.0
    assert up > 2.0 * out and back > out > 2.0
    widening = mouth_shape(face, positions=smile).width / mouth_shape(face, positions=rest).width - 1.0
    assert 0.1 < widening < 0.25


@pytest.mark.parametrize("character", ["ava", "kwame"])
def test_12_at_c_lifts_the_corners_most_of_the_way(face_of, marks, character):
    """Session 23: the tension net's 12 alone moves the corners 10.3 of its 11.7 mm at C (0.88) - its
    skin stiffens fast as zygomaticus draws it - where the register engine's common response gave 6.9
    of 10.4 mm (0.66) and a 50 % smile read neutral to FER2013 5 times in 6. 12 takes its own
    stiffening, fitted to the net: 12C lifts the corners over 0.8 of the way to 12E's."""

    face = face_of(character)
    rest = np.asarray(face.neutral, np.float64)
    corners = [marks["lip_corner_left"], marks["lip_corner_right"]]

    def lift(text):
        return (np.asarray(face.deform(text).positions, np.float64)[corners, Y] - rest[corners, Y]).mean()

    assert lift("12C") > 0.8 * lift("12E")


def _lower_lip_profile(face, positions) -> tuple[float, float]:
    """The lower lip's inner rim on ``positions`` (mm): how far it lies higher 0.85 of the way to the
    corners than at the midline (the depth of its U), and how far its midline moved up from rest."""
    rim = face._mouth_rim.lower
    rest = np.asarray(face.neutral, np.float64)[rim]
    moved = np.asarray(positions, np.float64)[rim]
    order = np.argsort(rest[:, X])
    across = rest[order, X] / np.abs(rest[:, X]).max()
    middle = np.interp(0.0, across, moved[order, Y])
    depth = np.interp([-0.85, 0.85], across, moved[order, Y]).mean() - middle
    return 100.0 * depth, 100.0 * (middle - np.interp(0.0, across, rest[order, Y]))


@pytest.mark.parametrize("character", ["ava", "mei", "kwame", "george"])
def test_a_half_smiles_lower_lip_hangs_in_a_u(face_of, character):
    """Session 23 (happiness at 50 % read neutral by FER2013 5 times in 6, "the half smile's lower lip is
    flat"): with the lips apart the lower lip hangs in a U between the raised corners, its middle lowest.
    Until then it rose with the corners (its middle 1 mm below rest in 6+12+25 at 50 %, the U 6.0-6.6 mm
    deeper than at rest); now the middle hangs 3 mm below rest and the U deepens by over 7.5 mm. 12
    without 25 keeps the lips together: the lower lip rests on the upper one and rises with it."""
    from facsim.facs.emotions import emotion

    face = face_of(character)
    at_rest, _ = _lower_lip_profile(face, face.neutral)
    depth, middle = _lower_lip_profile(face, face.deform(emotion("happiness", intensity=0.5)).positions)
    assert middle < -2.0
    assert depth - at_rest > 7.5
    for closed in ("12E", "12C", "6+12"):
        assert _lower_lip_profile(face, face.deform(closed).positions)[1] > 2.0   # risen with the upper lip


@pytest.mark.parametrize("character", ["ava", "george", "kwame"])
def test_27_stretches_the_mouth_open_taller_not_wider(face_of, character):
    """Session 21: in 27 the lips stretch over the widely dropped jaw and draw the corners in, an oval
    taller than wide; ARKit's mouthStretch pulled them out into a round ring (the mouth 0.4 mm narrower
    than at rest on ava, 1.7 on george)."""
    from facsim.speech.mouth import mouth_shape

    face = face_of(character)
    rest, open_ = mouth_shape(face, positions=face.neutral), mouth_shape(face, positions=face.deform("27E").positions)
    assert open_.width < rest.width - 4.0      # mm: the corners drawn in
    assert open_.gap > 0.6 * open_.width       # the opening's height against the mouth's width


@pytest.mark.parametrize("character", ["george", "ava", "kwame", "mei"])
def test_the_dropped_jaw_parts_the_lips_in_an_oval(face_of, character):
    """FACS 26/27: the lower lip rests on the mandible and, as the jaw drops, follows the chin in a
    rounded U. ARKit's jawOpen drops the lip's middle most, and the per-point limit to the chin's turn
    cut that U's bottom flat, the lip's outer parts left high: a flat bottom between straight walls
    (the "trapezoid mouth" of george's fear, session 22's blind reviewer). The lower rim's vertices
    0.6-0.85 of the way to the corner rose 1.4-2.3 times as high as on an oval through the rim's
    middle and corner on main 98c87e1 (26E: 1.56-2.29); now 0.6-1.2 at 26E, 0.9-1.7 at 27E."""
    face = face_of(character)
    rest = np.asarray(face.neutral, np.float64)
    rim = face._mouth_rim.lower
    left = rim[np.argsort(rest[rim, 0])]
    left = left[len(left) // 2:]                       # the middle out to the left corner
    for text, most, mean in (("26E", 1.4, 1.4), ("27E", 1.9, 1.6)):
        moved = np.asarray(face.deform(text).positions, np.float64)
        x, rise = moved[left, 0] - moved[left[0], 0], moved[left, 1] - moved[left[0], 1]
        oval = rise[-1] * (1.0 - np.sqrt(np.clip(1.0 - (x / x[-1]) ** 2, 0.0, 1.0)))
        near = (x > 0.6 * x[-1]) & (x < 0.85 * x[-1])
        if near.any():   # ava's rim has no vertex there at 27E
            ratio = rise[near] / oval[near]
            assert ratio.max() < most and ratio.mean() < mean, (character, text, ratio)


def _lips_red(face):
    """The lips' red (mask over 0.5) on ``face``'s skin and each point's lip (+1 upper, -1 lower, 0 neither)."""
    from facsim.engines.muscle.net import anatomy, mask_per_vertex

    anat = anatomy(face.head)
    n = anat.skin_count
    lips = mask_per_vertex(face.head, "lips")[:n]
    return np.maximum(lips, lips[anat.mirror[:n]]) > 0.5, anat.lip_half[:n], anat


@pytest.mark.parametrize("character", ["ava", "george", "liam"])
def test_the_dropped_jaw_stretches_the_lower_lip_evenly(face_of, character):
    """Session 25: the lower lip's red stretches over the dropped jaw evenly, it does not tear. The
    lower-lip rule of ``mandible`` turned the lip's points as far as the chin only where their own turn
    passed half the chin's, a hard cut through the lip's outer part: neighbours 0.4 mm apart there moved
    2.7 mm apart at 26E on ava, the red beside the opening smeared 5-9 times its length into the round,
    rubbery ring a blind reviewer saw in every fear and surprise (the longest lower-lip edge at 26E
    8.6 / 5.3 / 6.8 times its rest length on ava / george / liam, 7.2 / 4.5 / 5.9 in fear). The rule now
    comes in smoothly between 0.3 and 0.5 of the chin's turn: 2.5 / 2.3 / 2.2 and 3.2 / 2.7 / 2.9."""
    from facsim.facs.emotions import emotion

    face = face_of(character)
    red, half, anat = _lips_red(face)
    a, b = anat.edges.T
    lower = red[a] & red[b] & (half[a] == -1) & (half[b] == -1)
    rest = np.asarray(face.neutral, np.float64)
    length = np.linalg.norm(rest[a[lower]] - rest[b[lower]], axis=1)
    for expression in ("26E", emotion("fear")):
        moved = np.asarray(face.deform(expression).positions, np.float64)
        stretch = np.linalg.norm(moved[a[lower]] - moved[b[lower]], axis=1) / length
        assert stretch.max() < 4.0, (character, expression, stretch.max())


def _midline_red(face, positions) -> tuple[float, float]:
    """The upper and the lower lip's red seen from the front at the midline (mm): the height of their
    points within 2 mm of it that face the camera (normal's z over 0.3)."""
    from facsim.head.surface import vertex_normals

    red, half, anat = _lips_red(face)
    n = anat.skin_count
    skin = np.asarray(positions, np.float64)[:n]
    facing = vertex_normals(skin, anat.triangles)[:, 2] > 0.3
    middle = np.abs(np.asarray(face.neutral, np.float64)[:n, X]) < 0.02
    heights = []
    for lip in (1, -1):
        ys = skin[red & facing & middle & (half == lip), Y]
        heights.append(100.0 * (ys.max() - ys.min()))
    return heights[0], heights[1]


@pytest.mark.parametrize("code", ["23", "24"])
@pytest.mark.parametrize("character", ["ava", "george"])
def test_tightened_and_pressed_lips_narrow_both_reds(face_of, character, code):
    """FACS 23 and 24 narrow the red of both lips. ARKit's mouthRollUpper rolled the upper lip's red
    away (at 23E 1.3 of george's 5.1 mm at the midline) while the lower lip kept nearly all of its own
    (6.5 of 7.3; ava 9.2 of 10.0), so anger (4+5+7+23) showed a full lower lip pushed out under a
    vanished upper one ("pushed lip rubbery", session 24's blind reviewer). Now each keeps 0.45-0.75
    of its red (session 25)."""
    face = face_of(character)
    upper_rest, lower_rest = _midline_red(face, face.neutral)
    upper, lower = _midline_red(face, face.deform(code + "E").positions)
    assert 0.4 * upper_rest < upper < 0.85 * upper_rest, (upper, upper_rest)
    assert 0.4 * lower_rest < lower < 0.85 * lower_rest, (lower, lower_rest)


# Session 26: brows that rise or fall without being drawn together (registers.yaml `brows_not_gathered`).

def _spread_change(engine, marks, expression):
    """How much further apart the inner brows are than at rest (dm; negative: drawn together)."""
    moved = engine.deform(expression).positions - engine.neutral
    return float(moved[marks["inner_brow_left"], X] - moved[marks["inner_brow_right"], X])


@pytest.mark.parametrize("character", ["ava", "kwame"])
@pytest.mark.parametrize("level", [1.0, 0.5])
def test_surprise_raises_the_brows_without_drawing_them_together(face_of, marks, character, level):
    """FACS 1+2 (surprise, 1+2+5B+26): the whole brow is raised high and curved; drawn together is
    fear's 1+2+4. MakeHuman's inner-brow unit (AU 1) slid the inner brows 2.2 mm toward the midline
    at 1.0, so surprise drew them 1.1 mm together on every preset and FER2013 named it fear 3 times in
    6 (session 25); now they stay as far apart as at rest, raised as before (8.5 mm at the inner brow,
    9.7 at the outer on ava)."""
    from facsim.facs.emotions import emotion

    engine = face_of(character).engine
    surprise = activations(emotion("surprise", intensity=level))
    assert _spread_change(engine, marks, surprise) > -0.002
    moved = engine.deform(surprise).positions - engine.neutral
    assert moved[marks["inner_brow_left"], Y] > 0.04 * level
    assert moved[marks["outer_brow_left"], Y] > 0.04 * level
    # fear's brows (1+2+4) are drawn together, surprise's are not
    fear = activations(emotion("fear", intensity=level))
    assert _spread_change(engine, marks, fear) < _spread_change(engine, marks, surprise) - 0.02 * level


@pytest.mark.parametrize("character", ["ava", "george"])
def test_9_lowers_the_inner_brows_without_gathering_them(face_of, marks, character):
    """FACS 9 lowers the brows' medial part and wrinkles the root of the nose across; drawing the
    brows together, with the glabella's upright furrows, is 4's (corrugator). ARKit's noseSneer drew
    the inner brows 5.2 mm together at 9E on every preset (4: 6.0) and disgust (9+15+16) wore anger's
    knitted brows (FER2013 named ava's and amara's disgust anger, session 25). Now they come down and
    stay apart; 4 still draws them together."""
    engine = face_of(character).engine
    assert _spread_change(engine, marks, activations(parse("9"))) > -0.01
    assert (engine.deform(activations(parse("9"))).positions - engine.neutral)[marks["inner_brow_left"], Y] < -0.01
    assert _spread_change(engine, marks, activations(parse("4"))) < -0.04


@pytest.mark.parametrize("brows", ["1+4+15", "1+2+4"])
def test_sad_and_fearful_brows_are_drawn_together_by_4_not_further_by_1(face_of, marks, brows):
    """FACS 1+4 (sadness) and 1+2+4 (fear): the inner brows raised and drawn together - the drawing
    together is 4's, 1 raises; in 1+2+4 "not as close together as in AU 4 alone" (FACS 2002). 1's
    MakeHuman unit slid the inner brows together as well, so sadness (1+4+15) and fear's brows gathered
    them 7.9 mm on ava, more than 4 alone (6.0); now 1 alone does not gather them, 1+4 and 1+2+4 5.7 mm."""
    engine = face_of("ava").engine
    assert _spread_change(engine, marks, activations(parse("1"))) > -0.002
    gathered = _spread_change(engine, marks, activations(parse(brows)))
    assert _spread_change(engine, marks, activations(parse("4"))) - 0.002 < gathered < -0.03


# Session 26 (jaw): surprise's slack open mouth and disgust's raised upper lip, as the FACS manual describes them.
def _lower_teeth_shown(face, expression):
    """How far (dm) the lower incisors' edge stands above the lower lip's inner edge at the midline:
    the band of lower teeth a viewer sees over the lip (negative: the lip covers them)."""
    from facsim.speech.mouth import mouth_shape

    mouth_shape(face, positions=face.neutral)          # builds face._mouth_gauge
    gauge = face._mouth_gauge
    rest = np.asarray(face.neutral, np.float64)
    front = gauge.lower_teeth[np.abs(rest[gauge.lower_teeth, 0]) < 0.03]
    edge = front[np.argmax(rest[front, 1])]
    moved = np.asarray(face.deform(expression).positions, np.float64)
    return moved[edge, Y] - moved[gauge.lower_lip, Y]


@pytest.mark.parametrize("character", ["ava", "george", "kwame", "mei"])
def test_26_hangs_the_lower_lip_over_the_lower_teeth(face_of, character):
    """FACS 26: the jaw drops and the lips part relaxed - the slack lower lip lies over the lower teeth
    (the upper teeth's edges may show); drawing the lower lip down off them is 16's, and stretched wide
    over them fear's (20+26). On main fb62a7c the lower incisors stood 2.2-3.1 mm above the lower lip at
    26E and 1.7-3.3 mm in surprise at 100 % (ava, george, kwame, mei; FER2013 read surprise as fear);
    now at most 0.9 mm (1.2 at 50 %), and fear still shows them (4.5 mm or more)."""
    from facsim.facs.emotions import emotion

    face = face_of(character)
    for expression in ("26E", emotion("surprise"), emotion("surprise", intensity=0.5)):
        assert _lower_teeth_shown(face, expression) < 0.015, (character, expression)
    assert _lower_teeth_shown(face, emotion("fear")) > 0.035


@pytest.mark.parametrize("character", ["ava", "george", "mei"])
@pytest.mark.parametrize("level", [1.0, 0.5])
def test_surprise_opens_in_a_rounded_oval_fear_in_a_wide_slot(face_of, character, level):
    """Surprise's relaxed lips hang from the dropped jaw and draw the corners in, an oval as tall as it is
    half wide; fear's lips are stretched out sideways (20). On main fb62a7c surprise's mouth was 3.1-3.3 mm
    narrower than at rest at 100 % and 1.9 at 50 %; now 5.2-5.5 and 3.2-3.3, fear 9.7 mm wider."""
    from facsim.facs.emotions import emotion
    from facsim.speech.mouth import mouth_shape

    face = face_of(character)
    rest = mouth_shape(face, positions=face.neutral)
    surprise = mouth_shape(face, positions=face.deform(emotion("surprise", intensity=level)).positions)
    fear = mouth_shape(face, positions=face.deform(emotion("fear", intensity=level)).positions)
    assert surprise.width < rest.width - 5.0 * level          # mm: the slack corners drawn in
    assert surprise.gap > 0.45 * surprise.width * level        # the opening's height against its width
    assert fear.width > rest.width + 8.0 * level


def _upper_border_rise(face, expression, shares):
    """The upper lip's red border (its top edge) rise (dm) at ``shares`` of the way from the midline to the
    corners, both sides' mean: the highest sixth of the red's points in each column."""
    from facsim.head.landmarks import landmarks

    red, lip, _ = _lips_red(face)
    rest = np.asarray(face.neutral, np.float64)
    moved = np.asarray(face.deform(expression).positions, np.float64)
    marks = landmarks(face.head)
    half = abs(rest[marks["lip_corner_left"], 0] - rest[marks["lip_corner_right"], 0]) / 2
    upper = np.flatnonzero(red & (lip == 1))
    rises = []
    for share in shares:
        column = upper[np.abs(np.abs(rest[upper, 0]) - share * half) < 0.03 * half + 0.0015]
        top = column[np.argsort(rest[column, 1])[-max(2, len(column) // 6):]]
        rises.append(float((moved[top, 1] - rest[top, 1]).mean()))
    return rises


@pytest.mark.parametrize("character", ["ava", "george"])
@pytest.mark.parametrize("expression", ["10E", "9E", "disgust"])
def test_the_raised_upper_lips_border_is_an_inverted_u(face_of, character, expression):
    """FACS 10 (and 9's raise of the upper lip): the centre of the upper lip is drawn straight up, its
    outer parts less - an angular inverted U. The lips' inner edge bent so since session 19, but the
    red's top border (ARKit's mouthUpperUp and MakeHuman's lip elevation both peak halfway to the
    corners) rose most over the canines: on main fb62a7c 6.6 mm halfway against 4.6 at the centre in
    10E, 5.3 against 3.2 in disgust (9+15+16), a flat-topped box over bared teeth that FER2013 read as
    anger. Now the centre rises as far as anything and the outer part 1.5 mm or more less (10E 6.8 / 6.4 /
    4.1 mm at the centre / halfway / 0.7 of the way on ava, disgust 5.5 / 5.4 / 3.0)."""
    from facsim.facs.emotions import emotion, emotion_names

    face = face_of(character)
    text = emotion(expression) if expression in emotion_names() else expression
    centre, halfway, outer = _upper_border_rise(face, text, (0.0, 0.5, 0.7))
    assert centre > 0.025
    assert halfway < centre + 0.002 and outer < centre - 0.015, (centre, halfway, outer)
