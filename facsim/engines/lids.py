"""Closing lids fitted to the character: the upper lid stops where it meets the lower lid.

The Face Units' eyeBlink target was authored on MakeHuman's base mesh. On a
character its upper lid margin travels a fixed distance, which takes it 6–10°
of eyeball arc (2–3 mm) PAST the lower lid margin: the closed upper lid runs
over the lower lid's skin and, near the corners where the two margins meet,
turns it inside out. A real lid stops when its margin meets the lower one.

:meth:`EyeLids.close_on_lower` is a contact between the two margins, applied
to every expression after the targets are summed: where the closing targets'
share of the motion takes the upper margin past the lower margin (as the other
AUs have left it: a cheek raised by 6 lifts it), that share is scaled down per
direction around the eye (azimuth) until the margins just meet, and the skin
above follows by the same smooth factor (no new folds). The lower lid keeps its
motion. Angles are measured about the eyeball's centre, so the contact holds
for any eye size or lid shape the character's sliders give.

Examples
--------
>>> lids = EyeLids(rest, blink_offsets, centre, radius, margin)   # doctest: +SKIP
>>> lids.close_on_lower(positions, blink_share)                   # doctest: +SKIP

:class:`RestLids` is the relaxed aperture both engines start from (``lids.yaml``):
MakeHuman's sculpted lids stare, so each eye's upper lid is lowered by the share of
the closing target that brings its margin over the top of the iris, measured on
the character (none where the lid already covers it; hooded lids that cover more than
``most_cover_mm`` take a negative share, which lifts them to it).
"""
from __future__ import annotations

import numpy as np

from dataclasses import dataclass, field
from functools import lru_cache
from typing import Callable

from facsim._data import load_yaml
from facsim.head.surface import smoothstep

#: An upper-margin point whose elevation falls by more than this (degrees) at full weight
#: belongs to the closing upper lid; the others are the lower lid's margin.
UPPER_MOVES = 3.0
#: The upper margin comes to rest this far (degrees of arc, ~0.1 mm) below the lower margin's
#: elevation, so that no sliver of eye shows between them.
OVERLAP = -0.5
#: Skin from this far below the lower margin (degrees) up to this far above it blends from
#: the lower lid's motion (unchanged) to the upper lid's (rescaled).
BLEND = (0.0, 3.0)
#: Only skin within this many eyeball radii of the centre belongs to the lids.
REACH = 2.5
#: Bisection steps when solving for the weight at which a margin point meets the lower margin.
STEPS = 30


def spherical(points: np.ndarray, centre: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Azimuth (toward +X, degrees from straight ahead) and elevation (degrees) about ``centre``."""
    q = np.asarray(points, float) - centre
    r = np.maximum(np.linalg.norm(q, axis=-1), 1e-12)
    return np.degrees(np.arctan2(q[..., 0], q[..., 2])), np.degrees(np.arcsin(np.clip(q[..., 1] / r, -1, 1)))


def lid_margin(head, positions: np.ndarray, centre: np.ndarray, radius: float) -> np.ndarray:
    """The lid-margin skin vertices (the lashes' roots) of the eye at ``centre``, both lids."""
    anchors = np.unique(head.lash_anchors)
    return anchors[np.linalg.norm(np.asarray(positions)[anchors] - centre, axis=1) < 2 * radius]


class EyeLids:
    """One eye's lids, found from a closing target on a character's neutral skin.

    Parameters
    ----------
    rest : (N, 3) array
        The character's neutral skin positions.
    closing : (N, 3) array
        A target that closes this eye (its offsets at full weight): it tells the upper
        margin (which it moves down) from the lower.
    centre, radius
        The eyeball.
    margin : (K,) int array
        Skin vertices along both lid margins of this eye (the lashes' roots).
    """

    def __init__(self, rest, closing, centre, radius: float, margin):
        rest = np.asarray(rest, float)
        closing = np.asarray(closing, float)
        self.centre = np.asarray(centre, float)
        margin = np.asarray(margin)
        lam0, phi0 = spherical(rest[margin], self.centre)
        _, phi1 = spherical(rest[margin] + closing[margin], self.centre)
        upper = phi0 - phi1 > UPPER_MOVES
        self.ok = upper.sum() >= 2 and (~upper).sum() >= 2
        self.upper = margin[upper][np.argsort(lam0[upper])]
        self.lower = margin[~upper]
        self.upper_lam = np.sort(lam0[upper])
        order = np.argsort(lam0[~upper])
        lower_lam, lower_phi = lam0[~upper][order], phi0[~upper][order]
        # The lid skin: near the eye; above the lower margin it is the upper lid's.
        self.lid = np.flatnonzero(np.linalg.norm(rest - self.centre, axis=1) < REACH * radius)
        lam, phi = spherical(rest[self.lid], self.centre)
        self.lid_lam = lam
        self.upper_share = smoothstep(BLEND[0], BLEND[1], phi - np.interp(lam, lower_lam, lower_phi))

    def close_on_lower(self, positions: np.ndarray, closing: np.ndarray) -> None:
        """Hold the upper lid where it meets the lower one (in place).

        ``positions`` (N, 3) include ``closing`` (N, 3), the closing targets' share of the
        motion; where that share takes the upper margin below the lower margin (as the
        other AUs have left it), the upper lid's share is scaled down, per azimuth, until
        the margins just meet. Nothing changes while the lids are apart.
        """
        if not self.ok:
            return
        lam, phi = spherical(positions[self.lower], self.centre)
        order = np.argsort(lam)
        lower_lam, lower_phi = lam[order], phi[order]

        def through(share):
            lam, phi = spherical(positions[self.upper] - (1.0 - share)[:, None] * closing[self.upper], self.centre)
            return phi < np.interp(lam, lower_lam, lower_phi) - OVERLAP

        if not through(np.ones(len(self.upper))).any():
            return
        lo, hi = np.zeros(len(self.upper)), np.ones(len(self.upper))
        for _ in range(STEPS):
            mid = 0.5 * (lo + hi)
            below = through(mid)
            hi = np.where(below, mid, hi)
            lo = np.where(below, lo, mid)
        share = np.where(through(np.ones(len(self.upper))), lo, 1.0)
        keep = 1.0 - (1.0 - np.interp(self.lid_lam, self.upper_lam, share)) * self.upper_share
        positions[self.lid] -= ((1.0 - keep)[:, None] * closing[self.lid]).astype(positions.dtype)

    def meet_lower(self, positions: np.ndarray, amount: float) -> None:
        """Bring the upper lid onto the lower one (in place), closing ``amount`` (0..1) of the
        gap left between the margins (or of the overlap where it went through).

        An engine whose closing lid does not reach the lower one everywhere (the muscle
        engine's net leaves the corners open and dips in the middle) gets the contact the
        register engine's target has: each upper margin point turns about the eyeball's
        centre down to the lower margin's elevation at its azimuth, the lid skin above
        following less with height (turning about the centre keeps the skin on its sphere,
        and the order of points along each meridian, so no fold can form).
        """
        if not self.ok or amount <= 0.0:
            return
        lam_u, phi_u = spherical(positions[self.upper], self.centre)
        lam_l, phi_l = spherical(positions[self.lower], self.centre)
        order_l = np.argsort(lam_l)
        gap = phi_u - (np.interp(lam_u, lam_l[order_l], phi_l[order_l]) + OVERLAP)
        order = np.argsort(lam_u)
        # Signed: a margin left above the lower one comes down, one pulled through it (the net's
        # dip in the middle) comes back up to it.
        turn_u = float(amount) * gap[order]
        lam, phi = spherical(positions[self.lid], self.centre)
        above = phi - np.interp(lam, lam_u[order], phi_u[order])
        turn = np.radians(np.interp(lam, lam_u[order], turn_u)) * self.upper_share \
            * (1.0 - smoothstep(0.0, MEET_FOLLOW, above))
        q = positions[self.lid] - self.centre
        c, s = np.cos(turn), np.sin(turn)
        y, z = q[:, 1] * c - q[:, 2] * s, q[:, 1] * s + q[:, 2] * c
        positions[self.lid, 1] = (self.centre[1] + y).astype(positions.dtype)
        positions[self.lid, 2] = (self.centre[2] + z).astype(positions.dtype)


#: Lid skin this many degrees above the upper margin no longer follows :meth:`EyeLids.meet_lower`.
MEET_FOLLOW = 25.0
#: AU codes that close the eye, and the level from which :meth:`EyeLids.meet_lower` starts
#: bringing the margins together (fully at 1).
CLOSING = (43, 45, 46)
MEET_FROM = 0.6


def meet_amount(act, side: str) -> float:
    """How much of the gap between the margins :meth:`EyeLids.meet_lower` closes under ``act``."""
    level = max(act[code, side] for code in CLOSING)
    return float(smoothstep(MEET_FROM, 1.0, np.asarray(level, float)))


# ------------------------------------------------------------------ the relaxed rest

SIDES = ("left", "right")


@lru_cache(maxsize=1)
def rest_table() -> dict:
    """The ``rest`` entry of ``lids.yaml`` (the one source of the relaxed aperture)."""
    return load_yaml("lids.yaml")["rest"]


def _margin_over_pupil(lids: EyeLids, rest: np.ndarray, ahead_degrees: float,
                       lower: bool = False) -> tuple[np.ndarray, float]:
    """The upper (or ``lower``) margin's points over the pupil (within ``ahead_degrees`` of straight
    ahead; the whole margin if fewer than two are) and their mean height above the eye's centre
    on ``rest``."""
    points = lids.lower if lower else lids.upper
    lam = spherical(rest[points], lids.centre)[0] if lower else lids.upper_lam
    ahead = np.abs(lam) < ahead_degrees
    points = points[ahead] if ahead.sum() >= 2 else points
    return points, float(np.mean(rest[points, 1])) - float(lids.centre[1])


def _rest_mm(radius: float, table: dict) -> float:
    """One millimetre of the iris (``iris_mm`` across, ``iris_radius`` eyeball radii) in world units."""
    return float(table["iris_radius"]) * radius / (0.5 * float(table["iris_mm"]))


def rest_lid_weight(lids: EyeLids, rest: np.ndarray, closing: np.ndarray, radius: float,
                    spec: dict | None = None) -> float:
    """The share of ``closing`` that lowers this eye's upper lid margin to a relaxed height.

    The margin over the pupil (upper margin points within ``ahead_degrees`` of straight
    ahead) should sit ``cover_mm`` below the iris's top (``iris_radius`` eyeball radii above
    the centre). Heights change linearly with the share, so it is solved directly, then
    clipped to ``[0, max_weight]``: 0 where the sculpted lid already covers that much. A lid
    sculpted more than ``most_cover_mm`` over the iris (hooded) takes the negative share that
    lifts it to that (at most ``max_lift``).

    Parameters
    ----------
    lids : EyeLids
        The eye's lids on the sculpted neutral skin ``rest`` (N, 3).
    closing : (N, 3) array
        The closing target's offsets at full weight.
    radius : float
        The eyeball's radius (dm).
    """
    spec = spec or rest_table()
    if not lids.ok:
        return 0.0
    upper, height = _margin_over_pupil(lids, rest, float(spec["ahead_degrees"]))
    drop = -float(np.mean(closing[upper, 1]))           # dm per unit share
    iris_top = float(spec["iris_radius"]) * radius
    if drop <= 1e-9:
        return 0.0
    lowered = (height - (iris_top - 0.01 * float(spec["cover_mm"]))) / drop
    if lowered > 0.0:
        return float(min(lowered, float(spec["max_weight"])))
    # A lid sculpted lower than `most_cover_mm` (hooded) is lifted to it: a negative share.
    lifted = (height - (iris_top - 0.01 * float(spec.get("most_cover_mm", np.inf)))) / drop
    return float(np.clip(lifted, -float(spec.get("max_lift", 0.0)), 0.0))


def rest_lower_weight(lids: EyeLids, rest: np.ndarray, raising: np.ndarray, radius: float,
                      spec: dict | None = None) -> float:
    """The share of ``raising`` (N, 3), a target that lifts the lower lid, that brings this eye's
    lower margin over the pupil up to ``cover_mm`` above the iris's bottom (``lids.yaml``,
    ``rest: lower``): 0 where the sculpted lid already covers that much, at most ``max_weight``.

    The margin is measured as the upper one is (:func:`rest_lid_weight`): its points within
    ``ahead_degrees`` of straight ahead, on the sculpted skin ``rest`` (N, 3).
    """
    table = rest_table()
    spec = spec or table["lower"]
    if not lids.ok:
        return 0.0
    lower, height = _margin_over_pupil(lids, rest, float(table["ahead_degrees"]), lower=True)
    rise = float(np.mean(raising[lower, 1]))            # dm per unit share
    iris_bottom = -float(table["iris_radius"]) * radius
    mm = _rest_mm(radius, table)
    if rise <= 1e-9:
        return 0.0
    return float(np.clip((iris_bottom + float(spec["cover_mm"]) * mm - height) / rise, 0.0, float(spec["max_weight"])))


def raise_gain(lids: EyeLids, rest: np.ndarray, raising: np.ndarray, radius: float,
               spec: dict | None = None) -> float:
    """The factor on AU 5's targets that lifts this eye's upper margin ``bare_mm`` above the iris.

    The margin over the pupil (as in :func:`rest_lid_weight`) on the sculpted skin ``rest``
    (N, 3) rises by ``raising`` (N, 3), AU 5's targets at E, times the factor; heights change
    linearly with it, so it is solved directly and clipped to ``gain`` (``lids.yaml``,
    ``raise``). A lid sculpted low over the iris (hooded) takes :func:`bare_mm`'s larger height:
    its fold overhangs the margin. 1 where the eye has no upper margin to measure.
    """
    table = load_yaml("lids.yaml")
    rest_spec, spec = table["rest"], spec or table["raise"]
    if not lids.ok:
        return 1.0
    upper, height = _margin_over_pupil(lids, rest, float(rest_spec["ahead_degrees"]))
    lift = float(np.mean(raising[upper, 1]))
    iris_top = float(rest_spec["iris_radius"]) * radius
    mm = _rest_mm(radius, rest_spec)
    low, high = (float(g) for g in spec["gain"])
    if lift <= 1e-9:
        return 1.0
    bare = bare_mm(_cover_mm(lids, rest, radius, rest_spec), spec)
    return float(np.clip((iris_top + bare * mm - height) / lift, low, high))


def hooded_share(lids: EyeLids, rest: np.ndarray, radius: float, spec: dict | None = None) -> float:
    """How hooded this eye's upper lid is, 0 to 1: the smoothstep of its sculpted margin's cover of
    the iris (mm, on ``rest`` (N, 3), over the pupil) over ``hooded``'s ``cover_mm`` (``lids.yaml``
    ``raise``, :func:`hood_share`). 0 where the eye has no upper margin to measure."""
    table = load_yaml("lids.yaml")
    if not lids.ok:
        return 0.0
    return hood_share(_cover_mm(lids, rest, radius, table["rest"]), spec or table["raise"])


def _cover_mm(lids: EyeLids, rest: np.ndarray, radius: float, rest_spec: dict) -> float:
    """How much of the iris (iris-mm) the upper margin over the pupil covers on ``rest`` (N, 3)."""
    _, height = _margin_over_pupil(lids, rest, float(rest_spec["ahead_degrees"]))
    return (float(rest_spec["iris_radius"]) * radius - height) / _rest_mm(radius, rest_spec)


def squint_gain(lids: EyeLids, rest: np.ndarray, lifting: np.ndarray, squint: np.ndarray, spec: dict) -> float:
    """The factor on AU 6's lower-lid target that leaves this eye ``open_share`` of its aperture at 6E.

    The aperture is the upper margin's height over the pupil less the lower margin's (as in
    :func:`rest_lid_weight`) on the relaxed skin ``rest`` (N, 3); at E AU 6's other targets
    (``lifting``, (N, 3)) and its lower-lid target ``squint`` (N, 3, at its maximum) times the
    factor close it. Heights change linearly with the factor, so it is solved directly and clipped
    to ``spec["gain"]`` (``lids.yaml``, ``squint``). 1 where the eye has no margins to measure.
    """
    if not lids.ok:
        return 1.0
    ahead = float(rest_table()["ahead_degrees"])
    upper, top = _margin_over_pupil(lids, rest, ahead)
    lower, bottom = _margin_over_pupil(lids, rest, ahead, lower=True)

    def closing(offsets):
        return float(np.mean(offsets[lower, 1]) - np.mean(offsets[upper, 1]))

    per_unit = closing(squint)
    if per_unit <= 1e-9:
        return 1.0
    low, high = (float(g) for g in spec["gain"])
    allowed = (1.0 - float(spec["open_share"])) * (top - bottom) - closing(lifting)
    return float(np.clip(allowed / per_unit, low, high))


def bare_mm(cover_mm: float, spec: dict) -> float:
    """How high (iris-mm) AU 5 at E lifts the upper margin over the iris's top, for a lid whose
    sculpted margin covers ``cover_mm`` of the iris: ``spec["bare_mm"]``, rising to
    ``spec["hooded"]["bare_mm"]`` as the cover grows over ``spec["hooded"]["cover_mm"]``
    (``lids.yaml`` ``raise``).

    >>> spec = {"bare_mm": 2.5, "hooded": {"bare_mm": 3.5, "cover_mm": [2.5, 4.0]}}
    >>> [round(bare_mm(c, spec), 2) for c in (1.0, 3.25, 5.0)]
    [2.5, 3.0, 3.5]
    """
    hooded = spec.get("hooded")
    if not hooded:
        return float(spec["bare_mm"])
    return float(spec["bare_mm"]) + hood_share(cover_mm, spec) * (float(hooded["bare_mm"]) - float(spec["bare_mm"]))


def hood_share(cover_mm: float, spec: dict) -> float:
    """How hooded (0 to 1) a lid whose sculpted margin covers ``cover_mm`` of the iris is: the smoothstep
    over ``spec["hooded"]["cover_mm"]`` (``lids.yaml`` ``raise``).

    >>> spec = {"hooded": {"cover_mm": [2.5, 4.0]}}
    >>> [round(hood_share(c, spec), 2) for c in (1.0, 3.25, 5.0)]
    [0.0, 0.5, 1.0]
    """
    return float(smoothstep(*(float(c) for c in spec["hooded"]["cover_mm"]), cover_mm))


@dataclass(frozen=True)
class RestLids:
    """The relaxed lids of one character: a share of each eye's closing target (the upper lid)
    and of a target that lifts the lower lid.

    ``weights`` maps side to the closing target's share at rest, ``lower_weights`` to the
    lower lid's; :meth:`share` and :meth:`lower_share` are what is left of them under an
    expression (the ``fades_with`` and ``lower_fades_with`` AUs take them over); :meth:`offsets`
    the motion they add to the sculpted positions.
    """

    weights: dict
    columns: dict                    # side -> (N, 3) float32 offsets of the closing target
    fades_with: tuple
    lower_weights: dict = field(default_factory=lambda: {side: 0.0 for side in SIDES})
    lower_columns: dict = field(default_factory=dict)   # side -> (N, 3) offsets of the lower lid's target
    lower_fades_with: tuple = ()

    @classmethod
    def measure(cls, rest: np.ndarray, column: Callable[[str], np.ndarray], eye: Callable[[str], tuple],
                margin: Callable[[str], np.ndarray],
                lower_column: Callable[[str], np.ndarray] | None = None) -> "RestLids":
        """Measure both eyes on the sculpted neutral positions ``rest`` (N, 3).

        ``column(side)`` gives the closing target's offsets (N, 3), ``eye(side)`` the
        eyeball's (centre, radius), ``margin(side)`` the vertices along its lid margins,
        ``lower_column(side)`` the lower lid's target (``rest: lower`` in ``lids.yaml``; none
        without it).
        """
        spec = rest_table()
        weights, columns, lower_weights, lower_columns = {}, {}, {}, {}
        for side in SIDES:
            centre, radius = eye(side)
            closing = np.asarray(column(side), np.float32)
            lids = EyeLids(rest, closing, centre, radius, margin(side))
            weights[side] = rest_lid_weight(lids, np.asarray(rest, float), closing, radius, spec)
            columns[side] = closing
            if lower_column is not None:
                lower_columns[side] = np.asarray(lower_column(side), np.float32)
                lower_weights[side] = rest_lower_weight(lids, np.asarray(rest, float), lower_columns[side], radius)
            else:
                lower_weights[side] = 0.0
        # Faces are symmetric at rest: both eyes take the mean (the sculpted eyes differ by a hair).
        mean = 0.5 * (weights["left"] + weights["right"])
        lower_mean = 0.5 * (lower_weights["left"] + lower_weights["right"])
        return cls({side: mean for side in SIDES}, columns, tuple(int(c) for c in spec["fades_with"]),
                   {side: lower_mean for side in SIDES}, lower_columns,
                   tuple(int(c) for c in spec["lower"]["fades_with"]))

    @staticmethod
    def _left(weight: float, act, side: str, fades_with: tuple) -> float:
        taken = max((act[code, side] for code in fades_with), default=0.0)
        return weight * (1.0 - min(max(taken, 0.0), 1.0))

    def share(self, act, side: str) -> float:
        """The closing target's rest share left on ``side`` under activations ``act``."""
        return self._left(self.weights[side], act, side, self.fades_with)

    def lower_share(self, act, side: str) -> float:
        """The lower lid's rest share left on ``side`` under activations ``act``."""
        return self._left(self.lower_weights[side], act, side, self.lower_fades_with)

    def offsets(self, act, count: int | None = None) -> np.ndarray:
        """The rest lids' motion (N, 3) (or its first ``count`` rows) under ``act``."""
        out = None
        for side in SIDES:
            parts = [(self.share(act, side), self.columns[side])]
            if side in self.lower_columns:
                parts.append((self.lower_share(act, side), self.lower_columns[side]))
            for s, column in parts:
                column = column if count is None else column[:count]
                out = s * column if out is None else out + s * column
        return out.astype(np.float32)


def closing_column(head, data, base_positions: np.ndarray, pattern: str, side: str,
                   reach: tuple[float, float] = (0.05, 0.15)) -> np.ndarray:
    """Offsets (N_base_geo, 3) float32 of a one-sided closing target (``{Side}`` in ``pattern``)
    on ``side``, as the register engine's columns are: the left target kept within ``reach``
    (dm) of the midline (it carries stray offsets on the far side), the right one its mirror.
    """
    x = np.asarray(base_positions, np.float32)[head.base_index, 0]
    idx, delta = data.target(pattern.replace("{Side}", "Left"))
    geo = head.geo_of_base[idx]
    keep = geo >= 0
    left = np.zeros((len(head.base_index), 3), np.float32)
    left[geo[keep]] += delta[keep]
    left *= smoothstep(-reach[1], -reach[0], x).astype(np.float32)[:, None]
    if side == "left":
        return left
    mirror = head.mirror[: len(head.base_index)]
    return left[mirror] * np.array([-1.0, 1.0, 1.0], np.float32)



def lashes_turned_with_lids(roots: np.ndarray, rest_roots: np.ndarray, vectors: np.ndarray, centres: np.ndarray,
                            rest_centres: np.ndarray, rotation: np.ndarray | None = None) -> np.ndarray:
    """Lash vertices that turn about the eyeball with the lid margin they grow from.

    Lashes grow from the tarsal plate, which turns about the eyeball as the lid opens and
    closes: a closing upper lid (43, 45, 7) swings its lashes from up-and-out to forward and
    down instead of carrying them down still pointing up (a fence of spikes on the closed
    lid). Each lash vertex hangs off its root on the margin: ``rest_roots`` (V, 3) and
    ``vectors`` (V, 3, root to vertex) on the neutral face, ``roots`` (V, 3) now; the vector
    turns about the head's horizontal axis through the eyeball (``centres``/``rest_centres``
    (V, 3), each vertex's eye) by as much as the root's elevation changed, measured in the
    head's frame (``rotation``, (3, 3) rest to now, from :func:`facsim.engines.checks.head_rotation`;
    default none), then turns with the head.

    >>> up = lashes_turned_with_lids(np.array([[0.0, 0.0, 1.0]]), np.array([[0.0, 0.7071, 0.7071]]),
    ...                              np.array([[0.0, 0.1, 0.0]]), np.zeros((1, 3)), np.zeros((1, 3)))
    >>> [round(float(x), 3) for x in up[0]]   # the root fell 45 degrees: the lash leans forward
    [0.0, 0.071, 1.071]
    """
    turn_head = np.eye(3) if rotation is None else np.asarray(rotation, np.float64)
    q = (np.asarray(roots, np.float64) - centres) @ turn_head        # now, in the head's rest frame
    q0 = np.asarray(rest_roots, np.float64) - rest_centres
    turn = np.arctan2(q[:, 1], q[:, 2]) - np.arctan2(q0[:, 1], q0[:, 2])
    cos, sin = np.cos(turn), np.sin(turn)
    o = np.asarray(vectors, np.float64)
    turned = np.stack([o[:, 0], cos * o[:, 1] + sin * o[:, 2], -sin * o[:, 1] + cos * o[:, 2]], axis=1)
    return (np.asarray(roots, np.float64) + turned @ turn_head.T).astype(np.float32)
