"""Every pair of simulated AUs at intensity E solves to a valid face.

Valid: finite, no skin triangle turned inside out, no flesh inside the skull
(the model's own bone surface), no lid through an eyeball — checked on the
solver's contact points and again on EVERY skin vertex and triangle of the
final face (:class:`facsim.engines.checks.GeometryCheck`). Solving 1,500 pairs
one by one would take many minutes, so the pairs are covered by blocks of
``BLOCK`` codes performed together: a covering design in which every pair of
codes appears in at least one block (checked below). A block is a harder test
than any of its pairs — more actions pull on the face at once.
"""
from __future__ import annotations

from itertools import combinations

import numpy as np
import pytest

from facsim.facs.activations import activations
from facsim.facs.notation import parse

BLOCK = 8
#: The blocks are solved in this many parts, so ``pytest -n`` can share them out.
PARTS = 6
#: Contacts are one-sided constraints met by projection; what is left after it is rounding (dm).
SLACK = 5e-5


def covering_blocks(codes, size: int) -> list[tuple[int, ...]]:
    """Blocks of ``size`` codes such that every pair of ``codes`` lies in some block (greedy)."""
    codes = sorted(codes)
    uncovered = {frozenset(p) for p in combinations(codes, 2)}
    blocks = []
    while uncovered:
        first = min(tuple(sorted(p)) for p in uncovered)
        block = list(first)
        while len(block) < size:
            gains = [(sum(frozenset((c, b)) in uncovered for b in block), -c) for c in codes if c not in block]
            gain, neg = max(gains)
            if gain == 0:
                break
            block.append(-neg)
        blocks.append(tuple(sorted(block)))
        uncovered -= {frozenset(p) for p in combinations(block, 2)}
    return blocks


@pytest.fixture(scope="module")
def codes():
    from facsim.engines.muscle import simulated_codes

    return sorted(simulated_codes())


def test_blocks_cover_every_pair(codes):
    blocks = covering_blocks(codes, BLOCK)
    covered = {frozenset(p) for b in blocks for p in combinations(b, 2)}
    assert covered == {frozenset(p) for p in combinations(codes, 2)}
    assert len(blocks) < len(codes) * (len(codes) - 1) / 2 / 10  # far fewer solves than pairs


def _text(block) -> str:
    # 46 (wink) is one-sided: score it on the left so that the block is valid notation.
    return "+".join("L46" if code == 46 else str(code) for code in block)


@pytest.mark.parametrize("part", range(PARTS))
def test_every_pair_of_aus_at_e_solves_to_a_valid_face(face_of, head, codes, part):
    from facsim.engines.muscle import solver

    engine = face_of("ava", "muscle").engine
    model = engine.model
    skin_tris = head.triangles[(head.triangles < head.skin_vertex_count).all(axis=1)]
    rest = engine.neutral.astype(float)

    def normals(p):
        return np.cross(p[skin_tris[:, 1]] - p[skin_tris[:, 0]], p[skin_tris[:, 2]] - p[skin_tris[:, 0]])

    from facsim.engines.checks import GeometryCheck

    check = GeometryCheck(head, engine.neutral)  # every skin vertex and triangle, after the engine's last step
    rest_n = normals(rest)
    sound = np.linalg.norm(rest_n, axis=1) > 1e-10  # degenerate rest triangles have no orientation
    blocks = covering_blocks(codes, BLOCK)[part::PARTS]
    acts = [activations(parse(_text(b))) for b in blocks]
    problems = []
    for k, state, b in engine.static_states(acts):  # exactly the engine's static solve
        block = blocks[k]
        skull, eyes = solver.clearances(model, state.x[:, b:b + 1], solver.loads(model, _one(state.drive, b)))
        p = engine.geometry(state, acts[k], b).astype(float)
        if not np.isfinite(p).all():
            problems.append((block, "not finite"))
            continue
        report = check(p)
        if report.inside:
            problems.append((block, f"{report.inside} skin points {report.depth * 100:.2f} mm inside an eyeball"))
        if report.flipped:
            problems.append((block, f"{report.flipped} skin triangles of the final face turned inside out"))
        # Compare the skin before the rigid head motion (51-58 turn every normal alike).
        skin = state.points(b)[: head.skin_vertex_count]
        flipped = ((normals(skin) * rest_n).sum(1) <= 0) & sound
        if flipped.any():
            problems.append((block, f"{int(flipped.sum())} triangles turned inside out"))
        if skull.min() < -SLACK:
            problems.append((block, f"flesh {-skull.min() * 100:.2f} mm into the skull"))
        if eyes.min() < -SLACK:
            problems.append((block, f"lid {-eyes.min() * 100:.2f} mm into an eyeball"))
    assert not problems, "\n".join(f"{'+'.join(map(str, b))}: {why}" for b, why in problems)


def _one(drive, b):
    """Configuration ``b`` of a batched Drive."""
    from facsim.engines.muscle.muscles import Drive

    return Drive(drive.muscle[b:b + 1], drive.pressure[b:b + 1], drive.lip_pressure[b:b + 1], drive.tongue[b:b + 1])


@pytest.mark.parametrize("character", ["george", "noah"])
def test_open_mouth_with_head_motion_keeps_the_neck_unfolded(face_of, head, character):
    """25/26/27 × 51-58 at E: the head motion's blend into the neck turns a pleat that the open jaw
    leaves under the chin (once 14-24 triangles inside out under 27E+54E on kwame, george, noah)."""
    from facsim.engines.checks import GeometryCheck

    engine = face_of(character, "muscle").engine
    check = GeometryCheck(head, engine.neutral)
    texts = [f"{a}E+{b}E" for a in (25, 26, 27) for b in range(51, 59)]
    problems = []
    for text, deformation in zip(texts, engine.deform_many([activations(parse(t)) for t in texts])):
        report = check(deformation.positions)
        if report.flipped or report.inside:
            problems.append(f"{text}: {report.flipped} triangles inside out, {report.inside} skin points in an eye")
    assert not problems, "\n".join(problems)
