"""The Face API: neutral renders of real characters, views, backgrounds, files."""
from __future__ import annotations

import numpy as np
import pytest
from PIL import Image

from conftest import background_mask


def test_neutral_render_shows_a_face_filling_the_frame(face_of):
    img = face_of("ava").render(size=256)
    assert img.shape == (256, 256, 4) and img.dtype == np.uint8
    fg = ~background_mask(img)
    rows, cols = np.flatnonzero(fg.any(1)), np.flatnonzero(fg.any(0))
    assert rows[-1] - rows[0] > 0.8 * 256  # the head fills the frame top to bottom ...
    assert 0.4 * 256 < cols[-1] - cols[0] < 0.95 * 256  # ... and is narrower than tall
    skin = img[128, 128, :3].astype(int)  # the middle of the face is skin-coloured, not grey
    assert skin[0] > skin[2] + 20


def test_views_show_different_sides(face_of):
    face = face_of("ava")
    left = face.render(view="profile-left", size=128)
    right = face.render(view="profile-right", size=128)
    # In the left profile the face (nose) points to the image's right.
    def nose_side(img):
        fg = ~background_mask(img)
        cols = np.flatnonzero(fg[60])
        return (cols.mean() - 64)
    assert nose_side(left) * nose_side(right) < 0
    assert np.abs(left.astype(int) - right[:, ::-1].astype(int)).mean() < 20  # mirror images


def test_transparent_background(face_of):
    img = face_of("ava").render(size=128, background=None)
    assert img[0, 0, 3] == 0 and img[-1, 0, 3] == 0 and img[64, 64, 3] == 255


def test_skin_follows_the_character(face_of):
    light = face_of("ava").render(size=96)[48, 48, :3].astype(int).sum()
    dark = face_of("kwame").render(size=96)[48, 48, :3].astype(int).sum()
    assert dark < light - 100


def test_brows_are_visible_and_move_with_au1_2(face_of, head, marks):
    face = face_of("liam")
    neutral, raised = face.render(size=256), face.render("1+2", size=256)
    diff = np.abs(neutral[..., :3].astype(int) - raised[..., :3].astype(int)).sum(-1) > 40
    rows = np.flatnonzero(diff.any(1))
    assert rows.size and rows.min() < 110  # the brows, in the upper half, changed


def test_save_writes_a_png_atomically(face_of, tmp_path):
    out = tmp_path / "face.png"
    face_of("ava").save(out, "12", size=64)
    assert Image.open(out).size == (64, 64)
    assert [p.name for p in tmp_path.iterdir()] == ["face.png"]


def test_renders_are_reproducible(face_of):
    face = face_of("mei")
    assert np.array_equal(face.render("6+12", size=96), face.render("6+12", size=96))


@pytest.mark.parametrize("size", [8, 100000])
def test_bad_size_is_refused(face_of, size):
    with pytest.raises(ValueError, match="image size"):
        face_of("ava").render(size=size)


def test_fxaa_smooths_edges_like_msaa(face_of):
    # The head's own silhouette: the hair's outline is drawn soft by its shader already (frayed
    # card edges, loose strands, long hair's tapering ends), so FXAA has little left to do there.
    from facsim.face import Face

    with Face(face_of("ava").character.with_(hair="none")) as face:
        plain, fxaa, msaa = (face.render("6+12", size=128, antialias=a).astype(int) for a in (1, "fxaa", 4))
    bg = background_mask(plain.astype(np.uint8))
    silhouette = bg ^ np.roll(bg, 1, axis=1)  # pixels where the head meets the background
    def error(img):
        return np.abs(img - msaa)[silhouette].mean()
    assert error(fxaa) < 0.8 * error(plain)
