"""Loose strands over the hair (facsim.head.wisps): growing them, binding them, drawing them."""
from __future__ import annotations

import numpy as np
import pytest

from facsim.head.wisps import WispStyle, grow_wisps, wisp_style


def _cards():
    """A dome of small cards (strands along v) over a head-sized sphere."""
    rng = np.random.default_rng(0)
    centres = rng.standard_normal((300, 3))
    centres[:, 1] = np.abs(centres[:, 1])
    centres /= np.linalg.norm(centres, axis=1, keepdims=True)
    points, uv, tris = [], [], []
    for i, c in enumerate(centres):
        side = np.cross(c, [0.0, 1.0, 0.0]) + 1e-3
        side /= np.linalg.norm(side)
        down = np.cross(side, c)
        quad = [c - 0.05 * side, c + 0.05 * side, c + 0.05 * side + 0.1 * down, c - 0.05 * side + 0.1 * down]
        points += quad
        uv += [(0, 1), (1, 1), (1, 0), (0, 0)]
        tris += [(4 * i, 4 * i + 1, 4 * i + 2), (4 * i, 4 * i + 2, 4 * i + 3)]
    return np.array(points) + [0.0, 7.0, 0.0], np.array(tris), np.array(uv, np.float32)


def test_styles_take_the_default_and_refuse_unknown_keys():
    table = {"default": {"fuzz": 10, "flyaways": 2}, "afro01": {"coil_turns": 2.0, "coil_radius_mm": 1.0}}
    assert wisp_style(table, "long01") == WispStyle(fuzz=10, flyaways=2)
    assert wisp_style(table, "afro01").coil_turns == 2.0 and wisp_style(table, "afro01").fuzz == 10
    assert wisp_style({"default": {"fuzz": 0}}, "long01") is None
    assert wisp_style({}, "long01") is None
    with pytest.raises(ValueError, match="unknown keys \\['fuzzz'\\]"):
        wisp_style({"default": {"fuzzz": 3}}, "long01")


def test_strands_grow_from_the_outer_cards_and_taper_to_their_tips():
    points, tris, uv = _cards()
    exposure = np.ones(len(points))
    style = WispStyle(fuzz=200, flyaways=5, points=6)
    wisps = grow_wisps(points, tris, np.arange(len(points)), uv, exposure, style, seed="x")
    assert wisps.strand_count == 205 and wisps.points.shape == (205 * 6, 3)
    strands = wisps.points.reshape(-1, 6, 3)
    from scipy.spatial import cKDTree
    from facsim.head.scalp import card_samples

    tree = cKDTree(card_samples(points, tris, k=8))
    assert np.median(tree.query(strands[:, 0])[0]) < 0.01          # roots on the cards
    assert np.median(tree.query(strands[:, -1])[0]) > 0.02         # tips stand off the mass
    length = np.linalg.norm(np.diff(strands, axis=1), axis=2).sum(axis=1)
    assert 0.05 <= length.min() and length.max() <= 0.5 + 1e-6
    assert np.array_equal(wisps.along[:6], np.linspace(0, 1, 6).astype(np.float32))
    again = grow_wisps(points, tris, np.arange(len(points)), uv, exposure, style, seed="x")
    assert np.array_equal(again.points, wisps.points)
    triangles, corner_vertex, ribbon_uv = wisps.ribbon()
    assert len(triangles) == 205 * 5 * 2 and len(corner_vertex) == len(ribbon_uv) == 2 * len(wisps.points)
    assert set(np.unique(ribbon_uv[:, 0])) == {0.0, 1.0}


def test_strands_avoid_cards_under_others_and_coil_for_coily_hair():
    points, tris, uv = _cards()
    exposure = (points[:, 0] > 0).astype(float)  # only the right half lies in the open
    coily = WispStyle(fuzz=100, points=12, coil_radius_mm=1.0, coil_turns=2.5, fuzz_length_mm=(4.0, 6.0))
    wisps = grow_wisps(points, tris, np.arange(len(points)), uv, exposure, coily, seed=1)
    strands = wisps.points.reshape(-1, 12, 3)
    assert (strands[:, 0, 0] > -0.06).all()
    # A coil's path is several times longer than the distance it reaches.
    path = np.linalg.norm(np.diff(strands, axis=1), axis=2).sum(axis=1)
    reach = np.linalg.norm(strands[:, -1] - strands[:, 0], axis=1)
    assert np.median(path / reach) > 2.0


def test_the_face_draws_wisps_that_follow_the_hair_and_soften_its_outline(face_of):
    face = face_of("ava")  # long01
    meshes = face.proxy_meshes
    kinds = [m.kind for m in meshes]
    assert kinds.index("wisps") == kinds.index("hair") + 1
    wisps = meshes[kinds.index("wisps")]
    assert wisps.strand_points >= 2 and wisps.strand_width > 0
    draws = face.proxy_draws(face.neutral)
    wisp_draw = draws[kinds.index("wisps")]
    assert wisp_draw.color == draws[kinds.index("hair")].color
    turned = face.deform("51E").positions
    bound = face.wisps
    assert np.linalg.norm(bound.binding.positions(turned) - bound.binding.positions(face.neutral), axis=1).max() > 0.3

    from facsim.render.options import RenderOptions

    options = RenderOptions(size=160, background=None, antialias=1, body="none")
    camera = face.camera(view=options.view, size=options.size)
    p = face.neutral

    def partial(proxies):
        image = face.renderer(options).render(p, appearance=face.appearance, camera=camera,
                                              occlusion=face.frame_occlusion(p), lids=face.frame_lids(p), proxies=proxies)
        a = image[..., 3]
        return int(((a > 5) & (a < 230)).sum())

    without = partial([d for d in draws if d.mesh.kind != "wisps"])
    assert partial(draws) > without + 40
