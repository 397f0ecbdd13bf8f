"""The head model: a closed, symmetric head with working eyes."""
from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

from facsim.head.mesh import HEAD_REGIONS, REGIONS


def test_head_is_symmetric_and_has_every_part(head):
    p = head.positions(head.base_vertices)
    assert np.allclose(p[head.mirror] * [-1, 1, 1], p, atol=1e-5)
    counts = np.bincount(head.region, minlength=len(REGIONS))
    for name in HEAD_REGIONS:
        assert counts[REGIONS.index(name)] > 50, name
    assert counts[REGIONS.index("garment")] == 0  # the body's (facsim.head.body), not the head's


def test_neck_is_capped_so_the_surface_is_closed(head):
    tris = head.triangles[np.isin(head.triangles, head.skin).all(1) | (head.triangles == head.cap_vertex).any(1)]
    edges = np.sort(np.concatenate([tris[:, [0, 1]], tris[:, [1, 2]], tris[:, [2, 0]]]), axis=1)
    _, counts = np.unique(edges, axis=0, return_counts=True)
    assert (counts == 2).all()  # every skin edge has two triangles: no holes


def test_eye_rotation_keeps_the_eyeball_centre_fixed(head):
    base = head.base_vertices
    rot = Rotation.from_euler("xy", [20, -30], degrees=True).as_matrix()
    p = head.positions(base, eye_rotations={"left": rot, "right": np.eye(3)})
    centre, radius = head.eye_pivot(base, "left")
    eye = p[head.eye_vertices["left"]]
    assert np.allclose(np.linalg.norm(eye - centre, axis=1), radius, atol=1e-5)
    front = eye[np.argmax(head.eye_local[:, 2])]  # the pupil's centre
    assert np.allclose((front - centre) / radius, rot @ [0, 0, 1], atol=1e-5)
    neutral = head.positions(base)
    assert np.allclose(p[head.eye_vertices["right"]], neutral[head.eye_vertices["right"]])


def test_lashes_are_shortened_toward_the_lid(head):
    p = head.positions(head.base_vertices)
    raw = head.base_vertices[head.base_index[head.lashes]]
    roots = head.base_vertices[head.base_index[head.lash_roots]]
    assert np.linalg.norm(p[head.lashes] - p[head.lash_roots], axis=1).sum() < \
        np.linalg.norm(raw - roots, axis=1).sum()
