"""Eyes as a viewer sees them (issue 13): iris size, off-white sclera, a catch-light on the cornea.

The eye's pixels are found by rendering the same face again with a loud sclera or iris colour
and keeping the pixels that changed.
"""
from __future__ import annotations

import numpy as np
import pytest

from conftest import repo_module

from facsim.face import Face
from facsim.head.character import preset

SIZE = 320


def _render(character) -> np.ndarray:
    with Face(character) as face:
        return face.render("", size=SIZE, antialias=1, background=(1.0, 1.0, 1.0))[..., :3].astype(int)


@pytest.fixture(scope="module")
def eye_pixels():
    ava = preset("ava").with_(symmetric=True)   # both eyes alike: the shading, not ava's own asymmetry
    normal = _render(ava)
    green_sclera = _render(ava.with_(colors={**ava.colors, "sclera": "#00ff00"}))
    # (White, not a hue: the renderer greys the iris's colour, which would blunt a red marker.)
    white_iris = _render(ava.with_(colors={**ava.colors, "iris": "#ffffff"}))
    iris = np.abs(white_iris - normal).sum(-1) > 60
    sclera = (np.abs(green_sclera - normal).sum(-1) > 60) & ~iris
    return normal, sclera, iris


def _luminance(rgb):
    return rgb @ np.array([0.2126, 0.7152, 0.0722])


def test_iris_is_about_11_7_mm_across(eye_pixels):
    _, _, iris = eye_pixels
    half = SIZE // 2
    widths, centres = [], []
    for side in (slice(0, half), slice(half, SIZE)):
        cols = np.flatnonzero(iris[:, side].any(axis=0)) + side.start
        widths.append(cols.max() - cols.min() + 1)
        centres.append(np.nonzero(iris[:, side])[1].mean() + side.start)
    # hm08's eye centres are 57.6 mm apart: an 11.7-mm iris is about a fifth of that
    ratio = np.mean(widths) / (centres[1] - centres[0])
    assert 0.17 < ratio < 0.24, ratio


def test_sclera_is_off_white_and_redder_toward_the_corners(eye_pixels):
    image, sclera, iris = eye_pixels
    lum = _luminance(image[sclera])
    assert 150 < np.percentile(lum, 95) < 215  # not paper white (it was 229), not grey
    assert (image[sclera][:, 2] < image[sclera][:, 0]).mean() > 0.8  # warm, not blue-white
    redness = image[..., 0] - image[..., 1]
    ys, xs = np.nonzero(sclera)
    iris_x = np.nonzero(iris)[1]
    for right_half in (False, True):
        side = (xs >= SIZE // 2) == right_half
        centre = iris_x[(iris_x >= SIZE // 2) == right_half].mean()
        d = np.abs(xs[side] - centre)
        far, near = d > np.percentile(d, 75), d < np.percentile(d, 25)
        assert redness[ys[side][far], xs[side][far]].mean() > redness[ys[side][near], xs[side][near]].mean() + 3

def test_a_catch_light_sits_on_the_iris(eye_pixels):
    image, _, iris = eye_pixels
    lum_iris = _luminance(image[iris])
    assert lum_iris.max() > np.median(lum_iris) + 60  # a small bright catch-light ...
    assert (lum_iris > np.median(lum_iris) + 60).mean() < 0.05  # ... not a glossy sheet


@pytest.mark.parametrize("name", ["amara", "mei"])
def test_each_eye_shows_one_catch_light(name):
    """Issue 13: two large reflections (key and fill) read as glossy doll's eyes, and under
    lower-set lids the key's lay hidden (mei showed none). One small catch-light per eye, on the
    cornea (iris or pupil)."""
    from scipy import ndimage

    character = preset(name)
    image = _render(character)
    marked = _render(character.with_(colors={**character.colors, "iris": "#ff0000", "pupil": "#ff0000"}))
    # (Filled: a catch-light near white is near white in both renders, and the hole it left
    # split its rim in two.)
    cornea = ndimage.binary_fill_holes(np.abs(marked - image).sum(-1) > 60)
    bright = cornea & (_luminance(image) > 120)
    for side in (slice(0, SIZE // 2), slice(SIZE // 2, SIZE)):
        _, count = ndimage.label(bright[:, side], structure=np.ones((3, 3)))
        assert count == 1, count
    # (Its size: test_the_catch_light_is_a_small_bright_reflection_not_a_sticker, at 768 px, in
    # mm². Here, at 320, a catch-light about a pixel across spreads over its neighbours.)


def test_the_upper_lid_and_lashes_shade_the_sclera_below_them(eye_pixels):
    """Beside the iris, the sclera's top rows lie in the lash line's shadow: dark under the lid,
    brightening toward the middle (it was an evenly lit, glassy white to the lid's edge)."""
    image, sclera, iris = eye_pixels
    lum = _luminance(image)
    for side in (slice(0, SIZE // 2), slice(SIZE // 2, SIZE)):
        mask = np.zeros_like(sclera)
        mask[:, side] = sclera[:, side]
        ys, xs = np.nonzero(mask)
        beside = np.abs(xs - (np.nonzero(iris[:, side])[1].mean() + side.start)) < SIZE / 25
        rows = [lum[y, xs[beside][ys[beside] == y]].mean() for y in range(ys[beside].min(), ys[beside].max() + 1)]
        assert np.mean(rows[:3]) < 0.65 * max(rows), rows


def test_a_young_adults_pupil_is_a_studio_portraits(eye_pixels):
    """Under studio light a young adult's pupil is ~3.7 mm (4.2 seen through the cornea) of an
    11.7-mm iris: a 4-mm pupil left ava's iris a thin ring round a dark disc, a doll's eye (its
    width 0.46 of the iris's at 512 px, now 0.37)."""
    ava = preset("ava").with_(symmetric=True)
    with Face(ava) as face:
        normal = face.render("", size=512, antialias=1, background=(1.0, 1.0, 1.0))[..., :3].astype(int)
    with Face(ava.with_(colors={**ava.colors, "pupil": "#ffffff"})) as face:
        marked = face.render("", size=512, antialias=1, background=(1.0, 1.0, 1.0))[..., :3].astype(int)
    with Face(ava.with_(colors={**ava.colors, "pupil": "#ffffff", "iris": "#ffffff"})) as face:
        cornea = face.render("", size=512, antialias=1, background=(1.0, 1.0, 1.0))[..., :3].astype(int)
    pupil = np.abs(marked - normal).sum(-1) > 60
    iris = np.abs(cornea - normal).sum(-1) > 60
    for side in (slice(0, 256), slice(256, 512)):
        width = lambda mask: np.ptp(np.flatnonzero(mask[:, side].any(axis=0))) + 1   # noqa: E731
        assert 0.28 < width(pupil) / width(iris) < 0.42


@pytest.mark.parametrize("mirrored", [False, True])
def test_eye_rotation_recovers_the_eyes_turn(mirrored):
    """The cornea's refraction is computed in the eye's own frame: the renderer recovers each
    eye's turn from its vertices (a mirrored frame maps by a reflection)."""
    from scipy.spatial.transform import Rotation

    from facsim.render.geometry import eye_rotation, sphere_directions

    coords = sphere_directions(200)
    turn = Rotation.from_euler("yx", [30.0, -12.0], degrees=True).as_matrix()
    frame = np.diag([-1.0, 1.0, 1.0]) if mirrored else np.eye(3)
    now = 0.16 * coords @ (turn @ frame).T
    np.testing.assert_allclose(eye_rotation(coords, now), turn @ frame, atol=1e-9)


@pytest.mark.parametrize("name", ["amara", "mei"])
def test_the_catch_light_is_a_small_bright_reflection_not_a_sticker(name):
    """The key's catch-light is the softbox's mirror image in the cornea: for a ~30-cm box at
    1.2 m on a 7.8-mm cornea about 0.8 x 0.7 mm, and, as the image of a light source, brighter
    than any lit surface around it. As a grey plate (peak luminance 150-185, 1.7-2.3 mm² over
    half of it at 768 px) it sat on the iris like a sticker (issue 13, "glassy, doll-like eyes")."""
    from scipy import ndimage

    size = 768
    character = preset(name)
    with Face(character) as face:
        image = face.render("", size=size, antialias=1, background=(1.0, 1.0, 1.0))[..., :3].astype(int)
    with Face(character.with_(colors={**character.colors, "iris": "#ff0000", "pupil": "#ff0000"})) as face:
        marked = face.render("", size=size, antialias=1, background=(1.0, 1.0, 1.0))[..., :3].astype(int)
    # (Filled: a catch-light near white is near white in both renders.)
    cornea = ndimage.binary_fill_holes(np.abs(marked - image).sum(-1) > 60)
    lum = _luminance(image)
    for side in (slice(0, size // 2), slice(size // 2, size)):
        eye = np.zeros_like(cornea)
        eye[:, side] = cornea[:, side]
        px_per_mm = (np.ptp(np.flatnonzero(eye.any(axis=0))) + 1) / 11.7
        peak, iris = lum[eye].max(), np.median(lum[eye])
        core = eye & (lum > (peak + iris) / 2)
        assert peak > 200, peak
        assert core.sum() / px_per_mm ** 2 < 1.4, core.sum() / px_per_mm ** 2


def test_the_catch_light_lies_on_the_iris_clear_of_the_pupil():
    """The key (to the image's left and above) is mirrored on the cornea at about 10 o'clock,
    half-way out across the iris, with iris between it and the pupil, as in studio portraits.
    Level with the pupil's centre and ~2 mm out it sat on the pupil's rim (0-0.3 mm from it on
    ava and mei at 768 px, 9f8b92e), half on the black disc: the painted highlight of a doll's
    eye (issue 13, "glassy, doll eyes")."""
    from scipy import ndimage

    size = 768
    ava = preset("ava")
    renders = {}
    for key, colours in (("normal", {}), ("cornea", {"iris": "#ff0000", "pupil": "#ff0000"}), ("pupil", {"pupil": "#00ff00"})):
        with Face(ava.with_(colors={**ava.colors, **colours})) as face:
            renders[key] = face.render("", size=size, antialias=1, background=(1.0, 1.0, 1.0))[..., :3].astype(int)
    image = renders["normal"]
    # (Filled: a catch-light near white is near white in both renders.)
    cornea = ndimage.binary_fill_holes(np.abs(renders["cornea"] - image).sum(-1) > 60)
    pupil = ndimage.binary_fill_holes(np.abs(renders["pupil"] - image).sum(-1) > 60)
    lum = _luminance(image)
    for side in (slice(0, size // 2), slice(size // 2, size)):
        eye, own_pupil = np.zeros_like(cornea), np.zeros_like(pupil)
        eye[:, side], own_pupil[:, side] = cornea[:, side], pupil[:, side]
        px_per_mm = (np.ptp(np.flatnonzero(eye.any(axis=0))) + 1) / 11.7
        core = eye & (lum > (lum[eye].max() + np.median(lum[eye])) / 2)
        gap = ndimage.distance_transform_edt(~own_pupil)[core].min() / px_per_mm
        (cy, cx), (py, px) = (np.mean(np.nonzero(mask), axis=1) for mask in (core, own_pupil))
        assert gap > 0.45, gap                          # iris between it and the pupil
        assert (cx - px) / px_per_mm < -2.5             # on the key's side
        assert (py - cy) / px_per_mm > 0.2              # above the pupil's centre


@pytest.mark.parametrize("name", ["george", "kwame"])
def test_a_relaxed_or_hooded_lid_leaves_the_catch_light_in_view(name):
    """At rest the upper lid covers 2 mm or more of the iris's top (lids.yaml), and on hooded
    eyes reaches the pupil: the reflection of a key ~20 degrees above the eyes lay under it, and
    george's, kwame's, liam's and noah's eyes showed no catch-light at 448² (dead eyes). The
    cornea mirrors the softbox's lower part, near the eyes' level, as in studio portraits.
    (With the default 4x MSAA: a catch-light about a pixel across falls between single samples.)"""
    from scipy import ndimage

    size = 448
    character = preset(name)
    renders = {}
    for key, colors in (("normal", {}), ("cornea", {"iris": "#ff0000", "pupil": "#ff0000"}), ("sclera", {"sclera": "#00ff00"})):
        with Face(character.with_(colors={**character.colors, **colors})) as face:
            renders[key] = face.render("", size=size, antialias=4, background=(1.0, 1.0, 1.0))[..., :3].astype(int)
    image = renders["normal"]
    sclera = np.abs(renders["sclera"] - image).sum(-1) > 60
    # (Grown by two pixels, less the white: a catch-light is near white in both renders, and at
    # the lid's margin it mixes with the lashes: no hole in the cornea's mask.)
    cornea = ndimage.binary_dilation(np.abs(renders["cornea"] - image).sum(-1) > 60, iterations=2) & ~sclera
    lum = _luminance(image)
    peaks = [lum[:, side][cornea[:, side]].max() for side in (slice(0, size // 2), slice(size // 2, size))]
    assert min(peaks) > 165, peaks



def test_the_two_irises_are_not_one_pattern_twice():
    """Two eyes of one person share a colour, not a pattern: one noise drew both irises, the
    right a copy of the left (their fine detail correlated 0.78 on a symmetric face at 768 px;
    issue 13, "glassy, doll eyes"). Neither a copy nor a mirror image now (0.59 at most).
    The iris's own pattern: a render with a white iris less one with a black iris (the light
    on it times its pattern; the catch-light and the sclera cancel), high-passed."""
    from scipy import ndimage

    size = 768
    ava = preset("ava").with_(symmetric=True)
    renders = []
    for colour in ("#ffffff", "#000000"):
        with Face(ava.with_(colors={**ava.colors, "iris": colour})) as face:
            renders.append(face.render("", size=size, antialias=1, background=(1.0, 1.0, 1.0))[..., :3].astype(float))
    pattern = _luminance(renders[0] - renders[1])
    iris = pattern > 20
    detail = pattern - ndimage.gaussian_filter(pattern, 1.0)
    inner = ndimage.binary_erosion(iris, iterations=2)   # (not the pupil's nor the limbus's edge)
    reach = size // 30
    crops = []
    for side in (slice(0, size // 2), slice(size // 2, size)):
        eye = np.zeros_like(iris)
        eye[:, side] = iris[:, side]
        ys, xs = np.nonzero(eye)
        cy, cx = int(round(ys.mean())), int(round((xs.min() + xs.max()) / 2))
        window = (slice(cy - reach, cy + reach + 1), slice(cx - reach, cx + reach + 1))
        crops.append((detail[window], inner[window]))
    (left, left_in), (right, right_in) = crops
    for flip in (False, True):
        other, other_in = (right[:, ::-1], right_in[:, ::-1]) if flip else (right, right_in)
        best = -1.0
        for dy in range(-2, 3):      # (the two eyes' centres are found to a pixel or so)
            for dx in range(-2, 3):
                shifted, shifted_in = (np.roll(np.roll(a, dy, 0), dx, 1) for a in (other, other_in))
                both = left_in & shifted_in
                best = max(best, np.corrcoef(left[both], shifted[both])[0, 1])
        assert best < 0.7, (flip, best)


def test_at_448_px_the_iris_is_streaked_not_a_target():
    """At the blind review's size (448 px) an iris is ~22 px across: its fibres have faded into
    their mean, and what is left must still read as a streaked, mottled iris. On 9f8b92e its
    ciliary zone varied by 7-8 % of its light (ava) and a darker pupillary zone ringed the pupil
    (0.91-0.92 of the ciliary zone's light): a smooth disc with the rings of a target, glass
    (issue 13, "glassy eyes"). Measured on the lower half, clear of the lid's shade and the
    catch-light."""
    from scipy import ndimage

    size = 448
    ava = preset("ava").with_(symmetric=True)
    renders = {}
    for key, colours in (("normal", {}), ("iris", {"iris": "#ff0000"}), ("pupil", {"pupil": "#00ff00"})):
        with Face(ava.with_(colors={**ava.colors, **colours})) as face:
            renders[key] = face.render("", size=size, background=(1.0, 1.0, 1.0))[..., :3].astype(float)
    image = renders["normal"]
    iris = ndimage.binary_erosion(np.abs(renders["iris"] - image).sum(-1) > 60)   # (not its anti-aliased rim)
    pupil = ndimage.binary_fill_holes(np.abs(renders["pupil"] - image).sum(-1) > 60)
    figures = repo_module("scripts/eyes_mouth_figures.py")   # its --iris figures: the same zones
    lum = _luminance(image)
    spreads = []
    for eye, own_pupil in figures.per_eye(size, iris, pupil):
        ciliary, pupillary = figures.iris_zones(lum, eye, own_pupil)
        spreads.append(ciliary.std() / ciliary.mean())
        assert pupillary.mean() / ciliary.mean() > 0.94
    assert np.mean(spreads) > 0.095, spreads


def test_the_rim_of_a_raised_upper_lid_is_skin_not_a_teal_band():
    """Where 5 raises the upper lid (fear, 1+2+4+5+20+26) its rim over the eyeball faces the key
    while the normal averaged over a centimetre runs down into the socket; red light, which sees
    the averaged normal most, lost most of the key there and the strip drew teal-grey (george at
    1024 px: 91 bright pixels greener than red within 8 px of the eye's opening), a glassy rim
    along the lid. Light that has come through skin is at least as red as it went in."""
    from scipy import ndimage

    size = 1024
    george = preset("george")
    renders = []
    for colours in ({}, {"sclera": "#00ff00"}, {"iris": "#ff0000", "pupil": "#ff0000"}):
        with Face(george.with_(colors={**george.colors, **colours})) as face:
            renders.append(face.render("1+2+4+5+20+26", size=size, antialias=1,
                                       background=(1.0, 1.0, 1.0))[..., :3].astype(int))
    image = renders[0]
    eye = (np.abs(renders[1] - image).sum(-1) > 60) | (np.abs(renders[2] - image).sum(-1) > 60)
    near = ndimage.binary_dilation(eye, iterations=8) & ~eye
    teal = near & (image[..., 1] > image[..., 0] + 2) & (image.sum(-1) > 200)
    assert teal.sum() < 10, teal.sum()


@pytest.mark.parametrize("name", ["liam", "kwame"])
def test_the_white_that_5_bares_above_the_iris_lies_in_the_lids_shade(name):
    """In photographs of surprise the white above the iris lies under the raised lid's shadow and
    its lashes', darker than the white beside the iris. Lit to 0.85-0.88 of that white (liam's and
    kwame's surprise, 1+2+5+26, at 512 px), the eye read as a lit ball in a ring of white: the
    reviewer's "bulging glassy eyes" (issue 13, session 24). The two eyes' mean was 0.85 (liam)
    and 0.88 (kwame) on 67a54cb; now 0.74 and 0.76."""
    from scipy import ndimage

    size = 512
    character = preset(name).with_(symmetric=True)
    renders = []
    for colours in ({}, {"iris": "#ff0000", "pupil": "#ff0000"}, {"sclera": "#00ff00"}):
        with Face(character.with_(colors={**character.colors, **colours})) as face:
            renders.append(face.render("1+2+5+26", size=size, antialias=1,
                                       background=(1.0, 1.0, 1.0))[..., :3].astype(int))
    image = renders[0]
    iris = np.abs(renders[1] - image).sum(-1) > 60
    sclera = (np.abs(renders[2] - image).sum(-1) > 60) & ~iris
    lum = _luminance(image)
    eyes, count = ndimage.label(ndimage.binary_dilation(iris, iterations=2))
    ratios = []
    for k in range(1, count + 1):
        ys, xs = np.nonzero(iris & (eyes == k))
        if len(ys) < 20:
            continue
        side = np.zeros_like(sclera)
        side[:, : size // 2] = xs.mean() < size / 2
        side[:, size // 2:] = xs.mean() >= size / 2
        above = sclera & side
        above[ys.min():] = False
        above[:, : xs.min()] = above[:, xs.max() + 1:] = False
        beside = sclera & side & (np.abs(np.arange(size) - ys.mean())[:, None] < 3)
        assert above.sum() >= 5 and beside.sum() > 0
        ratios.append(lum[above].mean() / lum[beside].mean())
    assert len(ratios) == 2 and np.mean(ratios) < 0.775, ratios
