"""What the renderer is given: mesh topology, appearance, lighting and the brow UV frame.

Plain data checked as it is built, with no GL: :class:`Lighting` (the studio rig fixed to
the camera) and the eyebrow-stroke UV frames, beside what the head package provides and
is re-exported here: :class:`~facsim.head.mesh.RenderTopology` (the static mesh, its UVs
and regions, uploaded once per renderer) and :class:`~facsim.head.appearance.Appearance`
(colours and paint masks). :class:`~facsim.render.renderer.Renderer` draws with them.

Colour conventions: :class:`Appearance` colours are display sRGB values in [0, 1] (what a
colour picker shows); :func:`srgb_to_linear` turns them into the linear light the shaders
work in.

Examples
--------
>>> Appearance().colors["skin"]
(0.85, 0.68, 0.6)
>>> float(srgb_to_linear(0.5)) > 0.2
True
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from facsim.head.appearance import COLOR_NAMES, DEFAULT_COLORS, Appearance
from facsim.head.colour import srgb_to_linear
from facsim.head.mesh import REGIONS, RenderTopology
from facsim.render.camera import Camera, camera_basis

#: Eyebrow strokes for hm08's raw UV layout, where the head's island is turned 90 degrees:
#: the brows run along v (strokes ~3 mm long) and u runs up the face (strands ~0.5 mm apart).
HM08_BROW_UV_FRAME = ((0.0, 160.0), (1600.0, 0.0))


def brow_uv_frame(uv_box=None, frame=HM08_BROW_UV_FRAME) -> np.ndarray:
    """The brow-stroke frame for UVs normalised to ``uv_box = (u0, v0, u1, v1)``.

    A head whose UVs are ``u' = (u - u0) / (u1 - u0)`` (same for v) needs the raw frame's
    columns scaled by the box's size; ``uv_box=None`` returns the raw frame.
    """
    m = np.asarray(frame, dtype=float)
    if uv_box is None:
        return m
    u0, v0, u1, v1 = (float(x) for x in uv_box)
    return m * np.array([u1 - u0, v1 - v0])[None, :]


#: The default: facsim's head model, whose UVs are normalised to ``facsim.assets.PAINT_UV_BOX``
#: (0.60, 0.10, 1.00, 0.90) (a test checks the two agree).
DEFAULT_BROW_UV_FRAME = ((0.0, 128.0), (640.0, 0.0))


@dataclass(frozen=True)
class Lighting:
    """A studio light rig fixed to the camera.

    Directions are in CAMERA space (x right, y up, z from the subject toward the camera)
    and point toward the light; they need not be unit length. Colours are linear RGB with
    the intensity folded in. ``sky``/``ground`` are the hemispheric ambient for world-up and
    world-down facing surfaces. ``exposure`` scales everything before tone mapping.
    """

    # A portrait studio's soft light (as stimulus sets such as KDEF and Radboud are
    # photographed): a large key above the camera, a little to its left, so the nose and chin
    # cast soft shadows down and the face is modelled but never dramatic; a broad fill beside
    # the camera on the right at about a sixth of the key, which opens the shade on the face
    # without lighting its outline, so the face falls off toward its sides (until session 25 it
    # stood 51 degrees to the side and lit the right side's outline as brightly as the cheek); a
    # faint rim from behind; a bright room lit from above, its floor returning little (until
    # session 25 half the ceiling's light: the undersides of the brows, nose and jaw were lit
    # nearly as the tops, one more way the face read "flat" to the blind reviewer). The key
    # stands 38 degrees above the lens axis (32 until session 25: the brows, nose, lips and chin
    # barely shaded their undersides, "flat lighting"); a point source that high laid its
    # reflection across the forehead as a glaze, a softbox's spreads it broad and dim
    # (KEY_SOFTBOX_HALF_ANGLE in face.frag.glsl; tests/test_skin.py).
    key_direction: tuple[float, float, float] = (-0.42, 0.70, 0.78)
    key_color: tuple[float, float, float] = (1.27, 1.21, 1.13)
    fill_direction: tuple[float, float, float] = (0.6, 0.0, 0.8)
    fill_color: tuple[float, float, float] = (0.23, 0.225, 0.23)
    rim_direction: tuple[float, float, float] = (0.35, 0.55, -0.75)
    rim_color: tuple[float, float, float] = (0.38, 0.38, 0.4)
    sky: tuple[float, float, float] = (0.15, 0.15, 0.16)
    ground: tuple[float, float, float] = (0.035, 0.027, 0.022)
    exposure: float = 1.0

    def world_uniforms(self, camera: Camera) -> dict[str, tuple[float, ...]]:
        """The ``u_*`` shader uniforms for this rig seen from ``camera``."""
        right, up, back = camera_basis(camera.yaw, camera.pitch)
        rot = np.stack([right, up, back], axis=1)  # camera -> world

        def direction(d):
            w = rot @ np.asarray(d, dtype=float)
            return tuple(float(x) for x in w / np.linalg.norm(w))

        return {
            "u_key_dir": direction(self.key_direction), "u_key_col": tuple(self.key_color),
            "u_fill_dir": direction(self.fill_direction), "u_fill_col": tuple(self.fill_color),
            "u_rim_dir": direction(self.rim_direction), "u_rim_col": tuple(self.rim_color),
            "u_sky_col": tuple(self.sky), "u_ground_col": tuple(self.ground),
            "u_exposure": float(self.exposure),
            "u_cam_pos": tuple(float(x) for x in camera.position),
        }


__all__ = ["COLOR_NAMES", "DEFAULT_COLORS", "REGIONS", "Appearance", "Lighting", "RenderTopology", "brow_uv_frame",
           "srgb_to_linear", "DEFAULT_BROW_UV_FRAME", "HM08_BROW_UV_FRAME"]
