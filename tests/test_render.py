"""The renderer on small synthetic heads (headless: EGL on llvmpipe, no GPU needed).

The scene: an ellipsoid "head" (skin, with a UV seam) looking toward +Z, one eyeball on
its front, and a small green "marker" sphere (drawn as teeth, coloured pure green) on the
character's LEFT (+X) side.
"""
from __future__ import annotations

import math

import numpy as np
import pytest

from facsim.render.camera import Camera, frame_camera, project
from facsim.render.renderer import (
    COLOR_NAMES, DEFAULT_BROW_UV_FRAME, DEFAULT_COLORS, REGIONS, Appearance, Lighting,
    CREASES_PER_DM, RenderError, Renderer, RenderTopology, bake_occlusion, brow_uv_frame, crease_phase,
    lash_coordinates,
    normal_operator, region_components, sphere_centre, srgb_to_linear, vertex_normals,
    write_png,
)

HEAD_CENTRE = np.array([0.0, 15.5, 0.0])
HEAD_RADII = np.array([0.8, 1.1, 0.9])
EYE_CENTRE = np.array([-0.25, 15.75, 0.78])   # the character's right eye, on the face
EYE_RADIUS = 0.14
MARKER_CENTRE = np.array([0.95, 15.5, 0.0])   # just outside the head on +X
MARKER_RADIUS = 0.15
GREEN = (0.0, 1.0, 0.0)


def uv_sphere(n_lat: int, n_lon: int):
    """Directions, UVs, render->geo map (seam column and poles welded) and faces."""
    theta = np.linspace(0, np.pi, n_lat + 1)
    phi = np.linspace(0, 2 * np.pi, n_lon + 1)
    t, p = np.meshgrid(theta, phi, indexing="ij")
    dirs = np.stack([np.sin(t) * np.sin(p), np.cos(t), np.sin(t) * np.cos(p)], -1).reshape(-1, 3)
    uv = np.stack([p / (2 * np.pi), 1 - t / np.pi], -1).reshape(-1, 2)
    ids = np.arange((n_lat + 1) * (n_lon + 1)).reshape(n_lat + 1, n_lon + 1)
    geo = ids.copy()
    geo[:, -1] = geo[:, 0]
    geo[0, :], geo[-1, :] = geo[0, 0], geo[-1, 0]
    _, r2g = np.unique(geo.reshape(-1), return_inverse=True)
    a, b, c, d = ids[:-1, :-1], ids[1:, :-1], ids[1:, 1:], ids[:-1, 1:]
    faces = np.concatenate([np.stack([a, b, c], -1).reshape(-1, 3),
                            np.stack([a, c, d], -1).reshape(-1, 3)])
    return dirs, uv, r2g.reshape(-1), faces


def build_scene(*, with_marker=True, with_lashes=False, reverse_winding=False):
    """(topology, positions, parts) where parts maps a name to its geometry-vertex indices."""
    parts_in = []
    dirs, uv, r2g, faces = uv_sphere(32, 48)
    geo = np.zeros((r2g.max() + 1, 3))
    geo[r2g] = dirs * HEAD_RADII + HEAD_CENTRE
    parts_in.append(("head", geo, faces, r2g, uv, "skin", np.zeros((len(r2g), 3))))
    dirs, _, r2g, faces = uv_sphere(16, 24)
    geo = np.zeros((r2g.max() + 1, 3))
    geo[r2g] = dirs * EYE_RADIUS + EYE_CENTRE
    parts_in.append(("eye", geo, faces, r2g, np.zeros((len(r2g), 2)), "eyeball", dirs))
    if with_marker:
        dirs, _, r2g, faces = uv_sphere(8, 12)
        geo = np.zeros((r2g.max() + 1, 3))
        geo[r2g] = dirs * MARKER_RADIUS + MARKER_CENTRE
        parts_in.append(("marker", geo, faces, r2g, np.zeros((len(r2g), 2)), "teeth",
                         np.zeros((len(r2g), 3))))
    if with_lashes:  # a fan-shaped card over the eye: roots on the lid, tips further out
        a = np.radians(np.linspace(-50, 50, 8))
        up = np.array([0.0, 0.6, 0.8])
        spoke = np.sin(a)[:, None] * [1.0, 0.0, 0.0] + np.cos(a)[:, None] * up
        geo = np.concatenate([EYE_CENTRE + 1.1 * EYE_RADIUS * spoke,
                              EYE_CENTRE + 1.5 * EYE_RADIUS * (spoke + [0, 0.3, 0])])
        idx = np.arange(8)
        faces = np.concatenate([np.stack([idx[:-1], idx[1:], idx[1:] + 8], 1),
                                np.stack([idx[:-1], idx[1:] + 8, idx[:-1] + 8], 1)])
        parts_in.append(("lashes", geo, faces, np.arange(16), np.zeros((16, 2)), "lashes",
                         np.zeros((16, 3))))
    positions, faces_all, r2g_all, uv_all, region_all, eye_all, parts = [], [], [], [], [], [], {}
    n_geo = n_render = 0
    for name, geo, faces, r2g, uv, region, eye in parts_in:
        parts[name] = np.arange(n_geo, n_geo + len(geo))
        positions.append(geo)
        faces_all.append(faces + n_render)
        r2g_all.append(r2g + n_geo)
        uv_all.append(uv)
        region_all.append(np.full(len(r2g), REGIONS.index(region), np.uint8))
        eye_all.append(eye)
        n_geo += len(geo)
        n_render += len(r2g)
    faces = np.concatenate(faces_all)
    if reverse_winding:
        faces = faces[:, ::-1]
    topology = RenderTopology(faces=faces, render_to_geo=np.concatenate(r2g_all),
                              uv=np.concatenate(uv_all).astype(np.float32),
                              region=np.concatenate(region_all),
                              eye_coord=np.concatenate(eye_all).astype(np.float32))
    return topology, np.concatenate(positions).astype(np.float32), parts


def make_paint(size=128, *, brows=0.0, lips=0.0):
    """GL-order paint (row 0 = v 0) with a brow band and a lip band on the sphere's front."""
    v, u = np.meshgrid((np.arange(size) + 0.5) / size, (np.arange(size) + 0.5) / size,
                       indexing="ij")
    front = np.minimum(u, 1 - u) < 0.12   # u = 0 (and 1) is the +Z meridian
    paint = np.zeros((size, size, 4), np.uint8)
    paint[..., 0] = (brows * 255 * (front & (np.abs(v - 0.66) < 0.03))).astype(np.uint8)
    paint[..., 1] = (lips * 255 * (front & (np.abs(v - 0.33) < 0.03))).astype(np.uint8)
    return paint


def appearance(**overrides) -> Appearance:
    colors = dict(DEFAULT_COLORS)
    colors["teeth"] = GREEN
    colors.update(overrides)
    return Appearance(colors, make_paint())


def head_camera(view="front", **kw) -> Camera:
    lo, hi = HEAD_CENTRE - [1.2, 1.2, 1.2], HEAD_CENTRE + [1.2, 1.2, 1.2]
    return frame_camera(lo, hi, view=view, **kw)


def greenness(img: np.ndarray) -> np.ndarray:
    """Where the (green) marker shows."""
    rgb = img[..., :3].astype(int)
    return (rgb[..., 1] > rgb[..., 0] + 60) & (rgb[..., 1] > rgb[..., 2] + 60)


def dark(img: np.ndarray, threshold=60) -> np.ndarray:
    return img[..., :3].astype(int).max(-1) < threshold


@pytest.fixture(scope="module")
def scene():
    return build_scene()


@pytest.fixture(scope="module")
def renderer(scene):
    topology, _, _ = scene
    with Renderer(topology, size=96, background=(0.5, 0.5, 0.5)) as r:
        yield r


def test_render_is_nonempty_with_the_right_shape(renderer, scene):
    _, pos, _ = scene
    img = renderer.render(pos, appearance=appearance(), camera=head_camera())
    assert img.shape == (96, 96, 4) and img.dtype == np.uint8
    differs = np.abs(img[..., :3].astype(int) - 128).max(-1) > 8
    assert 0.3 < differs.mean() < 0.95
    skin = img[60, 48, :3].astype(int)  # lower middle of the face: skin, warm
    assert skin[0] > skin[2] + 20


def test_background_colour_where_nothing_is_drawn(scene):
    topology, pos, _ = scene
    with Renderer(topology, size=64, background=(0.2, 0.4, 0.6)) as r:
        img = r.render(pos, appearance=appearance(), camera=head_camera())
    for y, x in ((0, 0), (0, -1), (-1, 0), (-1, -1)):
        assert np.abs(img[y, x].astype(int) - (51, 102, 153, 255)).max() <= 1


@pytest.mark.parametrize("aa_method,antialias", [("msaa", 4), ("ssaa", 2), ("msaa", 1), ("fxaa", 4)])
def test_transparent_background_has_straight_alpha(scene, aa_method, antialias):
    topology, pos, _ = scene
    with Renderer(topology, size=64, background=None, aa_method=aa_method,
                  antialias=antialias) as r:
        img = r.render(pos, appearance=appearance(), camera=head_camera())
    assert (img[[0, 0, -1, -1], [0, -1, 0, -1], 3] == 0).all()
    assert img[32, 32, 3] == 255
    assert (img[img[..., 3] == 0][:, :3] == 0).all()
    edge = (img[..., 3] > 0) & (img[..., 3] < 255)
    if antialias > 1:
        assert edge.any()  # anti-aliased silhouette ...
        # ... whose colours are un-premultiplied: as bright as the skin inside, not darkened
        skin_lum = img[img[..., 3] == 255][:, :3].astype(int).sum(-1)
        edge_lum = img[edge][:, :3].astype(int).sum(-1)
        assert np.median(edge_lum) > 0.5 * np.median(skin_lum)
    else:
        assert not edge.any()


def test_front_view_shows_the_characters_left_on_the_image_right(renderer, scene):
    _, pos, _ = scene
    cam = head_camera("front")
    img = renderer.render(pos, appearance=appearance(), camera=cam)
    green = greenness(img)
    assert green.any()
    cols = np.flatnonzero(green.any(0))
    assert cols.mean() > 48  # +X (the character's left) is on the image's right
    (px, py), = project(cam, [MARKER_CENTRE], 96)[0]
    assert green[int(py), int(min(px, 95))] or green[int(py), int(px) - 2]


def test_profile_left_faces_the_characters_left_side(renderer, scene):
    _, pos, _ = scene
    left = renderer.render(pos, appearance=appearance(), camera=head_camera("profile-left"))
    right = renderer.render(pos, appearance=appearance(), camera=head_camera("profile-right"))
    green = greenness(left)
    assert green.sum() > 30  # the +X marker faces the camera: seen whole, near the centre
    ys, xs = np.nonzero(green)
    assert abs(xs.mean() - 48) < 10 and abs(ys.mean() - 48) < 10
    assert not greenness(right).any()  # from the other side the head hides it
    # The eye (on the face, +Z) appears on the image's LEFT in the left profile: the
    # character faces image-left when we look at their left side.
    cam = head_camera("profile-left")
    (px, _), = project(cam, [EYE_CENTRE + [0, 0, EYE_RADIUS]], 96)[0]
    assert px < 48


def test_geometry_appears_where_the_camera_projects_it(renderer, scene):
    _, pos, _ = scene
    for view in ("front", "three-quarter-left"):
        cam = head_camera(view)
        img = renderer.render(pos, appearance=appearance(), camera=cam)
        green = greenness(img)
        ys, xs = np.nonzero(green)
        (px, py), = project(cam, [MARKER_CENTRE], 96)[0]
        # The visible part of the marker sits around its projected centre.
        assert abs(xs.mean() - px) < 6 and abs(ys.mean() - py) < 6


def test_changing_positions_changes_the_image_only_there(renderer, scene):
    _, pos, parts = scene
    cam = head_camera("front")
    app = appearance()
    before = renderer.render(pos, appearance=app, camera=cam).astype(int)
    moved = pos.copy()
    moved[parts["marker"]] += [0.0, 0.5, 0.0]
    after = renderer.render(moved, appearance=app, camera=cam).astype(int)
    changed = np.abs(after - before).max(-1) > 10
    assert changed.any()
    cols = np.flatnonzero(changed.any(0))
    assert cols.min() > 48  # only around the marker, on the image's right
    green_rows = np.flatnonzero(greenness(after.astype(np.uint8)).any(1))
    old_rows = np.flatnonzero(greenness(before.astype(np.uint8)).any(1))
    assert green_rows.mean() < old_rows.mean() - 3  # up in space is up in the image


def test_rendering_is_deterministic_and_stateless(renderer, scene):
    _, pos, _ = scene
    cam, app = head_camera("front"), appearance()
    first = renderer.render(pos, appearance=app, camera=cam)
    renderer.render(pos * 1.01, appearance=appearance(skin=(0.3, 0.2, 0.1)),
                    camera=head_camera("profile-right"), wrinkle=np.ones(len(pos)))
    again = renderer.render(pos, appearance=app, camera=cam)
    assert np.array_equal(first, again)


def _rotate_y(points, centre, degrees):
    a = math.radians(degrees)
    rot = np.array([[math.cos(a), 0, math.sin(a)], [0, 1, 0], [-math.sin(a), 0, math.cos(a)]])
    return (points - centre) @ rot.T + centre


def test_iris_moves_with_the_eyeball_rotation(scene):
    topology, pos, parts = scene
    cam = frame_camera(EYE_CENTRE - 0.2, EYE_CENTRE + 0.2, view="front")
    app = appearance()
    with Renderer(topology, size=96) as r:
        straight = r.render(pos, appearance=app, camera=cam)
        turned = pos.copy()
        # Positive rotation about +Y turns +Z (the gaze) toward +X: the character's left,
        # which is the image's right in the front view.
        turned[parts["eye"]] = _rotate_y(pos[parts["eye"]], EYE_CENTRE, 25.0)
        looking_left = r.render(turned, appearance=app, camera=cam)
    x0 = np.nonzero(dark(straight))[1].mean()
    x1 = np.nonzero(dark(looking_left))[1].mean()
    assert abs(x0 - 48) < 4  # pupil and iris centred when looking straight
    assert x1 > x0 + 8


def test_iris_and_pupil_sizes(scene):
    topology, pos, _ = scene
    cam = frame_camera(EYE_CENTRE - 0.2, EYE_CENTRE + 0.2, view="front", projection="orthographic")
    app = appearance(iris=(0.1, 0.3, 0.8))
    with Renderer(topology, size=200) as r:
        img = r.render(pos, appearance=app, camera=cam).astype(int)
    px_per_dm = 200 / (2 * cam.half_height)
    pupil = dark(img.astype(np.uint8), 25)
    # (+12: the iris's rim fades into the white and its top lies in the socket's shade, so its
    # outermost, darker pixels are less blue than its middle.)
    blue = (img[..., 2] > img[..., 0] + 12) | pupil
    r_pupil = math.sqrt(pupil.sum() / math.pi) / px_per_dm / EYE_RADIUS
    r_iris = math.sqrt(blue.sum() / math.pi) / px_per_dm / EYE_RADIUS
    assert 0.08 < r_pupil < 0.17   # a 4 mm pupil on hm08's 1.59 cm-radius eye = 0.13
    assert 0.31 < r_iris < 0.42, r_iris    # an 11.7 mm iris on it = 0.368


def test_wrinkle_darkens_the_skin(renderer, scene):
    _, pos, parts = scene
    cam, app = head_camera("front"), appearance()
    plain = renderer.render(pos, appearance=app, camera=cam).astype(int)
    zero = renderer.render(pos, appearance=app, camera=cam, wrinkle=np.zeros(len(pos)))
    assert np.array_equal(plain, zero)
    wrinkle = np.zeros(len(pos), np.float32)
    head = parts["head"]
    wrinkle[head] = np.clip((pos[head, 1] - 15.3) * 4, 0, 1)  # the upper face, a gradient
    creased = renderer.render(pos, appearance=app, camera=cam, wrinkle=wrinkle).astype(int)
    upper = slice(10, 40)
    # (Session 25: the folds are relief, lit on one flank and shaded in their valleys, and no
    # longer a stain over the whole compressed skin: 3.6 % darker here, not 5 % and more.)
    assert creased[upper, 30:66, :3].sum() < 0.98 * plain[upper, 30:66, :3].sum()
    lower = slice(70, 85)
    assert np.abs(creased[lower, 35:60] - plain[lower, 35:60]).max() <= 2


def test_creases_run_where_the_crease_phase_says(renderer, scene):
    """An engine's own crease phase decides the furrows' direction: a phase rising with height
    draws horizontal lines (the image changes down a column), one rising across draws vertical ones."""
    _, pos, parts = scene
    cam, app = head_camera("front"), appearance()
    wrinkle = np.zeros(len(pos), np.float32)
    wrinkle[parts["head"]] = 1.0
    spacing = 0.2  # dm between furrows: about ten pixels apart in this small render

    def grey(phase):
        img = renderer.render(pos, appearance=app, camera=cam, wrinkle=wrinkle, crease_phase=phase)
        return img.astype(float)[15:45, 35:60, :3].mean(2)

    # Lines survive averaging along them and vanish averaging across them: the profile down
    # the image (each row's mean) carries horizontal lines, the profile across it vertical ones.
    # (Folds vary in depth along their length and are wavy, so single rows are noisy; the
    # render without creases takes out the skin's mottle, second differences the slow shading.)
    plain = renderer.render(pos, appearance=app, camera=cam).astype(float)[15:45, 35:60, :3].mean(2)
    images = {axis: grey(pos[:, axis] / spacing) - plain for axis in (0, 1)}
    down = {axis: np.abs(np.diff(img.mean(1), 2)).mean() for axis, img in images.items()}
    across = {axis: np.abs(np.diff(img.mean(0), 2)).mean() for axis, img in images.items()}
    assert down[1] > 1.5 * across[1]   # phase rises with height: horizontal lines
    assert across[0] > 1.5 * down[0]   # phase rises across: vertical lines
    with pytest.raises(ValueError, match="crease_phase must have one value per geometry vertex"):
        renderer.render(pos, appearance=app, camera=cam, wrinkle=wrinkle, crease_phase=np.zeros(3))


def test_occlusion_darkens(renderer, scene):
    _, pos, _ = scene
    cam, app = head_camera("front"), appearance()
    open_sky = renderer.render(pos, appearance=app, camera=cam, occlusion=np.ones(len(pos)))
    plain = renderer.render(pos, appearance=app, camera=cam)
    assert np.array_equal(open_sky, plain)
    shut = renderer.render(pos, appearance=app, camera=cam, occlusion=np.full(len(pos), 0.2))
    assert shut[..., :3].astype(int).sum() < plain[..., :3].astype(int).sum() - 1000


def test_paint_masks_colour_the_skin(renderer, scene):
    _, pos, _ = scene
    cam = head_camera("front")
    colors = dict(DEFAULT_COLORS, teeth=GREEN, lips=(0.9, 0.0, 0.0), brows=(0.0, 0.0, 0.0))
    plain = renderer.render(pos, appearance=Appearance(colors, make_paint()), camera=cam)
    painted = renderer.render(pos, appearance=Appearance(colors, make_paint(brows=1, lips=1)),
                              camera=cam)
    diff = np.abs(painted.astype(int) - plain.astype(int)).max(-1) > 20
    rows = np.flatnonzero(diff.any(1))
    assert rows.size and rows.min() < 48 < rows.max()  # brows above, lips below the middle
    upper, lower = diff.copy(), diff.copy()
    upper[48:], lower[:48] = False, False
    p, q = painted[..., :3].astype(int), plain[..., :3].astype(int)
    assert p[upper].sum() < 0.8 * q[upper].sum()                       # dark brows
    assert (p[lower][:, 0] - p[lower][:, 1]).mean() > (q[lower][:, 0] - q[lower][:, 1]).mean() + 30


def test_lashes_are_drawn_thin_and_dark():
    topology, pos, parts = build_scene(with_lashes=True)
    cam = frame_camera(EYE_CENTRE - 0.25, EYE_CENTRE + 0.25, view="front")
    with Renderer(topology, size=96) as r:
        img = r.render(pos, appearance=appearance(), camera=cam)
        bare = r.render(pos, appearance=appearance(lashes=(0.95, 0.95, 0.95)), camera=cam)
    # The lash card covers some pixels partly: they differ with the lash colour but, as
    # strands, do not cover a solid block.
    diff = np.abs(img.astype(int) - bare.astype(int)).max(-1)
    assert (diff > 20).sum() > 10
    lash_coord = lash_coordinates(pos, region_components(topology, "eyeball"),
                                  region_components(topology, "lashes"))
    order = np.argsort(np.concatenate(region_components(topology, "lashes")))
    lash_coord = lash_coord[order]  # back to geometry order: 8 roots, then 8 tips
    assert np.allclose(lash_coord[:8], 0, atol=1e-5) and (lash_coord[8:] > 0.85).all()


def test_reversed_winding_renders_the_same(scene):
    topology, pos, _ = scene
    flipped, _, _ = build_scene(reverse_winding=True)
    cam, app = head_camera("three-quarter-left"), appearance()
    with Renderer(topology, size=64) as a, Renderer(flipped, size=64) as b:
        img_a = a.render(pos, appearance=app, camera=cam).astype(int)
        img_b = b.render(pos, appearance=app, camera=cam).astype(int)
    assert np.abs(img_a - img_b).max() <= 2


def test_without_culling_the_image_is_the_same(scene):
    topology, pos, _ = scene
    cam, app = head_camera("front"), appearance()
    with Renderer(topology, size=64) as a, Renderer(topology, size=64, cull_backfaces=False) as b:
        diff = np.abs(a.render(pos, appearance=app, camera=cam).astype(int)
                      - b.render(pos, appearance=app, camera=cam).astype(int)).max(-1)
    assert (diff > 2).sum() <= 8  # a few silhouette samples may differ, nothing else


def test_ssaa_and_msaa_agree(scene):
    topology, pos, _ = scene
    cam, app = head_camera("front"), appearance()
    with Renderer(topology, size=64, aa_method="ssaa", antialias=2) as a, \
            Renderer(topology, size=64, aa_method="msaa", antialias=4) as b:
        diff = np.abs(a.render(pos, appearance=app, camera=cam).astype(int)
                      - b.render(pos, appearance=app, camera=cam).astype(int))
    assert diff.mean() < 2.0


@pytest.mark.parametrize("size,shape", [(40, (40, 40, 4)), ((80, 48), (48, 80, 4))])
def test_size_is_respected(scene, size, shape):
    topology, pos, _ = scene
    with Renderer(topology, size=size) as r:
        img = r.render(pos, appearance=appearance(), camera=head_camera(aspect=shape[1] / shape[0]))
    assert img.shape == shape
    assert r.size == (shape[1], shape[0])


def test_close_is_idempotent_and_render_after_close_fails(scene):
    topology, pos, _ = scene
    r = Renderer(topology, size=32)
    r.render(pos, appearance=appearance(), camera=head_camera())
    r.close()
    r.close()
    assert r.closed
    with pytest.raises(RenderError, match="closed"):
        r.render(pos, appearance=appearance(), camera=head_camera())
    with Renderer(topology, size=32) as r2:
        assert not r2.closed
    assert r2.closed


def test_render_rejects_bad_inputs(renderer, scene):
    _, pos, _ = scene
    cam, app = head_camera(), appearance()
    with pytest.raises(ValueError, match=r"positions must be \(N_geo, 3\)"):
        renderer.render(pos[:10], appearance=app, camera=cam)
    with pytest.raises(ValueError, match="NaN"):
        renderer.render(np.full_like(pos, np.nan), appearance=app, camera=cam)
    with pytest.raises(ValueError, match="wrinkle must have one value per geometry vertex"):
        renderer.render(pos, appearance=app, camera=cam, wrinkle=np.zeros(3))
    with pytest.raises(ValueError, match="occlusion must have one value"):
        renderer.render(pos, appearance=app, camera=cam, occlusion=np.zeros(3))
    with pytest.raises(TypeError, match="camera must be a Camera"):
        renderer.render(pos, appearance=app, camera="front")


def test_appearance_and_topology_validation(scene):
    topology, _, _ = scene
    with pytest.raises(ValueError, match=r"missing \['cheek'\]"):
        Appearance({k: v for k, v in DEFAULT_COLORS.items() if k != "cheek"})
    with pytest.raises(ValueError, match=r"unknown \['skn'\]"):
        Appearance(dict(DEFAULT_COLORS, skn=(1, 1, 1)))
    with pytest.raises(ValueError, match=r"colors\['skin'\] must be 3 numbers in \[0, 1\]"):
        Appearance(dict(DEFAULT_COLORS, skin=(255, 200, 180)))
    with pytest.raises(ValueError, match="paint must be an"):
        Appearance(DEFAULT_COLORS, np.zeros((8, 8, 3), np.uint8))
    with pytest.raises(ValueError, match="uv must have shape"):
        RenderTopology(topology.faces, topology.render_to_geo, topology.uv[:5], topology.region,
                       topology.eye_coord)
    with pytest.raises(ValueError, match="faces index render vertex"):
        RenderTopology(topology.faces + 10**6, topology.render_to_geo, topology.uv,
                       topology.region, topology.eye_coord)
    with pytest.raises(ValueError, match="region values must index REGIONS"):
        RenderTopology(topology.faces, topology.render_to_geo, topology.uv,
                       np.full_like(topology.region, 9), topology.eye_coord)
    assert set(COLOR_NAMES) == set(DEFAULT_COLORS)
    with pytest.raises(ValueError, match="aa_method must be one of"):
        Renderer(topology, aa_method="taa")
    with pytest.raises(ValueError, match="background must be"):
        Renderer(topology, background=(300, 0, 0))


# ---------------------------------------------------------------- pure helpers (no GL)

def test_vertex_normals_are_radial_on_a_sphere_and_match_add_at():
    dirs, _, r2g, faces = uv_sphere(12, 16)
    geo = np.zeros((r2g.max() + 1, 3))
    geo[r2g] = dirs
    geo_faces = r2g[faces]
    normals = vertex_normals(geo, geo_faces)
    assert np.allclose(np.linalg.norm(normals, axis=1), 1, atol=1e-5)
    assert (np.einsum("ij,ij->i", normals, geo) > 0.99).all()
    # Reference: np.add.at over face normals.
    p = geo.astype(np.float32)
    fn = np.cross(p[geo_faces[:, 1]] - p[geo_faces[:, 0]], p[geo_faces[:, 2]] - p[geo_faces[:, 0]])
    ref = np.zeros_like(p)
    for k in range(3):
        np.add.at(ref, geo_faces[:, k], fn)
    ref /= np.linalg.norm(ref, axis=1, keepdims=True)
    assert np.allclose(normals, ref, atol=1e-5)
    op = normal_operator(geo_faces, len(geo))
    assert op.shape == (len(geo), len(faces))
    assert np.allclose(np.asarray(op.sum(axis=0)).ravel(), 3)  # each face feeds 3 corners


def test_seam_vertices_share_their_normal():
    """Render vertices split at the UV seam get the same normal (it lives on the geometry)."""
    dirs, uv, r2g, faces = uv_sphere(8, 12)
    geo = np.zeros((r2g.max() + 1, 3))
    geo[r2g] = dirs * [1.0, 1.3, 0.8]
    normals = vertex_normals(geo, r2g[faces])[r2g]
    seam = np.flatnonzero(uv[:, 0] == 0)
    twin = np.flatnonzero(uv[:, 0] == 1)
    assert np.allclose(normals[seam], normals[twin])


def test_scattered_normals_soften_a_fold_and_leave_a_plane_alone():
    """The normal subsurface light sees (facsim.render.geometry.scattered_normals) is averaged over
    neighbours: across a sharp crease it tilts far less than the surface's own; on a plane it is
    the plane's."""
    from facsim.render.geometry import scattered_normals, smoothing_operator

    n = 9
    x, y = np.meshgrid(np.arange(n, dtype=float), np.arange(n, dtype=float))
    index = np.arange(n * n).reshape(n, n)
    a, b, c, d = index[:-1, :-1].ravel(), index[:-1, 1:].ravel(), index[1:, :-1].ravel(), index[1:, 1:].ravel()
    faces = np.concatenate([np.c_[a, b, d], np.c_[a, d, c]])
    op = smoothing_operator(faces, n * n)
    flat = np.c_[x.ravel(), y.ravel(), np.zeros(n * n)]
    normals = vertex_normals(flat, faces)
    assert np.allclose(scattered_normals(normals, op), normals, atol=1e-6)
    crease = flat.copy()
    crease[:, 2] = -np.abs(x.ravel() - 4)   # a ridge along x = 4, flanks at 45 degrees
    normals = vertex_normals(crease, faces)
    scattered = scattered_normals(normals, op)
    assert np.allclose(np.linalg.norm(scattered, axis=1), 1, atol=1e-5)
    beside = (np.abs(x.ravel() - 4) == 1) & (y.ravel() > 1) & (y.ravel() < n - 2)
    assert (normals[beside, 2] < 0.75).all()            # the flanks face 45 degrees away ...
    assert (scattered[beside, 2] > normals[beside, 2] + 0.05).all()   # ... scattered light sees them flatter


def test_unused_vertices_get_a_valid_normal():
    normals = vertex_normals(np.zeros((4, 3)), np.array([[0, 1, 2]]))
    assert np.allclose(np.linalg.norm(normals, axis=1), 1)


def test_srgb_to_linear():
    assert srgb_to_linear(0.0) == 0.0 and abs(srgb_to_linear(1.0) - 1.0) < 1e-12
    assert abs(srgb_to_linear(0.5) - 0.21404) < 1e-4


def test_sphere_centre_and_components(scene):
    topology, pos, parts = scene
    eyes = region_components(topology, "eyeball")
    assert len(eyes) == 1 and set(eyes[0]) == set(parts["eye"])
    assert np.allclose(sphere_centre(pos[eyes[0]]), EYE_CENTRE, atol=1e-4)
    assert region_components(topology, "tongue") == []


def test_brow_frame_default_matches_the_head_paint_box():
    from facsim.head.assets import PAINT_UV_BOX

    assert np.allclose(brow_uv_frame(PAINT_UV_BOX), DEFAULT_BROW_UV_FRAME)


def test_bake_occlusion_darkens_hidden_places():
    closed_topology, pos, parts = build_scene(with_marker=False)
    occ = bake_occlusion(closed_topology, pos, directions=48, resolution=128)
    assert occ.shape == (len(pos),) and occ.dtype == np.float32
    assert ((0 <= occ) & (occ <= 1)).all()
    head = parts["head"]
    assert np.median(occ[head]) > 0.85       # a convex head is mostly open
    eye_back = parts["eye"][np.argmin(pos[parts["eye"], 2])]
    assert occ[eye_back] < 0.3                # the back of the eye is buried in the head


def test_write_png_round_trips_and_leaves_no_temp_files(tmp_path):
    from PIL import Image

    img = np.random.default_rng(0).integers(0, 256, (12, 20, 4), dtype=np.uint8)
    out = write_png(tmp_path / "x.png", img)
    assert np.array_equal(np.asarray(Image.open(out)), img)
    assert [p.name for p in tmp_path.iterdir()] == ["x.png"]
    with pytest.raises(ValueError, match="image must be"):
        write_png(tmp_path / "y.png", img.astype(np.float32))
    assert [p.name for p in tmp_path.iterdir()] == ["x.png"]


def test_lighting_rig_is_camera_relative():
    rig = Lighting()
    front = rig.world_uniforms(Camera(yaw=0))
    side = rig.world_uniforms(Camera(yaw=90))
    # The key comes from the camera's upper left: world -X seen from the front, and world
    # +Z (the camera's left) seen from +X.
    assert front["u_key_dir"][0] < 0 and side["u_key_dir"][2] > 0
    assert np.isclose(np.linalg.norm(front["u_key_dir"]), 1)


def test_crease_phase_runs_across_the_wrinkle_contours():
    """A wrinkle band varying along v on a flat sheet: creases run along u."""
    n = 21
    u, v = np.meshgrid(np.linspace(0, 1, n), np.linspace(0, 1, n))
    uv = np.stack([u.ravel(), v.ravel()], 1)
    positions = np.c_[uv * [2.0, 1.0], np.zeros(n * n)]   # 2 dm wide, 1 dm tall: anisotropic
    ids = np.arange(n * n).reshape(n, n)
    a, b, c, d = ids[:-1, :-1], ids[:-1, 1:], ids[1:, 1:], ids[1:, :-1]
    faces = np.concatenate([np.stack([a, b, c], -1).reshape(-1, 3),
                            np.stack([a, c, d], -1).reshape(-1, 3)])
    wrinkle = np.clip(1 - np.abs(uv[:, 1] - 0.5) / 0.4, 0, 1)
    phase = crease_phase(positions, uv, faces, wrinkle).reshape(n, n)
    inner = phase[3:-3, 3:-3]
    assert np.allclose(inner, inner[:, :1], atol=1e-6)            # constant along u
    assert np.allclose(inner[:, 0], np.abs(v[3:-3, 0] - 0.5) * 1.0 * CREASES_PER_DM, atol=1e-5)  # v in dm, in spacings
    assert (crease_phase(positions, uv, faces, np.zeros(n * n)) == 0).all()
