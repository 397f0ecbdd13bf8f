"""Wrinkles, furrows and folds from skin compression (the renderer's ``wrinkle`` input).

Platt & Badler: bulges, furrows and wrinkles appear where forces push skin
points toward each other and the skin buckles. The net's skin is a membrane
that goes soft in compression (its arcs keep only a fraction of their
stiffness there), so compression shows where it would buckle; the bulges come
from the tissue columns keeping their volume (geometry, see :mod:`.solver`).
This module turns the compression into a per-vertex crease strength:

1. :func:`principal_compression` — per triangle, the smaller principal stretch
   of the deformation (rest → now) and its direction in the rest surface.
2. per vertex, the area-weighted compression tensor, its strength and direction;
3. :func:`wrinkle_field` — the strength, and a furrow phase that runs along
   the compression direction, so the renderer draws lines perpendicular to it
   (horizontal forehead lines when the brows rise, vertical glabellar furrows
   when they are drawn together, crow's feet beside the eye), with the
   anatomical creases (nasolabial fold, lid folds, the fold at the inner eye)
   deepened where they lie.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from facsim.engines.muscle.net import OUTER, Anatomy, TensionNet, resolve_vertex


@dataclass(frozen=True, eq=False)
class WrinkleModel:
    """Constant data for the wrinkle field of one character (see :func:`build_wrinkles`)."""

    triangles: np.ndarray       # (T, 3) skin triangles
    rest_inverse: np.ndarray    # (T, 2, 2) inverse of each triangle's rest edge matrix in its own frame
    rest_frame: np.ndarray      # (T, 2, 3) the rest frame's two in-plane axes
    to_vertex: sp.csr_matrix    # (N, T) area-weighted average of triangles onto vertices
    rest: np.ndarray            # (N, 3) rest positions (phase of the furrow pattern)
    wavelength: np.ndarray      # (N,) furrow spacing
    zone_gain: np.ndarray       # (N,) how readily the skin creases there (deep forehead lines, fine crow's feet)
    threshold: np.ndarray       # (N,) compression at which the skin starts to buckle there
    across_gain: np.ndarray     # (N,) the same for vertical furrows (skin squeezed sideways) where zones differ
    straight: np.ndarray        # (N,) 1 where lines run straight across the face (forehead, glabella)
    upright: np.ndarray         # (N,) 1 where the lines run straight up whatever squeezes the skin (the glabella)
    on_face: np.ndarray         # (N,) 1 on the outer skin, 0 inside the lips and lids
    crease: np.ndarray          # (N,) extra depth along anatomical folds (0 = none, 1 = twice as deep)
    gain: float
    exponent: float
    smooth: sp.csr_matrix       # (N, N) one pass of neighbour averaging
    passes: int                 # how many, on the compression tensor (a steady direction field)
    edges: np.ndarray           # (E, 2) skin edges
    incidence: sp.csr_matrix    # (E, N) −1 at an edge's first point, +1 at its second
    integrate: object           # solves (BᵀB + εI) φ = b: the phase from its edge differences


def build_wrinkles(anat: Anatomy, net: TensionNet, spec: dict) -> WrinkleModel:
    """Frames, averaging operator and per-vertex furrow properties from ``muscles.yaml``."""
    w = spec["wrinkles"]
    tri = net.triangles
    rest = net.rest
    e1 = rest[tri[:, 1]] - rest[tri[:, 0]]
    e2 = rest[tri[:, 2]] - rest[tri[:, 0]]
    normal = np.cross(e1, e2)
    area = 0.5 * np.linalg.norm(normal, axis=1)
    ax = e1 / np.maximum(np.linalg.norm(e1, axis=1, keepdims=True), 1e-12)
    ay = np.cross(normal / np.maximum(2 * area[:, None], 1e-12), ax)
    frame = np.stack([ax, ay], axis=1)                                   # (T, 2, 3)
    dm = np.stack([np.einsum("tij,tj->ti", frame, e1), np.einsum("tij,tj->ti", frame, e2)], axis=2)  # (T, 2, 2)
    det = dm[:, 0, 0] * dm[:, 1, 1] - dm[:, 0, 1] * dm[:, 1, 0]
    safe = np.abs(det) > 1e-14
    inv = np.zeros_like(dm)
    inv[safe] = np.linalg.inv(dm[safe])

    n = net.count
    rows = tri.ravel()
    cols = np.repeat(np.arange(len(tri)), 3)
    vals = np.repeat(np.where(safe, area, 0.0), 3)
    to_vertex = sp.csr_matrix((vals, (rows, cols)), shape=(n, len(tri)))
    total = np.asarray(to_vertex.sum(axis=1)).ravel()
    to_vertex = sp.diags(1.0 / np.maximum(total, 1e-14)) @ to_vertex

    # Furrow spacing per zone (drawn per pixel by the renderer, so it may be finer than the mesh).
    wavelength = np.full(n, float(w["wavelength"]))
    zone_gain = np.ones(n)
    across_gain = np.ones(n)
    threshold = np.full(n, float(w["threshold"]))
    straight = np.zeros(n)
    upright = np.zeros(n)
    base = anat.base[: anat.skin_count]
    for zone in w.get("zones", []):
        weight = _blob(zone, base)
        if "wavelength" in zone:
            wavelength = wavelength * (1 - weight) + zone["wavelength"] * weight
        if "threshold" in zone:
            threshold = threshold * (1 - weight) + zone["threshold"] * weight
        if "gain" in zone or "across_gain" in zone:
            zone_gain = zone_gain * (1 - weight) + zone.get("gain", 1.0) * weight
            across_gain = across_gain * (1 - weight) + zone.get("across_gain", zone.get("gain", 1.0)) * weight
        if zone.get("straight"):
            straight = np.maximum(straight, weight)
        if zone.get("upright"):
            upright = np.maximum(upright, weight)
    wavelength = wavelength * net.scale

    crease = np.zeros(n)
    for line in w.get("creases", []):
        for side in ("left", "right"):
            pts = np.array([anat.base[resolve_vertex(anat, sel, side)] for sel in line["points"]])
            crease = np.maximum(crease, line.get("strength", 1.0) * _near_polyline(base, pts, line["width"]))
    on_face = (anat.kind == OUTER).astype(float)
    crease *= on_face
    edges = anat.edges
    adj = sp.coo_matrix((np.ones(2 * len(edges)), (edges.ravel(), edges[:, ::-1].ravel())), shape=(n, n)).tocsr()
    adj = adj + sp.identity(n)
    smooth = sp.diags(1.0 / np.asarray(adj.sum(axis=1)).ravel()) @ adj
    m = len(edges)
    incidence = sp.csr_matrix((np.r_[-np.ones(m), np.ones(m)], (np.r_[np.arange(m), np.arange(m)],
                                                                 np.r_[edges[:, 0], edges[:, 1]])), shape=(m, n))
    # The graph Laplacian never changes, so it is factorised once; ε pins the free constant.
    integrate = spla.factorized((incidence.T @ incidence + 1e-4 * sp.identity(n)).tocsc())
    if "lips_gain" in w:
        red = _lips_red(anat, smooth)
        zone_gain = zone_gain * (1.0 - (1.0 - float(w["lips_gain"])) * red)
        across_gain = across_gain * (1.0 - (1.0 - float(w["lips_gain"])) * red)
    return WrinkleModel(
        triangles=tri, rest_inverse=inv, rest_frame=frame, to_vertex=to_vertex.tocsr(), rest=rest,
        wavelength=wavelength, zone_gain=zone_gain, threshold=threshold, across_gain=across_gain, straight=np.clip(straight * 4.0, 0.0, 1.0),
        upright=np.clip(upright * 4.0, 0.0, 1.0), crease=crease,
        on_face=on_face,
        gain=float(w["gain"]), exponent=float(w["exponent"]),
        smooth=smooth.tocsr(), passes=int(w.get("smoothing", 2)),
        edges=edges, incidence=incidence, integrate=integrate,
    )


def _lips_red(anat: Anatomy, smooth: sp.csr_matrix, passes: int = 2) -> np.ndarray:
    """(N,) 1 on the lips' red (either lip, outer skin), fading to 0 over about a ring of points
    beyond the vermilion border, so the crease gain there changes smoothly, not at one edge."""
    red = ((anat.lip_half != 0) & (anat.kind == OUTER)).astype(float)
    soft = red
    for _ in range(passes):
        soft = smooth @ soft
    return np.maximum(red, np.clip(2.0 * soft, 0.0, 1.0))


def _blob(zone, points) -> np.ndarray:
    centre, radii = np.asarray(zone["centre"], float), np.asarray(zone["radii"], float)
    rel = points.copy()
    if centre[0] > 0:
        rel[:, 0] = np.abs(rel[:, 0])
    return np.clip(1.0 - (((rel - centre) / radii) ** 2).sum(1), 0.0, 1.0) ** 2


def _near_polyline(points, line, width) -> np.ndarray:
    """1 on a polyline, falling smoothly to 0 at ``width`` from it."""
    best = np.full(len(points), np.inf)
    for a, b in zip(line[:-1], line[1:]):
        ab = b - a
        t = np.clip(((points - a) @ ab) / max(ab @ ab, 1e-12), 0.0, 1.0)
        best = np.minimum(best, np.linalg.norm(points - (a + t[:, None] * ab), axis=1))
    return np.clip(1.0 - (best / width) ** 2, 0.0, 1.0) ** 2


def principal_compression(model: WrinkleModel, positions: np.ndarray):
    """Per triangle: compression ``1 − λ_min`` (≥ 0), its rest-space direction, and the
    larger stretch (T,), (T, 3), (T,)."""
    tri = model.triangles
    e1 = positions[tri[:, 1]] - positions[tri[:, 0]]
    e2 = positions[tri[:, 2]] - positions[tri[:, 0]]
    ds = np.stack([e1, e2], axis=2)                                      # (T, 3, 2)
    f = ds @ model.rest_inverse                                          # (T, 3, 2) deformation gradient
    c = np.einsum("tki,tkj->tij", f, f)                                  # right Cauchy-Green (T, 2, 2)
    a, b, d = c[:, 0, 0], c[:, 0, 1], c[:, 1, 1]
    mean, half = 0.5 * (a + d), np.sqrt(0.25 * (a - d) ** 2 + b * b)
    small, large = np.sqrt(np.maximum(mean - half, 0.0)), np.sqrt(np.maximum(mean + half, 0.0))
    # Eigenvector of the smaller eigenvalue, in the triangle's rest frame, then in 3-D.
    vx, vy = b, (mean - half) - a
    alt = np.abs(b) < 1e-12
    vx = np.where(alt, np.where(a <= d, 1.0, 0.0), vx)
    vy = np.where(alt, np.where(a <= d, 0.0, 1.0), vy)
    norm = np.maximum(np.hypot(vx, vy), 1e-12)
    direction = (vx / norm)[:, None] * model.rest_frame[:, 0] + (vy / norm)[:, None] * model.rest_frame[:, 1]
    return np.maximum(1.0 - small, 0.0), direction, large


def _principal_axis(tensors: np.ndarray, iterations: int = 6) -> np.ndarray:
    """Unit eigenvector of the largest eigenvalue of symmetric PSD 3×3 tensors (K, 3, 3), by power
    iteration from each tensor's largest column (a few products; no per-point eigensolver)."""
    columns = np.linalg.norm(tensors, axis=1)                            # (K, 3)
    v = tensors[np.arange(len(tensors)), :, columns.argmax(axis=1)]
    for _ in range(iterations):
        v = np.einsum("kij,kj->ki", tensors, v)
        v /= np.maximum(np.linalg.norm(v, axis=1, keepdims=True), 1e-30)
    return v


def wrinkle_field(model: WrinkleModel, positions: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Crease strength and crease phase per skin vertex for skin ``positions`` (N, 3).

    Returns ``(strength, phase)``, both (N,) float32: ``strength`` ≥ 0 is how deeply the skin
    creases there (smooth: it varies over the width of a furrow pattern, not from point to
    point); ``phase`` is the position across the furrows, in furrow spacings (the renderer
    draws a furrow at each whole number, per pixel — far finer than the mesh could carry).
    The furrows run across the main compression direction, so their phase is the rest
    position measured along it.
    """
    squeeze, direction, _ = principal_compression(model, positions)
    # Average the compression as a tensor, so opposite directions agree.
    tensor = squeeze[:, None, None] * direction[:, :, None] * direction[:, None, :]
    fields = model.to_vertex @ np.c_[tensor.reshape(len(squeeze), 9), squeeze]
    for _ in range(model.passes):  # buckling is a pattern over several points, not one
        fields = model.smooth @ fields
    v_dir = _principal_axis(fields[:, :9].reshape(-1, 3, 3))             # main compression direction
    v_squeeze = fields[:, 9]
    strength = np.clip((v_squeeze - model.threshold) / (1.0 - model.threshold), 0.0, None) ** model.exponent

    # On the forehead and glabella the lines run straight across or straight up (their skin is
    # held flat by the bone beneath): the direction snaps to the nearer of height and width.
    snapped = np.where(np.abs(v_dir[:, 1:2]) >= np.abs(v_dir[:, 0:1]), [[0.0, 1.0, 0.0]], [[1.0, 0.0, 0.0]])
    along = (1 - model.straight)[:, None] * v_dir + model.straight[:, None] * snapped
    # Between the brows the furrows run straight up (corrugator, FACS 4): brows lowered and
    # drawn together shear this skin diagonally as well as squeezing it sideways, and the
    # shear's vertical part must not draw horizontal lines across the glabella - those read
    # as the wrinkled nose root of 9 (issue 13: anger read as disgust for a "nose wrinkle").
    along = (1 - model.upright)[:, None] * along + model.upright[:, None] * np.array([[1.0, 0.0, 0.0]])
    phase = _furrow_phase(model, along, positions)
    # Squeezed sideways the skin makes vertical furrows; zones may crease less that way (the
    # forehead's deep lines are horizontal: drawn together, brows furrow the glabella, not the brow).
    sideways = along[:, 0] ** 2 / np.maximum((along ** 2).sum(1), 1e-12)
    gain = model.zone_gain * (1.0 - sideways) + model.across_gain * sideways
    out = model.gain * gain * strength * model.on_face * (1.0 + model.crease)
    return np.clip(out, 0.0, 2.0).astype(np.float32), phase.astype(np.float32)


def _furrow_phase(model: WrinkleModel, along: np.ndarray, positions: np.ndarray) -> np.ndarray:
    """The phase whose gradient is ``along / wavelength`` as nearly as can be (least squares
    over the skin edges): furrows then keep their spacing where the direction turns, which
    measuring each point from one origin would not (a small turn there moves far points by
    many furrows).

    A direction's sign is arbitrary: each point takes the one whose largest component is
    positive, and an edge whose ends still disagree (where the field turns through the
    diagonal) asks for no change of phase across it.

    Where the lines run straight across (the forehead), their phase counts the skin's height
    NOW, not at rest: the frontalis lifts the skin above its bellies more than at the midline
    between them, so lines at a fixed rest height sagged into one V over the midline (issue 13).
    Counted on the deformed height they stay level, at an even spacing on the squeezed skin,
    as buckled skin's are. Only the height is taken so: sideways (the glabella's vertical
    furrows under 4) the phase still counts rest width, whose spacing the skin carries along.
    """
    largest = np.take_along_axis(along, np.abs(along).argmax(axis=1)[:, None], axis=1)
    along = along * np.where(largest < 0, -1.0, 1.0)
    i, j = model.edges[:, 0], model.edges[:, 1]
    mean = 0.5 * (along[i] + along[j])
    agree = (along[i] * along[j]).sum(1) > 0
    delta = model.rest[j] - model.rest[i]
    level = 0.5 * (model.straight[i] + model.straight[j])
    delta[:, 1] += level * ((positions[j, 1] - positions[i, 1]) - delta[:, 1])
    step = delta * mean
    diff = np.where(agree, step.sum(1) * 2.0 / (model.wavelength[i] + model.wavelength[j]), 0.0)
    return model.integrate(model.incidence.T @ diff)
