"""OBJ and PLY: one deformed frame of a character's head, for any mesh tool.

Both hold the head's geometry vertices (skin, teeth, tongue, lashes, eyeballs,
neck cap; one vertex per mesh point) in metres (facsim's decimetres × 0.1),
with facsim's axes (+Y up, the face looks toward +Z, +X the character's left),
smooth normals, and the triangles. When the engine computes skin compression
(a :class:`~facsim.engines.base.Deformation` with a wrinkle: the muscle engine; 0 = none,
1 = a deep fold) it goes along per vertex, for any expression but neutral:

PLY (binary little-endian)
    ``x y z nx ny nz`` floats, then a float property ``wrinkle`` when there
    is one; faces as ``vertex_indices`` lists. The header's comments name
    the expression, character and engine.
OBJ
    Standard and comment-free: ``v``, ``vt`` (skin UVs, normalised to the
    head's paint box, as the renderer uses them), ``vn``, one group per
    region (``g skin``, ``g mouth_interior``, ``g teeth``, ``g tongue``,
    ``g eyeball``, ``g lashes``; skin faces ``v/vt/vn``, others ``v//vn``).
    The wrinkle rides as a grey vertex colour, the widely read ``v x y z r g b``
    extension (MeshLab, Blender, Open3D) with r = g = b = wrinkle clipped to
    0..1; without a wrinkle the vertices are plain ``v x y z``.
"""
from __future__ import annotations

import io
from pathlib import Path

import numpy as np

from facsim.exchange import write_file

#: facsim decimetres → metres.
METRES = 0.1
SUFFIXES = (".obj", ".ply")


def deformed_frame(face, expression=None) -> tuple[np.ndarray, np.ndarray, np.ndarray | None]:
    """Positions (N_geo, 3) in metres, unit normals (N_geo, 3) and the wrinkle (N_geo,) or None."""
    from facsim.head.surface import vertex_normals

    deformation = face.deform(expression)
    positions = np.asarray(deformation.positions, np.float64)
    wrinkle = None if deformation.wrinkle is None else np.asarray(deformation.wrinkle, np.float32)
    normals = vertex_normals(positions, face.head.topology.geo_faces)
    return (positions * METRES).astype(np.float32), normals, wrinkle


def ply_bytes(positions, normals, triangles, wrinkle=None, *, comments=()) -> bytes:
    """A binary little-endian PLY of a triangle mesh (optional float vertex property ``wrinkle``)."""
    n, m = len(positions), len(triangles)
    props = ["x", "y", "z", "nx", "ny", "nz"] + (["wrinkle"] if wrinkle is not None else [])
    header = ["ply", "format binary_little_endian 1.0", *(f"comment {c}" for c in comments),
              f"element vertex {n}", *(f"property float {p}" for p in props),
              f"element face {m}", "property list uchar int vertex_indices", "end_header"]
    columns = [np.asarray(positions, np.float32), np.asarray(normals, np.float32)]
    if wrinkle is not None:
        columns.append(np.asarray(wrinkle, np.float32).reshape(-1, 1))
    vertices = np.ascontiguousarray(np.concatenate(columns, axis=1), dtype="<f4")
    faces = np.zeros(m, dtype=[("n", "u1"), ("v", "<i4", (3,))])
    faces["n"], faces["v"] = 3, np.asarray(triangles)
    return ("\n".join(header) + "\n").encode("ascii") + vertices.tobytes() + faces.tobytes()


def obj_text(positions, normals, topology, wrinkle=None) -> str:
    """A comment-free OBJ: vertices (with grey wrinkle colour), skin UVs, normals, a group per region."""
    from facsim.head.mesh import REGIONS

    out = io.StringIO()
    if wrinkle is None:
        np.savetxt(out, positions, fmt="v %.6f %.6f %.6f")
    else:
        grey = np.clip(np.asarray(wrinkle, float), 0.0, 1.0)[:, None]
        np.savetxt(out, np.hstack([positions, grey, grey, grey]), fmt="v %.6f %.6f %.6f %.4f %.4f %.4f")
    np.savetxt(out, topology.uv, fmt="vt %.6f %.6f")
    np.savetxt(out, normals, fmt="vn %.5f %.5f %.5f")
    regions = topology.face_regions()
    for index, name in enumerate(REGIONS):
        faces = topology.faces[regions == index]
        if not len(faces):
            continue
        out.write(f"g {name}\n")
        geo = topology.render_to_geo[faces] + 1
        if name == "skin":
            rows = np.stack([geo, faces + 1, geo], axis=-1).reshape(len(faces), 9)
            np.savetxt(out, rows, fmt="f %d/%d/%d %d/%d/%d %d/%d/%d")
        else:
            rows = np.stack([geo, geo], axis=-1).reshape(len(faces), 6)
            np.savetxt(out, rows, fmt="f %d//%d %d//%d %d//%d")
    return out.getvalue()


def write_mesh(face, expression, path) -> Path:
    """Write one frame of ``face`` showing ``expression`` as ``.obj`` or ``.ply`` (by suffix), atomically.

    Parameters
    ----------
    face : facsim.face.Face
        Its engine deforms the mesh; the muscle engine's skin compression
        goes into the file as ``wrinkle``.
    expression : str, Expression, Activations or None
        FACS notation such as ``"6+12"``; None is the neutral face.
    path : path
    """
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in SUFFIXES:
        raise ValueError(f"unsupported mesh file type {suffix or '(none)'!r} for {str(path)!r}; use .obj or .ply")
    positions, normals, wrinkle = deformed_frame(face, expression)
    if suffix == ".ply":
        from facsim import __version__

        label = expression if isinstance(expression, str) else str(expression or "neutral")
        comments = [f"facsim {__version__}: {label}", f"character {face.character.name or 'custom'}",
                    f"engine {face.engine_name}", "units metres, +Y up, face toward +Z, +X the character's left"]
        data = ply_bytes(positions, normals, face.head.triangles, wrinkle, comments=comments)
    else:
        data = obj_text(positions, normals, face.head.topology, wrinkle)
    return write_file(path, data)
