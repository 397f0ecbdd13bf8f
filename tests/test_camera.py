"""Camera conventions, matrices and framing (pure numpy, no GL)."""
from __future__ import annotations

import numpy as np
import pytest

from facsim.render.camera import (
    VIEWS, Camera, camera_basis, frame_camera, frame_points, project, projection_matrix,
    view_matrix,
)

LO, HI = np.array([-0.9, 14.3, -1.0]), np.array([0.9, 16.7, 1.1])  # a head-sized box


def corners(lo=LO, hi=HI):
    return np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1])
                     for z in (lo[2], hi[2])])


@pytest.mark.parametrize("projection", ["perspective", "orthographic"])
@pytest.mark.parametrize("view", sorted(VIEWS))
@pytest.mark.parametrize("size", [(512, 512), (640, 360)])
def test_the_target_projects_to_the_image_centre(projection, view, size):
    cam = frame_camera(LO, HI, view=view, projection=projection, aspect=size[0] / size[1])
    px, depth = project(cam, [cam.target], size)
    assert np.allclose(px[0], (size[0] / 2, size[1] / 2), atol=1e-6)
    assert np.isclose(depth[0], cam.distance)


def test_yaw_sign_and_named_views():
    # yaw = 0: camera on +Z, in front of the face; positive yaw: toward +X, the character's left.
    assert np.allclose(Camera(yaw=0, distance=5).position, [0, 0, 5])
    assert np.allclose(Camera(yaw=90, distance=5).position, [5, 0, 0], atol=1e-9)
    assert np.allclose(Camera(pitch=30, distance=2).position[1], 1.0)  # pitch > 0: from above
    assert VIEWS["front"] == (0.0, 0.0)
    for side, sign in (("left", 1), ("right", -1)):
        for kind in ("three-quarter", "profile"):
            yaw, pitch = VIEWS[f"{kind}-{side}"]
            assert np.sign(yaw) == sign and pitch == 0
            assert np.sign(Camera(yaw=yaw).position[0]) == sign  # the camera sees that side
    assert VIEWS["profile-left"][0] == 90 and VIEWS["three-quarter-left"][0] == 45


def test_image_orientation():
    """Front view: +X (the character's left) is on the image right, +Y is up (smaller row)."""
    cam = Camera(target=(0, 0, 0), distance=10)
    (left, top, centre), _ = project(cam, [[1, 0, 0], [0, 1, 0], [0, 0, 0]], 100)
    assert left[0] > centre[0] and np.isclose(left[1], centre[1])
    assert top[1] < centre[1] and np.isclose(top[0], centre[0])
    # Profile-left: the camera is on +X, so the face (+Z) points to the image LEFT.
    cam = Camera(target=(0, 0, 0), distance=10, yaw=90)
    (nose, centre), _ = project(cam, [[0, 0, 1], [0, 0, 0]], 100)
    assert nose[0] < centre[0]
    # Profile-right: the face points to the image right.
    cam = Camera(target=(0, 0, 0), distance=10, yaw=-90)
    (nose, centre), _ = project(cam, [[0, 0, 1], [0, 0, 0]], 100)
    assert nose[0] > centre[0]


def test_view_matrix_is_rigid_and_puts_the_camera_at_the_origin():
    cam = Camera(target=(0.3, 15.2, 0.1), distance=7.0, yaw=33.0, pitch=-12.0)
    v = view_matrix(cam)
    rot = v[:3, :3]
    assert np.allclose(rot @ rot.T, np.eye(3)) and np.isclose(np.linalg.det(rot), 1)
    assert np.allclose(v @ np.r_[cam.position, 1], [0, 0, 0, 1])
    assert np.allclose(v @ np.r_[cam.target, 1], [0, 0, -7.0, 1])  # straight ahead
    right, up, back = camera_basis(33.0, -12.0)
    assert np.isclose(right[1], 0) and up[1] > 0  # no roll


@pytest.mark.parametrize("projection", ["perspective", "orthographic"])
def test_projection_maps_near_and_far_to_the_clip_range(projection):
    cam = Camera(distance=5.0, near=1.0, far=20.0, projection=projection, half_height=2.0)
    p = projection_matrix(cam, 1.5)
    for z, ndc in ((-1.0, -1.0), (-20.0, 1.0)):
        clip = p @ [0, 0, z, 1]
        assert np.isclose(clip[2] / clip[3], ndc)
    if projection == "perspective":
        assert np.isclose(p[1, 1], 1 / np.tan(np.radians(cam.fov_deg / 2)))
        assert np.isclose(p[0, 0], p[1, 1] / 1.5)
    else:
        assert np.isclose(p[1, 1], 1 / 2.0)


@pytest.mark.parametrize("projection", ["perspective", "orthographic"])
@pytest.mark.parametrize("view", sorted(VIEWS))
def test_frame_camera_fills_the_image_with_the_bounds(projection, view):
    margin = 0.05
    cam = frame_camera(LO, HI, view=view, projection=projection, margin=margin)
    px, depth = project(cam, corners(), 512)
    assert (depth > cam.near).all() and (depth < cam.far).all()
    lo, hi = px.min(0), px.max(0)
    assert (lo >= -1e-6).all() and (hi <= 512 + 1e-6).all()  # everything inside
    # Centred, and the tight axis spans the image less the margins.
    assert np.allclose((lo + hi) / 2, 256, atol=0.5)
    span = (hi - lo).max()
    assert np.isclose(span, 512 * (1 - margin), rtol=0.01)


def test_frame_camera_respects_a_wide_aspect():
    cam = frame_camera(LO, HI, view="front", aspect=16 / 9)
    px, _ = project(cam, corners(), (1600, 900))
    span = px.max(0) - px.min(0)
    assert span[1] > 0.9 * 900 and span[0] < 1600  # the tall head fills the height


def test_frame_points_is_tighter_than_the_box_in_oblique_views():
    rng = np.random.default_rng(1)
    d = rng.normal(size=(2000, 3))
    head = d / np.linalg.norm(d, axis=1, keepdims=True) * [0.8, 1.15, 0.95] + [0, 15.5, 0]
    box = frame_camera(head.min(0), head.max(0), view="three-quarter-left")
    tight = frame_points(head, view="three-quarter-left")
    assert tight.distance < box.distance
    px, _ = project(tight, head, 512)
    assert np.isclose((px.max(0) - px.min(0)).max(), 512 * 0.95, rtol=0.01)


def test_explicit_yaw_and_pitch_override_the_view():
    cam = frame_camera(LO, HI, view="profile-left", yaw=10.0)
    assert cam.yaw == 10.0 and cam.pitch == 0.0
    cam = frame_camera(LO, HI, view=None, pitch=15.0)
    assert (cam.yaw, cam.pitch) == (0.0, 15.0)
    assert Camera().with_view("three-quarter-right").yaw == -45.0


def test_camera_validation():
    with pytest.raises(ValueError, match="projection must be one of"):
        Camera(projection="fisheye")
    with pytest.raises(ValueError, match="distance must be > 0"):
        Camera(distance=0)
    with pytest.raises(ValueError, match="pitch must be within"):
        Camera(pitch=90)
    with pytest.raises(ValueError, match="need 0 < near < far"):
        Camera(near=5, far=1)
    with pytest.raises(ValueError, match="target must be 3 finite numbers"):
        Camera(target=(0, 1))
    with pytest.raises(ValueError, match="view must be one of"):
        frame_camera(LO, HI, view="top")
    with pytest.raises(ValueError, match="bounds_max must be >= bounds_min"):
        frame_camera(HI, LO)
    with pytest.raises(ValueError, match="margin must be in"):
        frame_camera(LO, HI, margin=1.0)
    with pytest.raises(ValueError, match="size must be"):
        project(Camera(), [[0, 0, 0]], (0, 10))


def test_camera_is_frozen_and_hashable():
    cam = Camera(target=np.array([1.0, 2.0, 3.0]))
    assert cam.target == (1.0, 2.0, 3.0)
    with pytest.raises(Exception):
        cam.yaw = 3.0  # type: ignore[misc]
    assert hash(cam) == hash(Camera(target=(1.0, 2.0, 3.0)))
