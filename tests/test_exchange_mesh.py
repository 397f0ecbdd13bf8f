"""OBJ and PLY of one deformed frame, with the muscle engine's wrinkle when there is one."""
from __future__ import annotations


import numpy as np
import pytest

from facsim.exchange import write_mesh
from facsim.facs.activations import Activations
from facsim.facs.notation import parse



def read_ply(path):
    data = path.read_bytes()
    head, body = data.split(b"end_header\n", 1)
    lines = head.decode("ascii").splitlines()
    assert lines[:2] == ["ply", "format binary_little_endian 1.0"]
    n_vertices = int(next(l for l in lines if l.startswith("element vertex")).split()[-1])
    n_faces = int(next(l for l in lines if l.startswith("element face")).split()[-1])
    props = [l.split()[-1] for l in lines if l.startswith("property float")]
    vertices = np.frombuffer(body, "<f4", n_vertices * len(props)).reshape(n_vertices, len(props))
    faces = np.frombuffer(body[vertices.nbytes:], [("n", "u1"), ("v", "<i4", (3,))], n_faces)
    assert len(body) == vertices.nbytes + faces.nbytes
    return props, vertices, faces, lines


def test_ply_holds_the_deformed_frame_in_metres(tmp_path, face_of):
    face = face_of("ava")
    props, vertices, faces, header = read_ply(write_mesh(face, "6+12", tmp_path / "smile.ply"))
    assert props == ["x", "y", "z", "nx", "ny", "nz", "wrinkle"]        # both engines crease the skin
    assert vertices[:, 6].max() > 0.3                                   # 6+12: crow's feet, nasolabial fold
    expected = np.asarray(face.engine.deform(Activations({(c, s): 1.0 for c in (6, 12) for s in ("left", "right")})).positions)
    assert np.abs(vertices[:, :3] - expected * 0.1).max() < 1e-6
    assert np.allclose(np.linalg.norm(vertices[:, 3:6], axis=1), 1, atol=1e-4)
    assert np.all(faces["n"] == 3) and np.array_equal(faces["v"], face.head.triangles)
    assert "comment facsim" in header[2] and "6+12" in header[2]


def test_obj_is_standard_with_uvs_normals_and_region_groups(tmp_path, face_of):
    face = face_of("ava")
    text = write_mesh(face, parse("R12A+L14"), tmp_path / "face.obj").read_text()
    lines = text.splitlines()
    assert not any(line.startswith("#") for line in lines)
    kinds = {k: sum(1 for line in lines if line.startswith(k + " ")) for k in ("v", "vt", "vn", "f", "g")}
    topo = face.head.topology
    assert kinds == {"v": face.head.vertex_count, "vt": topo.n_render, "vn": face.head.vertex_count,
                     "f": len(topo.faces), "g": 6}
    assert "g skin" in lines and "g eyeball" in lines
    first_v = next(line for line in lines if line.startswith("v "))
    assert len(first_v.split()) == 7                                    # the wrinkle as a vertex colour
    skin_face = lines[lines.index("g skin") + 1]
    assert skin_face.count("/") == 6 and "//" not in skin_face


def test_neutral_and_bad_suffix(tmp_path, face_of):
    face = face_of("ava")
    _, vertices, _, _ = read_ply(write_mesh(face, None, tmp_path / "neutral.ply"))
    assert np.abs(vertices[:, :3] - np.asarray(face.neutral) * 0.1).max() < 1e-6
    with pytest.raises(ValueError, match="use .obj or .ply"):
        write_mesh(face, "12", tmp_path / "face.stl")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["neutral.ply"]


def test_muscle_engine_wrinkle_goes_into_both_formats(tmp_path, face_of):
    face = face_of("ava", "muscle")
    props, vertices, _, _ = read_ply(write_mesh(face, "4+6+12", tmp_path / "m.ply"))
    assert props[-1] == "wrinkle"
    assert np.array_equal(vertices[:, 6], np.asarray(face.deform("4+6+12").wrinkle, np.float32))
    first_v = next(line for line in write_mesh(face, "4", tmp_path / "m.obj").read_text().splitlines()
                   if line.startswith("v "))
    assert len(first_v.split()) == 7                                    # v x y z r g b
