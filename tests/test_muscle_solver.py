"""The muscle engine's pieces: the energy and its gradient, the solver, the jaw, the data, wrinkles."""
from __future__ import annotations

import numpy as np
import pytest

from facsim.facs.activations import Activations, activations
from facsim.facs.notation import parse


@pytest.fixture(scope="module")
def engine(face_of):
    return face_of("ava", "muscle").engine


@pytest.fixture(scope="module")
def model(engine):
    return engine.model


def _drive(model, text):
    from facsim.engines.muscle.muscles import drive

    return drive(model.layer, activations(parse(text)) if text else Activations())


@pytest.mark.parametrize("text", ["12", "4+6", "26", "33", "19", "24+17", "43"])
def test_gradient_matches_finite_differences(model, text):
    from facsim.engines.muscle import solver

    rng = np.random.default_rng(7)
    ld = solver.loads(model, _drive(model, text))
    x = solver.rest_state(model).x + 0.01 * rng.standard_normal((3, 1, model.count))
    _, grad = solver.energy(model, x, ld)
    v = rng.standard_normal(x.shape)
    h = 1e-6
    numeric = (solver.energy(model, x + h * v, ld)[0] - solver.energy(model, x - h * v, ld)[0]) / (2 * h)
    assert numeric[0] == pytest.approx((grad * v).sum(), rel=1e-5)


def test_rest_is_an_equilibrium(model):
    from facsim.engines.muscle import solver

    state = solver.rest_state(model)
    ld = solver.loads(model, state.drive)
    energy, grad = solver.energy(model, state.x, ld)
    assert abs(energy[0]) < 1e-8 and np.abs(grad).max() < 1e-8
    moved = solver.solve(model, state, state.drive, steps=1, iterations=10)
    assert np.abs(moved.x - state.x).max() < 1e-9


def test_the_stiffness_is_factorised_once_and_reused(engine, monkeypatch):
    import scipy.sparse.linalg as spla

    calls = []
    real = spla.splu
    monkeypatch.setattr(spla, "splu", lambda *a, **k: calls.append(1) or real(*a, **k))
    engine.reset()
    for k in range(1, 6):
        engine.step(activations(parse("12")).scaled(k / 5))
    engine.deform(activations(parse("4"))).positions
    assert calls == []  # frames and static solves only back-substitute


def test_a_character_model_is_built_once_and_shared(face_of):
    """A second engine for the same character reuses the net, muscles and factorisation;
    another character gets its own (bench_muscle.py times the build)."""
    from facsim.engines.muscle import MuscleEngine

    face = face_of("ava", "muscle")
    again = MuscleEngine(face.head, face.data, face.character, face.base_positions)
    assert again.model is face.engine.model and again.wrinkles is face.engine.wrinkles
    other = face_of("kwame", "muscle")
    assert other.engine.model is not face.engine.model


def test_batched_solves_equal_single_ones(engine):
    """A batch solves each expression as it would alone, up to round-off: the batch's width
    changes the last bits of the sparse solves, and 60 L-BFGS iterations can carry them to
    0.25 mm (15 on the symmetric ava since session 22's corrugator and orbicularis changes; hm08
    units are decimetres), half a pixel at 512². Each solve is still repeatable: the same batch
    gives the same bits."""
    acts = [activations(parse(t)) for t in ("1", "15", "26")]
    together = engine.solve_many(acts)
    for act, batched in zip(acts, together):
        assert np.abs(engine.deform(act).positions - batched).max() < 3e-3


def test_jaw_statics(model):
    from facsim.engines.muscle.muscles import jaw_pose

    def pose(text):
        return jaw_pose(model.layer, _drive(model, text).muscle, model.jaw_spec)[0]

    drop, stretch = np.degrees(pose("26")[0]), np.degrees(pose("27")[0])
    assert 8 < drop < 16 and stretch > drop + 8  # relaxed elevators drop it; digastric pulls it wide
    assert np.abs(pose("31")).max() < 1e-9  # clenching keeps it shut
    assert pose("29")[1] > 0.05  # thrust forward
    assert pose("30")[2] > 0.03  # sideways, to the character's left
    assert pose("")[0] == 0


def test_muscle_data_is_consistent(model):
    from facsim.engines.muscle import au_table
    from facsim.engines.muscle.net import load_spec

    spec = load_spec()
    names = set(spec["muscles"])
    required = {"frontalis_medial", "frontalis_lateral", "corrugator_supercilii", "procerus", "depressor_supercilii",
                "orbicularis_oculi_orbital", "orbicularis_oculi_palpebral_upper", "levator_palpebrae_superioris",
                "levator_labii_superioris", "levator_labii_superioris_alaeque_nasi", "zygomaticus_minor",
                "zygomaticus_major", "levator_anguli_oris", "risorius", "buccinator", "depressor_anguli_oris",
                "depressor_labii_inferioris", "mentalis", "incisivus_labii_superioris", "orbicularis_oris_peripheral",
                "nasalis_alar", "platysma", "masseter", "temporalis", "medial_pterygoid", "lateral_pterygoid",
                "digastric"}
    assert required <= names
    for code, entry in au_table()["action_units"].items():
        assert entry["how"], code
        for name, value in (entry.get("muscles") or {}).items():
            assert name in names, (code, name)
    # Paired muscles are mirror images: same number of fibre segments on each side.
    layer = model.layer
    for name in names:
        sides = [k for k, m in enumerate(layer.muscle) if m == name]
        counts = [int((layer.seg_muscle == k).sum()) for k in sides]
        assert len(set(counts)) == 1, name


def test_improved_muscles_bend_over_bone(model):
    """Frontalis passes through intermediate muscle points (Platt & Badler fig. 5); zygomaticus
    major bends over a pulley fixed on the cheekbone (issue 13: a pulley riding the skin let
    AU 6 re-aim the smile)."""
    layer = model.layer
    k = layer.names.index("frontalis_medial_left")
    segs = np.flatnonzero(layer.seg_muscle == k)
    assert ((layer.seg_a[segs] >= 0) & (layer.seg_b[segs] >= 0)).any()  # muscle point → muscle point
    k = layer.names.index("zygomaticus_major_left")
    segs = np.flatnonzero(layer.seg_muscle == k)
    assert len(segs) == 2                                                # origin → pulley → insertion
    assert layer.seg_a[segs[0]] < 0 and layer.seg_b[segs[0]] < 0        # the pulley is bone
    assert layer.seg_b[segs[1]] >= 0                                    # the insertion a muscle point


def test_coverage_lists_every_facial_action(engine):
    from facsim.facs.catalogue import catalogue
    from facsim.engines.muscle import coverage, simulated_codes

    explained = coverage()
    actions = [c for c, info in catalogue().items() if info.kind in ("action", "head", "eye")]
    assert set(actions) <= set(explained)
    assert {19, 25, 26, 27, 29, 30, 31, 33, 34, 35, 36, 37, 38, 39} <= simulated_codes()  # the paper's unsolved ones


def _wrinkles(engine, text):
    return engine.deform(activations(parse(text))).wrinkle


def test_wrinkles_appear_where_the_skin_is_squeezed(engine, head):
    from facsim.head.landmarks import landmarks

    marks = landmarks(head)
    rest = engine.neutral
    skin = head.skin
    forehead = skin[(rest[skin, 1] > rest[marks["inner_brow_left"], 1] + 0.06) & (np.abs(rest[skin, 0]) < 0.35)
                     & (rest[skin, 2] > rest[marks["inner_brow_left"], 2] - 0.25)]
    glabella = skin[np.linalg.norm(rest[skin] - rest[marks["glabella"]], axis=1) < 0.08]
    chin = skin[np.linalg.norm(rest[skin] - rest[marks["chin"]], axis=1) < 0.1]
    neutral = _wrinkles(engine, "")
    assert neutral is None or neutral.max() < 1e-6
    assert _wrinkles(engine, "1+2")[forehead].max() > 0.3   # forehead lines
    assert _wrinkles(engine, "4")[glabella].max() > 0.3     # glabellar furrows
    assert _wrinkles(engine, "17")[chin].max() > 0.05       # the chin boss dimples


def test_wrinkle_lines_run_across_the_compression(engine, head):
    """On 1+2 the forehead is squeezed vertically, so its lines run horizontally; on 4 the
    glabella is squeezed sideways, so its furrows run vertically."""
    from facsim.head.landmarks import landmarks
    from facsim.engines.muscle.wrinkles import principal_compression

    marks = landmarks(head)
    model = engine.wrinkles
    centre = engine.neutral[model.triangles].mean(axis=1)
    brow = engine.neutral[marks["inner_brow_left"]]
    regions = {
        "1+2": (1, (centre[:, 1] > brow[1] + 0.03) & (np.abs(centre[:, 0]) < 0.4) & (centre[:, 2] > brow[2] - 0.3)),
        "4": (0, np.linalg.norm(centre - engine.neutral[marks["glabella"]], axis=1) < 0.1),
    }
    for text, (axis, region) in regions.items():
        _, state, index = next(engine.static_states([activations(parse(text))]))
        skin = state.points(index)[: engine.model.net.count]
        squeeze, direction, _ = principal_compression(model, skin)
        weights = squeeze * region
        along = (np.abs(direction[:, axis]) * weights).sum() / weights.sum()
        assert along > 0.6, (text, along)


def test_furrow_phase_counts_furrows_across_the_compression(engine, head):
    """The renderer draws a furrow at each whole phase: on 4 the glabella's phase climbs
    sideways by about one per glabellar furrow spacing, and hardly at all upward."""
    from facsim.head.landmarks import landmarks

    marks = landmarks(head)
    phase = engine.deform(activations(parse("4"))).crease_phase
    rest = engine.neutral
    region = head.skin[np.linalg.norm(rest[head.skin] - rest[marks["glabella"]], axis=1) < 0.12]
    design = np.c_[rest[region, :2], np.ones(len(region))]
    (per_x, per_y, _), *_ = np.linalg.lstsq(design, phase[region], rcond=None)
    spacing = engine.wrinkles.wavelength[region].mean()
    assert abs(per_x) > 3 * abs(per_y), (per_x, per_y)
    assert 0.5 < abs(per_x) * spacing < 1.5, abs(per_x) * spacing


def test_raised_brows_lift_the_forehead_level_across_the_midline(engine, head):
    """On 1+2 the skin over the glabella rises with the brows beside it (issue 13: it lagged at
    half their rise, and the forehead folded into one V over the midline)."""
    from facsim.head.landmarks import landmarks

    marks = landmarks(head)
    rest, skin = engine.neutral, head.skin
    moved = engine.deform(activations(parse("1+2"))).positions
    brow = rest[marks["inner_brow_left"], 1]
    for low, high in ((0.08, 0.16), (0.16, 0.26)):  # two rows of the net above the brows
        band = skin[(rest[skin, 1] > brow + low) & (rest[skin, 1] < brow + high)
                    & (rest[skin, 2] > rest[marks["glabella"], 2] - 0.15)]
        x, rise = np.abs(rest[band, 0]), moved[band, 1] - rest[band, 1]
        midline, beside = rise[x < 0.05].mean(), rise[(x > 0.1) & (x < 0.22)].mean()
        assert midline > 0.65 * beside, (low, midline, beside)


def test_force_length_relation_is_full_above_its_range_and_none_below():
    from facsim.engines.muscle.solver import force_length

    ratio = np.linspace(0.2, 1.3, 221)
    f, phi = force_length(ratio, (0.45, 0.8))
    assert np.all(f[ratio <= 0.45] == 0.0) and np.all(f[ratio >= 0.8] == 1.0)
    assert np.all(np.diff(f) >= 0.0)
    # Φ is the integral of f (the fiber's energy is T L₀ Φ, its force T f).
    h = 1e-6
    numeric = (force_length(ratio + h, (0.45, 0.8))[1] - force_length(ratio - h, (0.45, 0.8))[1]) / (2 * h)
    assert np.allclose(numeric, f, atol=1e-6)


def _segment_ratios(model, state, drive):
    from facsim.engines.muscle import solver

    ld = solver.loads(model, drive)
    x = state.x
    pa, pb = solver._apply(model.seg_a, x), solver._apply(model.seg_b, x)
    ba, bb = model.seg_bone_a >= 0, model.seg_bone_b >= 0
    pa[:, :, ba] = ld.bone[:, :, model.seg_bone_a[ba]]
    pb[:, :, bb] = ld.bone[:, :, model.seg_bone_b[bb]]
    length = np.sqrt(solver._dot(pb - pa, pb - pa))
    return length / model.seg_rest, solver._per_row(model.fiber_sum, length) / model.fiber_rest


@pytest.mark.parametrize("text", ["12", "6+12", "4", "9", "15"])
def test_strong_contractions_settle_without_collapsing(engine, model, text):
    """Each fiber settles inside its active range (its force falls off as it shortens) and no
    segment of a muscle's path is shorter than the guard (issue 13: zygomaticus major's point
    ran onto its pulley, its segment at 28 % of its rest length)."""
    act = activations(parse(text))
    (_, state, b), = engine.static_states([act])
    drive = _drive(model, text)
    segment, fiber = _segment_ratios(model, solver_state(state, b), drive)
    assert segment.min() > model.segment_guard - 0.02
    assert fiber.min() > model.active_range[0]


def solver_state(state, b):
    from facsim.engines.muscle import solver

    return solver.State(state.x[:, b:b + 1], state.drive, state.jaw[b:b + 1])


def test_gradient_matches_finite_differences_where_fibers_are_short(engine, model):
    """The force-length relation's fall-off and the segment guard (active on a solved smile)."""
    from facsim.engines.muscle import solver

    (_, state, b), = engine.static_states([activations(parse("12"))])
    ld = solver.loads(model, _drive(model, "12"))
    x = state.x[:, b:b + 1]
    segment, fiber = _segment_ratios(model, solver_state(state, b), _drive(model, "12"))
    assert fiber.min() < model.active_range[1]  # some fiber is on the fall-off
    # (The muscles' share of the energy: the whole energy has kinks at a solved face — arcs at
    # their rest length, contacts — where a finite difference is not the derivative.)
    rng = np.random.default_rng(3)
    _, grad = solver.load_energy(model, x, ld)
    v = rng.standard_normal(x.shape)
    h = 1e-6
    numeric = (solver.load_energy(model, x + h * v, ld)[0] - solver.load_energy(model, x - h * v, ld)[0]) / (2 * h)
    assert numeric[0] == pytest.approx((grad * v).sum(), rel=1e-5)


def test_skin_is_stiffer_where_muscles_insert(model):
    """Skin arcs at the centre of a linear muscle's insertion are ``insertion_skin`` times stiffer."""
    from facsim.engines.muscle.net import load_spec

    factor = load_spec()["net"]["insertion_skin"]
    net, layer = model.net, model.layer
    centre = set(layer.head_ids[layer.head_weight == 1.0].tolist())
    base = net.arcs.k
    stiff = model.arc_k[: len(base)] / base
    both = np.array([i in centre and j in centre for i, j in zip(net.arcs.i, net.arcs.j)])
    neither = ~np.isin(net.arcs.i, layer.head_ids) & ~np.isin(net.arcs.j, layer.head_ids)
    assert both.any() and np.allclose(stiff[both], factor)
    assert np.allclose(stiff[neither], 1.0)


def test_an_increment_stops_once_its_residual_is_small(model, monkeypatch):
    """The minimiser stops a configuration when the force left on the points is below the
    ``residual`` share of what the increment added (and iterates on without it)."""
    from facsim.engines.muscle import solver

    calls = []
    real = solver.energy
    monkeypatch.setattr(solver, "energy", lambda *a, **k: calls.append(1) or real(*a, **k))
    drive = _drive(model, "12")
    loose = solver.solve(model, solver.rest_state(model), drive, steps=1, iterations=60, residual=0.5, settle=False)
    short = len(calls)
    calls.clear()
    solver.solve(model, solver.rest_state(model), drive, steps=1, iterations=60, residual=0.0, settle=False)
    assert short < len(calls)
    ld = solver.loads(model, drive)
    floors = solver.select_sites(model, loose.x, ld)
    _, g = real(model, loose.x, ld)
    held = solver._hold_on_contacts(model, g.copy(), solver._gaps(model, loose.x, floors), floors, sign=1.0)
    _, g0 = real(model, solver.rest_state(model).x, ld)
    assert np.linalg.norm(held) <= 0.5 * np.linalg.norm(g0)
