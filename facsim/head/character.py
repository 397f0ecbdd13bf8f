"""Characters: who the face belongs to, as MakeHuman macro and face-shape weights.

A :class:`Character` is plain parameters; :func:`character_positions` turns them
into base-mesh offsets (``base + offsets`` is that person's neutral face).

Macro weighting (MakeHuman / MPFB scheme, ``targets/macrodetails/macro.json``):
each macro factor is a piecewise-linear partition of unity over its anchors —

- gender 0 (female) … 1 (male): weights (1-g, g) on female/male;
- age in years, mapped to MakeHuman's slider by its anchors 1 y → 0, 11 y → 0.1875,
  25 y → 0.5, 90 y → 1, then split over baby/child/young/old;
- muscle and weight 0 … 1 (0.5 is average): split over min/average/max;
- ethnicity: african, asian, caucasian weights normalised to sum to 1.

Target ``{race}-{gender}-{age}`` gets race·gender·age; target
``universal-{gender}-{age}-{muscle}-{weight}`` gets gender·age·muscle·weight —
products of the factor weights, exactly as MakeHuman combines them. The
MakeHuman expression units exist per ethnicity; they are mixed by the same
ethnicity weights (``Character.ethnicity``).

Face-shape sliders are named after the target files without their direction:
``"nose/nose-hump": 0.4`` applies ``nose/nose-hump-incr`` at 0.4, −0.4 applies
``nose/nose-hump-decr``. Sided sliders may be given once for both sides
(``"eyes/eye-bag"`` drives ``l-eye-bag`` and ``r-eye-bag``).

Examples
--------
>>> macro_weights(Character(gender=1.0, age=25))["caucasian-male-young"]
1.0
>>> round(macro_weights(Character(gender=1.0, age=25, african=1.0))["caucasian-male-young"], 3)
0.5
"""
from __future__ import annotations

import re
import zlib
from dataclasses import dataclass, field, replace
from functools import lru_cache
from typing import Mapping

import numpy as np

from facsim._data import load_yaml

ETHNICITIES = ("african", "asian", "caucasian")
#: Age anchors: MakeHuman slider value ↔ years.
AGE_ANCHORS = ((0.0, 1.0), (0.1875, 11.0), (0.5, 25.0), (1.0, 90.0))
AGE_NAMES = ("baby", "child", "young", "old")
LEVEL_NAMES = {"muscle": ("minmuscle", "averagemuscle", "maxmuscle"), "weight": ("minweight", "averageweight", "maxweight")}
FACE_SHAPE_FOLDERS = ("head", "nose", "mouth", "chin", "cheek", "eyes", "eyebrows", "forehead", "ears", "neck")
#: Which end of a slider pair is negative.
_NEGATIVE_ENDS = ("decr", "down", "in", "backward", "concave", "compress")
_POSITIVE_ENDS = ("incr", "up", "out", "forward", "convex", "uncompress")
#: The colours a character has (display sRGB, 0..1), each overridable in ``colors``.
COLOR_NAMES = ("skin", "lips", "brows", "lashes", "sclera", "iris", "pupil", "teeth", "tongue",
               "mouth_interior", "eyelid", "cheek", "garment")
#: Colours a character has beyond the face renderer's: the scalp hair (its proxy's tint).
EXTRA_COLOR_NAMES = ("hair",)


class CharacterError(ValueError):
    """A character name or parameter is not valid."""


@dataclass(frozen=True)
class Character:
    """A person's identity parameters.

    Parameters
    ----------
    gender : float
        0 female … 1 male.
    age : float
        Years, 1 … 90.
    african, asian, caucasian : float
        Ethnicity mix (normalised; all zero means equal thirds).
    muscle, weight : float
        0 … 1, 0.5 average.
    face : mapping
        Face-shape sliders, ``{"nose/nose-hump": 0.4, ...}``, each in [-1, 1].
    colors : mapping
        Colour overrides, ``{"iris": "#3b6ea5", ...}``; keys in :data:`COLOR_NAMES` or ``hair``.
    hair, brows, lashes : str
        MakeHuman proxy names (``facsim.head.proxies.HAIR_STYLES``, ``EYEBROWS``, ``EYELASHES``;
        hair also a close crop, ``crops:`` in ``facsim/data/hair.yaml``),
        ``"none"``, or ``""`` for one chosen from gender, age and ethnicity
        (``facsim/data/hair.yaml``).
    name : str
        Preset name, or "" for a custom character.
    symmetric : bool
        True: the face's halves are mirror images (for FACS validation and tests). False
        (the default): the character's own small, seeded asymmetry (:func:`natural_asymmetry`,
        ``asymmetry`` in ``characters.yaml``) - its halves differ a little in shape, and its
        expressions act a little more strongly on one side.
    """

    gender: float = 0.5
    age: float = 25.0
    african: float = 0.0
    asian: float = 0.0
    caucasian: float = 1.0
    muscle: float = 0.5
    weight: float = 0.5
    face: Mapping[str, float] = field(default_factory=dict)
    colors: Mapping[str, str] = field(default_factory=dict)
    hair: str = ""
    brows: str = ""
    lashes: str = ""
    name: str = ""
    description: str = ""
    symmetric: bool = False

    def __post_init__(self):
        for key in ("gender", "muscle", "weight", "african", "asian", "caucasian"):
            value = getattr(self, key)
            if not 0.0 <= float(value) <= 1.0:
                raise CharacterError(f"character parameter {key!r} must be in [0, 1], got {value}")
        if not 1.0 <= float(self.age) <= 90.0:
            raise CharacterError(f"character parameter 'age' must be in years from 1 to 90, got {self.age}")
        for key, value in self.face.items():
            if not -1.0 <= float(value) <= 1.0:
                raise CharacterError(f"face-shape slider {key!r} must be in [-1, 1], got {value}")
        for key in self.colors:
            if key not in COLOR_NAMES + EXTRA_COLOR_NAMES:
                raise CharacterError(f"unknown colour {key!r}; choose from {', '.join(COLOR_NAMES + EXTRA_COLOR_NAMES)}")
        from facsim.head.proxies import EYEBROWS, EYELASHES, hair_names

        for key, names in (("hair", hair_names()), ("brows", EYEBROWS), ("lashes", EYELASHES)):
            value = getattr(self, key)
            if value not in ("", "none", *names):
                raise CharacterError(f"unknown {key} {value!r}; choose from {', '.join(names)} or 'none'")
        if not isinstance(self.symmetric, bool):
            raise CharacterError(f"character parameter 'symmetric' must be true or false, got {self.symmetric!r}")
        object.__setattr__(self, "face", dict(self.face))
        object.__setattr__(self, "colors", dict(self.colors))

    @property
    def ethnicity(self) -> dict[str, float]:
        """Ethnicity weights normalised to sum to 1."""
        raw = np.array([self.african, self.asian, self.caucasian], float)
        raw = raw / raw.sum() if raw.sum() > 0 else np.full(3, 1 / 3)
        return dict(zip(ETHNICITIES, raw.tolist()))

    def with_(self, **changes) -> "Character":
        """A copy with some parameters changed (``face``/``colors`` are merged)."""
        if "face" in changes:
            changes["face"] = {**self.face, **changes["face"]}
        if "colors" in changes:
            changes["colors"] = {**self.colors, **changes["colors"]}
        return replace(self, **changes)


# ------------------------------------------------------------ macro weights


def age_slider(years: float) -> float:
    """MakeHuman's age slider value (0 … 1) for an age in years."""
    values, years_at = zip(*AGE_ANCHORS)
    return float(np.interp(years, years_at, values))


def _split(value: float, anchors: tuple[float, ...], names: tuple[str, ...]) -> dict[str, float]:
    """Piecewise-linear partition of unity of ``value`` over anchored names."""
    weights = dict.fromkeys(names, 0.0)
    value = min(max(value, anchors[0]), anchors[-1])
    for i in range(len(anchors) - 1):
        lo, hi = anchors[i], anchors[i + 1]
        if value <= hi:
            t = (value - lo) / (hi - lo)
            weights[names[i]] += 1.0 - t
            weights[names[i + 1]] += t
            break
    return weights


def macro_weights(character: Character) -> dict[str, float]:
    """Weight of every macro target (name without ``macrodetails/``) for ``character``."""
    gender = {"female": 1.0 - character.gender, "male": character.gender}
    age = _split(age_slider(character.age), tuple(a for a, _ in AGE_ANCHORS), AGE_NAMES)
    muscle = _split(character.muscle, (0.0, 0.5, 1.0), LEVEL_NAMES["muscle"])
    weight = _split(character.weight, (0.0, 0.5, 1.0), LEVEL_NAMES["weight"])
    out: dict[str, float] = {}
    for g, wg in gender.items():
        for a, wa in age.items():
            for race, wr in character.ethnicity.items():
                out[f"{race}-{g}-{a}"] = wr * wg * wa
            for m, wm in muscle.items():
                for w, ww in weight.items():
                    out[f"universal-{g}-{a}-{m}-{w}"] = wg * wa * wm * ww
    return {k: v for k, v in out.items() if v > 1e-6}


def face_shape_weights(face: Mapping[str, float], available: set[str]) -> dict[str, float]:
    """Target weights for face-shape sliders; raises for unknown slider names."""
    out: dict[str, float] = {}
    for slider, value in face.items():
        folder, _, stem = slider.partition("/")
        if folder not in FACE_SHAPE_FOLDERS or not stem:
            raise CharacterError(f"unknown face-shape slider {slider!r}; names look like 'nose/nose-hump'")
        stems = [stem] if f"{folder}/{stem}" in available or _ends(folder, stem, available) else [
            s for s in (f"l-{stem}", f"r-{stem}") if _ends(folder, s, available)
        ]
        if not stems:
            raise CharacterError(f"unknown face-shape slider {slider!r}; `facsim characters --sliders` lists them")
        for s in stems:
            if f"{folder}/{s}" in available:  # one-ended slider (e.g. head/head-oval)
                if value < 0:
                    raise CharacterError(f"face-shape slider {slider!r} only goes from 0 to 1")
                out[f"{folder}/{s}"] = float(value)
                continue
            neg, pos = _ends(folder, s, available)
            out[f"{folder}/{s}-{pos if value >= 0 else neg}"] = abs(float(value))
    return out


def _ends(folder: str, stem: str, available: set[str]):
    for neg, pos in zip(_NEGATIVE_ENDS, _POSITIVE_ENDS):
        if f"{folder}/{stem}-{neg}" in available and f"{folder}/{stem}-{pos}" in available:
            return neg, pos
    return None


def slider_names(available) -> list[str]:
    """Every face-shape slider the data offers (sided ones also without l-/r-)."""
    names = set()
    for target in available:
        folder, _, file = target.partition("/")
        if folder not in FACE_SHAPE_FOLDERS:
            continue
        stem = re.sub(r"-(%s)$" % "|".join(_NEGATIVE_ENDS + _POSITIVE_ENDS), "", file)
        names.add(f"{folder}/{stem}")
        names.add(f"{folder}/{re.sub(r'^[lr]-', '', stem)}")
    return sorted(names)


def character_weights(character: Character, available: set[str]) -> dict[str, float]:
    """All target weights (macro + face shape, with the character's natural asymmetry) for ``character``."""
    weights = {f"macrodetails/{k}": v for k, v in macro_weights(character).items()}
    weights.update(face_shape_weights(asymmetric_face(character), available))
    return weights


# ------------------------------------------------------------ asymmetry


@dataclass(frozen=True)
class Asymmetry:
    """A character's natural asymmetry: how its two halves differ.

    ``shape``: sided slider (``"eyes/l-eye-trans"``) → value added on that side;
    ``expression``: side (``"left"``/``"right"``) → factor on every AU's register weights there.
    """

    shape: Mapping[str, float]
    expression: Mapping[str, float]


NO_ASYMMETRY = Asymmetry({}, {"left": 1.0, "right": 1.0})


def asymmetry_seed(character: Character) -> int:
    """The seed of a character's asymmetry: the CRC-32 of its name (0 for an unnamed one, so changing
    a custom character's sliders does not redraw its asymmetry)."""
    return zlib.crc32(character.name.encode())


def natural_asymmetry(character: Character) -> Asymmetry:
    """The character's own small differences between its halves (``asymmetry`` in ``characters.yaml``).

    Each listed sided slider moves apart on the two sides by a draw of N(0, sd), half each way;
    every AU acts on one side stronger by a draw of N(0, sd) of its weight, half each way. Draws
    are clipped to two sd and seeded by :func:`asymmetry_seed`, so a character always has the same face.
    A ``symmetric`` character has none.

    >>> natural_asymmetry(Character(symmetric=True)) == NO_ASYMMETRY
    True
    >>> natural_asymmetry(preset("ava")) == natural_asymmetry(preset("ava"))
    True
    """
    if character.symmetric:
        return NO_ASYMMETRY
    table = _preset_table()["asymmetry"]
    rng = np.random.default_rng([asymmetry_seed(character), 14])

    def draw(sd: float) -> float:
        return float(np.clip(rng.normal(0.0, sd), -2.0 * sd, 2.0 * sd))

    shape = {}
    for slider, sd in table["shape"].items():
        folder, _, stem = slider.partition("/")
        apart = draw(float(sd))
        shape[f"{folder}/l-{stem}"], shape[f"{folder}/r-{stem}"] = apart / 2, -apart / 2
    gain = draw(float(table["expression"]))
    return Asymmetry(shape, {"left": 1.0 + gain / 2, "right": 1.0 - gain / 2})


def asymmetric_face(character: Character) -> dict[str, float]:
    """The character's face-shape sliders with its natural asymmetry added, side by side."""
    face = dict(character.face)
    for sided, offset in natural_asymmetry(character).shape.items():
        folder, _, stem = sided.partition("/")
        both = f"{folder}/{stem[2:]}"   # the slider for both sides, now given per side
        base = character.face.get(sided, character.face.get(both, 0.0))
        face.pop(both, None)
        face[sided] = float(np.clip(base + offset, -1.0, 1.0))
    return face


def apply_targets(base: np.ndarray, data, weights: Mapping[str, float]) -> np.ndarray:
    """``base + Σ w·target`` over named targets of ``data`` (float32 copy)."""
    out = np.array(base, np.float32, copy=True)
    for name, w in weights.items():
        idx, delta = data.target(name)
        out[idx] += w * delta  # a target lists each vertex once
    return out


def character_positions(character: Character, data) -> np.ndarray:
    """Morphed base vertices (19158, 3) for ``character``, its mouth's parts at rest
    (:func:`facsim.head.mouth.rest_mouth`)."""
    from facsim.head.mouth import rest_mouth

    return rest_mouth(apply_targets(data.base_vertices, data, character_weights(character, set(data.target_names))), data,
                      age=character.age)


# ------------------------------------------------------------------ presets


@lru_cache(maxsize=1)
def _preset_table() -> dict:
    return load_yaml("characters.yaml")


def preset_names() -> list[str]:
    return list(_preset_table()["presets"])


def preset(name: str) -> Character:
    """The named preset character (see ``facsim/data/characters.yaml``)."""
    table = _preset_table()["presets"]
    if name not in table:
        raise CharacterError(f"unknown character {name!r}; choose from {', '.join(table)} (or 'random:SEED')")
    return character_from_mapping({"name": name, **table[name]})


def character_from_mapping(entry: Mapping) -> Character:
    """A Character from plain parameters; ethnicities not given count as 0 when any is given."""
    entry = dict(entry)
    unknown = set(entry) - set(Character.__dataclass_fields__)
    if unknown:
        raise CharacterError(f"unknown character parameter(s) {', '.join(sorted(unknown))}")
    if any(e in entry for e in ETHNICITIES):
        entry = {**dict.fromkeys(ETHNICITIES, 0.0), **entry}
    return Character(**entry)


def random_character(seed: int) -> Character:
    """A seeded random adult: the same seed always gives the same person.

    Face-shape sliders and head shapes are drawn as ``random`` in ``characters.yaml`` says.
    """
    table = _preset_table()["random"]
    rng = np.random.default_rng(seed)
    mix = rng.dirichlet([0.6, 0.6, 0.6])
    sd = float(table["sd"])
    face = {slider: float(np.clip(rng.normal(0.0, sd), -2.5 * sd, 2.5 * sd)) for slider in table["sliders"]}
    face[str(rng.choice(table["head_shapes"]))] = float(rng.uniform(0.0, table["head_shape_max"]))
    return Character(
        gender=float(np.clip(rng.integers(0, 2) + rng.normal(0.0, 0.08), 0, 1)),
        age=float(rng.uniform(18, 80)),
        african=float(mix[0]), asian=float(mix[1]), caucasian=float(mix[2]),
        muscle=float(np.clip(rng.normal(0.5, 0.12), 0, 1)),
        weight=float(np.clip(rng.normal(0.5, 0.15), 0, 1)),
        face=face,
        name=f"random:{seed}",
    )


def resolve_character(spec) -> Character:
    """A Character from a preset name, ``"random:SEED"``, a mapping or a Character."""
    if isinstance(spec, Character):
        return spec
    if isinstance(spec, Mapping):
        return character_from_mapping(spec)
    if spec is None:
        return preset(_preset_table()["default"])
    text = str(spec)
    if text.startswith("random:") or text.startswith("random"):
        seed = text.partition(":")[2] or "0"
        if not seed.isdigit():
            raise CharacterError(f"random characters are named 'random:SEED' with an integer seed, got {text!r}")
        return random_character(int(seed))
    return preset(text)
