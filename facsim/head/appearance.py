"""Appearance: a character's colours and the paint texture (brows, lips, lids, blush).

hm08 ships no skin textures, so facsim paints what carries expression in UV
space, where it moves with the skin for free: eyebrow hair (AUs 1, 2, 4 must
show), the lips and lids (MakeHuman's own masks), and a soft blush. Eyebrows are
placed from 3-D positions on the base mesh (the brow follows the upper orbital
rim), so every character's brows sit on the same anatomy.

Colours follow the ethnicity mix and age (mixed in linear light) unless the
character overrides them.
"""
from __future__ import annotations

from functools import lru_cache

import numpy as np

from facsim.head.assets import cache_dir
from facsim.atomic import atomic_write
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Mapping

from facsim.head.character import COLOR_NAMES, Character
from facsim.head.colour import hex_to_rgb, linear_to_srgb, srgb_to_linear
from facsim.head.surface import smoothstep

#: A plausible default appearance (light-medium skin, brown eyes), display sRGB.
DEFAULT_COLORS: Mapping[str, tuple[float, float, float]] = MappingProxyType({
    "skin": (0.85, 0.68, 0.60),
    "lips": (0.72, 0.42, 0.40),
    "brows": (0.22, 0.15, 0.11),
    "lashes": (0.07, 0.05, 0.04),
    "sclera": (0.90, 0.88, 0.85),
    "iris": (0.36, 0.24, 0.14),
    "pupil": (0.02, 0.02, 0.02),
    "teeth": (0.90, 0.87, 0.78),
    "tongue": (0.76, 0.40, 0.40),
    "mouth_interior": (0.36, 0.11, 0.11),
    "eyelid": (0.78, 0.58, 0.52),
    "cheek": (0.90, 0.56, 0.52),
})


@dataclass(frozen=True, eq=False)
class Appearance:
    """How a character looks: colours and a paint texture in skin-UV space.

    Parameters
    ----------
    colors : mapping name -> (r, g, b)
        Display sRGB in [0, 1] for every name in :data:`COLOR_NAMES` (extra names are an
        error, to catch typos). See :data:`DEFAULT_COLORS`.
    paint : (H, W, 4) uint8, optional
        R = eyebrow hair density, G = lip mask, B = eyelid mask, A = cheek/blush mask.
        Rows run with v UPWARD: row 0 is v = 0 (GL texture order, as ``facsim.assets``
        stores its masks; flip an image file's rows with ``paint[::-1]``). Each mask is the
        weight of its colour over the skin colour (255 = the colour itself), so the blush
        or eyelid strength is painted into the mask. ``None`` = no paint.
    """

    colors: Mapping[str, tuple[float, float, float]] = field(default_factory=lambda: DEFAULT_COLORS)
    paint: np.ndarray | None = None

    def __post_init__(self):
        colors = dict(self.colors)
        missing = [k for k in COLOR_NAMES if k not in colors]
        extra = [k for k in colors if k not in COLOR_NAMES]
        if missing or extra:
            raise ValueError(f"colors must give exactly {COLOR_NAMES}; missing {missing}, "
                             f"unknown {extra}")
        clean = {}
        for k in COLOR_NAMES:
            c = np.asarray(colors[k], dtype=float).reshape(-1)
            if c.shape != (3,) or not np.all((c >= 0) & (c <= 1)):
                raise ValueError(f"colors[{k!r}] must be 3 numbers in [0, 1], got {colors[k]!r}")
            clean[k] = tuple(float(v) for v in c)
        object.__setattr__(self, "colors", MappingProxyType(clean))
        if self.paint is not None:
            paint = np.asarray(self.paint)
            if paint.ndim != 3 or paint.shape[2] != 4 or paint.dtype != np.uint8:
                raise ValueError(f"paint must be an (H, W, 4) uint8 array, got "
                                 f"{paint.dtype} {paint.shape}")
            object.__setattr__(self, "paint", paint)



#: Young-adult colours per ethnicity (sRGB). Sources: typical values of the
#: Fitzpatrick II / IV / V–VI skin types; brows and irises the commonest shade.
ETHNIC_COLORS = {
    "caucasian": {"skin": "#e6b8a2", "brows": "#5c4332", "iris": "#5b7088"},
    "asian": {"skin": "#e1b690", "brows": "#211b17", "iris": "#3b2618"},
    "african": {"skin": "#7b4b31", "brows": "#161210", "iris": "#2e1b10"},
}
FIXED_COLORS = {
    "lashes": "#1b1511",
    "sclera": "#ede6df",
    "pupil": "#060505",
    "teeth": "#e8dfcf",
    "tongue": "#c46f6c",
    "mouth_interior": "#4a1a1c",
}
GREY_HAIR = "#9a9692"
PAINT_SIZE = (2048, 1024)  # rows (v), columns (u) over assets.PAINT_UV_BOX
_POSITION_MAP_SIZE = (512, 256)
_POSITION_MAP_FILE = "paint-positions-v1.npy"

#: Brow placement on the base mesh, in decimetres relative to the eye centre
#: (x measured outward from the midline). Medial head → peak → tail.
BROW = {
    "x_start": 0.06, "x_end": 0.64,      # along the brow, from the midline
    "lift": 0.20, "arch": 0.048,        # centre height above the eye centre; extra at the peak
    "peak": 0.62,                        # where the arch peaks (fraction along the brow)
    "half_height_head": 0.036, "half_height_tail": 0.013,
}


def character_colors(character: Character) -> dict[str, tuple[float, float, float]]:
    """sRGB colours (0 … 1) for every key in :data:`COLOR_NAMES`."""
    mix = character.ethnicity

    def blend(key):
        lin = sum(w * srgb_to_linear(hex_to_rgb(ETHNIC_COLORS[e][key])) for e, w in mix.items())
        return lin

    skin = blend("skin")
    older = float(np.clip((character.age - 50) / 40, 0, 1))
    skin = skin * (1 - 0.12 * older) + 0.12 * older * skin.mean()  # a little less saturated with age
    colors = {
        "skin": skin,
        "lips": skin * np.array([0.78, 0.50, 0.52]) * (1.0 - 0.1 * older),
        "eyelid": skin * np.array([0.92, 0.80, 0.80]),
        "cheek": skin * np.array([1.0, 0.70, 0.70]),
        "brows": (1 - 0.75 * older) * blend("brows") + 0.75 * older * srgb_to_linear(hex_to_rgb(GREY_HAIR)),
        "iris": blend("iris"),
    }
    colors = {k: tuple(linear_to_srgb(v).tolist()) for k, v in colors.items()}
    colors.update({k: hex_to_rgb(v) for k, v in FIXED_COLORS.items()})
    if older:  # teeth yellow with age
        colors["teeth"] = tuple(np.array(colors["teeth"]) * (1 - 0.08 * older * np.array([0.0, 0.3, 1.0])))
    colors.update({k: hex_to_rgb(v) for k, v in character.colors.items()})
    assert set(colors) == set(COLOR_NAMES)
    return colors


def character_appearance(character: Character, head, *, blush: float | None = None) -> Appearance:
    """The renderer's :class:`Appearance` for ``character`` on ``head``."""
    if blush is None:
        blush = 0.35 * (1.0 - character.gender) + 0.12
    return Appearance(colors=character_colors(character), paint=paint_texture(head, round(blush, 3)))


@lru_cache(maxsize=4)
def paint_texture(head, blush: float) -> np.ndarray:
    """(rows, cols, 4) uint8 paint in the head's normalised UV box: brows, lips, lids, blush."""
    data_masks = head.masks
    # Densities are smooth at half the paint resolution; computing them there saves ~0.4 s.
    positions = _resize(position_map(head), (PAINT_SIZE[0] // 2, PAINT_SIZE[1] // 2))
    brows = _resize(brow_density(positions), PAINT_SIZE)
    cheeks = _resize(blush * cheek_density(positions), PAINT_SIZE)
    lips = _resize(data_masks["lips"].astype(np.float32) / 255, PAINT_SIZE)
    lids = _resize(data_masks["eyelids"].astype(np.float32) / 255, PAINT_SIZE)
    paint = np.empty((*PAINT_SIZE, 4), np.uint8)  # GL order: row 0 is v = 0
    for channel, mask in enumerate((brows, lips, lids, cheeks)):
        paint[..., channel] = np.clip(mask * 255 + 0.5, 0, 255)
    return paint


def brow_density(positions: np.ndarray) -> np.ndarray:
    """Eyebrow hair density (0 … 1) at base-mesh positions (..., 3)."""
    x, y, z = positions[..., 0], positions[..., 1], positions[..., 2]
    c = BROW
    eye_y, eye_z = _EYE_CENTRE[1], _EYE_CENTRE[2]
    along = (np.abs(x) - c["x_start"]) / (c["x_end"] - c["x_start"])
    s = np.clip(along, 0, 1)
    rise = np.where(s < c["peak"], np.sin(0.5 * np.pi * s / c["peak"]), np.cos(0.5 * np.pi * (s - c["peak"]) / (1 - c["peak"]) * 0.8))
    centre = eye_y + c["lift"] + c["arch"] * rise - 0.015 * (s < 0.15) * (0.15 - s) / 0.15
    half = c["half_height_head"] * (1 - s) ** 0.7 + c["half_height_tail"] * s
    across = np.abs(y - centre) / half
    density = smoothstep(1.15, 0.75, across) * smoothstep(-0.02, 0.08, along) * smoothstep(1.02, 0.88, along)
    density *= smoothstep(eye_z - 0.1, eye_z + 0.05, z)  # front of the head only
    return np.where(np.isfinite(density), density, 0.0).astype(np.float32)


def cheek_density(positions: np.ndarray) -> np.ndarray:
    """Soft blush on the apples of the cheeks (0 … 1)."""
    centre = np.array([0.40, _EYE_CENTRE[1] - 0.36, 1.40])
    d = positions - centre * np.array([1, 1, 1])
    d[..., 0] = np.abs(positions[..., 0]) - centre[0]
    r2 = (d ** 2).sum(-1) / 0.16 ** 2
    return np.where(np.isfinite(r2), np.exp(-r2), 0.0).astype(np.float32)


#: hm08's left eye centre (joint-l-eye), decimetres.
_EYE_CENTRE = np.array([0.308, 7.284, 1.245])


def _resize(image: np.ndarray, size: tuple[int, int]) -> np.ndarray:
    """Bilinear resize of a (H, W[, C]) float array to ``size`` (rows, cols)."""
    from PIL import Image

    rows, cols = size
    if image.ndim == 3:
        return np.stack([_resize(image[..., k], size) for k in range(image.shape[2])], axis=-1)
    return np.asarray(Image.fromarray(image.astype(np.float32), "F").resize((cols, rows), Image.BILINEAR))


def position_map(head) -> np.ndarray:
    """Base-mesh 3-D position at each texel of the paint box (NaN off the mesh); cached on disk."""
    path = cache_dir() / _POSITION_MAP_FILE
    if path.exists():
        try:
            return np.load(path)
        except (OSError, ValueError):
            pass  # rebuild a damaged file below
    from scipy.interpolate import LinearNDInterpolator

    topo = head.topology
    inside = (topo.uv >= 0).all(1) & (topo.uv <= 1).all(1) & (topo.region == 0)
    uv = topo.uv[inside]
    xyz = head.base_vertices[head.base_index[topo.render_to_geo[inside]]]
    rows, cols = _POSITION_MAP_SIZE
    v, u = np.meshgrid((np.arange(rows) + 0.5) / rows, (np.arange(cols) + 0.5) / cols, indexing="ij")
    result = LinearNDInterpolator(uv, xyz)(np.stack([u.ravel(), v.ravel()], 1)).reshape(rows, cols, 3)
    result = np.nan_to_num(result, nan=-100.0).astype(np.float32)  # far away: no paint
    path.parent.mkdir(parents=True, exist_ok=True)

    def write(tmp):
        with open(tmp, "wb") as f:
            np.save(f, result)
    atomic_write(path, write)
    return result
