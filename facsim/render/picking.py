"""Which triangle is under a pixel: the renderer's depth test, answered exactly on the CPU for a few pixels.

The camera processor binds image landmarks to the mesh surface with it
(:mod:`facsim.analysis.correspondence`): for each pixel, every triangle whose
projection covers it is a candidate and the nearest one along the view ray
wins — what the z-buffer keeps — with perspective-correct barycentrics.
No GL: for a few hundred pixels this is exact and needs no read-back.
"""
from __future__ import annotations

import numpy as np


def pick(points_px: np.ndarray, positions: np.ndarray, triangles: np.ndarray, camera, size, *,
         occluders: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The nearest triangle under each pixel and the hit's perspective-correct barycentrics.

    Parameters
    ----------
    points_px : (L, 2) pixel positions
    positions : (N, 3) geometry positions
    triangles : (M, 3) candidate triangles (skin)
    occluders : (K, 3) triangles that hide skin but are never bound to (the eyeballs)

    Returns
    -------
    tri : (L,) index into ``triangles`` or -1 where no skin is hit or an occluder is nearer
    bary : (L, 3) barycentric weights
    depth : (L,) depth of the hit (inf on a miss)
    """
    from .camera import project

    px, depth = project(camera, positions, size)
    tri_out = np.full(len(points_px), -1)
    bary_out = np.zeros((len(points_px), 3))
    depth_out = np.full(len(points_px), np.inf)
    for k, p in enumerate(points_px):
        hit = _nearest_hit(p, px, depth, triangles)
        if hit is None:
            continue
        t, b, z = hit
        if occluders is not None and len(occluders):
            block = _nearest_hit(p, px, depth, occluders)
            if block is not None and block[2] < z:
                continue
        tri_out[k], bary_out[k], depth_out[k] = t, b, z
    return tri_out, bary_out, depth_out


def _nearest_hit(p, px, depth, triangles):
    a, b, c = px[triangles[:, 0]], px[triangles[:, 1]], px[triangles[:, 2]]
    v0, v1, v2 = b - a, c - a, p - a
    den = v0[:, 0] * v1[:, 1] - v1[:, 0] * v0[:, 1]
    ok = np.abs(den) > 1e-12
    den = np.where(ok, den, 1.0)
    u = (v2[:, 0] * v1[:, 1] - v1[:, 0] * v2[:, 1]) / den
    v = (v0[:, 0] * v2[:, 1] - v2[:, 0] * v0[:, 1]) / den
    inside = ok & (u >= 0) & (v >= 0) & (u + v <= 1)
    if not inside.any():
        return None
    idx = np.flatnonzero(inside)
    w = np.stack([1 - u[idx] - v[idx], u[idx], v[idx]], axis=1)
    z = depth[triangles[idx]]
    # screen-space weights → perspective-correct: divide by depth, renormalise
    pc = w / z
    pc /= pc.sum(axis=1, keepdims=True)
    zhit = (pc * z).sum(axis=1)
    best = int(np.argmin(zhit))
    return int(idx[best]), pc[best], float(zhit[best])
