"""Skin tone maps: where skin is darker, thinner, more porous or more sun-marked.

A second small texture beside :func:`facsim.head.appearance.detail_texture`, in the same
UV box and row order (v upward, GL order), placed by anatomy on the base mesh so every
character's maps sit on the same features. Channels (0 … 1):

- R, **periorbital darkening**: the thin skin around the eyes shows the vessels and
  muscle beneath it (under-eye hollows, the inner corner, the upper lid's sulcus).
- G, **translucency**: thin tissue that light passes through, so it glows red when lit
  from behind or the side (ear rims, nose wings and tip).
- B, **pore strength**: pores are largest on the nose and the cheeks beside it, finer on
  the forehead and chin, absent on the lids and lips.
- A, **sun exposure**: where freckles and age spots gather (cheekbones, nose, forehead,
  temples); the renderer shows spots there in proportion to the character's age.

The maps depend on the base mesh only, so they are computed once and cached on disk.
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
TONE_VERSION = 1
#: hm08's left eye centre (joint-l-eye), decimetres.
EYE_CENTRE = (0.308, 7.284, 1.245)


@lru_cache(maxsize=2)
def tone_texture(head, position_map: Callable) -> np.ndarray:
    """(rows, cols, 4) uint8: periorbital darkening, translucency, pore strength, sun exposure.

    ``position_map(head)`` gives the base-mesh position (rows, cols, 3) at each texel of
    the paint box, NaN or far away off the mesh (:func:`facsim.head.appearance.position_map`).
    """
    return cached_array(cache_dir() / f"skin-tone-v{TONE_VERSION}.npy",
                        lambda: build_tone(position_map(head)),
                        valid=lambda a: a.shape == (*TONE_SIZE, 4) and a.dtype == np.uint8)


def build_tone(positions: np.ndarray) -> np.ndarray:
    """The tone maps at base-mesh ``positions`` (rows, cols, 3), resampled to :data:`TONE_SIZE`."""
    positions = np.asarray(positions, np.float32)
    if positions.shape[:2] != TONE_SIZE:
        from scipy.ndimage import zoom

        factors = (TONE_SIZE[0] / positions.shape[0], TONE_SIZE[1] / positions.shape[1], 1)
        positions = zoom(positions, factors, order=1)
    channels = (periorbital_density(positions), translucency_density(positions),
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
