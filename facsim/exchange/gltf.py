"""glTF 2.0 binary (``.glb``): a character's head with its AUs as morph targets, rigged and animated.

What the file holds
    * Units are metres (facsim's decimetres × 0.1); glTF's axes are
      facsim's: +Y up, the face looks toward +Z, +X is the character's left.
    * Mesh ``face``: the head's render topology (positions, normals, UVs,
      indices; vertices split at UV seams) without the eyeballs, one
      primitive per material: ``skin`` (colour texture baked from the
      character's paint: skin, lips, lids, blush, brows), ``mouth_interior``,
      ``teeth``, ``tongue``, ``lashes`` (hm08's lash strips, when no lash
      proxy replaces them). All primitives share the vertex data.
    * Meshes ``hair``, ``brows``, ``eyelashes``: the character's MakeHuman
      proxies (``facsim.head.proxies``), each with its own alpha-masked texture
      tinted with the character's colour, skinned like the face and with the
      same AU morph targets (brows follow AU 1, 2 and 4). Mesh ``scalp``: the
      fine hair on the skin under the hair (``facsim.head.scalp``), a blended
      layer whose tiled strand texture (repeating sampler) is faded by the hair's
      density per vertex (``COLOR_0`` alpha). The loose strands the renderer draws
      over the hair (``facsim.head.wisps``) are camera-facing ribbons and are not
      exported.
    * Morph targets, one per AU the register engine simulates with morphs,
      per side for AUs that can act on one side: ``AU12_L``, ``AU12_R``,
      ``AU26``. A target is the register engine at that AU (and side) at
      intensity 1 minus neutral, as POSITION (and NORMAL) deltas, stored as
      sparse accessors where most vertices do not move. Names are in
      ``mesh.extras.targetNames`` (three.js, Blender).
    * Skin with joints ``neck`` (the neck joint, root) and ``head`` (its
      child, same place). Each vertex follows ``head`` by the register
      engine's neck blend (smoothstep over height), so rotating ``head``
      reproduces codes 51–56 (and translating it 57/58) as the engine does.
    * Mesh ``body`` (unless ``body="none"``): hm08's neck, shoulders and chest top
      under the head in the character's garment (``facsim.head.body``), primitives
      ``skin`` and ``garment`` (matte, double-sided), skinned like the face so the
      neck twists into the shoulders when ``head`` turns; no morph targets.
    * Nodes ``eye_L``/``eye_R`` (children of ``head``) at the eye centres,
      each with an eyeball mesh (material ``eye``: baked sclera, iris and
      pupil texture), so rotating them turns the eyes (61–66).
    * With a timeline, animation ``timeline``: the morph weights at every
      frame time (``i / fps``), ``head`` rotation (quaternions) and
      translation, and each eye's rotation; ``LINEAR`` or ``STEP``.

Morph weights are the AU levels of the frame. glTF adds morph targets
linearly, whereas the register engine clamps registers that several active
AUs share (HapFACS Eq. 1), so strong overlapping AUs look slightly stronger
in a glTF viewer than in facsim's own renders.
"""
from __future__ import annotations

import io
import json
import struct
from pathlib import Path

import numpy as np

from facsim.facs.activations import Activations

from facsim.engines.rigid import eye_motion, head_motion
from facsim.exchange import write_file
from facsim.render.options import DEFAULT_BODY

#: facsim decimetres → glTF metres.
METRES = 0.1
FLOAT, UBYTE, USHORT, UINT = 5126, 5121, 5123, 5125
ARRAY_BUFFER, ELEMENT_ARRAY_BUFFER = 34962, 34963
_NCOMP = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4, "MAT4": 16}
_DTYPE = {FLOAT: np.float32, UBYTE: np.uint8, USHORT: np.uint16, UINT: np.uint32}
#: Morph deltas smaller than this (metres) are stored as zero.
DELTA_EPSILON = 1e-7
#: Head-mesh primitives, in drawing order: (region, material).
PRIMITIVES = ("skin", "mouth_interior", "teeth", "tongue", "lashes")
#: Metallic-roughness per material: (roughness, double-sided).
MATERIALS = {"skin": (0.55, False), "mouth_interior": (0.8, False), "teeth": (0.3, False),
             "tongue": (0.4, False), "lashes": (0.9, True), "eye": (0.08, False), "garment": (1.0, True)}
SKIN_TEXTURE_SIZE = (2048, 1024)  # rows (v), columns (u): the paint's own resolution
EYE_TEXTURE_SIZE = 512
#: Eye texture geometry, as the renderer's eye shader (fractions of the eyeball radius across the gaze).
IRIS_RADIUS, PUPIL_RADIUS, LIMBUS_WIDTH = 0.5, 0.125, 0.22


class GlbBuilder:
    """Collects binary data, buffer views and accessors for one GLB buffer."""

    def __init__(self):
        self.blob = bytearray()
        self.views: list[dict] = []
        self.accessors: list[dict] = []

    def view(self, data: bytes, target: int | None = None) -> int:
        self.blob += b"\0" * (-len(self.blob) % 4)
        entry = {"buffer": 0, "byteOffset": len(self.blob), "byteLength": len(data)}
        if target is not None:
            entry["target"] = target
        self.blob += data
        self.views.append(entry)
        return len(self.views) - 1

    def accessor(self, array, kind: str, component: int = FLOAT, *, target: int | None = None,
                 bounds: bool = False, normalized: bool = False) -> int:
        data = np.ascontiguousarray(np.asarray(array).reshape(-1, _NCOMP[kind]), dtype=_DTYPE[component])
        entry = {"bufferView": self.view(data.tobytes(), target), "componentType": component,
                 "count": len(data), "type": kind}
        if normalized:
            entry["normalized"] = True
        if bounds:
            entry["min"], entry["max"] = _bounds(data)
        self.accessors.append(entry)
        return len(self.accessors) - 1

    def delta_accessor(self, deltas: np.ndarray) -> int:
        """A VEC3 float morph-target accessor, sparse when most rows are zero."""
        deltas = np.where(np.abs(deltas) < DELTA_EPSILON, 0.0, deltas).astype(np.float32)
        moving = np.flatnonzero(np.any(deltas != 0.0, axis=1))
        if len(moving) * 16 >= deltas.size * 4:          # sparse would not be smaller
            return self.accessor(deltas, "VEC3", target=ARRAY_BUFFER, bounds=True)
        if len(moving) == 0:
            moving = np.array([0])                         # sparse.count must be >= 1
        index_type = USHORT if len(deltas) < 65536 else UINT
        low, high = _bounds(deltas)
        entry = {"componentType": FLOAT, "count": len(deltas), "type": "VEC3", "min": low, "max": high,
                 "sparse": {"count": len(moving),
                            "indices": {"bufferView": self.view(moving.astype(_DTYPE[index_type]).tobytes()),
                                        "componentType": index_type},
                            "values": {"bufferView": self.view(deltas[moving].tobytes())}}}
        self.accessors.append(entry)
        return len(self.accessors) - 1

    def image(self, png: bytes) -> int:
        return self.view(png)

    def glb(self, document: dict) -> bytes:
        document = dict(document, buffers=[{"byteLength": len(self.blob)}], bufferViews=self.views,
                        accessors=self.accessors)
        text = json.dumps(document, separators=(",", ":")).encode("utf-8")
        text += b" " * (-len(text) % 4)
        blob = bytes(self.blob) + b"\0" * (-len(self.blob) % 4)
        total = 12 + 8 + len(text) + 8 + len(blob)
        return (struct.pack("<4sII", b"glTF", 2, total) + struct.pack("<I4s", len(text), b"JSON") + text
                + struct.pack("<I4s", len(blob), b"BIN\0") + blob)


def _bounds(data: np.ndarray) -> tuple[list, list]:
    cast = float if data.dtype.kind == "f" else int
    return [cast(v) for v in data.min(axis=0)], [cast(v) for v in data.max(axis=0)]


def _png(rgb: np.ndarray) -> bytes:
    from PIL import Image

    out = io.BytesIO()
    Image.fromarray(np.ascontiguousarray(rgb, dtype=np.uint8)).save(out, format="PNG", optimize=True)
    return out.getvalue()


def _srgb8(linear: np.ndarray) -> np.ndarray:
    """Linear light (0..1) → 8-bit sRGB, through a 4096-step table (exact to the 8-bit step)."""
    from facsim.head.colour import linear_to_srgb

    table = np.clip(linear_to_srgb(np.linspace(0.0, 1.0, 4096)) * 255 + 0.5, 0, 255).astype(np.uint8)
    return table[np.clip(np.rint(np.asarray(linear) * 4095), 0, 4095).astype(np.intp)]


def _linear(colour) -> np.ndarray:
    from facsim.head.colour import srgb_to_linear

    return srgb_to_linear(np.asarray(colour, float))


# ----------------------------------------------------------------- textures ---

def skin_texture(appearance) -> np.ndarray:
    """(rows, cols, 3) uint8 sRGB skin colour over the head's normalised UV box, row 0 at v = 0.

    The renderer's paint layers mixed as its skin shader mixes them (blush,
    lids, lips, then brow hair at its average coverage); the one-texel border
    is plain skin, which UVs outside the box clamp to.
    """
    from facsim.head.appearance import _resize

    colours = {k: _linear(v).astype(np.float32) for k, v in appearance.colors.items()}
    paint = appearance.paint.astype(np.float32) / 255 if appearance.paint is not None else None
    rows, cols = SKIN_TEXTURE_SIZE
    albedo = np.empty((rows, cols, 3), np.float32)
    albedo[:] = colours["skin"]
    if paint is not None:
        if paint.shape[:2] != SKIN_TEXTURE_SIZE:
            paint = _resize(paint, SKIN_TEXTURE_SIZE)
        for channel, name in ((3, "cheek"), (2, "eyelid"), (1, "lips")):
            albedo += (colours[name] - albedo) * paint[..., channel:channel + 1]
        from facsim.head.surface import smoothstep

        hair = 0.75 * smoothstep(0.0, 0.5, paint[..., 0:1])           # the shader's mean strand coverage
        albedo += (colours["brows"] - albedo) * hair
    albedo[[0, -1], :] = colours["skin"]
    albedo[:, [0, -1]] = colours["skin"]
    return _srgb8(albedo)


def eye_uv(directions: np.ndarray) -> np.ndarray:
    """Texture coordinates of unit eye directions (+Z = gaze): azimuthal equidistant about the gaze."""
    d = np.asarray(directions, float)
    theta = np.arccos(np.clip(d[:, 2], -1.0, 1.0))
    phi = np.arctan2(d[:, 1], d[:, 0])
    r = 0.5 * theta / np.pi
    return np.stack([0.5 + r * np.cos(phi), 0.5 - r * np.sin(phi)], axis=1).astype(np.float32)


def eye_texture(appearance, size: int = EYE_TEXTURE_SIZE) -> np.ndarray:
    """(size, size, 3) uint8 sRGB eyeball texture for :func:`eye_uv`: sclera, iris with limbus, pupil."""
    colours = {k: _linear(appearance.colors[k]) for k in ("sclera", "iris", "pupil")}
    centres = (np.arange(size) + 0.5) / size
    u, v = np.meshgrid(centres, centres)
    theta = np.pi * np.hypot(u - 0.5, v - 0.5) / 0.5
    across = np.where(theta < np.pi / 2, np.sin(np.minimum(theta, np.pi)), 2.0)   # shader's length(eye.xy)
    aa = 2.0 * np.pi / size                                   # about a texel, in units of sin(theta)
    iris_mask = np.clip((IRIS_RADIUS + aa - across) / (2 * aa), 0, 1)[..., None]
    pupil_mask = np.clip((PUPIL_RADIUS + aa - across) / (2 * aa), 0, 1)[..., None]
    t = np.clip((across - PUPIL_RADIUS) / (IRIS_RADIUS - PUPIL_RADIUS), 0, 1)[..., None]
    iris = colours["iris"] * np.where(t < 0.3, 1.2, 1.0) * (1 - 0.65 * np.clip((t - (1 - LIMBUS_WIDTH)) / LIMBUS_WIDTH, 0, 1))
    iris = iris * (1 - pupil_mask) + colours["pupil"] * pupil_mask
    return _srgb8(colours["sclera"] * (1 - iris_mask) + iris * iris_mask)


# ------------------------------------------------------------------ content ---

def morph_target_keys(aus="all") -> list[tuple[int, str]]:
    """(code, side) of every morph target: side "left"/"right" for AUs that can act on one side, else "both".

    ``aus`` is ``"all"`` or AU codes to keep (the register engine's morph AUs only).
    """
    from facsim.facs.catalogue import info
    from facsim.engines.registers import register_table

    codes = sorted(register_table()["action_units"])
    if aus != "all":
        wanted = {int(c) for c in aus}
        unknown = sorted(wanted - set(codes))
        if unknown:
            raise ValueError(f"AU{unknown[0]} has no morph target (the register engine moves AUs "
                             f"{', '.join(map(str, codes))} with morphs; 51-58 and 61-66 are joint rotations)")
        codes = [c for c in codes if c in wanted]
    return [(c, side) for c in codes for side in (("left", "right") if info(c).unilateral else ("both",))]


def target_name(code: int, side: str) -> str:
    """``AU12_L``, ``AU12_R`` or ``AU26``."""
    return f"AU{code:02d}" + {"left": "_L", "right": "_R", "both": ""}[side]


def target_weights(act, keys) -> np.ndarray:
    """Morph weights of one frame's activations (one per key of :func:`morph_target_keys`).

    Each target is its AU at E; at a lower intensity it moves as the register engine's
    AU does, by the engine's concave :func:`~facsim.engines.registers.response`.
    """
    from facsim.engines.registers import response

    return np.array([response(act.level(code) if side == "both" else act[code, side], code) for code, side in keys],
                    np.float32)


def _quaternions(rotvecs: np.ndarray) -> np.ndarray:
    from scipy.spatial.transform import Rotation

    quats = Rotation.from_rotvec(rotvecs).as_quat().astype(np.float32)   # x, y, z, w
    return quats / np.linalg.norm(quats, axis=1, keepdims=True)


def glb_bytes(face, timeline=None, *, aus="all", interpolation: str = "LINEAR", normals: bool = True,
              fps: float | None = None, body: str = DEFAULT_BODY) -> bytes:
    """The character of ``face`` as GLB bytes (see the module docstring and :func:`export_glb`)."""
    interpolation = interpolation.upper()
    if interpolation not in ("LINEAR", "STEP"):
        raise ValueError(f"interpolation must be LINEAR or STEP, got {interpolation!r}")
    keys = morph_target_keys(aus)
    head = face.head
    pivot = head.joint(face.base_positions, "joint-neck").astype(np.float64)
    b = GlbBuilder()
    rig = face.body_rig(body)
    materials, material_index = _materials(b, face.appearance, garment=rig is not None)
    meshes = [_face_mesh(b, face, keys, pivot, material_index, normals)]
    nodes = [{"name": "neck", "translation": _floats(pivot * METRES), "children": [1]},
             {"name": "head", "children": [2, 3]}]
    for side, suffix in (("left", "L"), ("right", "R")):
        centre, radius = head.eye_pivot(face.base_positions, side)
        meshes.append(_eye_mesh(b, head.topology, head.eye_vertices[side], radius * METRES,
                                material_index["eye"], suffix))
        nodes.append({"name": f"eye_{suffix}", "mesh": len(meshes) - 1,
                      "translation": _floats((np.asarray(centre, float) - pivot) * METRES)})
    inverse_bind = np.tile(np.eye(4), (2, 1, 1))
    inverse_bind[:, 3, :3] = -pivot * METRES                           # column-major: translation in row 3
    skin = {"name": "neck_head", "joints": [0, 1], "skeleton": 0,
            "inverseBindMatrices": b.accessor(inverse_bind, "MAT4")}
    nodes.append({"name": "face", "mesh": 0, "skin": 0})
    scene_nodes = [0, 4]
    for mesh in _proxy_meshes(b, face, keys, pivot, materials):
        meshes.append(mesh)
        scene_nodes.append(len(nodes))
        nodes.append({"name": mesh["name"], "mesh": len(meshes) - 1, "skin": 0})
    if rig is not None:
        meshes.append(_body_mesh(b, face, rig, material_index, normals))
        scene_nodes.append(len(nodes))
        nodes.append({"name": "body", "mesh": len(meshes) - 1, "skin": 0})
    document = {
        "asset": {"version": "2.0", "generator": _generator(),
                  "extras": {"character": face.character.name or "custom",
                             "units": "metres (facsim decimetres x 0.1)"}},
        "scene": 0, "scenes": [{"name": "facsim", "nodes": scene_nodes}],
        "nodes": nodes, "meshes": meshes, "skins": [skin], **materials,
    }
    if timeline is not None:
        document["animations"] = [_animation(b, timeline, keys, fps, interpolation)]
    return b.glb(document)


def _floats(values) -> list[float]:
    return [float(v) for v in values]


def _face_mesh(b: GlbBuilder, face, keys, pivot, material_index: dict, normals: bool) -> dict:
    """Mesh ``face``: the head without eyeballs, skinned to neck/head, one primitive per material, AU targets."""
    from facsim.engines.registers import RegisterEngine
    from facsim.engines.rigid import neck_weight
    from facsim.head.mesh import REGIONS
    from facsim.head.surface import vertex_normals

    head = face.head
    topo = getattr(face, "topology", head.topology)  # without hm08's lash strips when a lash proxy replaces them
    engine = face.engine if face.engine_name == "registers" else RegisterEngine(
        head, face.data, face.character, face.base_positions)
    neutral = np.asarray(face.neutral, np.float64)
    keep = np.flatnonzero(topo.region != REGIONS.index("eyeball"))   # head-mesh render vertices
    local = np.full(topo.n_render, -1)
    local[keep] = np.arange(len(keep))
    geo = topo.render_to_geo[keep]
    normals_of = lambda positions: vertex_normals(positions, topo.geo_faces)[geo]  # noqa: E731

    rest_normals = normals_of(neutral)
    attributes = {"POSITION": b.accessor(neutral[geo] * METRES, "VEC3", target=ARRAY_BUFFER, bounds=True)}
    if normals:
        attributes["NORMAL"] = b.accessor(rest_normals, "VEC3", target=ARRAY_BUFFER)
    attributes["TEXCOORD_0"] = b.accessor(topo.uv[keep], "VEC2", target=ARRAY_BUFFER)
    weights = np.zeros((len(keep), 4), np.float32)
    weights[:, 1] = neck_weight(head, neutral, face.base_positions)[geo]
    weights[:, 0] = 1.0 - weights[:, 1]
    joints = np.zeros((len(keep), 4), np.uint8)
    joints[:, 1] = weights[:, 1] > 0                                  # an unused slot names joint 0
    attributes["JOINTS_0"] = b.accessor(joints, "VEC4", UBYTE, target=ARRAY_BUFFER)
    attributes["WEIGHTS_0"] = b.accessor(weights, "VEC4", target=ARRAY_BUFFER)

    targets = []
    for code, side in keys:
        sides = ("left", "right") if side == "both" else (side,)
        moved = np.asarray(engine.deform(Activations({(code, s): 1.0 for s in sides})).positions, np.float64)
        target = {"POSITION": b.delta_accessor((moved[geo] - neutral[geo]) * METRES)}
        if normals:
            target["NORMAL"] = b.delta_accessor(normals_of(moved) - rest_normals)
        targets.append(target)

    primitives = []
    face_region = topo.face_regions()
    for region in PRIMITIVES:
        tris = topo.faces[face_region == REGIONS.index(region)]
        if not len(tris):
            continue
        primitive = {"attributes": {k: v for k, v in attributes.items() if region == "skin" or k != "TEXCOORD_0"},
                     "indices": b.accessor(local[tris].reshape(-1), "SCALAR", USHORT if len(keep) < 65536 else UINT,
                                           target=ELEMENT_ARRAY_BUFFER, bounds=True),
                     "material": material_index[region], "mode": 4}
        if targets:
            primitive["targets"] = targets
        primitives.append(primitive)
    mesh = {"name": "face", "primitives": primitives}
    if targets:
        mesh["weights"] = [0.0] * len(targets)
        mesh["extras"] = {"targetNames": [target_name(*k) for k in keys]}
    return mesh


def _body_mesh(b: GlbBuilder, face, rig, material_index: dict, normals: bool) -> dict:
    """Mesh ``body``: the neck, shoulders and garment under the head (:mod:`facsim.head.body`), one
    primitive each for ``skin`` and ``garment``, skinned to neck/head as the neck cut it hangs
    from (so turning ``head`` twists the neck into the shoulders), without morph targets."""
    from facsim.engines.rigid import neck_weight
    from facsim.head.mesh import REGIONS
    from facsim.head.surface import vertex_normals

    model = rig.model
    faces, render_to_geo, uv, region = model.render_topology()
    positions = rig.with_body(face.neutral).astype(np.float64)
    topo = face.render_topology(model.style)
    attributes = {"POSITION": b.accessor(positions[render_to_geo] * METRES, "VEC3", target=ARRAY_BUFFER, bounds=True)}
    if normals:
        attributes["NORMAL"] = b.accessor(vertex_normals(positions, topo.geo_faces)[render_to_geo], "VEC3",
                                          target=ARRAY_BUFFER)
    attributes["TEXCOORD_0"] = b.accessor(uv, "VEC2", target=ARRAY_BUFFER)
    follow_head = neck_weight(face.head, np.asarray(face.neutral, np.float64), face.base_positions)
    head_weight = np.concatenate([follow_head, rig.follow @ follow_head[model.neck_loop]])
    weights = np.zeros((len(render_to_geo), 4), np.float32)
    weights[:, 1] = np.clip(head_weight[render_to_geo], 0.0, 1.0)
    weights[:, 0] = 1.0 - weights[:, 1]
    joints = np.zeros((len(render_to_geo), 4), np.uint8)
    joints[:, 1] = weights[:, 1] > 0
    attributes["JOINTS_0"] = b.accessor(joints, "VEC4", UBYTE, target=ARRAY_BUFFER)
    attributes["WEIGHTS_0"] = b.accessor(weights, "VEC4", target=ARRAY_BUFFER)
    majority = np.where((region[faces[:, 1]] == region[faces[:, 2]]), region[faces[:, 1]], region[faces[:, 0]])
    primitives = []
    for name in ("skin", "garment"):
        tris = faces[majority == REGIONS.index(name)]
        primitives.append({
            "attributes": {k: v for k, v in attributes.items() if name == "skin" or k != "TEXCOORD_0"},
            "indices": b.accessor(tris.reshape(-1).astype(np.uint32), "SCALAR",
                                  USHORT if len(render_to_geo) < 65536 else UINT, target=ELEMENT_ARRAY_BUFFER,
                                  bounds=True),
            "material": material_index[name], "mode": 4})
    return {"name": "body", "primitives": primitives}


def _proxy_meshes(b: GlbBuilder, face, keys, pivot, materials: dict) -> list[dict]:
    """Hair, brows and lashes (MakeHuman proxies): one skinned mesh each, with their own
    alpha-masked texture (tinted with the character's colour) and the AU morph targets
    that move them with the skin (brows under AU 1, 2, 4). Adds their materials."""
    from facsim.engines.registers import RegisterEngine
    from facsim.engines.rigid import neck_weight
    from facsim.render.proxies import shade_texture

    scalp = getattr(face, "scalp", None)
    exported = ([scalp] if scalp is not None else []) + [b for b in face.proxies if not b.crop]
    if not exported:
        return []
    engine = face.engine if face.engine_name == "registers" else RegisterEngine(
        face.head, face.data, face.character, face.base_positions)
    moved = [np.asarray(engine.deform(Activations({(code, s): 1.0 for s in (("left", "right") if side == "both" else (side,))})).positions,
                        np.float32) for code, side in keys]
    follow_head = neck_weight(face.head, np.asarray(face.neutral, np.float64), face.base_positions)
    out = []
    for bound in exported:
        proxy, binding = bound.proxy, bound.binding
        rest = binding.positions(face.neutral).astype(np.float64)
        corner = proxy.corner_vertex
        tint = _linear(face.colors[bound.color_key])
        is_scalp = proxy.kind == "scalp"
        # Texture: the strand brightness times the character's colour, alpha kept. The scalp
        # layer's tile is made for the renderer already (R brightness, A cover; tiled).
        if is_scalp:
            shade = np.asarray(proxy.texture, np.float32) / 255.0
            rgb = tint * (0.55 + 0.9 * shade[..., :1]) * 0.7   # the roots lie in the cards' shade
        else:
            shade = shade_texture(proxy.texture)[::-1].astype(np.float32) / 255.0  # back to image row order
            rgb = tint * (0.6 + 0.8 * shade[..., :1])
        rgba = np.empty(shade.shape, np.uint8)
        rgba[..., :3] = _srgb8(rgb)
        rgba[..., 3] = (shade[..., 3] * 255 + 0.5).astype(np.uint8)
        image = len(materials["images"])
        materials["images"].append({"name": proxy.name, "mimeType": "image/png", "bufferView": b.image(_png(rgba))})
        if is_scalp and len(materials["samplers"]) < 2:
            materials["samplers"].append({"magFilter": 9729, "minFilter": 9987, "wrapS": 10497, "wrapT": 10497})
        materials["textures"].append({"source": image, "sampler": 1 if is_scalp else 0, "name": proxy.name})
        pbr = {"metallicFactor": 0.0, "roughnessFactor": 0.6 if proxy.kind in ("hair", "scalp") else 0.9,
               "baseColorTexture": {"index": len(materials["textures"]) - 1}}
        materials["materials"].append(
            {"name": proxy.name, "alphaMode": "BLEND", "pbrMetallicRoughness": pbr} if is_scalp else
            {"name": proxy.name, "alphaMode": "MASK", "alphaCutoff": 0.5, "doubleSided": True, "pbrMetallicRoughness": pbr})
        weights = np.zeros((len(corner), 4), np.float32)
        # Each proxy vertex follows the head as the skin it is bound to does.
        follow = np.einsum("vk,vk->v", binding.weights, follow_head[binding.ref])
        weights[:, 1] = np.clip(follow, 0.0, 1.0)[corner]  # bindings may extrapolate a little
        weights[:, 0] = 1.0 - weights[:, 1]
        joints = np.zeros((len(corner), 4), np.uint8)
        joints[:, 1] = weights[:, 1] > 0
        uv = proxy.uv * np.array([1.0, -1.0], np.float32) + np.array([0.0, 1.0], np.float32)  # glTF v runs down
        primitive = {
            "attributes": {
                "POSITION": b.accessor(rest[corner] * METRES, "VEC3", target=ARRAY_BUFFER, bounds=True),
                "TEXCOORD_0": b.accessor(uv, "VEC2", target=ARRAY_BUFFER),
                "JOINTS_0": b.accessor(joints, "VEC4", UBYTE, target=ARRAY_BUFFER),
                "WEIGHTS_0": b.accessor(weights, "VEC4", target=ARRAY_BUFFER),
                **({"COLOR_0": b.accessor(np.column_stack([np.ones((len(corner), 3), np.float32),
                                                           np.clip(bound.depth, 0.0, 1.0)[corner]]),
                                          "VEC4", target=ARRAY_BUFFER)} if is_scalp else {})},
            "indices": b.accessor(proxy.triangles.reshape(-1).astype(np.uint32), "SCALAR",
                                  USHORT if len(corner) < 65536 else UINT, target=ELEMENT_ARRAY_BUFFER, bounds=True),
            "material": len(materials["materials"]) - 1, "mode": 4}
        if keys:
            primitive["targets"] = [{"POSITION": b.delta_accessor((binding.positions(m)[corner] - rest[corner]) * METRES)}
                                    for m in moved]
        mesh = {"name": proxy.kind if proxy.kind != "eyebrows" else "brows", "primitives": [primitive]}
        if keys:
            mesh["weights"] = [0.0] * len(keys)
            mesh["extras"] = {"targetNames": [target_name(*k) for k in keys], "proxy": proxy.name}
        out.append(mesh)
    return out


def _generator() -> str:
    try:
        from facsim import __version__
    except ImportError:
        __version__ = "unknown"
    return f"facsim {__version__}"


def _materials(b: GlbBuilder, appearance, *, garment: bool = False) -> tuple[dict, dict]:
    """glTF materials, textures, images and samplers; and material index per region name
    (``garment`` only with a body: an unused material would be an unused object)."""
    colours = appearance.colors
    base = {"skin": "skin", "mouth_interior": "mouth_interior", "teeth": "teeth", "tongue": "tongue",
            "lashes": "lashes", "eye": "sclera", "garment": "garment"}
    images = [{"name": "skin", "mimeType": "image/png", "bufferView": b.image(_png(skin_texture(appearance)))},
              {"name": "eye", "mimeType": "image/png", "bufferView": b.image(_png(eye_texture(appearance)))}]
    samplers = [{"magFilter": 9729, "minFilter": 9987, "wrapS": 33071, "wrapT": 33071}]
    textures = [{"source": 0, "sampler": 0, "name": "skin"}, {"source": 1, "sampler": 0, "name": "eye"}]
    materials, index = [], {}
    for name, (roughness, double) in MATERIALS.items():
        if name == "garment" and not garment:
            continue
        pbr = {"metallicFactor": 0.0, "roughnessFactor": roughness}
        if name in ("skin", "eye"):
            pbr["baseColorTexture"] = {"index": 0 if name == "skin" else 1}
        else:
            pbr["baseColorFactor"] = [*(float(c) for c in _linear(colours[base[name]])), 1.0]
        entry = {"name": name, "pbrMetallicRoughness": pbr}
        if double:
            entry["doubleSided"] = True
        index[name] = len(materials)
        materials.append(entry)
    return {"materials": materials, "textures": textures, "images": images, "samplers": samplers}, index


def _eye_mesh(b: GlbBuilder, topo, eye_geo, radius: float, material: int, suffix: str) -> dict:
    on_eye = np.isin(topo.render_to_geo, eye_geo)
    faces = topo.faces[np.all(on_eye[topo.faces], axis=1)]
    verts = np.unique(faces)
    local = np.full(topo.n_render, -1)
    local[verts] = np.arange(len(verts))
    directions = topo.eye_coord[verts].astype(np.float64)
    directions /= np.linalg.norm(directions, axis=1, keepdims=True)
    attributes = {"POSITION": b.accessor(directions * radius, "VEC3", target=ARRAY_BUFFER, bounds=True),
                  "NORMAL": b.accessor(directions, "VEC3", target=ARRAY_BUFFER),
                  "TEXCOORD_0": b.accessor(eye_uv(directions), "VEC2", target=ARRAY_BUFFER)}
    indices = b.accessor(local[faces].reshape(-1), "SCALAR", USHORT, target=ELEMENT_ARRAY_BUFFER, bounds=True)
    return {"name": f"eye_{suffix}", "primitives": [{"attributes": attributes, "indices": indices,
                                                      "material": material, "mode": 4}]}


def _animation(b: GlbBuilder, timeline, keys, fps, interpolation: str) -> dict:
    from facsim.timeline.sampling import frame_times, sample_frames

    times = frame_times(timeline, fps)
    frames = sample_frames(timeline, fps)
    if len(frames) == 0:
        raise ValueError("the timeline has no frames to animate")
    head = [head_motion(act.level) for act in frames]
    eyes = [eye_motion(act.level) for act in frames]
    outputs = {
        ("face", "weights"): (np.stack([target_weights(a, keys) for a in frames]).reshape(-1), "SCALAR"),
        ("head", "rotation"): (_quaternions(np.array([h[0] for h in head])), "VEC4"),
        ("head", "translation"): (np.array([h[1] for h in head]) * METRES, "VEC3"),
        ("eye_L", "rotation"): (_quaternions(np.array([e["left"] for e in eyes])), "VEC4"),
        ("eye_R", "rotation"): (_quaternions(np.array([e["right"] for e in eyes])), "VEC4"),
    }
    if not keys:
        del outputs[("face", "weights")]
    node_index = {"head": 1, "eye_L": 2, "eye_R": 3, "face": 4}
    time_accessor = b.accessor(times, "SCALAR", bounds=True)
    samplers, channels = [], []
    for (node, path), (values, kind) in outputs.items():
        samplers.append({"input": time_accessor, "output": b.accessor(values, kind), "interpolation": interpolation})
        channels.append({"sampler": len(samplers) - 1, "target": {"node": node_index[node], "path": path}})
    return {"name": "timeline", "samplers": samplers, "channels": channels}


def export_glb(face, path, timeline=None, *, aus="all", interpolation: str = "LINEAR", normals: bool = True,
               fps: float | None = None, body: str = DEFAULT_BODY) -> Path:
    """Write ``face``'s character as a ``.glb`` (atomically); returns the path.

    Parameters
    ----------
    face : facsim.face.Face
        The character (its appearance colours the materials; targets come
        from the register engine whatever ``face``'s engine).
    path : path
    timeline : Timeline, optional
        Adds animation ``timeline`` sampled at ``fps`` (default the timeline's).
    aus : "all" or iterable of int
        Which AUs get morph targets (the animation drives only these).
    interpolation : {"LINEAR", "STEP"}
    normals : bool
        Store vertex normals and their morph deltas (about twice the size).
    body : str
        A garment (``"crewneck"``) adds mesh ``body``; ``"none"`` exports the head alone.
    """
    return write_file(path, glb_bytes(face, timeline, aus=aus, interpolation=interpolation, normals=normals,
                                        fps=fps, body=body))
