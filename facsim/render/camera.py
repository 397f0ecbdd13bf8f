"""Cameras for the face renderer: an orbit camera around a target, and framing from bounds.

Conventions (the geometry's: decimetres, Y up, the face looks toward +Z, +X is the
character's LEFT):

- ``yaw`` (degrees) orbits the camera about the vertical axis through ``target``.
  ``yaw = 0`` puts the camera on the +Z side, looking at the face along -Z.
  **Positive yaw moves the camera toward +X, the character's left**: at ``yaw = +90``
  the camera looks along -X and sees the character's left ear.
- ``pitch`` (degrees) raises the camera above the target (positive = looking down).
- Images are top row first, x to the right. In the front view the character's left
  (+X) therefore appears on the IMAGE's RIGHT, as when looking at a person facing you.

Named views (:data:`VIEWS`) follow the same rule: ``"...-left"`` shows the character's
left side (positive yaw), ``"...-right"`` the right side (negative yaw).

Examples
--------
>>> cam = frame_camera((-1, 14, -1), (1, 17, 1), view="three-quarter-left")
>>> cam.yaw
45.0
>>> px, depth = project(cam, [cam.target], (512, 512))
>>> px.round(3).tolist()
[[256.0, 256.0]]
"""
from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from facsim.render.options import PROJECTIONS, VIEWS

__all__ = [
    "Camera", "VIEWS", "PROJECTIONS", "frame_camera", "frame_points", "view_matrix",
    "projection_matrix", "project", "camera_basis",
]

#: Portrait lens: a vertical field of view of 20 degrees (about a 65 mm lens on full frame
#: in portrait orientation) keeps perspective distortion of the face low.
DEFAULT_FOV_DEG = 20.0


@dataclass(frozen=True)
class Camera:
    """An orbit camera looking at ``target`` from ``distance`` away.

    Parameters
    ----------
    target : (3,) float
        The point looked at (world units, decimetres); it projects to the image centre.
    distance : float
        Camera-to-target distance, for both projections (orthographic uses it to
        place the camera and for the near/far planes only).
    yaw, pitch : float
        Orbit angles in degrees; see the module docstring for the signs.
    projection : {"perspective", "orthographic"}
    fov_deg : float
        Vertical field of view of the perspective projection.
    half_height : float
        Orthographic projection: half the visible height at the target (world units).
    near, far : float
        Clip planes, distances from the camera along the view direction.
    """

    target: tuple[float, float, float] = (0.0, 0.0, 0.0)
    distance: float = 10.0
    yaw: float = 0.0
    pitch: float = 0.0
    projection: str = "perspective"
    fov_deg: float = DEFAULT_FOV_DEG
    half_height: float = 1.0
    near: float = 0.1
    far: float = 100.0

    def __post_init__(self):
        target = tuple(float(v) for v in np.asarray(self.target, dtype=float).reshape(-1))
        if len(target) != 3 or not all(math.isfinite(v) for v in target):
            raise ValueError(f"target must be 3 finite numbers, got {self.target!r}")
        object.__setattr__(self, "target", target)
        for name in ("distance", "yaw", "pitch", "fov_deg", "half_height", "near", "far"):
            value = float(getattr(self, name))
            if not math.isfinite(value):
                raise ValueError(f"{name} must be finite, got {value!r}")
            object.__setattr__(self, name, value)
        if self.projection not in PROJECTIONS:
            raise ValueError(f"projection must be one of {PROJECTIONS}, got {self.projection!r}")
        if self.distance <= 0:
            raise ValueError(f"distance must be > 0, got {self.distance}")
        if not -89.9 <= self.pitch <= 89.9:
            raise ValueError(f"pitch must be within [-89.9, 89.9] degrees, got {self.pitch}")
        if not 0 < self.fov_deg < 179:
            raise ValueError(f"fov_deg must be in (0, 179), got {self.fov_deg}")
        if self.half_height <= 0:
            raise ValueError(f"half_height must be > 0, got {self.half_height}")
        if not 0 < self.near < self.far:
            raise ValueError(f"need 0 < near < far, got near={self.near}, far={self.far}")

    @property
    def position(self) -> np.ndarray:
        """(3,) camera position in world coordinates."""
        _, _, back = camera_basis(self.yaw, self.pitch)
        return np.asarray(self.target) + self.distance * back

    def with_view(self, view: str) -> "Camera":
        """The same camera orbited to a named view of :data:`VIEWS`."""
        yaw, pitch = _view_angles(view)
        return replace(self, yaw=yaw, pitch=pitch)


def camera_basis(yaw: float, pitch: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """World-space ``(right, up, back)`` unit vectors of a camera at ``yaw``/``pitch`` degrees.

    ``back`` points from the target toward the camera (the camera looks along ``-back``).
    """
    y, p = math.radians(yaw), math.radians(pitch)
    back = np.array([math.sin(y) * math.cos(p), math.sin(p), math.cos(y) * math.cos(p)])
    right = np.array([math.cos(y), 0.0, -math.sin(y)])
    up = np.cross(back, right)
    return right, up, back


def view_matrix(camera: Camera) -> np.ndarray:
    """4x4 world-to-camera matrix (column-vector convention, ``x_cam = V @ [x, 1]``)."""
    right, up, back = camera_basis(camera.yaw, camera.pitch)
    eye = camera.position
    m = np.eye(4)
    m[0, :3], m[1, :3], m[2, :3] = right, up, back
    m[:3, 3] = -m[:3, :3] @ eye
    return m


def projection_matrix(camera: Camera, aspect: float) -> np.ndarray:
    """4x4 OpenGL clip matrix (NDC z in [-1, 1]); ``aspect`` = width / height."""
    if not aspect > 0:
        raise ValueError(f"aspect must be > 0, got {aspect}")
    n, f = camera.near, camera.far
    m = np.zeros((4, 4))
    if camera.projection == "perspective":
        t = 1.0 / math.tan(math.radians(camera.fov_deg) / 2)
        m[0, 0], m[1, 1] = t / aspect, t
        m[2, 2], m[2, 3] = (f + n) / (n - f), 2 * f * n / (n - f)
        m[3, 2] = -1.0
    else:
        h = camera.half_height
        m[0, 0], m[1, 1] = 1.0 / (h * aspect), 1.0 / h
        m[2, 2], m[2, 3] = -2.0 / (f - n), -(f + n) / (f - n)
        m[3, 3] = 1.0
    return m


def project(camera: Camera, points, size) -> tuple[np.ndarray, np.ndarray]:
    """Pixel coordinates of world points in an image of ``size``.

    Parameters
    ----------
    points : (N, 3) array_like
    size : int or (width, height)

    Returns
    -------
    pixels : (N, 2) float
        ``(x, y)`` with x to the right and y DOWN from the top-left corner of the
        image (top row first, as :meth:`facsim.render.Renderer.render` returns it);
        pixel ``(i, j)`` covers ``[i, i+1) x [j, j+1)``, so the centre is ``(w/2, h/2)``.
    depth : (N,) float
        Distance in front of the camera along the view direction (> 0 = visible side).
    """
    w, h = _size_pair(size)
    pts = np.asarray(points, dtype=float).reshape(-1, 3)
    homo = np.c_[pts, np.ones(len(pts))]
    cam = homo @ view_matrix(camera).T
    clip = cam @ projection_matrix(camera, w / h).T
    ndc = clip[:, :2] / clip[:, 3:4]
    pixels = np.c_[(ndc[:, 0] + 1) * 0.5 * w, (1 - ndc[:, 1]) * 0.5 * h]
    return pixels, -cam[:, 2]


def frame_camera(bounds_min, bounds_max, *, view: str | None = "front", yaw: float | None = None,
                 pitch: float | None = None, projection: str = "perspective",
                 fov_deg: float = DEFAULT_FOV_DEG, margin: float = 0.05,
                 aspect: float = 1.0) -> Camera:
    """A camera whose image the axis-aligned box ``[bounds_min, bounds_max]`` just fills.

    The eight box corners are fitted inside the image with ``margin`` (a fraction of the
    image's half-width/height) left free on the tightest side, and centred. A box is
    looser than the head it encloses in oblique views; use :func:`frame_points` with the
    mesh vertices to frame the silhouette exactly.

    Parameters
    ----------
    bounds_min, bounds_max : (3,) array_like
    view : str, optional
        A key of :data:`VIEWS`; ``yaw``/``pitch`` given explicitly override it.
    projection, fov_deg : see :class:`Camera`.
    margin : float in [0, 0.9)
    aspect : float
        Image width / height the camera will be used with.
    """
    lo = np.asarray(bounds_min, dtype=float).reshape(-1)
    hi = np.asarray(bounds_max, dtype=float).reshape(-1)
    if lo.shape != (3,) or hi.shape != (3,):
        raise ValueError("bounds_min and bounds_max must each be 3 numbers")
    if np.any(hi < lo):
        raise ValueError(f"bounds_max must be >= bounds_min per axis, got {lo} and {hi}")
    corners = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1])
                        for z in (lo[2], hi[2])])
    return frame_points(corners, view=view, yaw=yaw, pitch=pitch, projection=projection,
                        fov_deg=fov_deg, margin=margin, aspect=aspect)


def frame_points(points, *, view: str | None = "front", yaw: float | None = None,
                 pitch: float | None = None, projection: str = "perspective",
                 fov_deg: float = DEFAULT_FOV_DEG, margin: float = 0.05,
                 aspect: float = 1.0) -> Camera:
    """A camera whose image the given points just fill (see :func:`frame_camera`)."""
    pts = np.asarray(points, dtype=float).reshape(-1, 3)
    if len(pts) == 0 or not np.all(np.isfinite(pts)):
        raise ValueError("points must be a non-empty (N, 3) array of finite numbers")
    if not 0 <= margin < 0.9:
        raise ValueError(f"margin must be in [0, 0.9), got {margin}")
    if not aspect > 0:
        raise ValueError(f"aspect must be > 0, got {aspect}")
    if projection not in PROJECTIONS:
        raise ValueError(f"projection must be one of {PROJECTIONS}, got {projection!r}")
    base_yaw, base_pitch = _view_angles(view) if view is not None else (0.0, 0.0)
    yaw = base_yaw if yaw is None else float(yaw)
    pitch = base_pitch if pitch is None else float(pitch)
    right, up, back = camera_basis(yaw, pitch)
    fill = 1.0 - margin
    centre = 0.5 * (pts.min(0) + pts.max(0))
    radius = max(float(np.linalg.norm(pts - centre, axis=1).max()), 1e-6)

    if projection == "orthographic":
        x, y = (pts - centre) @ right, (pts - centre) @ up
        centre = centre + right * 0.5 * (x.max() + x.min()) + up * 0.5 * (y.max() + y.min())
        half_w, half_h = 0.5 * (x.max() - x.min()), 0.5 * (y.max() - y.min())
        half_height = max(half_h, half_w / aspect, 1e-6) / fill
        distance = 3.0 * radius
        return Camera(target=centre, distance=distance, yaw=yaw, pitch=pitch,
                      projection=projection, fov_deg=fov_deg, half_height=half_height,
                      near=distance - 2.0 * radius, far=distance + 2.0 * radius)

    ty = math.tan(math.radians(fov_deg) / 2) * fill
    tx = ty * aspect
    target = centre
    for _ in range(4):  # fit the distance, then re-centre the projected extent; converges fast
        rel = pts - target
        x, y, z = rel @ right, rel @ up, rel @ back
        distance = float(np.max(z + np.maximum(np.abs(x) / tx, np.abs(y) / ty)))
        depth = distance - z
        sx, sy = x / depth, y / depth
        shift_x, shift_y = 0.5 * (sx.max() + sx.min()), 0.5 * (sy.max() + sy.min())
        if abs(shift_x) < 1e-9 and abs(shift_y) < 1e-9:
            break
        target = target + distance * (right * shift_x + up * shift_y)
    rel = pts - target
    z = rel @ back
    distance = float(np.max(z + np.maximum(np.abs(rel @ right) / tx, np.abs(rel @ up) / ty)))
    distance = max(distance, float(z.max()) + 1e-3)
    near = max(0.5 * (distance - float(z.max())), 1e-3 * distance)
    return Camera(target=target, distance=distance, yaw=yaw, pitch=pitch, projection=projection,
                  fov_deg=fov_deg, half_height=distance * math.tan(math.radians(fov_deg) / 2),
                  near=near, far=distance + 3.0 * radius)


def _view_angles(view: str) -> tuple[float, float]:
    try:
        return VIEWS[view]
    except KeyError:
        raise ValueError(f"view must be one of {sorted(VIEWS)}, got {view!r}") from None


def _size_pair(size) -> tuple[int, int]:
    if isinstance(size, (int, np.integer)):
        w = h = int(size)
    else:
        try:
            w, h = (int(v) for v in size)
        except (TypeError, ValueError):
            raise ValueError(f"size must be an int or (width, height), got {size!r}") from None
    if w <= 0 or h <= 0:
        raise ValueError(f"size must be positive, got {size!r}")
    return w, h
