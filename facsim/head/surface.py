"""Per-vertex geometry of triangle meshes, shared by the engines, the renderer and the exporters.

Examples
--------
>>> faces = np.array([[0, 1, 2]])
>>> vertex_normals(np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0]]), faces).tolist()
[[0.0, 0.0, 1.0], [0.0, 0.0, 1.0], [0.0, 0.0, 1.0]]
>>> smoothstep(0.0, 2.0, [0.0, 1.0, 3.0]).tolist()
[0.0, 0.5, 1.0]
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp


def smoothstep(edge0: float, edge1: float, x) -> np.ndarray:
    """0 below ``edge0``, 1 above ``edge1``, ``3t² - 2t³`` between (``edge0 > edge1`` falls instead)."""
    t = np.clip((np.asarray(x, float) - edge0) / (edge1 - edge0), 0.0, 1.0)
    return t * t * (3.0 - 2.0 * t)


def normal_operator(faces: np.ndarray, n_vertices: int) -> sp.csr_matrix:
    """Sparse (n_vertices, M) float32 matrix summing each face's value onto its 3 vertices.

    ``operator @ face_normals`` with unnormalised face normals (cross products, length =
    twice the area) gives area-weighted vertex normals.
    """
    faces = np.asarray(faces, dtype=np.int64)
    m = len(faces)
    rows = faces.reshape(-1)
    cols = np.repeat(np.arange(m), 3)
    data = np.ones(len(rows), dtype=np.float32)
    return sp.csr_matrix((data, (rows, cols)), shape=(n_vertices, m), dtype=np.float32)


def vertex_normals(positions: np.ndarray, faces: np.ndarray,
                   operator: sp.csr_matrix | None = None, *, dtype=np.float32) -> np.ndarray:
    """Area-weighted unit vertex normals.

    Parameters
    ----------
    positions : (N, 3) float
    faces : (M, 3) int, indices into positions
    operator : the :func:`normal_operator` of ``faces`` (pass it to avoid rebuilding)
    dtype : the precision: float32 (drawing; summed by the sparse operator) or float64 (the physics)

    Returns
    -------
    (N, 3) ``dtype``; vertices on no face (or only degenerate ones) get (0, 0, 1).
    """
    if dtype == np.float64 and operator is None:
        # The physics' reference: cross products in the positions' own precision, summed
        # corner by corner in triangle order (the muscle engine's equilibrium depends on its
        # rest normals to the last bit).
        p = np.asarray(positions)
        fn = np.cross(p[faces[:, 1]] - p[faces[:, 0]], p[faces[:, 2]] - p[faces[:, 0]])
        vn = np.zeros(p.shape, np.float64)
        for k in range(3):
            np.add.at(vn, faces[:, k], fn)
        length = np.linalg.norm(vn, axis=1, keepdims=True)
        return np.where(length > 0, vn / np.where(length > 0, length, 1.0), (0.0, 0.0, 1.0))
    else:
        p = np.asarray(positions, dtype=dtype)
        a = p[faces[:, 0]]
        e1 = p[faces[:, 1]] - a
        e2 = p[faces[:, 2]] - a
        fn = np.empty_like(e1)
        fn[:, 0] = e1[:, 1] * e2[:, 2] - e1[:, 2] * e2[:, 1]
        fn[:, 1] = e1[:, 2] * e2[:, 0] - e1[:, 0] * e2[:, 2]
        fn[:, 2] = e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0]
        if operator is None:
            operator = normal_operator(faces, len(p))
        vn = operator.astype(dtype, copy=False) @ fn
    length = np.sqrt(np.einsum("ij,ij->i", vn, vn))
    bad = length < 1e-20
    length[bad] = 1.0
    vn /= length[:, None]
    if bad.any():
        vn[bad] = (0.0, 0.0, 1.0)
    return vn.astype(dtype, copy=False)
