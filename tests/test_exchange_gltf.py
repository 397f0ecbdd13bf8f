"""glTF export: Khronos-valid .glb with AU morph targets, a neck/head skin, eye nodes and an animation.

The validator test runs the pinned npm ``gltf-validator`` (tests/gltf_validator/)
with node; it skips only where node is not installed.
"""
from __future__ import annotations

import json
import shutil
import struct
import subprocess
from pathlib import Path

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from facsim.exchange.gltf import METRES, glb_bytes, morph_target_keys, target_name
from facsim.engines.registers import response
from facsim.facs.activations import Activations
from facsim.timeline.model import Envelope, Hold, Timeline, Track
from facsim.timeline.sampling import frame_count, frame_times, sample

VALIDATOR_DIR = Path(__file__).parent / "gltf_validator"
_COMPONENTS = {5126: np.float32, 5121: np.uint8, 5123: np.uint16, 5125: np.uint32}
_SIZES = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4, "MAT4": 16}

TIMELINE = Timeline((
    Track(facs="1+2+12+26", timing=Envelope(0.1, 0.3, 0.2, 0.3, 0.85)),
    Track(au=12, side="left", timing=Hold(0.2, 0.7, 0.3)),
    Track(au=51, timing=Envelope(0.0, 0.4, 0.2, 0.3, 0.6)),
    Track(au=54, timing=Hold(0.3, 0.6, 0.5)),
    Track(au=61, timing=Hold(0.2, 0.8, 0.5)),
    Track(au=64, timing=Hold(0.5, 0.9, 0.4)),
), duration=1.0, fps=10)


def read_glb(data: bytes) -> tuple[dict, bytes]:
    magic, version, length = struct.unpack_from("<4sII", data, 0)
    assert magic == b"glTF" and version == 2 and length == len(data)
    json_len, json_type = struct.unpack_from("<I4s", data, 12)
    assert json_type == b"JSON"
    doc = json.loads(data[20:20 + json_len])
    bin_len, bin_type = struct.unpack_from("<I4s", data, 20 + json_len)
    assert bin_type == b"BIN\0"
    return doc, data[28 + json_len:28 + json_len + bin_len]


def accessor(doc: dict, blob: bytes, index: int) -> np.ndarray:
    acc = doc["accessors"][index]
    dtype, size = _COMPONENTS[acc["componentType"]], _SIZES[acc["type"]]

    def view(i, count, dt, n):
        v = doc["bufferViews"][i]
        return np.frombuffer(blob, dt, count * n, v["byteOffset"]).reshape(count, n)

    if "bufferView" in acc:
        out = view(acc["bufferView"], acc["count"], dtype, size).copy()
    else:
        out = np.zeros((acc["count"], size), dtype)
    if "sparse" in acc:
        sp = acc["sparse"]
        idx = view(sp["indices"]["bufferView"], sp["count"], _COMPONENTS[sp["indices"]["componentType"]], 1)[:, 0]
        out[idx] = view(sp["values"]["bufferView"], sp["count"], dtype, size)
    return out


@pytest.fixture(scope="module")
def face(face_of):
    return face_of("ava")


@pytest.fixture(scope="module")
def animated(face):
    data = glb_bytes(face, TIMELINE)
    return data, *read_glb(data)


@pytest.fixture(scope="module")
def validator():
    """The command that validates a .glb with the pinned Khronos validator (installs it once if needed)."""
    node = shutil.which("node")
    if node is None:
        pytest.skip("node is not installed: the Khronos glTF validator (npm gltf-validator) runs on node")
    if not (VALIDATOR_DIR / "node_modules" / "gltf-validator").is_dir():
        npm = shutil.which("npm")
        done = npm and subprocess.run([npm, "ci", "--no-audit", "--no-fund"], cwd=VALIDATOR_DIR,
                                      capture_output=True, text=True, timeout=300)
        if not done or done.returncode != 0:
            pytest.fail("node is installed but gltf-validator is not, and `npm ci` in tests/gltf_validator failed: "
                        + (done.stderr[-500:] if done else "npm not found"))
    script = ("const fs=require('fs'),v=require('gltf-validator');"
              "v.validateBytes(new Uint8Array(fs.readFileSync(process.argv[1])),{maxIssues:0,writeTimestamp:false})"
              ".then(r=>console.log(JSON.stringify(r)),e=>{console.error(String(e));process.exit(1);});")
    return lambda path: [node, "-e", script, str(path)]


def validate(validator, path) -> dict:
    run = subprocess.run(validator(path), cwd=VALIDATOR_DIR, capture_output=True, text=True, timeout=120)
    assert run.returncode == 0, run.stderr
    return json.loads(run.stdout)


def test_validator_reports_no_errors_on_an_animated_character(tmp_path, animated, validator):
    path = tmp_path / "ava.glb"
    path.write_bytes(animated[0])
    report = validate(validator, path)
    issues = report["issues"]
    assert issues["numErrors"] == 0 and issues["numWarnings"] == 0, issues["messages"][:10]
    info = report["info"]
    assert info["hasMorphTargets"] and info["hasSkins"] and info["hasTextures"] and info["animationCount"] == 1


def test_validator_is_clean_on_another_character_with_step_keys(tmp_path, face_of, validator):
    path = tmp_path / "kwame.glb"
    path.write_bytes(glb_bytes(face_of("kwame"), TIMELINE, aus=[4, 12, 26, 45], interpolation="step", normals=False))
    issues = validate(validator, path)["issues"]
    assert issues["numErrors"] == 0 and issues["numWarnings"] == 0, issues["messages"][:10]


def test_morph_targets_are_named_per_au_and_side(animated):
    _, doc, _ = animated
    keys = morph_target_keys()
    names = doc["meshes"][0]["extras"]["targetNames"]
    assert names == [target_name(*k) for k in keys]
    assert {"AU12_L", "AU12_R", "AU26", "AU01_L", "AU45"} <= set(names) and "AU51" not in names
    assert len(doc["meshes"][0]["weights"]) == len(names)
    for primitive in doc["meshes"][0]["primitives"]:
        assert len(primitive["targets"]) == len(names)


def test_a_morph_target_is_the_register_engine_at_that_au_minus_neutral(face, animated):
    _, doc, blob = animated
    primitive = doc["meshes"][0]["primitives"][0]
    names = doc["meshes"][0]["extras"]["targetNames"]
    base = accessor(doc, blob, primitive["attributes"]["POSITION"])
    delta = accessor(doc, blob, primitive["targets"][names.index("AU12_L")]["POSITION"])
    geo = _head_geometry_vertices(face)
    expected = np.asarray(face.engine.deform(Activations({(12, "left"): 1.0})).positions, float)[geo] * METRES
    assert np.abs(base + delta - expected).max() < 1e-6
    assert np.abs(base - np.asarray(face.neutral, float)[geo] * METRES).max() < 1e-6


def test_accessor_bounds_match_the_data(animated):
    _, doc, blob = animated
    checked = 0
    for i, acc in enumerate(doc["accessors"]):
        if "min" in acc:
            data = accessor(doc, blob, i)
            assert acc["min"] == data.min(axis=0).tolist() and acc["max"] == data.max(axis=0).tolist()
            checked += 1
    assert checked > 20


def test_animation_has_weights_head_and_eye_channels_sampled_per_frame(animated):
    _, doc, blob = animated
    anim = doc["animations"][0]
    nodes = doc["nodes"]
    channels = {(nodes[c["target"]["node"]]["name"], c["target"]["path"]) for c in anim["channels"]}
    assert channels == {("face", "weights"), ("head", "rotation"), ("head", "translation"),
                        ("eye_L", "rotation"), ("eye_R", "rotation")}
    n = frame_count(TIMELINE)
    times = accessor(doc, blob, anim["samplers"][0]["input"])[:, 0]
    assert np.allclose(times, frame_times(TIMELINE)) and len(times) == n
    assert {s["interpolation"] for s in anim["samplers"]} == {"LINEAR"}
    by_target = {(nodes[c["target"]["node"]]["name"], c["target"]["path"]): anim["samplers"][c["sampler"]]
                 for c in anim["channels"]}
    names = doc["meshes"][0]["extras"]["targetNames"]
    weights = accessor(doc, blob, by_target["face", "weights"]["output"]).reshape(n, len(names))
    frame = 5                                                       # t = 0.5 s
    act = sample(TIMELINE, frame / 10)
    # each target is its AU at E, weighted as the register engine moves it (its concave response)
    assert weights[frame, names.index("AU12_L")] == pytest.approx(response(act[12, "left"], 12))
    assert weights[frame, names.index("AU26")] == pytest.approx(response(act.level(26)))
    assert 0.0 < act.level(26) < response(act.level(26)) < 1.0
    quats = accessor(doc, blob, by_target["head", "rotation"]["output"])
    assert np.allclose(np.linalg.norm(quats, axis=1), 1.0, atol=1e-6)
    rotvec = Rotation.from_quat(quats[frame]).as_rotvec(degrees=True)
    assert rotvec == pytest.approx([25 * act.level(54), 35 * act.level(51), 0.0], abs=1e-3)
    eye = Rotation.from_quat(accessor(doc, blob, by_target["eye_L", "rotation"]["output"])[frame])
    assert eye.as_rotvec(degrees=True) == pytest.approx([30 * act.level(64), 30 * act.level(61), 0], abs=1e-3)


def test_skin_follows_the_engines_neck_blend(face, animated):
    _, doc, blob = animated
    primitive = doc["meshes"][0]["primitives"][0]
    joints = accessor(doc, blob, primitive["attributes"]["JOINTS_0"])
    weights = accessor(doc, blob, primitive["attributes"]["WEIGHTS_0"])
    assert np.allclose(weights.sum(axis=1), 1.0, atol=1e-6)
    assert set(np.unique(joints[:, :2])) <= {0, 1} and not np.any((joints > 0) & (weights == 0))
    # Rotating the head joint by AU51 reproduces the engine where the blend is 0 or 1.
    act = Activations({(51, "left"): 1.0, (51, "right"): 1.0})
    pivot = np.array(doc["nodes"][0]["translation"])
    base = accessor(doc, blob, primitive["attributes"]["POSITION"]).astype(float)
    turned = Rotation.from_rotvec([0, np.radians(35), 0]).apply(base - pivot) + pivot
    skinned = weights[:, :1] * base + weights[:, 1:2] * turned
    expected = np.asarray(face.engine.deform(act).positions, float)[_head_geometry_vertices(face)] * METRES
    rigid = (weights[:, 1] > 1 - 1e-6) | (weights[:, 1] < 1e-6)
    assert rigid.mean() > 0.8 and np.abs(skinned[rigid] - expected[rigid]).max() < 1e-5


def test_step_interpolation_and_au_subset(face):
    doc, blob = read_glb(glb_bytes(face, TIMELINE, aus=[12, 26], interpolation="step", normals=False))
    assert doc["meshes"][0]["extras"]["targetNames"] == ["AU12_L", "AU12_R", "AU26"]
    assert {s["interpolation"] for s in doc["animations"][0]["samplers"]} == {"STEP"}
    assert "NORMAL" not in doc["meshes"][0]["primitives"][0]["attributes"]
    with pytest.raises(ValueError, match="AU51 has no morph target"):
        glb_bytes(face, aus=[51])


def test_eyes_are_separate_nodes_at_the_eye_centres(face, animated):
    _, doc, blob = animated
    nodes = {n["name"]: n for n in doc["nodes"]}
    assert nodes["head"]["children"] == [doc["nodes"].index(nodes["eye_L"]), doc["nodes"].index(nodes["eye_R"])]
    centre, radius = face.head.eye_pivot(face.base_positions, "left")
    pivot = np.array(nodes["neck"]["translation"])
    assert pivot + np.array(nodes["eye_L"]["translation"]) == pytest.approx(np.asarray(centre) * METRES, abs=1e-6)
    mesh = doc["meshes"][nodes["eye_L"]["mesh"]]
    points = accessor(doc, blob, mesh["primitives"][0]["attributes"]["POSITION"])
    assert np.linalg.norm(points, axis=1) == pytest.approx(radius * METRES, rel=1e-5)
    # skin, eye, then the scalp layer under the hair and one per proxy (hair, brows, lashes)
    assert face.scalp is not None
    assert len(doc["images"]) == 3 + len(face.proxies) and all(img["mimeType"] == "image/png" for img in doc["images"])


def _head_geometry_vertices(face):
    from facsim.head.mesh import REGIONS

    topo = face.head.topology
    return topo.render_to_geo[topo.region != REGIONS.index("eyeball")]
