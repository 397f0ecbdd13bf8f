"""The register engine: AUs → morph-target weights (HapFACS §3.2) → geometry.

Each AU drives a set of ⟨target, maximum weight⟩ pairs read from
``facsim/data/registers.yaml``; targets shared by several active AUs combine by
HapFACS Eq. 1 (:func:`combine_registers`), each AU at :func:`response` of its
intensity (concave: skin stiffens as it stretches). Head codes 51–58 move the head
rigidly with a smooth blend into the neck, eye codes 61–66 rotate the
eyeballs about their centres (and the lids follow vertical gaze via registers).

Examples
--------
>>> combine_registers([(0.3, 0.6), (0.5, 1.0)])   # AUs x, y share a register
0.6
>>> round(combine_registers([(0.2, 0.6), (0.3, 1.0)]), 2)   # 0.2·0.6 + 0.3·1.0, under 0.6
0.42
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property, lru_cache
from typing import Iterable, Mapping

import numpy as np

from facsim._data import load_yaml
from facsim.engines.base import Deformation
from facsim.engines.guard import SkinGuard
from facsim.engines.rigid import RigidMotion, rigid_codes, rigid_table
from facsim.facs.activations import Activations
from facsim.head.surface import smoothstep

#: Half-width (dm) of the smooth left/right split of two-sided targets at the midline.
MIDLINE_BLEND = 0.06
#: One-sided targets may act across the midline (the lips are one piece) but not
#: beyond this band (dm): the authored Face Units carry stray offsets on the far
#: side (eyeBlinkLeft moves the right eye socket), which unilateral AUs must not show.
SIDED_REACH = (0.05, 0.15)
#: Two-sided targets that move the mandible, one bone: the character's natural asymmetry (one
#: hemiface acting more strongly) must not drop one half of the jaw further than the other - it
#: skewed the open mouth and shifted the chin sideways (liam's and george's surprise, blind review).
BONE_TARGETS = frozenset({"faceunits/jawOpen", "faceunits/jawForward"})


@lru_cache(maxsize=1)
def register_table() -> dict:
    """The parsed ``registers.yaml`` (the one source of the mapping)."""
    return load_yaml("registers.yaml")


def simulated_codes() -> set[int]:
    """AU codes this engine renders."""
    return set(register_table()["action_units"]) | rigid_codes()


def stiffening(code: int | None = None) -> float:
    """The ``k`` of :func:`response`: AU ``code``'s own ``stiffening`` in the table, else the table's."""
    entry = register_table()["action_units"].get(code, {}) if code is not None else {}
    return float(entry.get("stiffening", register_table()["response"]["stiffening"]))


def response(level: float, code: int | None = None) -> float:
    """The share of its registers' maxima AU ``code`` reaches at intensity ``level`` (0..1).

    ``ln(1 + k·level) / ln(1 + k)`` with ``k`` the table's ``response: stiffening`` (or the AU's
    own): 0 at 0, 1 at 1, concave, as skin that stiffens as it stretches moves under a
    growing pull (the reasoning and the fit are in ``registers.yaml``).

    >>> response(0.0), response(1.0)
    (0.0, 1.0)
    >>> round(response(0.5), 2)
    0.62
    """
    k = stiffening(code)
    return math.log1p(k * level) / math.log1p(k)


def response_inverse(weight: float, code: int | None = None) -> float:
    """The intensity whose :func:`response` is ``weight`` (0..1): reads levels back from weights.

    >>> round(response_inverse(response(0.3)), 12)
    0.3
    """
    k = stiffening(code)
    return math.expm1(weight * math.log1p(k)) / k


def combine_registers(contributions: Iterable[tuple[float, float]]) -> float:
    """HapFACS Eq. 1: sum of ``intensity × max`` over AUs, clamped to the smallest max —
    but never below what the strongest AU gives the register on its own.

    ``contributions`` holds one ``(intensity, max)`` pair per active AU sharing the register.
    Eq. 1 taken literally lets a weak partner undo a strong AU: 25 (lips part, jaw max 0.06)
    added to 26 (jaw drop) would close the jaw to 25's 0.06, and 9 added to 4 would lift
    the brows. The clamp is there to stop sums beyond what the face can do, and a value
    one AU reaches alone is within that, so it stays.

    >>> combine_registers([(0.2, 0.6), (0.3, 1.0)])  # within the smallest max: the sum
    0.42
    >>> combine_registers([(1.0, 0.06), (1.0, 0.4)])  # 25 + 26 keeps 26's jaw drop
    0.4
    """
    pairs = list(contributions)
    if not pairs:
        return 0.0
    total = sum(level * vmax for level, vmax in pairs)
    strongest = max(level * vmax for level, vmax in pairs)
    return max(min(total, min(vmax for _, vmax in pairs)), strongest)


@dataclass(frozen=True)
class Column:
    """One morph direction: a target (or an ethnicity mix of one) on one side or both."""

    pattern: str         # target name with {Side}/{side}/{s} (and maybe {ethnicity}) unexpanded
    side: str            # "left" or "right"

    @property
    def target(self) -> str:
        return _expand(self.pattern, self.side)[0]

    @property
    def sided(self) -> bool:
        """A one-sided target; otherwise this column is the ``side`` half of a two-sided one."""
        return _expand(self.pattern, self.side)[1]


def _expand(pattern: str, side: str) -> tuple[str, bool]:
    """Fill the side placeholders; returns (name, whether the target is one-sided)."""
    sided = any(k in pattern for k in ("{Side}", "{side}", "{s}"))
    name = pattern.replace("{Side}", side.capitalize()).replace("{side}", side).replace("{s}", side[0])
    return name, sided


def register_weights(act: Activations, fitted: Mapping[tuple[int, str], float] | None = None) -> dict[Column, float]:
    """Column weights for ``act`` by Eq. 1 — the pure heart of the engine.

    Each AU takes :func:`response` of its intensity times each register's maximum
    (the combination rules, read from intensities, may scale the maximum; ``fitted``
    maps ``(code, target pattern)`` to a character's own factor on one register). A
    two-sided target used by an AU on one side only is split at the midline:
    it gets a left and a right column, each weighted by its own side's AUs.
    """
    fitted = fitted or {}
    table = register_table()["action_units"]
    contributions: dict[Column, list[tuple[float, float]]] = {}
    for (code, side), level in act:
        if table.get(code, {}).get("direction") and side == "right" and act[code, "left"] == level:
            continue  # a direction code given without a side (e.g. 30) moves to the left only
        scale = combination_scales(act, code, side)
        weight = response(level, code)
        for reg in table.get(code, {}).get("registers", []):
            vmax = float(reg["max"]) * scale.get(reg["target"], 1.0) * fitted.get((code, reg["target"]), 1.0)
            contributions.setdefault(Column(reg["target"], side), []).append((weight, vmax))
    return {col: combine_registers(pairs) for col, pairs in contributions.items()}


def combination_scales(act: Activations, code: int, side: str) -> dict[str, float]:
    """Target → factor on AU ``code``'s maxima on ``side`` from the table's ``combinations``.

    A rule applies when every AU it names acts on that side and none of those it
    lists under ``unless`` does. Its factor applies in full when the other AUs of the
    rule act at least as strongly as ``code`` and fades with their share of ``code``'s
    intensity (and out with an ``unless`` AU's), so the face moves smoothly as a
    partner AU fades in. The whole expression at half intensity (HapFACS's 50 %
    emotions) keeps the combination's appearance: both AUs are halved, the conflict
    between them is the same, so is the rule (fear at 50 % keeps raised inner brows).

    >>> round(combination_scales(Activations({(1, "left"): 1.0, (4, "left"): 1.0}), 4, "left")["faceunits/browDown{Side}"], 6)
    0.7
    >>> round(combination_scales(Activations({(1, "left"): 0.5, (4, "left"): 0.5}), 4, "left")["faceunits/browDown{Side}"], 6)
    0.7
    >>> round(combination_scales(Activations({(1, "left"): 0.5, (4, "left"): 1.0}), 4, "left")["faceunits/browDown{Side}"], 6)
    0.85
    >>> combination_scales(Activations({(4, "left"): 1.0}), 4, "left")
    {}
    >>> combination_scales(Activations({(1, "left"): 1.0, (4, "left"): 1.0, (5, "left"): 1.0}), 5, "left")
    {}
    """
    out: dict[str, float] = {}
    level = act[code, side]
    if level <= 0.0:
        return out
    for rule in register_table().get("combinations") or []:
        scale = rule["scale"]
        if scale["au"] != code:
            continue
        partners = [act[c, side] for c in rule["when"] if c != code]
        share = min(1.0, min(partners, default=level) / level)
        # ``unless``: AUs that undo the rule's reason fade it out as they come in
        share *= 1.0 - min(1.0, max((act[c, side] for c in rule.get("unless", ())), default=0.0) / level)
        if share <= 0.0:
            continue
        factor = 1.0 - share * (1.0 - float(scale["by"]))
        for target in scale["targets"]:
            out[target] = out.get(target, 1.0) * factor
    return out


def mandible_spec() -> dict:
    """The table's ``mandible``: the jaw's target, its hinge joint and the landmark that turns with the bone."""
    return register_table().get("mandible") or {}


def turning_angles(offsets: np.ndarray, positions: np.ndarray, hinge: np.ndarray) -> np.ndarray:
    """How far (radians, + opening the jaw: the front moving down) each offset (N, 3) turns its
    point of ``positions`` (N, 3) about the left-right axis through ``hinge`` (3,).

    >>> turning_angles(np.array([[0.0, -0.1, 0.0]]), np.array([[0.0, 0.0, 1.0]]), np.zeros(3)).round(3)
    array([0.1])
    """
    radial = np.asarray(positions, np.float64)[:, 1:] - np.asarray(hinge, np.float64)[1:]
    tangent = np.stack([-radial[:, 1], radial[:, 0]], axis=1)  # (y, z) -> (-z, y): the front turns down
    return (np.asarray(offsets, np.float64)[:, 1:] * tangent).sum(axis=1) / np.maximum((radial ** 2).sum(axis=1), 1e-12)


def turn_no_further_than(offsets: np.ndarray, positions: np.ndarray, hinge: np.ndarray, reference: int) -> np.ndarray:
    """A jaw target's ``offsets`` (N, 3) with no point turning about ``hinge`` further than the point
    ``reference`` (an index: the chin) does: the offsets of points that turn further are scaled
    down to its angle. The lower lip lies on the mandible and drops with it.

    >>> pos = np.array([[0.0, 0.0, 1.0], [0.0, -0.2, 1.0]])
    >>> off = np.array([[0.0, -0.1, 0.0], [0.0, -0.15, -0.03]])
    >>> turn_no_further_than(off, pos, np.zeros(3), 0).round(3)
    array([[ 0.  , -0.1 ,  0.  ],
           [ 0.  , -0.1 , -0.02]])
    """
    angles = turning_angles(offsets, positions, hinge)
    limit = float(angles[reference])
    scale = np.where(angles > limit, limit / np.maximum(angles, 1e-12), 1.0)
    return (np.asarray(offsets) * scale[:, None]).astype(np.asarray(offsets).dtype)


def carried_by_the_bone(offsets: np.ndarray, positions: np.ndarray, hinge: np.ndarray, reference: int) -> np.ndarray:
    """Offsets (N, 3) of ``positions`` (N, 3) moved rigidly with the point ``reference`` (the chin):
    turned about the left-right axis through ``hinge`` by the angle ``offsets`` turn it, then shifted
    by what its own offset adds to that turn (the condyles gliding down and forward).

    The chin keeps its own offset; a point half as far in front of the hinge drops half as far:

    >>> pos = np.array([[0.0, 0.0, 1.0], [0.3, 0.0, 0.5]])
    >>> carried_by_the_bone(np.array([[0.0, -0.1, 0.0], [0.0, 0.0, 0.0]]), pos, np.zeros(3), 0).round(3)
    array([[ 0.   , -0.1  ,  0.   ],
           [ 0.   , -0.05 ,  0.002]])
    """
    positions = np.asarray(positions, np.float64)
    angle = float(turning_angles(offsets[reference:reference + 1], positions[reference:reference + 1], hinge)[0])
    radial = positions[:, 1:] - np.asarray(hinge, np.float64)[1:]
    c, s = math.cos(angle), math.sin(angle)
    turned = np.stack([radial[:, 0] * c - radial[:, 1] * s, radial[:, 0] * s + radial[:, 1] * c], axis=1) - radial
    shift = np.asarray(offsets[reference], np.float64)[1:] - turned[reference]
    out = np.zeros_like(positions)
    out[:, 1:] = turned + shift
    return out


def lowering_part(offsets: np.ndarray, band: float) -> np.ndarray:
    """The downward part of a target's ``offsets`` (N, 3): points it lowers by ``band`` (dm) or more
    keep their whole offset, points it raises keep none (a smooth step between), so an AU can take
    one lip's motion from a target that moves both (``lowering_only`` in the table).

    >>> lowering_part(np.array([[0.1, -0.2, 0.0], [0.1, 0.2, 0.0], [0.1, 0.0, 0.0]]), 0.1).round(3)
    array([[ 0.1, -0.2,  0. ],
           [ 0. ,  0. ,  0. ],
           [ 0. ,  0. ,  0. ]])
    """
    offsets = np.asarray(offsets)
    share = smoothstep(0.0, -band, offsets[:, 1].astype(np.float64))
    return (offsets * share[:, None]).astype(offsets.dtype)


def mandible_share(heights: np.ndarray, lip_line: float, band: tuple[float, float]) -> np.ndarray:
    """How much of the jaw target's motion each skin point of height ``heights`` (N,) keeps: all of it
    ``band[0]`` (dm) or more below ``lip_line`` (the lip corners' height), none ``band[1]`` or more above
    it, where the skin lies on the maxilla, which does not move (a smooth step between).

    >>> mandible_share(np.array([-0.1, 0.0, 0.1]), 0.0, (0.04, 0.08)).round(3)
    array([1.   , 0.741, 0.   ])
    """
    return smoothstep(lip_line + band[1], lip_line - band[0], np.asarray(heights, np.float64))


class RegisterEngine:
    """The register engine (an :class:`~facsim.engines.base.Engine`): Activations → :class:`Deformation`.

    Built once per character from ``(head, data, character, base_positions)``, as every
    :class:`~facsim.engines.base.Engine` is.
    """

    name = "registers"
    #: Each frame depends on its activations alone (a video may reuse a frame's picture).
    stateless = True

    def __init__(self, head, data, character, base_positions):
        self.head = head
        self.data = data
        self.base_positions = np.asarray(base_positions, np.float32)
        self.ethnicity = character.ethnicity
        from facsim.head.character import natural_asymmetry

        #: Side → factor on every AU's register weights there (the character's natural asymmetry).
        self.side_gain = dict(natural_asymmetry(character).expression)
        # The sculpted face (MakeHuman's staring lids); the rest is it with relaxed lids (:attr:`neutral`).
        self.sculpted = head.positions(self.base_positions)
        x = self.base_positions[head.base_index, 0]
        self._half = smoothstep(-MIDLINE_BLEND, MIDLINE_BLEND, x).astype(np.float32)
        self._reach = smoothstep(-SIDED_REACH[1], -SIDED_REACH[0], x).astype(np.float32)  # left-side targets
        self._columns: dict[Column, np.ndarray] = {}
        self.rigid = RigidMotion(head, self.base_positions)

    def column(self, col: Column) -> np.ndarray:
        """Offsets (N_base_geo, 3) of one column, mixed by ethnicity and split by side.

        Right-side columns are the mirror images of the left ones: the authored
        targets are a little asymmetric, and FACS stimuli must not be.
        """
        if col not in self._columns and col.side == "right":
            left = self.column(Column(col.pattern, "left"))
            mirror = self.head.mirror[: len(self.head.base_index)]
            self._columns[col] = left[mirror] * np.array([-1.0, 1.0, 1.0], np.float32)
        if col not in self._columns:
            offsets = np.zeros((len(self.head.base_index), 3), np.float32)
            mixes = self.ethnicity.items() if "{ethnicity}" in col.target else [(None, 1.0)]
            for ethnicity, weight in mixes:
                name = col.target.replace("{ethnicity}", ethnicity) if ethnicity else col.target
                idx, delta = self.data.target(name)
                geo = self.head.geo_of_base[idx]
                keep = geo >= 0
                offsets[geo[keep]] += weight * delta[keep]
            if col.pattern == mandible_spec().get("target"):
                offsets = self._on_the_mandible(offsets)
            if col.pattern in (register_table().get("skin_only") or ()):
                offsets[self.head.skin_vertex_count:] = 0.0   # the teeth and tongue keep their shape
            lowering = (register_table().get("lowering_only") or {}).get(col.pattern)
            if lowering:
                offsets = lowering_part(offsets, float(lowering["band_mm"]) / 100.0)
            reach = (register_table().get("corner_reach") or {}).get(col.pattern)
            if reach:
                offsets = self._near_the_corner(offsets, col.side, reach)
            ungathered = (register_table().get("brows_not_gathered") or {}).get(col.pattern)
            if ungathered:
                offsets = self._brows_not_gathered(offsets, ungathered)
            offsets *= (self._reach if col.sided else self._half)[:, None]
            self._columns[col] = offsets
        return self._columns[col]

    def _on_the_mandible(self, offsets: np.ndarray) -> np.ndarray:
        """The jaw target's ``offsets`` (N_base_geo, 3), no skin point turning further about the jaw's
        hinge than the chin does (:func:`turn_no_further_than`, ``mandible`` in the table)."""
        from facsim.head.landmarks import landmarks

        spec = mandible_spec()
        positions = self.base_positions[self.head.base_index]
        skin = self.head.skin_vertex_count
        marks = landmarks(self.head)
        out = np.array(offsets, copy=True)
        hinge = self.head.joint(self.base_positions, spec["hinge"])
        out[:skin] = turn_no_further_than(offsets[:skin], positions[:skin], hinge, marks[spec["reference"]])
        # how far each point rides the mandible: its own turn as a share of the chin's, or its binding to the bone
        angles = turning_angles(out, positions, hinge)
        riding = np.clip(angles / float(angles[marks[spec["reference"]]]), 0.0, 1.0)
        bone = spec.get("rigid")
        if bone:
            share = self._on_the_bone(bone)
            riding[:skin] += share * (1.0 - riding[:skin])
            carried = carried_by_the_bone(out[:skin], positions[:skin], hinge, marks[spec["reference"]])
            out[:skin] += share[:, None].astype(out.dtype) * (carried - out[:skin])
        lower_lip = spec.get("lower_lip")
        if lower_lip:
            out[:skin] *= self._lower_lip_turn(out[:skin], positions[:skin], hinge, lower_lip)[:, None].astype(out.dtype)
        glide = spec.get("glide")
        if glide:
            out[:, 2] += (float(glide["forward_mm"]) / 100.0 * riding).astype(out.dtype)
        held = spec.get("maxilla")
        if held:
            out[:skin] = self._held_by_the_maxilla(out[:skin], positions[:skin], held, share if bone else None)
        return out

    def _held_by_the_maxilla(self, offsets: np.ndarray, positions: np.ndarray, spec: Mapping, bound) -> np.ndarray:
        """The jaw target's skin ``offsets`` (N_skin, 3) kept below the lip corners' line and stilled above it,
        where the skin lies on the maxilla (:func:`mandible_share`, ``mandible.maxilla`` in the table). Beside
        the mouth (``spec["beside"]``) the band between the two grows taller - the cheek hangs between the
        zygoma and the mandible - and the skin in it follows smoothly from the moving to the still skin."""
        lip_line, half_width = self._mouth_line(positions, spec["lip_line"])
        below, above = float(spec["free_below_mm"]) / 100.0, float(spec["held_above_mm"]) / 100.0
        beside = spec.get("beside")
        if beside:
            lateral = smoothstep(float(beside["from"]) * half_width, float(beside["full"]) * half_width, np.abs(positions[:, 0]))
            below = below + lateral * (float(beside["free_below_mm"]) / 100.0 - below)
            above = above + lateral * (float(beside["held_above_mm"]) / 100.0 - above)
        share = mandible_share(positions[:, 1], lip_line, (below, above))
        out = offsets * share[:, None].astype(offsets.dtype)
        passes = int(beside.get("smoothing_passes", 0)) if beside else 0
        if passes:
            zone = (positions[:, 1] < lip_line + above) & (positions[:, 1] > lip_line - float(beside["smooth_below_mm"]) / 100.0)
            if bound is not None:
                zone &= bound < float(beside["bound"])
            # the height only: the depth keeps the target's, so the skin stays in front of the mouth's lining
            out[:, 1] = self._relaxed(out[:, 1:2], passes, ~zone, int(beside.get("lip_rings", 0)))[:, 0]
        return out

    def _lower_lip_turn(self, offsets: np.ndarray, positions: np.ndarray, hinge: np.ndarray, spec: Mapping) -> np.ndarray:
        """Per skin point (N_skin,), the factor on the jaw target's ``offsets`` (N_skin, 3) that turns the lower
        lip and the lining behind it (below the corners' line) as far about ``hinge`` as the chin, in full
        within ``spec["full_within"]`` of the mouth's half-width and fading to the target's own turn at the
        corners (``mandible.lower_lip`` in the table). Points turning less than ``spec["share_ramp"][0]`` of the
        chin's angle keep their own turn: mostly the upper lip's inner side, hanging below that line; from there
        to ``spec["share_ramp"][1]`` the factor comes in smoothly, as the lower lip's turn itself grows toward
        the corners (a hard cut there tore neighbouring points of the lateral lower lip 2-3 mm apart)."""
        from facsim.engines.muscle.net import MOUTH, anatomy
        from facsim.head.landmarks import landmarks

        anat = anatomy(self.head)
        marks = landmarks(self.head)
        angles = turning_angles(offsets, positions, hinge)
        chin = float(angles[marks[mandible_spec()["reference"]]])
        lip_line, half_width = self._mouth_line(positions, "lip_corner")
        lower = ((self._lips > 0.5) | (anat.kind == MOUTH)) & (positions[:, 1] < lip_line) & (angles < chin)
        low, high = (float(share) * chin for share in spec["share_ramp"])
        taper = smoothstep(half_width, float(spec["full_within"]) * half_width, np.abs(positions[:, 0]))
        taper = taper * smoothstep(low, high, angles)
        return np.where(lower, 1.0 + taper * (chin / np.maximum(angles, 1e-12) - 1.0), 1.0)

    def _mouth_line(self, positions: np.ndarray, mark: str) -> tuple[float, float]:
        """(height, half-width) of the line through the two ``mark`` landmarks (``lip_corner``:
        the lip corners) on skin ``positions`` (N_skin, 3), both sides' mean."""
        from facsim.head.landmarks import landmarks

        marks = landmarks(self.head)
        corners = [positions[marks[f"{mark}_{side}"]] for side in ("left", "right")]
        return float(np.mean([c[1] for c in corners])), float(np.mean([abs(c[0]) for c in corners]))

    @cached_property
    def _lips(self) -> np.ndarray:
        """The lips' mask per skin point (N_skin,), 0 to 1, made symmetric (the larger of a point's and its
        mirror's), so both halves of the mouth are treated alike."""
        from facsim.engines.muscle.net import anatomy, mask_per_vertex

        anat = anatomy(self.head)
        lips = mask_per_vertex(self.head, "lips")[: anat.skin_count]
        return np.maximum(lips, lips[anat.mirror[: anat.skin_count]])

    def _on_the_bone(self, spec: Mapping) -> np.ndarray:
        """How much of each skin point (N_skin,) moves rigidly with the mandible: the muscle engine's
        jaw attachment (:func:`~facsim.engines.muscle.net.anatomy`), less the lips and the mouth's lining,
        which stretch over the teeth and keep the target's own motion."""
        from facsim.engines.muscle.net import MOUTH, adjacency, anatomy, smooth_field

        anat = anatomy(self.head)
        free = (anat.kind == MOUTH) | (self._lips > float(spec["lip_mask"]))
        share = np.where(free, 0.0, anat.jaw_weight)
        share = smooth_field(share, adjacency(anat.edges, anat.skin_count), int(spec["smoothing_passes"]))
        share[free] = 0.0
        return share.astype(np.float32)

    def _near_the_corner(self, offsets: np.ndarray, side: str, reach: Mapping[str, float]) -> np.ndarray:
        """A lip-corner target's ``offsets`` (N_base_geo, 3) kept in full within ``reach["full_mm"]`` of the
        ``side`` lip corner and fading out by ``reach["none_mm"]`` (``corner_reach`` in the table); with
        ``below: true`` the distance is the depth below the corner's height (nothing above it is held); with
        ``smoothing_passes`` the skin between the two follows the corner smoothly (:meth:`_smoothed_beyond_the_lips`)."""
        from facsim.head.landmarks import landmarks

        positions = self.base_positions[self.head.base_index]
        corner = positions[landmarks(self.head)[f"lip_corner_{side}"]]
        if reach.get("below"):
            distance = np.maximum(corner[1] - positions[:, 1], 0.0)
        else:
            distance = np.linalg.norm(positions - corner, axis=1)
        share = smoothstep(float(reach["none_mm"]) / 100.0, float(reach["full_mm"]) / 100.0, distance)
        out = offsets * share[:, None]
        passes = int(reach.get("smoothing_passes", 0))
        if passes:
            out = self._smoothed_beyond_the_lips(out, passes, (share <= 0.0) | (share >= 1.0))
        return out.astype(offsets.dtype)

    def _brows_not_gathered(self, offsets: np.ndarray, spec: Mapping[str, float]) -> np.ndarray:
        """``offsets`` (N_base_geo, 3) without their motion across the face (x) at the brows and above:
        kept in full ``spec["full_mm"]`` or more below the inner brows' line, none from ``spec["none_mm"]``
        below it up (``brows_not_gathered`` in the table). The motion up and down is kept."""
        from facsim.head.landmarks import landmarks

        positions = self.base_positions[self.head.base_index]
        marks = landmarks(self.head)
        brows = float(np.mean([positions[marks[f"inner_brow_{s}"], 1] for s in ("left", "right")]))
        below = brows - positions[:, 1]
        share = smoothstep(float(spec["none_mm"]) / 100.0, float(spec["full_mm"]) / 100.0, below)
        out = np.array(offsets, copy=True)
        out[:, 0] *= share
        return out

    def _smoothed_beyond_the_lips(self, offsets: np.ndarray, passes: int, held: np.ndarray) -> np.ndarray:
        """``offsets`` (N_base_geo, 3) with the skin beyond the lips following them smoothly: its motion
        averaged with its neighbours' ``passes`` times. The lips, the mouth's lining and the skin two rings
        off them keep their own motion (smoothed there, the lining showed through the skin at george's
        corners), as do the ``held`` points (N_base_geo,): the corner's skin and the still skin."""
        skin = self.head.skin_vertex_count
        out = np.array(offsets, np.float64, copy=True)
        out[:skin] = self._relaxed(out[:skin], passes, held[:skin], 2)
        return out

    def _relaxed(self, offsets: np.ndarray, passes: int, held: np.ndarray, rings: int) -> np.ndarray:
        """Skin ``offsets`` (N_skin, 3) averaged with their neighbours' ``passes`` times, the ``held`` points
        (N_skin,), the lips, the mouth's lining and ``rings`` rings of skin off them keeping their own."""
        from facsim.engines.muscle.net import MOUTH, adjacency, anatomy

        anat = anatomy(self.head)
        neighbours = adjacency(anat.edges, anat.skin_count)
        mouth = ((anat.kind == MOUTH) | (self._lips > 0.5)).astype(np.float64)
        for _ in range(rings):
            mouth = np.minimum(neighbours @ mouth + mouth, 1.0)
        keep = (mouth > 0.0) | held
        degree = np.asarray(neighbours.sum(axis=1)).ravel() + 1.0
        field = np.array(offsets, np.float64, copy=True)
        for _ in range(passes):
            field = np.where(keep[:, None], field, (neighbours @ field + field) / degree[:, None])
        return field

    @cached_property
    def lids(self) -> dict:
        """(target, side) -> :class:`~facsim.engines.lids.EyeLids` for the closing targets
        (``lid_closing`` in the table)."""
        from facsim.engines.lids import EyeLids, lid_margin

        skin = self.head.skin_vertex_count
        out = {}
        for pattern in register_table().get("lid_closing", ()):
            for side in ("left", "right"):
                centre, radius = self.head.eye_pivot(self.base_positions, side)
                out[pattern, side] = EyeLids(self.sculpted[:skin], self.column(Column(pattern, side))[:skin],
                                             centre, radius, lid_margin(self.head, self.sculpted, centre, radius))
        return out

    @cached_property
    def rest_lids(self):
        """The relaxed lids at rest (:class:`~facsim.engines.lids.RestLids`, ``lids.yaml``)."""
        from facsim.engines.lids import RestLids, lid_margin, rest_table

        skin = self.head.skin_vertex_count
        pattern = rest_table()["target"]

        def eye(side):
            return self.head.eye_pivot(self.base_positions, side)

        def margin(side):
            return lid_margin(self.head, self.sculpted, *eye(side))

        lower = rest_table()["lower"]["target"]
        return RestLids.measure(self.sculpted[:skin], lambda side: self.column(Column(pattern, side))[:skin], eye, margin,
                                lambda side: self.column(Column(lower, side))[:skin])

    @cached_property
    def lid_raise(self) -> tuple[frozenset, float]:
        """AU 5's lid-raising column patterns and this character's factor on them
        (:func:`~facsim.engines.lids.raise_gain`, ``lids.yaml`` ``raise``; the mean of both eyes)."""
        from facsim.engines.lids import raise_gain

        spec = load_yaml("lids.yaml")["raise"]
        registers = register_table()["action_units"][int(spec["au"])]["registers"]
        skin = self.head.skin_vertex_count
        gains = []
        for side in ("left", "right"):
            raising = sum(float(reg["max"]) * self.column(Column(reg["target"], side))[:skin] for reg in registers)
            lids = self.lids["faceunits/eyeBlink{Side}", side]
            gains.append(raise_gain(lids, self.sculpted[:skin], raising, self.head.eye_pivot(self.base_positions, side)[1]))
        return frozenset(reg["target"] for reg in registers), float(np.mean(gains))

    @cached_property
    def hooded(self) -> float:
        """How hooded this character's upper lids are, 0 (open) to 1 (the mean of both eyes,
        :func:`~facsim.engines.lids.hooded_share`)."""
        from facsim.engines.lids import hooded_share

        skin = self.head.skin_vertex_count
        return float(np.mean([hooded_share(self.lids["faceunits/eyeBlink{Side}", side], self.sculpted[:skin],
                                           self.head.eye_pivot(self.base_positions, side)[1])
                              for side in ("left", "right")]))

    def _hood_lifted(self, act: Activations) -> Activations:
        """``act`` with a hooded lid's AU 5 raised further under 1+2 (``lids.yaml`` ``raise``
        ``hood_lift``): by ``share`` of its own level times :attr:`hooded` and the smaller of 1's
        and 2's levels on each side, at most to 5E; none with ``unless`` (4)."""
        spec = load_yaml("lids.yaml")["raise"]
        rule, code = spec.get("hood_lift"), int(spec["au"])
        if not rule or not self.hooded:
            return act
        levels = dict(act)
        for side in ("left", "right"):
            own = act[code, side]
            if own <= 0 or any(act[int(c), side] > 0 for c in rule.get("unless", ())):
                continue
            brows = min(act[int(c), side] for c in rule["with"])
            levels[code, side] = min(own * (1.0 + float(rule["share"]) * self.hooded * brows), max(own, 1.0))
        return Activations(levels)

    @cached_property
    def brow_push(self) -> dict[tuple[int, str], float]:
        """The lowered brow's push on the upper lid fitted to the character (``lids.yaml``
        ``brow_push``): each brow-lowering AU's share of the closing target, scaled so that at E it
        lowers the relaxed lid to cover at most ``cover_mm`` of the iris (none on lids that rest that
        low already)."""
        from facsim.engines.lids import rest_lid_weight, rest_table

        spec = load_yaml("lids.yaml")["brow_push"]
        pattern = spec["target"]
        skin = self.head.skin_vertex_count
        relaxed = self.sculpted[:skin] + self.rest_lids.offsets(Activations(), skin)
        fitted = {}
        for code in map(int, spec["aus"]):
            vmax = next(float(reg["max"]) for reg in register_table()["action_units"][code]["registers"]
                        if reg["target"] == pattern)
            limits = {**rest_table(), "cover_mm": float(spec["cover_mm"]), "max_weight": vmax}
            shares = [rest_lid_weight(self.lids[pattern, side], relaxed, self.column(Column(pattern, side))[:skin],
                                      self.head.eye_pivot(self.base_positions, side)[1], limits)
                      for side in ("left", "right")]
            fitted[code, pattern] = float(np.mean(shares)) / vmax
        return fitted

    @cached_property
    def squint(self) -> dict[tuple[int, str], float]:
        """AU 6's lower-lid target fitted to the character (``lids.yaml`` ``squint``): the factor
        (the mean of both eyes, :func:`~facsim.engines.lids.squint_gain`) that leaves the relaxed
        eye ``open_share`` of its aperture at 6E, so a small or hooded eye is narrowed, not shut."""
        from facsim.engines.lids import squint_gain

        spec = load_yaml("lids.yaml")["squint"]
        code, pattern = int(spec["au"]), spec["target"]
        skin = self.head.skin_vertex_count
        relaxed = self.sculpted[:skin] + self.rest_lids.offsets(Activations(), skin)
        gains = []
        for side in ("left", "right"):
            lifting, squint = np.zeros_like(relaxed), np.zeros_like(relaxed)
            for reg in register_table()["action_units"][code]["registers"]:
                offsets = float(reg["max"]) * self.column(Column(reg["target"], side))[:skin]
                if reg["target"] == pattern:
                    squint += offsets
                else:
                    lifting += offsets
            gains.append(squint_gain(self.lids["faceunits/eyeBlink{Side}", side], relaxed, lifting, squint, spec))
        return {(code, pattern): float(np.mean(gains))}

    @cached_property
    def neutral(self) -> np.ndarray:
        """The face at rest (N_geo, 3): the sculpted face with relaxed lids."""
        return self.deform(Activations()).positions

    def weights(self, act: Activations) -> dict[Column, float]:
        """Column weights of ``act`` (Eq. 1), each side's by the character's gain there (its natural
        asymmetry) and AU 5's lid-raising targets by :attr:`lid_raise`, AU 4's push on the lid
        fitted (:attr:`brow_push`) and AU 6's lower lid (:attr:`squint`), plus the relaxed lids' shares of
        the closing and the lower lid's targets."""
        from facsim.engines.lids import rest_table

        raising, raise_gain = self.lid_raise
        weights = {col: w * (1.0 if col.pattern in BONE_TARGETS else self.side_gain[col.side])
                   * (raise_gain if col.pattern in raising else 1.0)
                   for col, w in register_weights(self._hood_lifted(act), {**self.brow_push, **self.squint}).items()}
        for side in ("left", "right"):
            for pattern, share in ((rest_table()["target"], self.rest_lids.share(act, side)),
                                   (rest_table()["lower"]["target"], self.rest_lids.lower_share(act, side))):
                if share:
                    col = Column(pattern, side)
                    weights[col] = weights.get(col, 0.0) + share
        return weights

    def deform(self, act: Activations) -> Deformation:
        """The expression ``act`` from the relaxed rest: targets weighted by Eq. 1, then the eyes
        and the head moved rigidly."""
        positions = self.guard(self._morphed(act))
        skin = positions[: self.head.skin_vertex_count]
        return Deformation(self.rigid.move_head(positions, act), creases=lambda: self._creases(skin))

    def _morphed(self, act: Activations) -> np.ndarray:
        """Positions (N_geo, 3) of ``act``'s weighted targets, the upper lids stopped on the lower
        ones and the eyes turned: the expression before the skin guard and the head motion."""
        base = self.base_positions[self.head.base_index]  # a copy (fancy indexing)
        closing = {}
        for col, weight in self.weights(act).items():
            if weight:
                base += weight * self.column(col)
                if (col.pattern, col.side) in self.lids:
                    closing[col.pattern, col.side] = weight * self.column(col)
        skin = self.head.skin_vertex_count
        for key, share in closing.items():  # the upper lid stops on the lower one
            self.lids[key].close_on_lower(base[:skin], share[:skin])
        morphed = np.array(self.base_positions, copy=True)
        morphed[self.head.base_index] = base
        return self.head.positions(morphed, neutral_base=self.base_positions,
                                   eye_rotations=self.rigid.eye_rotations(act))

    def _creases(self, skin: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Skin compression (N_geo,) and furrow phase (N_geo,) of deformed skin positions.

        The same field as the muscle engine's (:func:`~facsim.engines.muscle.wrinkles.wrinkle_field`):
        the authored targets move the skin but carry no furrows, so the creases FACS
        describes (glabellar furrows in 4, crow's feet in 6, forehead lines in 1+2,
        the wrinkled nose of 9) come from where the targets compress the skin.
        """
        from facsim.engines.muscle.wrinkles import wrinkle_field

        strength, phase = wrinkle_field(self.wrinkles, np.asarray(skin, np.float64))
        wrinkle, crease_phase = (np.zeros(self.head.vertex_count, np.float32) for _ in range(2))
        wrinkle[: len(skin)] = strength
        crease_phase[: len(skin)] = phase
        return wrinkle, crease_phase

    @cached_property
    def wrinkles(self):
        """The wrinkle model of this character's skin (built on first use, a fraction of a second)."""
        from facsim.engines.muscle.net import anatomy, build_net, load_spec
        from facsim.engines.muscle.wrinkles import build_wrinkles

        spec, anat = load_spec(), anatomy(self.head)
        return build_wrinkles(anat, build_net(self.head, self.base_positions, anat=anat, spec=spec), spec)

    @cached_property
    def guard(self) -> SkinGuard:
        """The physical last step: skin off the eyeballs, no skin turned inside out, against the
        face at rest (the relaxed lids: a triangle of the upper lid that 5 turns nearly on edge
        from the sculpted lid has turned through it from the relaxed one, mei's fear)."""
        centres = [self.head.eye_pivot(self.base_positions, side)[0] for side in ("left", "right")]
        return SkinGuard(self.head, self._morphed(Activations()), centres, self.head.eye_pivot(self.base_positions, "left")[1],
                         neck_below=float(self.head.joint(self.base_positions, "joint-jaw")[1]))

    def reset(self) -> None:
        """Nothing to do: the register engine keeps no state between frames."""

    def step(self, act: Activations) -> Deformation:
        """An animation frame: the same as :meth:`deform` (each frame is independent)."""
        return self.deform(act)


def coverage() -> dict[int, str]:
    """AU code → one line on how this engine renders it (or why it cannot)."""
    table, rigid = register_table(), rigid_table()
    out = {code: spec["why"] for code, spec in table["action_units"].items()}
    out.update({code: spec["why"] for code, spec in rigid["head_motions"].items()})
    out.update({code: spec["why"] for code, spec in rigid["eye_rotations"].items()})
    out.update({code: "not simulated: " + why for code, why in table["not_simulated"].items()})
    return dict(sorted(out.items()))
