"""Face Mesh landmark ↔ hm08 surface point: the table, and how it is made.

Each of the 468 Face Mesh v1 landmarks is bound to one point on the hm08
skin: three base-mesh vertex indices and barycentric weights. The binding is
measured, not hand-placed: facsim's own neutral heads are rendered for many
identities and views, the landmark model is run on the renders, and each
landmark pixel is cast back onto the mesh (the nearest skin triangle under the
pixel — the depth test a z-buffer makes, done exactly on the CPU). The hits
of all renders are averaged on the reference (hm08 base) mesh and snapped to
its surface. The spread of the hits (mm) is kept as each landmark's
uncertainty, so the fit can trust stable points more.

Landmarks on the lid margins often fall on the eyeball in a render; they are
bound to the nearest lid skin instead (the margin is what the model tracks).

Run ``python -m facsim.analysis.correspondence`` to rebuild
``facsim/data/facemesh_hm08.yaml``.
"""
from __future__ import annotations

from functools import lru_cache
from importlib import resources

import numpy as np
import yaml

DATA_FILE = "data/facemesh_hm08.yaml"
#: Identities and views the shipped table was measured on.
BUILD_CHARACTERS = ("ava", "liam", "amara", "kwame", "mei", "hiro", "margaret", "george", "sofia", "arjun",
                    "random:1", "random:2")
BUILD_VIEWS = ((0, 0), (-20, 0), (20, 0), (-35, 0), (35, 0), (0, -12), (0, 12))
BUILD_SIZE = 448


@lru_cache(maxsize=1)
def load_correspondence() -> dict:
    """The shipped table: ``vertices`` (468, 3) hm08 base indices, ``weights`` (468, 3), ``spread_mm`` (468,)."""
    table = yaml.safe_load(resources.files("facsim").joinpath(DATA_FILE).read_text())
    rows = np.array(table["landmarks"], dtype=float)
    out = {
        "vertices": rows[:, 0:3].astype(np.int64),
        "weights": rows[:, 3:6],
        "spread_mm": rows[:, 6],
        "samples": rows[:, 7].astype(int),
    }
    for value in out.values():
        value.flags.writeable = False
    return out


def surface_points(base_positions: np.ndarray, table: dict | None = None) -> np.ndarray:
    """Landmark positions (468, 3) on a morphed hm08 base mesh (19158, 3)."""
    table = table or load_correspondence()
    return np.einsum("lk,lkd->ld", table["weights"], np.asarray(base_positions)[table["vertices"]])


# ------------------------------------------------------------------ building


def closest_surface_point(point: np.ndarray, positions: np.ndarray, triangles: np.ndarray):
    """The closest point of a triangle soup to ``point``: (triangle index, barycentrics)."""
    centroid = positions[triangles].mean(axis=1)
    near = np.argsort(((centroid - point) ** 2).sum(axis=1))[:24]
    best = (None, None, np.inf)
    for t in near:
        a, b, c = positions[triangles[t]]
        bary = _closest_on_triangle(point, a, b, c)
        d = float(((bary @ np.stack([a, b, c]) - point) ** 2).sum())
        if d < best[2]:
            best = (int(t), bary, d)
    return best[0], best[1]


def _closest_on_triangle(p, a, b, c) -> np.ndarray:
    """Barycentrics of the point of triangle abc closest to p (Ericson, Real-Time Collision Detection 5.1.5)."""
    ab, ac, ap = b - a, c - a, p - a
    d1, d2 = ab @ ap, ac @ ap
    if d1 <= 0 and d2 <= 0:
        return np.array([1.0, 0, 0])
    bp = p - b
    d3, d4 = ab @ bp, ac @ bp
    if d3 >= 0 and d4 <= d3:
        return np.array([0, 1.0, 0])
    vc = d1 * d4 - d3 * d2
    if vc <= 0 and d1 >= 0 and d3 <= 0:
        v = d1 / (d1 - d3)
        return np.array([1 - v, v, 0])
    cp = p - c
    d5, d6 = ab @ cp, ac @ cp
    if d6 >= 0 and d5 <= d6:
        return np.array([0, 0, 1.0])
    vb = d5 * d2 - d1 * d6
    if vb <= 0 and d2 >= 0 and d6 <= 0:
        w = d2 / (d2 - d6)
        return np.array([1 - w, 0, w])
    va = d3 * d6 - d5 * d4
    if va <= 0 and (d4 - d3) >= 0 and (d5 - d6) >= 0:
        w = (d4 - d3) / ((d4 - d3) + (d5 - d6))
        return np.array([0, 1 - w, w])
    denom = 1.0 / (va + vb + vc)
    v, w = vb * denom, vc * denom
    return np.array([1 - v - w, v, w])


def build_correspondence(characters=BUILD_CHARACTERS, views=BUILD_VIEWS, *, size: int = BUILD_SIZE,
                         progress: bool = True) -> dict:
    """Render, detect, cast and aggregate (see the module docstring); returns the table as a dict."""
    import sys

    from facsim.face import Face, load_head
    from facsim.render.picking import pick

    from .landmarks import LandmarkDetector

    head = load_head()
    n_base_geo = len(head.base_index)
    skin_tris = head.triangles[(head.triangles < head.skin_vertex_count).all(axis=1)]
    skin_tris = skin_tris[(head.region[skin_tris] == 0).all(axis=1)]
    skin_tris = skin_tris[(skin_tris < n_base_geo).all(axis=1)]
    eyes = np.concatenate(list(head.eye_vertices.values()))
    eye_tris = head.triangles[np.isin(head.triangles, eyes).all(axis=1)]
    lid_tris = skin_tris[_near_eyes(head, skin_tris)]
    reference = head.base_vertices
    samples = [[] for _ in range(468)]
    with LandmarkDetector(irises=False) as detector:
        for ci, name in enumerate(characters):
            face = Face(name)
            for yaw, pitch in views:
                image = face.render(None, yaw=yaw, pitch=pitch, size=size, background=(0.5, 0.5, 0.5))
                found = detector.faces(image[..., :3])
                if not found:
                    continue
                camera = face.camera(yaw=yaw, pitch=pitch, size=(size, size))
                geo = face.neutral
                tri, bary, _ = pick(found[0].points[:, :2], geo, skin_tris, camera, size, occluders=eye_tris)
                visible_lids = None
                for k in range(468):
                    if tri[k] < 0:  # on the eyeball (lid margin): the closest visible lid skin in the image
                        if visible_lids is None:
                            visible_lids = _visible(lid_tris, geo, skin_tris, camera, size, eye_tris)
                        t, b = _closest_in_image(found[0].points[k, :2], geo, visible_lids, camera, size)
                    else:
                        t, b = skin_tris[tri[k]], bary[k]
                    samples[k].append(b @ reference[head.base_index[t]])
            face.close()
            if progress:
                sys.stderr.write(f"\rcorrespondence: {ci + 1}/{len(characters)} identities")
    if progress:
        sys.stderr.write("\n")
    ref_tris = head.base_index[skin_tris]
    rows = []
    for k in range(468):
        pts = np.array(samples[k])
        centre = np.median(pts, axis=0)
        t, b = closest_surface_point(centre, reference, ref_tris)
        spread = float(np.sqrt(((pts - centre) ** 2).sum(axis=1).mean())) * 100.0  # dm → mm
        rows.append([*map(int, ref_tris[t]), *(round(float(x), 5) for x in b), round(spread, 2), len(pts)])
    return {"landmarks": rows, "characters": list(characters), "views": [list(v) for v in views], "size": size}


def _near_eyes(head, tris) -> np.ndarray:
    """Skin triangles within 6 mm of an eyeball's surface (the lids)."""
    pos = head.positions(head.base_vertices)
    keep = np.zeros(len(tris), bool)
    for side in head.eye_vertices:
        centre, radius = head.eye_pivot(head.base_vertices, side)
        d = np.linalg.norm(pos[tris].mean(axis=1) - centre, axis=1)
        keep |= d < radius + 0.06
    return keep


def _visible(tris, positions, skin_tris, camera, size, occluders) -> np.ndarray:
    """The triangles of ``tris`` that are the nearest surface at their own centroid pixel."""
    from facsim.render.camera import project
    from facsim.render.picking import pick

    px, _ = project(camera, positions, size)
    centres = px[tris].mean(axis=1)
    hit, _, _ = pick(centres, positions, skin_tris, camera, size, occluders=occluders)
    keep = np.array([h >= 0 and set(skin_tris[h]) == set(t) for h, t in zip(hit, tris)])
    return tris[keep]


def _closest_in_image(p, positions, tris, camera, size):
    from facsim.render.camera import project

    px, _ = project(camera, positions, size)
    centre = px[tris].mean(axis=1)
    t = int(np.argmin(((centre - p) ** 2).sum(axis=1)))
    return tris[t], np.full(3, 1 / 3)


def main() -> None:
    import datetime

    from facsim.atomic import atomic_write

    table = build_correspondence()
    header = (
        "# Face Mesh v1 landmark -> hm08 surface point, made by `python -m facsim.analysis.correspondence`\n"
        f"# on {datetime.date.today().isoformat()}: {len(table['characters'])} identities x {len(table['views'])} "
        "views of facsim's neutral heads, landmarks detected and cast back onto the skin.\n"
        "# Each row: three hm08 base-mesh vertex indices, barycentric weights, spread of the hits (mm),\n"
        "# number of renders the landmark was measured in. Row i is Face Mesh landmark i.\n"
    )
    body = yaml.safe_dump({"characters": table["characters"], "views": table["views"], "size": table["size"]},
                          sort_keys=False)
    rows = "landmarks:\n" + "".join(f"  - {row}\n" for row in table["landmarks"])
    path = resources.files("facsim").joinpath(DATA_FILE)
    atomic_write(path, lambda tmp: tmp.write_text(header + body + rows))
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
