"""The lids at rest and their shade on the eyes (issue 13): a relaxed aperture, measured per
character, that both engines start from, which 5 still widens and 43 still closes."""
from __future__ import annotations

import numpy as np
import pytest

from facsim._data import load_yaml
from facsim.engines.lids import RestLids, rest_table, spherical
from facsim.facs.activations import Activations

#: amara's sculpted upper lid covers only ~1.5 mm of the iris (relaxed lids lower it);
#: noah's and george's cover 4-5 mm already (hooded: lifted to `most_cover_mm`, so they do not look sleepy).
HIGH_LID, COVERED = "amara", ("noah", "george")


def _cover_mm(face, positions, side="left") -> float:
    """How far (mm) the upper lid margin over the pupil sits below the top of the iris."""
    centre, radius = face.head.eye_pivot(face.base_positions, side)
    upper = face._lid_margins[side][1]
    lam, _ = spherical(positions[upper], centre)
    ahead = upper[np.abs(lam) < float(rest_table()["ahead_degrees"])]
    return 100.0 * (float(rest_table()["iris_radius"]) * radius - (positions[ahead, 1].mean() - centre[1]))


def test_rest_share_fades_under_the_aus_that_take_the_lid_over():
    rest = RestLids({"left": 0.1, "right": 0.1}, {s: np.ones((3, 3), np.float32) for s in ("left", "right")}, (5, 43))
    assert rest.share(Activations(), "left") == pytest.approx(0.1)
    assert rest.share(Activations({(5, "left"): 1.0}), "left") == 0.0
    assert rest.share(Activations({(43, "left"): 0.5}), "left") == pytest.approx(0.05)
    assert rest.share(Activations({(43, "left"): 0.5}), "right") == pytest.approx(0.1)  # one side only
    assert np.allclose(rest.offsets(Activations({(5, "right"): 1.0})), 0.1)


@pytest.mark.parametrize("engine", ["registers", "muscle"])
def test_a_high_upper_lid_rests_over_the_top_of_the_iris(face_of, engine):
    face = face_of(HIGH_LID, engine)
    sculpted = face.engine.sculpted
    assert face.engine.rest_lids.weights["left"] > 0.02
    assert _cover_mm(face, sculpted) < float(rest_table()["cover_mm"]) - 0.3
    assert _cover_mm(face, face.neutral) == pytest.approx(float(rest_table()["cover_mm"]), abs=0.3)
    assert np.allclose(face.neutral, face.deform("").positions)


@pytest.mark.parametrize("name", COVERED)
def test_hooded_lids_are_lifted_to_a_relaxed_cover(face_of, name):
    """Hooded lids keep their fold but their margin rests no lower than `most_cover_mm` over the
    iris: sculpted 4-5 mm over it (to the pupil) they got nothing until session 26, and the blind
    reviewer saw "sleepy, dead eyes" on kwame and george at rest, the key's catch-light under the lid."""
    face = face_of(name)
    most = float(rest_table()["most_cover_mm"])
    assert face.engine.rest_lids.weights["left"] < 0.0
    for side in ("left", "right"):      # (george's, 5.4 mm, rises by max_lift's 1.6 mm)
        sculpted, rest = _cover_mm(face, face.engine.sculpted, side), _cover_mm(face, face.neutral, side)
        assert most - 0.4 < rest < sculpted - 1.2, (sculpted, rest)


def _lower_sag_mm(face, positions, side="left") -> float:
    """How far (mm) the lower lid margin under the pupil sits below the bottom of the iris
    (negative: it covers the iris's bottom)."""
    centre, radius = face.head.eye_pivot(face.base_positions, side)
    lower = face._lid_margins[side][2]
    lam, _ = spherical(positions[lower], centre)
    ahead = lower[np.abs(lam) < float(rest_table()["ahead_degrees"])]
    return 100.0 * (-(positions[ahead, 1].mean() - centre[1]) - float(rest_table()["iris_radius"]) * radius)


@pytest.mark.parametrize("name", ["kwame", "george", "noah"])
def test_the_lower_lid_rests_on_the_iris_s_bottom(face_of, name):
    """Session 19: the hooded presets' sculpted lower lids sagged 0.5-1.1 mm below the iris (white
    under it at rest, more at 5E: the iris floated in white, a bulging eye in fear and surprise).
    The relaxed lower lid touches the iris's bottom; 5 does not pull it back down; 7, which lifts
    it with the same target at full weight, takes the rest share over (it is not added twice)."""
    face = face_of(name)
    assert _lower_sag_mm(face, face.engine.sculpted) > 0.3
    assert face.engine.rest_lids.lower_weights["left"] > 0.1
    assert _lower_sag_mm(face, face.neutral) < 0.0
    assert _lower_sag_mm(face, face.deform("5E").positions) < 0.5
    assert face.engine.rest_lids.lower_share(face.activations("7E"), "left") == 0.0
    assert face.engine.rest_lids.lower_share(face.activations("5E"), "left") == face.engine.rest_lids.lower_weights["left"]


def test_lower_lids_that_cover_the_iris_are_left_as_they_are(face_of):
    face = face_of(HIGH_LID)
    assert face.engine.rest_lids.lower_weights == {"left": 0.0, "right": 0.0}


@pytest.mark.parametrize("engine", ["registers", "muscle"])
def test_5_widens_and_43_closes_from_the_relaxed_rest(face_of, engine):
    """(The muscle engine's net leaves the lid corners open and dips in the middle; its lids are
    brought together by facsim.engines.lids.EyeLids.meet_lower.)"""
    face = face_of(HIGH_LID, engine)
    rest = _cover_mm(face, face.neutral)
    wide, closed = (face.deform(code).positions for code in ("5E", "43E"))
    assert rest - _cover_mm(face, wide) > 1.5          # the lid rises more than 1.5 mm over the iris
    assert not face.engine.rest_lids.offsets(face.activations("43E")).any()  # 43 closes as from the sculpted rest
    centre, upper, lower = face._lid_margins["left"]
    lam_u, phi_u = spherical(closed[upper], centre)
    lam_l, phi_l = spherical(closed[lower], centre)
    order = np.argsort(lam_l)
    ahead = np.abs(lam_u) < 12
    gap = phi_u[ahead] - np.interp(lam_u[ahead], lam_l[order], phi_l[order])
    assert np.abs(gap).max() < 2.0, gap                # closed: the margins meet over the eye (degrees of arc)


@pytest.mark.parametrize("name", ["ava", "mei", "amara", "kwame", "george"])
def test_5E_bares_the_sclera_above_the_iris_on_every_preset(face_of, name):
    """FACS 5 at E shows white above the iris. Session 18: AU 5's targets lift every lid about
    5 mm from where it rests, so kwame's and george's (which cover 5 mm of the iris at rest) bared
    none (their margin 0.3 and -0.5 mm over the iris's top) and mei's, over a smaller eye, rose 3.9
    iris-mm over it; lids.yaml's `raise` fits the factor per character (the skin guard, which will
    not let the lid's skin fold under the hood, holds kwame's at 2.5 and george's at 1.6).
    Session 19: fitted to 3.5 iris-mm, ava's, mei's and amara's margins stood 3.3-3.5 mm over the
    iris and the wide-open eyes read as bulging; open lids rise to 2.5 mm (2.3-2.6), hooded ones
    keep 3.5 (their fold hides the margin). Session 26: the skin guard had held kwame's short of
    that, at 2.5; lifted at rest (most_cover_mm) it reaches 3.1, and shows 0.5 mm of white over
    the iris at 512 px (none before)."""
    face = face_of(name)
    centre, radius = face.head.eye_pivot(face.base_positions, "left")
    iris_mm = 100.0 * float(rest_table()["iris_radius"]) * radius / (0.5 * float(rest_table()["iris_mm"]))
    over_iris = -_cover_mm(face, face.deform("5E").positions) / iris_mm
    hooded = float(load_yaml("lids.yaml")["raise"]["hooded"]["bare_mm"])
    assert 1.2 < over_iris < (hooded if name in ("kwame", "george") else 3.0)
    assert -_cover_mm(face, face.neutral) < 0.0                 # at rest the lid covers the iris's top


def _over_iris_mm(face, expression) -> float:
    """How far (iris-mm) the upper margin over the pupil stands above the iris's top in ``expression``."""
    centre, radius = face.head.eye_pivot(face.base_positions, "left")
    iris_mm = 100.0 * float(rest_table()["iris_radius"]) * radius / (0.5 * float(rest_table()["iris_mm"]))
    positions = face.deform(expression).positions if expression else face.neutral
    return -_cover_mm(face, positions) / iris_mm


@pytest.mark.parametrize("name", ["george", "kwame"])
def test_raised_brows_let_5_lift_a_hooded_lid_off_the_iris(face_of, name):
    """FACS 1+2 stretch the skin between the brow and the lid's crease upward, lifting a hooded
    lid's fold, and in surprise (1+2+5B) the eye looks widened. Session 23: george's and kwame's
    lids (sculpted 5.4 and 4.8 mm over the iris) stayed 1.6 and 1.4 mm below the iris's top at
    1+2+5B, as at 5B, and their surprise read as fear (lids.yaml `raise` `hood_lift`). The margin
    itself still rises only with 5."""
    face = face_of(name)
    assert _over_iris_mm(face, "1+2+5B") > 0.5
    assert _over_iris_mm(face, "1+2+5B") > _over_iris_mm(face, "5B") + 1.5
    assert abs(_over_iris_mm(face, "1+2") - _over_iris_mm(face, "")) < 0.2
    assert _over_iris_mm(face, "1+2+4+5B") < _over_iris_mm(face, "1+2+5B") - 1.0  # 4 brings the lid's skin down


@pytest.mark.parametrize("name", ["ava", "amara"])
def test_raised_brows_leave_open_lids_to_5(face_of, name):
    """Open lids get no hood lift: 1+2+5B raises ava's and amara's margins as 5B does (session 19:
    their lids raised further looked "bulging")."""
    face = face_of(name)
    assert abs(_over_iris_mm(face, "1+2+5B") - _over_iris_mm(face, "5B")) < 0.2


def test_the_lids_shade_on_the_eyeball_follows_the_upper_lid(face_of):
    """Sclera just above the iris lies under the upper lid or in its shadow at rest (the shader
    shades the eyeball by its distance below the margin, Face.frame_lids), bared by 5, covered
    further by 43; the lower lid is far below it throughout."""
    face = face_of("ava")
    eye = face.head.eye_vertices["left"]
    local = face.head.eye_local
    band = eye[(local[:, 2] > 0.8) & (local[:, 1] > 0.3) & (local[:, 1] < 0.45) & (np.abs(local[:, 0]) < 0.15)]
    assert len(band) >= 2
    at_rest, widened, closed = (face.frame_lids(p)[band] for p in (face.neutral, face.deform("5E").positions,
                                                                   face.deform("43E").positions))
    assert at_rest[:, 0].mean() < 3.0                          # under the lid or within its shadow (degrees)
    assert widened[:, 0].mean() > at_rest[:, 0].mean() + 10.0  # 5 raises the margin well above it
    assert closed[:, 0].mean() < at_rest[:, 0].mean() - 20.0
    assert (at_rest[:, 1] > 25.0).all() and (widened[:, 1] > 25.0).all()
    others = np.setdiff1d(np.arange(len(face.neutral)), np.concatenate(list(face.head.eye_vertices.values())))
    assert (face.frame_lids(face.neutral)[others] == 90.0).all()   # only eyeballs carry lid distances

def test_lashes_turn_with_the_closing_lid(face_of):
    """Upper lashes swing forward and down with a closing lid (no fence of spikes standing on a
    closed lid) and sit exactly where their binding puts them at rest."""
    face = face_of("ava")
    lashes = next(b for b in face.proxies if b.proxy.kind == "eyelashes")
    rest = face._proxy_positions(lashes, face.neutral)
    assert np.allclose(rest, lashes.binding.positions(face.neutral), atol=1e-5)
    roots, _, _ = face._lash_roots[id(lashes)]
    upper = np.isin(roots, np.concatenate([m[1] for m in face._lid_margins.values()]))
    closed = np.asarray(face.deform("45E").positions)
    turned = face._proxy_positions(lashes, closed)
    rise = lambda p, geo: (p - geo[roots])[upper, 1]   # noqa: E731 — each vertex's height above its root
    stiff = lashes.binding.positions(closed)
    assert rise(turned, closed).mean() < 0.5 * rise(rest, face.neutral).mean()
    assert rise(stiff, closed).mean() > rise(turned, closed).mean() + 0.005   # the plain binding kept them up


def _aperture_mm(face, positions, side="left") -> float:
    """The upper lid margin's height over the pupil less the lower margin's (mm)."""
    centre, _ = face.head.eye_pivot(face.base_positions, side)
    _, upper, lower = face._lid_margins[side]
    ahead = float(rest_table()["ahead_degrees"])

    def height(margin):
        lam, _ = spherical(positions[margin], centre)
        return positions[margin[np.abs(lam) < ahead], 1].mean()

    return 100.0 * (height(upper) - height(lower))


@pytest.mark.parametrize("name", ["ava", "mei", "kwame", "george"])
def test_6_narrows_the_eye_from_below_without_shutting_it(face_of, name):
    """Session 22: 6's lower lid rose about 3.5 mm on every preset, which left a small or hooded eye
    a slit in a full smile (george 44 % of its aperture, mei 57 %: "squinting", a blind reviewer).
    Its lower-lid target is fitted per character (``lids.yaml`` ``squint``); the lower lid still rises."""
    from facsim.facs.emotions import emotion

    face = face_of(name)
    rest = np.asarray(face.neutral)
    smile = np.asarray(face.deform(emotion("happiness")).positions)
    six = np.asarray(face.deform("6E").positions)
    assert _aperture_mm(face, smile) > 0.58 * _aperture_mm(face, rest)
    assert _aperture_mm(face, six) < _aperture_mm(face, rest) - 1.8        # still narrowed from below
    assert _lower_sag_mm(face, six) < _lower_sag_mm(face, rest) - 0.015    # the lower lid up 1.5 mm or more

