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

import hashlib
from functools import lru_cache

import numpy as np

from facsim.head.assets import cache_dir, cached_array
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Mapping

from facsim.head.character import COLOR_NAMES, EXTRA_COLOR_NAMES, Character
from facsim.head.colour import hex_to_rgb, linear_to_srgb, srgb_to_linear
from facsim.head.skin import fold_texture, tone_texture
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
    "garment": (0.45, 0.47, 0.50),
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
    detail : (H, W, 4) uint8, optional
        Skin detail in the same UV space and row order: R = redness (nose, cheeks, ears,
        caruncle), G = beard area, B = oiliness (the T-zone's sheen, wet lid margins),
        A = the lips' mucosa (their wet inner surface, :func:`facsim.head.mouth.lip_mucosa`).
    beard : float
        0 … 1: how much the beard area shows a shaved stubble shadow.
    beard_grey : float
        0 … 1: how grey the stubble is, from dark hairs' blue-grey shadow to grey and white
        hairs' fainter, neutral one (it follows the scalp hair, not the brows, which grey later).
    age : float
        0 … 1: how strongly the age lines of ``folds`` show (and the skin's mottling).
    tone : (H, W, 4) uint8, optional
        Skin tone maps in the same UV space and row order: R = periorbital darkening,
        G = translucency, B = pore strength, A = sun exposure (see :mod:`facsim.head.skin`).
    freckles : float
        0 … 1: how densely freckles cover the sun-exposed skin (nose, cheekbones, forehead).
    redness : float
        0 … 2: how strongly the redder areas of ``detail`` show (1 = as painted).
    seed : float
        0 … 1000: where this person's skin patterns (mottling, moles, freckles) fall, so two
        people of the same colouring do not share one skin.
    folds : (H, W, 4) uint8, optional
        The skin's folds in the same UV space and row order, shaded as soft grooves:
        R = forehead lines and crow's feet (deepened where expression compresses the skin),
        G = under-eye lines, B = nasolabial and marionette fold shade, A = where R and G replace
        the expression engine's furrows (see :func:`facsim.head.skin.fold_texture`). ``None`` =
        no age lines or folds.
    """

    colors: Mapping[str, tuple[float, float, float]] = field(default_factory=lambda: DEFAULT_COLORS)
    paint: np.ndarray | None = None
    detail: np.ndarray | None = None
    beard: float = 0.0
    beard_grey: float = 0.0
    age: float = 0.0
    tone: np.ndarray | None = None
    freckles: float = 0.0
    redness: float = 1.0
    seed: float = 0.0
    folds: np.ndarray | None = None

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
        if self.detail is not None:
            detail = np.asarray(self.detail)
            if detail.ndim != 3 or detail.shape[2] != 4 or detail.dtype != np.uint8:
                raise ValueError(f"detail must be an (H, W, 4) uint8 array, got {detail.dtype} {detail.shape}")
        for name in ("tone", "folds"):
            value = getattr(self, name)
            if value is not None:
                value = np.asarray(value)
                if value.ndim != 3 or value.shape[2] != 4 or value.dtype != np.uint8:
                    raise ValueError(f"{name} must be an (H, W, 4) uint8 array, got {value.dtype} {value.shape}")
        for name, top in (("beard", 1.0), ("beard_grey", 1.0), ("age", 1.0), ("freckles", 1.0), ("redness", 2.0), ("seed", 1000.0)):
            value = float(getattr(self, name))
            if not 0.0 <= value <= top:
                raise ValueError(f"{name} must be in [0, {top:g}], got {value}")
            object.__setattr__(self, name, value)



#: Young-adult colours per ethnicity (sRGB). Sources: typical values of the
#: Fitzpatrick II / IV / V–VI skin types; brows and irises the commonest shade.
#: The skins' chroma is skin's as measured in vivo (CIELAB C* ~16-18, hue 56-62 degrees): the
#: studio key's warmth, blood and scattering add the rest. (Until session 19 they were at C* 22-26,
#: hue 50-63, and drew at 27-35 on the cheeks: peach and copper, the reviewers' waxy skin;
#: ``python3 scripts/skin_figures.py``, column C*.)
#: Scleras are warmer where the conjunctiva holds more melanin (darker skin types).
ETHNIC_COLORS = {
    "caucasian": {"skin": "#dbbaa8", "brows": "#5c4332", "iris": "#5b7088", "sclera": "#ede6df"},
    "asian": {"skin": "#d9b8a1", "brows": "#211b17", "iris": "#4a321f", "sclera": "#ebe3d8"},
    "african": {"skin": "#6b4f3e", "brows": "#161210", "iris": "#3d2617", "sclera": "#dacdba"},
}
FIXED_COLORS = {
    "lashes": "#1b1511",
    "pupil": "#060505",
    "teeth": "#e8dfcf",
    "tongue": "#c46f6c",
    "mouth_interior": "#4a1a1c",
    # A mid-grey top for characters without their own (characters.yaml gives most theirs):
    # muted and mid-toned, so the clothes never draw the eye from the face.
    "garment": "#7a7d82",
}
GREY_HAIR = "#a8a299"
#: Older skin's loss of red and blue (linear RGB, per unit of character_colors' ``older``, 0 at 50
#: years, 1 at 90): its CIELAB hue turns ~7 degrees toward yellow at 72 (george's base colour: hue 54.5
#: to 61.9). (Until session 24 only desaturated with age: george's cheeks rendered at hue 47, a* 16 -
#: the blind reviewer's "pink waxy skin" on 17 of his 26 images.)
SALLOW_WITH_AGE = (0.02, 0.0, 0.10)
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


@dataclass(frozen=True)
class Complexion:
    """How one person's skin departs from their group's typical colouring.

    ``lightness`` scales the skin colour in linear light; ``undertone`` is -1 (cooler,
    pinker) … 1 (warmer, more golden/olive); ``freckles`` and ``redness`` as in
    :class:`Appearance`; ``seed`` places the person's skin patterns.
    """

    lightness: float = 1.0
    undertone: float = 0.0
    freckles: float = 0.0
    redness: float = 1.0
    seed: float = 0.0


def complexion(character: Character) -> Complexion:
    """The character's own complexion, drawn from a hash of who they are.

    People of one ancestry differ widely in skin colour, undertone, freckling and
    flushing (issue 13: reviewers said the same few identities repeat; every preset of an
    ethnicity had one skin colour). Each character gets a fixed draw (a hash of its preset
    name, or of its parameters for custom characters): lightness within about ±1 Fitzpatrick
    step (wider for dark skin), an undertone, a redness, and freckles mostly on light skin
    (fewer with age: they give way to age spots). The same character always gets the same
    complexion. A ``colors: {skin: ...}`` override still wins.
    """
    key = character.name or repr((character.gender, character.age, character.african, character.asian,
                                  character.caucasian, character.muscle, character.weight,
                                  sorted(character.face.items())))
    digest = hashlib.sha256(f"complexion:{key}".encode()).digest()
    u = [int.from_bytes(digest[4 * k: 4 * k + 4], "little") / 2 ** 32 for k in range(5)]
    mix = character.ethnicity
    light = float(mix.get("caucasian", 0.0)) + 0.4 * float(mix.get("asian", 0.0))
    freckled = light * smoothstep(0.45, 0.75, u[2]) * (1.0 - 0.6 * float(np.clip((character.age - 30) / 40, 0, 1)))
    # Dark skin spans a wider range of lightness (Fitzpatrick IV-VI) than light skin.
    spread = 0.2 + 0.3 * float(mix.get("african", 0.0))
    return Complexion(lightness=round(1.0 + spread * (2.0 * u[0] - 1.0), 3), undertone=round(2.0 * u[1] - 1.0, 3),
                      freckles=round(float(freckled), 3), redness=round(0.8 + 0.6 * u[3], 3),
                      seed=round(1000.0 * u[4], 2))


def character_colors(character: Character) -> dict[str, tuple[float, float, float]]:
    """sRGB colours (0 … 1) for every key in :data:`COLOR_NAMES`, and the scalp ``hair``."""
    mix = character.ethnicity

    def blend(key):
        lin = sum(w * srgb_to_linear(hex_to_rgb(ETHNIC_COLORS[e][key])) for e, w in mix.items())
        return lin

    skin = blend("skin")
    own = complexion(character)
    # Warmer undertones have relatively less blue (and a touch less red: olive), cooler ones
    # are pinker (more red, less green).
    tint = np.array([1.0 - 0.02 * own.undertone, 1.0 - 0.025 * min(own.undertone, 0.0),
                     1.0 - 0.05 * own.undertone])
    skin = skin * own.lightness * tint
    older = float(np.clip((character.age - 50) / 40, 0, 1))
    greying = float(np.clip((character.age - 45) / 25, 0, 1))
    female = float(np.clip(1.0 - character.gender, 0, 1))
    skin = skin * (1 - 0.12 * older) + 0.12 * older * skin.mean()  # a little less saturated with age
    # ... and sallower: older skin yellows (glycated collagen, thinner capillary bed) while its
    # pink fades (SALLOW_WITH_AGE: linear RGB's loss per unit of ``older``), so an old man's skin
    # is a yellowish beige with ruddy patches, not an even pink.
    skin = skin * (1.0 - older * np.array(SALLOW_WITH_AGE))
    colors = {
        "skin": skin,
        # Women's lips are redder and more contrasted against the skin than men's (a cue
        # observers use to tell the sexes apart); both fade a little with age. Lips are darker
        # than the skin and a rose red, bluer than the skin's own hue, and only moderately
        # saturated (measured lips: CIELAB L* 50-57, C* 18-24, hue 25-35 degrees on light skin);
        # until session 20 a paler, orange salmon (ava's lower lip rendered L* 62, C* 35, hue 36).
        "lips": skin * (female * np.array([0.60, 0.40, 0.46]) + (1 - female) * np.array([0.66, 0.49, 0.53]))
        * (1.0 - 0.1 * older),
        # The lids: thin skin over vessels, a little darker and cooler than the face, not pink (until
        # session 20 0.86/0.74/0.74 and 0.92/0.80/0.80: a sore pink ring round george's eyes).
        "eyelid": skin * (female * np.array([0.84, 0.76, 0.78]) + (1 - female) * np.array([0.89, 0.82, 0.84])),
        "cheek": skin * np.array([1.0, 0.76, 0.76]),   # (0.70 until session 20)
        # Brows a shade darker than the scalp hair (their hairs are drawn translucent over
        # the skin, which lightens them); they grey later and less than the scalp.
        "brows": (1 - 0.5 * older) * 0.7 * blend("brows") + 0.5 * older * srgb_to_linear(hex_to_rgb(GREY_HAIR)),
        "iris": blend("iris"),
        # The sclera yellows a little with age.
        "sclera": blend("sclera") * (1.0 - 0.08 * older * np.array([0.0, 0.25, 1.0])),
        # Scalp hair greys earlier and further than the brows.
        "hair": (1 - 0.85 * greying) * blend("brows") * 1.15 + 0.85 * greying * srgb_to_linear(hex_to_rgb(GREY_HAIR)),
    }
    colors = {k: tuple(linear_to_srgb(v).tolist()) for k, v in colors.items()}
    colors.update({k: hex_to_rgb(v) for k, v in FIXED_COLORS.items()})
    if older:  # teeth yellow with age
        colors["teeth"] = tuple(np.array(colors["teeth"]) * (1 - 0.05 * older * np.array([0.0, 0.3, 1.0])))
    colors.update({k: hex_to_rgb(v) for k, v in character.colors.items()})
    assert set(colors) == set(COLOR_NAMES) | set(EXTRA_COLOR_NAMES)
    return colors


def character_appearance(character: Character, head, *, blush: float | None = None,
                         painted_brows: bool = True) -> Appearance:
    """The renderer's :class:`Appearance` for ``character`` on ``head``.

    ``painted_brows=False`` leaves the brows out of the paint (a brow proxy draws them).
    """
    if blush is None:
        # A faint flush on the cheeks' apples, more on women (until session 20 0.35 and 0.12 of a
        # redder colour: session 19 measured the cheeks above in-vivo skin's chroma, mei C* 28).
        blush = 0.2 * (1.0 - character.gender) + 0.06
    every_color = character_colors(character)
    colors = {k: v for k, v in every_color.items() if k in COLOR_NAMES}
    # A shaved beard shows as a faint blue-grey shadow on men; age lines from about 35.
    beard = float(np.clip((character.gender - 0.5) * 2, 0, 1) * np.clip((character.age - 16) / 6, 0, 1)) * 0.8
    # The stubble greys with the scalp hair (linear luminance: dark brown ~0.03, GREY_HAIR 0.36).
    hair_luminance = float(srgb_to_linear(np.asarray(every_color["hair"])) @ np.array([0.2126, 0.7152, 0.0722]))
    beard_grey = float(smoothstep(0.08, 0.25, hair_luminance))
    age = float(np.clip((character.age - 32) / 45, 0, 1))
    own = complexion(character)
    return Appearance(colors=colors, paint=paint_texture(head, round(blush, 3), painted_brows),
                      detail=detail_texture(head), beard=round(beard, 3), beard_grey=round(beard_grey, 3),
                      age=round(age, 3),
                      tone=tone_texture(head, position_map), freckles=own.freckles, redness=own.redness,
                      seed=own.seed, folds=fold_texture(head, position_map))


DETAIL_SIZE = (2048, 1024)  # rows (v), columns (u) over assets.PAINT_UV_BOX; fine enough for the
# lids' wet margins, about a millimetre wide


#: Bump when the detail recipe changes, so cached detail textures are redone.
DETAIL_VERSION = 9  # 9: the beard area over the jaw and lower cheeks to the sideburns; 8: the lips' mucosa in A; 7: the age lines moved to the fold map (facsim.head.skin.fold_texture); 6: wider grooves; 5: positions upsampled cubically; 4: 2048 rows; 3: sheen on the cheekbones; 2: irregular age lines, an asymmetric nasolabial fold


@lru_cache(maxsize=2)
def detail_texture(head) -> np.ndarray:
    """(rows, cols, 4) uint8 skin detail: redness, beard area, oiliness, the lips' mucosa
    (:func:`facsim.head.mouth.lip_mucosa`), placed by anatomy on the base mesh.
    It depends on the base mesh only, so it is computed once and cached on disk."""
    return cached_array(cache_dir() / f"skin-detail-v{DETAIL_VERSION}.npy", lambda: _build_detail(head),
                        valid=lambda a: a.shape == (*DETAIL_SIZE, 4) and a.dtype == np.uint8)


def _build_detail(head) -> np.ndarray:
    # Cubic, not bilinear: a bilinear upsampling's kinks every few texels show as dashes
    # along the thin lid margins.
    from scipy.ndimage import zoom

    from facsim.head.mouth import lip_mucosa

    source = position_map(head)
    positions = zoom(source, (DETAIL_SIZE[0] / source.shape[0], DETAIL_SIZE[1] / source.shape[1], 1), order=3)
    lips = _resize(head.masks["lips"].astype(np.float32) / 255, DETAIL_SIZE)
    centre, radius = head.eye_pivot(head.base_vertices, "left")
    margin = lid_margin_density(positions, centre, radius)
    channels = (np.maximum(redness_density(positions), caruncle_density(positions, centre, radius)),
                beard_density(positions) * (1 - np.clip(lips * 2, 0, 1)),
                np.maximum(oil_density(positions), margin), _vertex_map(head, lip_mucosa(head), DETAIL_SIZE))
    detail = np.empty((*DETAIL_SIZE, 4), np.uint8)
    for k, mask in enumerate(channels):
        detail[..., k] = np.clip(mask * 255 + 0.5, 0, 255)
    return detail


def _blob(positions, centre, radius, *, mirror=True) -> np.ndarray:
    d = np.array(positions, np.float64, copy=True)
    if mirror:
        d[..., 0] = np.abs(d[..., 0])
    r2 = (((d - np.asarray(centre)) / np.asarray(radius)) ** 2).sum(-1)
    return np.exp(-r2)


def lid_margin_density(positions: np.ndarray, centre, radius: float) -> np.ndarray:
    """The wet rim of the lids: skin within half a millimetre or so of the eyeball's front."""
    p = np.array(positions, np.float64, copy=True)
    p[..., 0] = np.abs(p[..., 0])
    gap = np.abs(np.linalg.norm(p - np.asarray(centre), axis=-1) - radius)
    front = smoothstep(centre[2] + 0.3 * radius, centre[2] + 0.6 * radius, p[..., 2])
    return (smoothstep(0.012, 0.0, gap) * front).astype(np.float32)


def caruncle_density(positions: np.ndarray, centre, radius: float) -> np.ndarray:
    """The caruncle: a small pink mound in the inner corner of each eye."""
    # Where the lid margins meet at the inner canthus (measured on hm08: 0.208, 7.280, 1.360).
    inner = (float(centre[0]) - 0.68 * radius, float(centre[1]) - 0.03 * radius, float(centre[2]) + 0.76 * radius)
    return np.clip(1.3 * _blob(positions, inner, (0.022, 0.016, 0.04)), 0, 1).astype(np.float32)


def redness_density(positions: np.ndarray) -> np.ndarray:
    """Where skin is redder: nose tip and wings, the cheeks, chin, ears, lids."""
    red = (0.9 * _blob(positions, (0.0, 6.95, 1.68), (0.10, 0.09, 0.12))
           + 0.6 * _blob(positions, (0.14, 6.87, 1.52), (0.06, 0.06, 0.1))
           + 0.55 * _blob(positions, (0.45, 6.92, 1.30), (0.16, 0.14, 0.2))
           + 0.35 * _blob(positions, (0.0, 6.32, 1.48), (0.12, 0.08, 0.15))
           + 0.35 * _blob(positions, (0.3, 7.28, 1.42), (0.16, 0.09, 0.12))
           + 0.7 * _blob(positions, (0.72, 7.1, 0.75), (0.12, 0.35, 0.3)))
    return np.clip(red, 0, 1).astype(np.float32)


def beard_density(positions: np.ndarray) -> np.ndarray:
    """A man's beard area: upper lip, chin, jaw and the cheeks below the cheekbones, back to the
    sideburns, fading up the cheek.

    The cheek line runs from the nostrils' wings up and out to the sideburns in front of the ear
    (until session 26 it fell toward the ear and stopped 7 mm short of the jaw's sides: at 448 px
    a muzzle round the mouth, and the jaw of george, kofi and the young men as bare as a woman's).
    """
    x, y, z = np.abs(positions[..., 0]), positions[..., 1], positions[..., 2]
    top = 6.84 - 0.3 * np.clip(x - 0.12, 0, 0.12) + 0.42 * np.clip(x - 0.26, 0, 0.46)   # the cheek line
    below_line = smoothstep(top + 0.06, top - 0.1, y)
    not_neck = smoothstep(5.85, 6.05, y) * smoothstep(0.5, 0.72, z)
    off_nose = 1 - _blob(positions, (0.0, 6.86, 1.6), (0.11, 0.05, 0.3))
    # The ear and the skin behind it stay bare: the sideburn ends in front of the tragus.
    off_ear = 1 - smoothstep(0.66, 0.76, x) * smoothstep(0.85, 0.7, z)
    return np.clip(below_line * not_neck * off_nose * off_ear * smoothstep(0.84, 0.74, x), 0, 1).astype(np.float32)


def oil_density(positions: np.ndarray) -> np.ndarray:
    """The T-zone (forehead, nose, chin) is oilier, hence glossier, than the cheeks."""
    oil = (0.85 * _blob(positions, (0.0, 7.75, 1.45), (0.35, 0.25, 0.3))
           + 1.0 * _blob(positions, (0.0, 7.1, 1.62), (0.09, 0.3, 0.2))
           + 0.6 * _blob(positions, (0.0, 6.32, 1.48), (0.14, 0.1, 0.2))
           + 0.3 * _blob(positions, (0.42, 7.0, 1.32), (0.12, 0.09, 0.2)))   # cheekbones catch a sheen
    return np.clip(0.35 + oil, 0, 1).astype(np.float32)


@lru_cache(maxsize=4)
def paint_texture(head, blush: float, brows: bool = True) -> np.ndarray:
    """(rows, cols, 4) uint8 paint in the head's normalised UV box: brows, lips, lids, blush."""
    data_masks = head.masks
    # Densities are smooth at half the paint resolution; computing them there saves ~0.4 s.
    positions = _resize(position_map(head), (PAINT_SIZE[0] // 2, PAINT_SIZE[1] // 2))
    brows = _resize(brow_density(positions), PAINT_SIZE) if brows else np.zeros(PAINT_SIZE, np.float32)
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
    return cached_array(cache_dir() / _POSITION_MAP_FILE, lambda: _build_position_map(head))


def _vertex_map(head, values: np.ndarray, size: tuple[int, int]) -> np.ndarray:
    """(rows, cols) float32 texels of the paint box (``size``) with the skin's per-vertex
    ``values`` ((N_geo,), zero beyond a small patch) interpolated linearly in UV; zero
    outside the patch where they are not."""
    from scipy.interpolate import LinearNDInterpolator

    topo = head.topology
    inside = (topo.uv >= 0).all(1) & (topo.uv <= 1).all(1) & (topo.region == 0)
    uv, value = topo.uv[inside], np.asarray(values, np.float32)[topo.render_to_geo[inside]]
    out = np.zeros(size, np.float32)
    if not (value > 0).any():
        return out
    rows, cols = size
    # Only the texels around the vertices that carry a value (plus a texel), not the whole box.
    lo, hi = uv[value > 0].min(axis=0), uv[value > 0].max(axis=0)
    c0, c1 = int(lo[0] * cols) - 1, int(np.ceil(hi[0] * cols)) + 1
    r0, r1 = int(lo[1] * rows) - 1, int(np.ceil(hi[1] * rows)) + 1
    c0, r0, c1, r1 = max(c0, 0), max(r0, 0), min(c1, cols), min(r1, rows)
    v, u = np.meshgrid((np.arange(r0, r1) + 0.5) / rows, (np.arange(c0, c1) + 0.5) / cols, indexing="ij")
    patch = LinearNDInterpolator(uv, value, fill_value=0.0)(np.stack([u.ravel(), v.ravel()], 1))
    out[r0:r1, c0:c1] = patch.reshape(r1 - r0, c1 - c0)
    return out


def _build_position_map(head) -> np.ndarray:
    from scipy.interpolate import LinearNDInterpolator

    topo = head.topology
    inside = (topo.uv >= 0).all(1) & (topo.uv <= 1).all(1) & (topo.region == 0)
    uv = topo.uv[inside]
    xyz = head.base_vertices[head.base_index[topo.render_to_geo[inside]]]
    rows, cols = _POSITION_MAP_SIZE
    v, u = np.meshgrid((np.arange(rows) + 0.5) / rows, (np.arange(cols) + 0.5) / cols, indexing="ij")
    result = LinearNDInterpolator(uv, xyz)(np.stack([u.ravel(), v.ravel()], 1)).reshape(rows, cols, 3)
    result = np.nan_to_num(result, nan=-100.0).astype(np.float32)  # far away: no paint
    return result
