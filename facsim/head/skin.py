"""Skin tone maps: where skin is darker, thinner, more porous or more sun-marked.

A second small texture beside :func:`facsim.head.appearance.detail_texture`, in the same
UV box and row order (v upward, GL order), placed by anatomy on the base mesh so every
character's maps sit on the same features. Channels (0 … 1):

- R, **darker skin**: the thin skin around the eyes shows the vessels and muscle beneath
  it (under-eye hollows, the inner corner, the upper lid's sulcus), and pigment lies
  unevenly (more around the mouth, at the temples and hairline, along the jaw's sides):
  no face is one even tone, and in dark skin this unevenness is what a photograph shows most.
- G, **translucency**: thin tissue that light passes through, so it glows red when lit
  from behind or the side (ear rims, nose wings and tip).
- B, **pore strength**: pores are largest on the nose and the cheeks beside it, finer on
  the forehead and chin, absent on the lids and lips.
- A, **sun exposure**: where freckles and age spots gather (cheekbones, nose, forehead,
  temples); the renderer shows spots there in proportion to the character's age.

The maps depend on the base mesh only, so they are computed once and cached on disk.
:func:`fold_texture` is a third map in the same box: the broad folds of the skin that come with
age and with expression (forehead lines, crow's feet, under-eye lines, the nasolabial and
marionette folds), as soft grooves a few millimetres across rather than thin painted lines.
:func:`contact_shadow` places, per vertex, the soft dark lines of small skin folds (nostrils,
lip line, alar crease, inner eye corners) that the baked ambient occlusion is too coarse to see.
"""
from __future__ import annotations

from functools import lru_cache
from typing import Callable

import numpy as np

from facsim.head.assets import cache_dir, cached_array
from facsim.head.surface import smoothstep

TONE_SIZE = (512, 256)  # rows (v), columns (u) over assets.PAINT_UV_BOX; the maps are smooth
#: Bump when the recipe changes, so cached tone maps are redone.
TONE_VERSION = 2  # 2: uneven pigment in R
#: hm08's left eye centre (joint-l-eye), decimetres.
EYE_CENTRE = (0.308, 7.284, 1.245)


FOLD_SIZE = (1024, 512)  # rows (v), columns (u) over assets.PAINT_UV_BOX: a texel is ~0.8 mm on the face
#: Bump when the fold recipe changes, so cached fold maps are redone.
FOLD_VERSION = 2  # 2: forehead lines unevenly spaced, wavy and broken


@lru_cache(maxsize=2)
def tone_texture(head, position_map: Callable) -> np.ndarray:
    """(rows, cols, 4) uint8: darker skin, translucency, pore strength, sun exposure.

    ``position_map(head)`` gives the base-mesh position (rows, cols, 3) at each texel of
    the paint box, NaN or far away off the mesh (:func:`facsim.head.appearance.position_map`).
    """
    return cached_array(cache_dir() / f"skin-tone-v{TONE_VERSION}.npy",
                        lambda: build_tone(position_map(head)),
                        valid=lambda a: a.shape == (*TONE_SIZE, 4) and a.dtype == np.uint8)


def _resampled(positions: np.ndarray, size: tuple[int, int], order: int) -> np.ndarray:
    """Base-mesh ``positions`` (rows, cols, 3) as float32, resampled to ``size`` (spline ``order``)."""
    positions = np.asarray(positions, np.float32)
    if positions.shape[:2] == tuple(size):
        return positions
    from scipy.ndimage import zoom

    return zoom(positions, (size[0] / positions.shape[0], size[1] / positions.shape[1], 1), order=order)


def build_tone(positions: np.ndarray) -> np.ndarray:
    """The tone maps at base-mesh ``positions`` (rows, cols, 3), resampled to :data:`TONE_SIZE`."""
    positions = _resampled(positions, TONE_SIZE, order=1)
    channels = (np.maximum(periorbital_density(positions), pigment_density(positions)), translucency_density(positions),
                pore_density(positions), sun_density(positions))
    tone = np.empty((*TONE_SIZE, 4), np.uint8)
    for k, mask in enumerate(channels):
        tone[..., k] = np.clip(np.nan_to_num(mask) * 255 + 0.5, 0, 255)
    return tone


def blob(positions: np.ndarray, centre, radius) -> np.ndarray:
    """exp(-r²) of the distance to ``centre`` in units of ``radius`` (per axis), mirrored in x."""
    d = np.array(positions, np.float64, copy=True)
    d[..., 0] = np.abs(d[..., 0])
    r2 = (((d - np.asarray(centre)) / np.asarray(radius)) ** 2).sum(-1)
    return np.exp(-r2)


def _front(positions: np.ndarray, z0: float = 1.0, z1: float = 1.2) -> np.ndarray:
    """1 on the face's front, fading out toward the sides and back of the head."""
    return smoothstep(z0, z1, positions[..., 2])


def periorbital_density(positions: np.ndarray) -> np.ndarray:
    """Darker skin around the eyes: strongest in the under-eye hollow and inner corner."""
    x, y, z = EYE_CENTRE
    dark = (0.75 * blob(positions, (x - 0.05, y - 0.12, z + 0.16), (0.13, 0.055, 0.12))    # under-eye hollow
            + 0.6 * blob(positions, (x - 0.17, y - 0.02, z + 0.14), (0.055, 0.08, 0.1))    # inner corner
            + 0.35 * blob(positions, (x + 0.02, y + 0.09, z + 0.1), (0.16, 0.045, 0.12)))  # upper lid sulcus
    return np.clip(dark * _front(positions), 0, 1).astype(np.float32)


def pigment_density(positions: np.ndarray) -> np.ndarray:
    """More pigment: around the mouth, at the temples and hairline, along the jaw's sides (the
    cheeks' middle, the nose and the forehead's centre are the face's lightest skin)."""
    pigment = (0.6 * blob(positions, (0.0, 6.6, 1.5), (0.24, 0.2, 0.3))          # around the mouth
               + 0.35 * blob(positions, (0.5, 7.8, 1.0), (0.22, 0.35, 0.3))       # temples
               + 0.3 * blob(positions, (0.0, 8.25, 1.3), (0.5, 0.15, 0.4))        # hairline
               + 0.3 * blob(positions, (0.6, 6.5, 0.9), (0.15, 0.35, 0.3)))       # the jaw's sides
    return np.clip(pigment, 0, 1).astype(np.float32)


def translucency_density(positions: np.ndarray) -> np.ndarray:
    """Thin tissue: the ears (rims most), the nose's wings and tip."""
    ears = blob(positions, (0.74, 7.1, 0.72), (0.13, 0.34, 0.3))
    nose = (0.3 * blob(positions, (0.15, 6.88, 1.5), (0.06, 0.06, 0.1))
            + 0.2 * blob(positions, (0.0, 6.95, 1.68), (0.08, 0.08, 0.1)))
    return np.clip(ears + nose, 0, 1).astype(np.float32)


def pore_density(positions: np.ndarray) -> np.ndarray:
    """Pore strength: nose and the cheeks beside it most, forehead and chin less, lids none."""
    base = 0.45 * _front(positions, 0.6, 1.0)
    pores = (base + 0.55 * blob(positions, (0.0, 6.98, 1.62), (0.12, 0.16, 0.15))
             + 0.4 * blob(positions, (0.3, 6.95, 1.4), (0.16, 0.14, 0.2))
             + 0.15 * blob(positions, (0.0, 7.75, 1.45), (0.35, 0.25, 0.3)))
    x, y, z = EYE_CENTRE
    lids = blob(positions, (x, y, z + 0.12), (0.2, 0.09, 0.2))
    return np.clip(pores * (1 - 0.85 * lids), 0, 1).astype(np.float32)


def sun_density(positions: np.ndarray) -> np.ndarray:
    """Where the sun marks skin: cheekbones, nose, forehead, temples."""
    sun = (0.8 * blob(positions, (0.42, 7.0, 1.32), (0.2, 0.14, 0.25))
           + 0.6 * blob(positions, (0.0, 7.0, 1.62), (0.1, 0.22, 0.15))
           + 0.7 * blob(positions, (0.0, 7.8, 1.4), (0.45, 0.25, 0.35))
           + 0.6 * blob(positions, (0.6, 7.55, 1.0), (0.15, 0.2, 0.25)))
    return np.clip(sun * _front(positions, 0.7, 1.0), 0, 1).astype(np.float32)


#: How much a full contact shadow takes off the ambient visibility.
CONTACT_DEPTH = 0.4
#: Where skin meets skin in small folds too narrow for the baked occlusion's depth maps:
#: (centre, radius, strength) on the base mesh, decimetres, mirrored in x.
CONTACT_SHADOWS = (
    ((0.165, 6.855, 1.47), (0.028, 0.05, 0.06), 1.0),    # alar crease: nose wing against cheek
    ((0.075, 6.825, 1.575), (0.04, 0.02, 0.05), 0.8),    # nostril openings, under the wing
    ((0.0, 6.795, 1.62), (0.035, 0.02, 0.05), 0.6),      # subnasale: columella meets upper lip
    ((0.0, 6.642, 1.56), (0.2, 0.011, 0.12), 0.9),       # lip line (stomion)
    ((0.248, 6.647, 1.356), (0.03, 0.03, 0.06), 0.9),    # mouth corners
    ((0.0, 6.46, 1.53), (0.13, 0.028, 0.08), 0.45),      # mentolabial sulcus under the lower lip
    ((0.205, 7.3, 1.375), (0.035, 0.045, 0.05), 0.7),    # inner eye corner against the nose
    ((0.31, 7.405, 1.385), (0.13, 0.022, 0.08), 0.5),    # upper lid crease under the brow
)


def contact_shadow(positions: np.ndarray) -> np.ndarray:
    """(N,) float32 in [0, 1]: how deep in a small skin fold each base-mesh point lies.

    Per-vertex ambient occlusion from depth maps misses folds narrower than its texels
    (the nostrils, the lip line, the alar crease, the inner eye corner); photographs show
    soft dark contact lines there. :meth:`facsim.face.Face.shading_occlusion` darkens the
    occlusion with this.
    """
    positions = np.asarray(positions, np.float64)
    dark = np.zeros(len(positions))
    for centre, radius, strength in CONTACT_SHADOWS:
        dark = np.maximum(dark, strength * blob(positions, centre, radius))
    return np.clip(dark, 0, 1).astype(np.float32)


# --------------------------------------------------------------------------------------------
# Folds
# --------------------------------------------------------------------------------------------

@lru_cache(maxsize=2)
def fold_texture(head, position_map: Callable) -> np.ndarray:
    """(rows, cols, 4) uint8 fold map in the paint box (GL row order, like :func:`tone_texture`).

    Channels (0 … 1):

    - R, **expression lines**: the forehead lines and crow's feet, as groove depth. They show
      with age and deepen where the skin is pushed together (raised brows, 1 and 2, for the
      forehead; the raised cheek of 6 for the crow's feet), so a young face shows them only then.
    - G, **under-eye lines**: the tear trough and a soft line under the lower lid, as groove
      depth; age only (a smile's lower-lid bulge is the geometry's).
    - B, **fold shade**: the nasolabial and marionette folds as a broad soft shade on the
      cheek's side of the fold (age only: the smile's deepening fold is the geometry's).
    - A, **lines drawn here**: where R and G stand in for the expression engine's furrows (the
      forehead, around the eyes); the renderer fades the engine's crease pattern out there.

    Grooves are 3-5 mm across with gently sloping sides: shaded from their slopes they read as
    folds of skin, where the thin 1-2 mm lines they replace read as painted strokes (issue 13).
    """
    return cached_array(cache_dir() / f"skin-folds-v{FOLD_VERSION}.npy",
                        lambda: build_folds(position_map(head)),
                        valid=lambda a: a.shape == (*FOLD_SIZE, 4) and a.dtype == np.uint8)


def build_folds(positions: np.ndarray) -> np.ndarray:
    """The fold map at base-mesh ``positions`` (rows, cols, 3), resampled to :data:`FOLD_SIZE`."""
    # Cubic: the grooves are shaded from their slopes, and bilinear kinks show as dashes.
    positions = _resampled(positions, FOLD_SIZE, order=3)
    channels = (np.maximum(forehead_line_density(positions), crows_feet_density(positions)),
                under_eye_line_density(positions), fold_shade_density(positions), fold_region_density(positions))
    folds = np.empty((*FOLD_SIZE, 4), np.uint8)
    for k, mask in enumerate(channels):
        folds[..., k] = np.clip(np.nan_to_num(mask) * 255 + 0.5, 0, 255)
    return folds


def _groove(distance, width):
    """Depth profile across a groove: 1 at its floor, sides falling as a smooth bell."""
    return np.exp(-(distance / width) ** 2)


def forehead_line_density(positions: np.ndarray) -> np.ndarray:
    """Five gently arched forehead lines, as on a real forehead: unevenly spaced, wavy (a few
    millimetres up and down along their length), each its own depth, deepest in the middle
    rows, and broken into two or three stretches that fade out and restart. Evenly spaced,
    straight, unbroken lines of one depth read as drawn on (issue: "painted forehead lines")."""
    x, y, z = positions[..., 0], positions[..., 1], positions[..., 2]
    ax = np.abs(x)
    rng = np.random.default_rng(13)   # fixed: the lines are part of the head model
    out = np.zeros(np.shape(x))
    for k in range(5):
        height = 7.56 + 0.065 * k + rng.uniform(-0.008, 0.008)
        # Two swaying waves, one slow and one quicker; each line's own.
        sway = (rng.uniform(0.006, 0.012) * np.sin(rng.uniform(3, 5) * x + rng.uniform(0, 2 * np.pi))
                + rng.uniform(0.002, 0.005) * np.sin(rng.uniform(9, 14) * x + rng.uniform(0, 2 * np.pi)))
        across = y - 0.12 * ax ** 2 - sway - height
        reach = rng.uniform(0.22, 0.4)
        # Depth along the line: two slow waves, so it fades out and restarts in places.
        along = np.clip(0.75 + 0.35 * np.sin(rng.uniform(5, 8) * x + rng.uniform(0, 2 * np.pi))
                        + 0.15 * np.sin(rng.uniform(12, 16) * x + rng.uniform(0, 2 * np.pi)), 0, 1) \
            * smoothstep(reach, reach - 0.18, ax)
        depth = rng.uniform(0.55, 0.9) * (1.0 - 0.35 * abs(k - 2) / 2)
        width = 0.03 * rng.uniform(0.85, 1.2)
        out = np.maximum(out, depth * _groove(across, width) * along)
    return np.clip(out * smoothstep(1.1, 1.3, z), 0, 1).astype(np.float32)


#: Where the crow's feet fan out from: beside hm08's outer eye corner (x, y, decimetres).
CROWS_FEET_CENTRE = (0.47, 7.28)


def crows_feet_density(positions: np.ndarray) -> np.ndarray:
    """Five soft rays fanning out from beside the outer eye corner over the temple and the top
    of the cheek, each its own length and depth. They begin 5 mm out from the corner: the
    corner itself folds tightly in 6, where a groove drawn on the skin breaks into blocks."""
    x, y, z = positions[..., 0], positions[..., 1], positions[..., 2]
    dx, dy = np.abs(x) - CROWS_FEET_CENTRE[0], y - CROWS_FEET_CENTRE[1]
    radius = np.hypot(dx, dy)
    angle = np.arctan2(dy, np.maximum(dx, 1e-6))
    rng = np.random.default_rng(6)
    out = np.zeros(np.shape(x))
    for k in range(5):
        ray = -0.75 + 0.35 * k + rng.uniform(-0.06, 0.06)
        bend = ray + rng.uniform(-0.3, 0.3) * (radius - 0.05)
        across = (angle - bend) * np.maximum(radius, 0.04)     # distance across the ray (dm)
        length = rng.uniform(0.16, 0.22)
        along = smoothstep(0.05, 0.09, radius) * smoothstep(length, length - 0.08, radius)
        out = np.maximum(out, rng.uniform(0.5, 0.75) * _groove(across, 0.026) * along)
    return np.clip(out * (dx > 0) * smoothstep(0.6, 0.9, z), 0, 1).astype(np.float32)


def under_eye_line_density(positions: np.ndarray) -> np.ndarray:
    """The tear trough (inner half, under the lower lid) and a soft lid-cheek line beside it."""
    x, y, z = EYE_CENTRE
    trough = blob(positions, (0.22, 7.13, 1.42), (0.08, 0.04, 0.1))
    lid_cheek = 0.5 * blob(positions, (x + 0.02, y - 0.165, z + 0.14), (0.13, 0.045, 0.12))
    return np.clip(np.maximum(trough, lid_cheek) * _front(positions), 0, 1).astype(np.float32)


#: The nasolabial (nose wing to past the lip corner) and marionette folds: segment ends on the
#: base mesh (x, y, decimetres, mirrored), strength, and the shade's reach toward the lip and
#: onto the cheek (the cheek's bulge over the fold shades a broad band on its side).
FOLD_LINES = (
    ((0.15, 6.86), (0.29, 6.60), 1.0, (0.018, 0.07)),   # nasolabial
    ((0.26, 6.58), (0.24, 6.38), 0.55, (0.02, 0.05)),   # marionette
)


def fold_shade_density(positions: np.ndarray) -> np.ndarray:
    """A soft shade along the nasolabial and marionette folds, broad on the cheek's side."""
    ax, y = np.abs(positions[..., 0]), positions[..., 1]
    out = np.zeros(np.shape(ax))
    for (x0, y0), (x1, y1), strength, (inner, outer) in FOLD_LINES:
        distance = _segment_distance(ax, y, x0, y0, x1, y1)
        reach = np.where(_segment_side(ax, y, x0, y0, x1, y1) > 0, outer, inner)
        out = np.maximum(out, strength * _groove(distance, reach))
    return np.clip(out * smoothstep(1.1, 1.3, positions[..., 2]), 0, 1).astype(np.float32)


def fold_region_density(positions: np.ndarray) -> np.ndarray:
    """Where the fold map draws the lines itself: the forehead above the brows, around the eyes."""
    x, y, z = EYE_CENTRE
    forehead = smoothstep(7.5, 7.56, positions[..., 1]) * smoothstep(1.0, 1.2, positions[..., 2])
    eyes = np.clip(2.5 * blob(positions, (x + 0.12, y - 0.02, z), (0.22, 0.2, 0.4)), 0, 1)
    return np.clip(np.maximum(forehead, eyes), 0, 1).astype(np.float32)


def _segment_side(x, y, x0, y0, x1, y1):
    """Which side of the line through the segment each point lies: > 0 on its left
    (going from (x0, y0) to (x1, y1)), < 0 on its right."""
    return (x1 - x0) * (y - y0) - (y1 - y0) * (x - x0)


def _segment_distance(x, y, x0, y0, x1, y1):
    dx, dy = x1 - x0, y1 - y0
    t = np.clip(((x - x0) * dx + (y - y0) * dy) / (dx * dx + dy * dy), 0, 1)
    return np.hypot(x - (x0 + t * dx), y - (y0 + t * dy))
