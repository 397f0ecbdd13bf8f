"""The muscle engine: each simulated AU moves the face the way FACS says, sides, masking, animation."""
from __future__ import annotations

import numpy as np
import pytest

from facsim.engines.muscle import SETTLED_ITERATIONS as SETTLED
from facsim.facs.catalogue import catalogue
from facsim.facs.activations import Activations, activations
from facsim.facs.notation import parse

X, Y, Z = 0, 1, 2
#: AU → checks (landmark on the character's left, axis, sign): the FACS manual's appearance changes.
#: "lip_corner" is the outer corner of the mouth (the muscle engine's modiolus).
DIRECTIONS = {
    1: [("inner_brow", Y, +1)],
    2: [("outer_brow", Y, +1)],
    4: [("inner_brow", Y, -1), ("inner_brow", X, -1)],      # lowered and drawn together
    5: [("upper_lid", Y, +1)],
    6: [("cheek", Y, +1), ("lower_lid", Y, +1)],
    7: [("lower_lid", Y, +1)],
    8: [("lower_lip", Y, +1)],                              # the lips come toward each other
    9: [("nose_wing", Y, +1), ("inner_brow", Y, -1)],
    10: [("upper_lip", Y, +1)],
    11: [("nasolabial_fold", Y, +1)],
    12: [("lip_corner", Y, +1), ("lip_corner", X, +1)],
    13: [("lip_corner", Y, +1)],
    14: [("lip_corner", Z, -1)],
    15: [("lip_corner", Y, -1)],
    16: [("lower_lip", Y, -1)],
    17: [("chin", Y, +1)],
    18: [("lip_corner", X, -1)],
    19: [("lower_lip", Y, -1), ("tongue_tip", Z, +1)],
    20: [("lip_corner", X, +1)],
    21: [("jaw_angle", Y, -1)],
    22: [("upper_lip", Z, +1)],
    23: [("lip_corner", X, -1)],
    24: [("lower_lip", Y, +1)],
    25: [("lower_lip", Y, -1)],
    26: [("chin", Y, -1)],
    27: [("chin", Y, -1)],
    28: [("lower_lip", Z, -1)],
    29: [("chin", Z, +1)],
    30: [("chin", X, +1)],                                  # toward the character's left
    31: [("jaw_angle", X, +1)],                             # the masseter bulges
    32: [("lower_lip", Y, +1)],
    33: [("buccal", X, +1)],                                # the cheek over the mouth cavity inflates
    34: [("buccal", X, +1)],
    35: [("buccal", X, -1)],
    36: [("buccal", X, +1)],                                # the tongue pushes the left cheek out
    37: [("lower_lip", Y, -1), ("tongue_tip", Z, +1)],
    38: [("nose_wing", X, +1)],
    39: [("nose_wing", X, -1)],
    41: [("glabella", Y, -1)],
    42: [("inner_brow", Y, -1)],
    43: [("upper_lid", Y, -1)],
    44: [("inner_brow", X, -1)],
    45: [("upper_lid", Y, -1)],
    46: [("upper_lid", Y, -1)],
    51: [("nose_tip", X, +1)],
    52: [("nose_tip", X, -1)],
    53: [("nose_tip", Y, +1)],
    54: [("nose_tip", Y, -1)],
    55: [("glabella", X, +1)],
    56: [("glabella", X, -1)],
    57: [("nose_tip", Z, +1)],
    58: [("nose_tip", Z, -1)],
    63: [("upper_lid", Y, +1)],
    64: [("upper_lid", Y, -1)],
}
#: Least motion (dm) that counts as moving: 0.3 mm.
MOVES = 0.003


@pytest.fixture(scope="module")
def face(face_of):
    return face_of("noah", "muscle")


@pytest.fixture(scope="module")
def engine(face):
    return face.engine


@pytest.fixture(scope="module")
def marks(head, engine):
    from facsim.head.landmarks import landmarks
    from facsim.engines.muscle.net import anatomy

    from facsim.engines.muscle.net import resolve_vertex

    found = dict(landmarks(head))
    found["lip_corner_left"] = anatomy(head).mouth_corner
    found["buccal"] = resolve_vertex(anatomy(head), {"front": [0.4, 6.6]})
    tongue = engine.model.tongue
    found["tongue_tip"] = int(tongue.ids[np.argmax(tongue.rest[:, 2])])
    return found


@pytest.fixture(scope="module")
def single(engine):
    """Every simulated code at E, solved in one batch: code → positions."""
    from facsim.engines.muscle import simulated_codes

    codes = sorted(simulated_codes())
    acts = [activations(parse(str(code))) for code in codes]
    return dict(zip(codes, engine.solve_many(acts))), engine.neutral


def test_every_simulated_au_is_checked_or_is_an_eye_turn():
    from facsim.engines.muscle import simulated_codes

    assert simulated_codes() - set(DIRECTIONS) <= {61, 62, 65, 66}


@pytest.mark.parametrize("code", sorted(DIRECTIONS))
def test_au_moves_landmarks_the_way_facs_says(single, marks, code):
    solved, neutral = single
    delta = solved[code] - neutral
    for name, axis, sign in DIRECTIONS[code]:
        key = name if name in marks else name + "_left"
        assert sign * delta[marks[key], axis] > MOVES, (code, name, axis, delta[marks[key]])


def test_eyes_turn_left_on_61_and_right_on_62(single, head):
    solved, neutral = single
    for code, sign in ((61, +1), (62, -1)):
        for side in ("left", "right"):
            eye = head.eye_vertices[side]
            pupil = eye[np.argmax(head.eye_local[:, 2])]
            assert sign * (solved[code][pupil, X] - neutral[pupil, X]) > 0.03


def test_every_catalogue_action_is_simulated_or_explained():
    from facsim.engines.muscle import coverage, simulated_codes

    explained = coverage()
    for code, info in catalogue().items():
        if info.rendered:
            assert code in explained, code
            assert code in simulated_codes() or explained[code].startswith("not simulated")


@pytest.mark.parametrize("code", [1, 2, 4, 5, 6, 9, 12, 15, 17, 20, 24, 26, 27, 33, 43])
def test_bilateral_aus_are_symmetric(single, head, code):
    p = single[0][code]
    skin = head.skin
    assert np.abs(p[head.mirror[skin]] * [-1, 1, 1] - p[skin]).max() < 1e-3  # 0.1 mm


#: The other side moves less than this share of the acting side's most ...
SPILL = 0.25
#: ... except where a unilateral action stretches the lips, one band from corner to corner: its other
#: half is drawn toward the acting corner (L20 on noah, settled: the corner 10.5 mm, the other
#: half of the lips 3.0 mm, the other corner 1.4 mm).
LIP_SPILL = {20: 0.3}


@pytest.mark.parametrize("code", [1, 2, 4, 6, 12, 15, 20, 46])
def test_unilateral_aus_move_only_their_side(engine, code):
    left, right = engine.solve_many([activations(parse(f"L{code}")), activations(parse(f"R{code}"))])
    x = engine.neutral[:, X]
    for moved, own, other in ((left, x > 0.05, x < -0.15), (right, x < -0.05, x > 0.15)):
        delta = np.linalg.norm(moved - engine.neutral, axis=1)
        assert delta[own].max() > 0.01
        assert delta[other].max() < LIP_SPILL.get(code, SPILL) * delta[own].max()


def test_smile_lifts_the_corners_not_the_lower_lip(single, marks):
    """12 pulls the lip corners up and back; the lower lip stretches and flattens, it is not carried
    up with them (before the lower lip's base was tied to the jaw its middle rose 0.48 of the corners' rise
    on noah, 0.55 on ava; now 0.37 on noah)."""
    solved, neutral = single
    delta = solved[12] - neutral
    corner = delta[marks["lip_corner_left"], Y]
    assert delta[marks["lower_lip"], Y] < 0.4 * corner




def test_smile_draws_the_corners_up_and_out(engine, marks):
    """FACS 12 pulls the lip corners up and out, obliquely toward the cheekbone (session 21: over
    a pulley above the corner, noah's corner went 7.9 mm out and 17.9 up, a narrow smile)."""
    neutral, smile = engine.solve_many([Activations(), activations(parse("12"))], iterations=SETTLED)
    corner = marks["lip_corner_left"]
    moved = smile[corner] - neutral[corner]
    assert moved[Y] > 0.1 and moved[X] > 0.095                 # up 10 mm, out 9.5 mm at least


def test_masking_cheek_raiser_after_smile_lifts_the_corner_less(engine, marks):
    corner = marks["lip_corner_left"]
    neutral, six, twelve, both = engine.solve_many(
        [Activations(), activations(parse("6")), activations(parse("12")), activations(parse("12+6"))],
        iterations=SETTLED)
    alone = six[corner, Y] - neutral[corner, Y]
    after = both[corner, Y] - twelve[corner, Y]
    assert alone > MOVES  # the cheek raiser lifts the corner ...
    assert after < 0.6 * alone  # ... much less once the smile has stretched the tissue


def test_animation_path_converges_to_the_static_solve(engine):
    target = activations(parse("1+2+12"))
    engine.reset()
    for k in range(1, 9):  # the expression comes on over 8 frames, then is held
        engine.step(target.scaled(k / 8))
    for _ in range(20):
        held = engine.step(target).positions
    direct = engine.deform(target).positions
    gap = np.linalg.norm(held - direct, axis=1)
    assert gap.max() < 0.04 and gap.mean() < 0.002  # within 4 mm anywhere and 0.2 mm on average


def test_solves_do_not_depend_on_how_many_threads_blas_runs(engine):
    """A static solve is the same bit for bit on one BLAS thread and on two (OpenBLAS split the
    minimiser's dot products over its threads: the animation test above failed run alone, 4.9 mm,
    and passed in the full suite, where an earlier test had left one thread)."""
    threadpoolctl = pytest.importorskip("threadpoolctl")
    act = activations(parse("1+2+12"))
    solved = []
    for threads in (1, 2):
        with threadpoolctl.threadpool_limits(threads):
            solved.append(engine.deform(act).positions)
    assert np.array_equal(*solved)


def test_a_step_applies_only_the_change(engine):
    act = activations(parse("4"))
    engine.reset()
    for _ in range(40):  # reach the expression and hold it
        held = engine.step(act).positions
    again = engine.step(act).positions  # nothing changed: the face stays where it is
    assert np.abs(again - held).max() < 0.003
    from facsim.head.landmarks import landmarks

    brow = landmarks(engine.head)["inner_brow_left"]
    first = engine.step(act.scaled(0.5)).positions  # half the action: the brows start back up at once ...
    for _ in range(10):
        later = engine.step(act.scaled(0.5)).positions
    assert first[brow, 1] > held[brow, 1] + 0.0005
    # ... and keep rising over the next frames. (How much of the way the first frame goes
    # depends on the minimiser's state: 0.16-0.85 mm is left for the next ten frames in
    # different runs, so the check is that they rise, by more than 0.1 mm.)
    assert later[brow, 1] > first[brow, 1] + 0.001


def test_engine_api(face, engine, head):
    assert engine.name == "muscle"
    d = engine.deform(activations(parse("4+6")))
    p = d.positions
    assert p.shape == (head.vertex_count, 3) and p.dtype == np.float32
    w = d.wrinkle
    assert w.shape == (head.vertex_count,) and w.dtype == np.float32 and (w >= 0).all()
    assert w.max() > 0.2  # 4+6 creases the skin


def test_face_renders_with_the_muscle_engine(face):
    img = face.render("4+6", size=96)
    assert img.shape == (96, 96, 4)


def test_emotions_show_their_upper_face_signs(engine, marks):
    """Issue 13: 1+4 (sadness, fear) raises the inner brows while drawing them together; surprise
    widens the eyes (5); a smile (12) lifts the corner at least 5 mm."""
    from facsim.facs.emotions import emotion

    names = ["sadness", "fear", "surprise"]
    acts = [activations(parse("1+4")), activations(parse("12"))] + [activations(emotion(n)) for n in names]
    got = engine.solve_many(acts) - engine.neutral
    brow, lid, corner = marks["inner_brow_left"], marks["upper_lid_left"], marks["lip_corner_left"]
    assert got[0][brow, 1] > 0.02 and got[0][brow, 0] < -0.01   # 1+4: up 2 mm and in 1 mm at least
    assert got[1][corner, 1] > 0.05
    assert got[2][brow, 1] > 0.01 and got[3][brow, 1] > 0.01   # sadness and fear: inner brows raised
    assert got[4][lid, 1] > 0.02                              # surprise: upper lid up 2 mm


def test_lash_frames_span_a_plane_where_lid_points_fall_on_a_line():
    from facsim.engines.muscle import _frames, _spanning_triples

    # Three lid points on one line (as ngozi's face shape makes them) then two off it.
    points = np.array([[0, 0, 0], [0, 0, 1], [0, 0, 2], [1, 0, 0], [0, 1, 0]], float)
    triples = _spanning_triples(points, np.array([[0, 1, 2, 3, 4]]))
    assert triples.tolist() == [[0, 1, 3]]
    assert np.isfinite(_frames(points, triples)).all()
    # Where the nearest three span a plane, they are kept.
    assert _spanning_triples(points, np.array([[0, 1, 3, 2, 4]])).tolist() == [[0, 1, 3]]


def test_a_face_shape_with_lid_points_on_a_line_gets_finite_positions():
    import facsim

    # ngozi's face shape squeezes lid points onto a line; its lashes once came out NaN.
    positions = facsim.Face("ngozi", engine="muscle").deform("12").positions
    assert np.isfinite(positions).all()


def test_fear_draws_the_raised_brows_together_and_straightens_them(engine, marks):
    """Issue 13: in fear (1+2+4) the brows are raised AND drawn together and straightened (FACS).
    On session 21's main noah's brow heads came 1.6 mm together in fear (the register engine
    draws ava's 7.9 mm together), raised 9 mm like surprise's: the panel read fear as surprise."""
    from facsim.facs.emotions import emotion

    got = engine.solve_many([activations(emotion("fear"))])[0] - engine.neutral
    left, right = marks["inner_brow_left"], marks["inner_brow_right"]
    together = got[left, 0] - got[right, 0]
    assert together < -0.03                                     # drawn together by 3 mm at least
    inner = 0.5 * (got[left, 1] + got[right, 1])
    outer = 0.5 * (got[marks["outer_brow_left"], 1] + got[marks["outer_brow_right"], 1])
    assert inner > 0.02 and outer > 0.02                         # both raised 2 mm at least
    assert abs(outer - inner) < 0.04                             # straightened: no slant of 4 mm


def test_cheek_raiser_leaves_the_nose_unwrinkled(engine, marks):
    """Issue 13: AU 6 raises the cheeks and bags the skin under the eyes; the nose wrinkles in 9,
    not in 6. On session 21's main the orbital ring's medial ends lay on the nasal sidewalls and 6
    pinched the nose into ridges and lines (creases there 1.2 times 9's on noah, now 0.46): every
    smile (6+12+25) wore disgust's nose and the panel read it as neutral 4-5 times in 6."""
    rest = engine.neutral
    glabella, tip = rest[marks["glabella"]], rest[marks["nose_tip"]]
    nose = np.flatnonzero((np.abs(rest[:, 0]) < 0.13) & (rest[:, 1] > tip[1]) & (rest[:, 1] < glabella[1])
                          & (rest[:, 2] > tip[2] - 0.35))
    cheek_raiser, nose_wrinkler = (engine.deform(activations(parse(code))) for code in ("6", "9"))
    assert cheek_raiser.wrinkle[nose].mean() < 0.6 * nose_wrinkler.wrinkle[nose].mean()
    lifted = cheek_raiser.positions - rest
    assert lifted[marks["cheek_left"], 1] > 0.03          # and the cheek still rises 3 mm
