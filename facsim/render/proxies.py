"""Drawing proxy meshes (hair, eyebrows, eyelashes) with their alpha textures.

A proxy is a set of textured cards (MakeHuman's hair and brow proxies) whose texture
alpha cuts out the strands. Cards overlap in depth, so they are drawn in two passes
(the classic order-independent-enough scheme for hair cards):

1. **alpha-tested**: fragments with alpha >= 0.5 are drawn opaque and write depth;
2. **blended**: the remaining soft fringe (0.02 <= alpha < 0.5) is blended over, back to
   front (triangles sorted by distance from the camera each frame), without writing depth.

Hair is lit with a Kajiya–Kay strand model: diffuse from the angle between strand and
light (``sin(T, L)``), two shifted specular lobes along the strand (a white primary and a
hair-coloured secondary), and a self-shadowing term that darkens cards near the scalp.
Strand tangents follow the texture's v direction (MakeHuman's hair textures run along v).

Plain data in (:class:`ProxyMesh`, static; :class:`ProxyDraw`, per frame); one
:class:`ProxyLayer` per mesh holds the GL objects, created by the
:class:`~facsim.render.Renderer` that draws it.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from facsim.render.geometry import normal_operator, vertex_normals
from facsim.render.gl import _set_uniform, _shader_source
from facsim.render.inputs import srgb_to_linear

PROXY_KINDS = ("hair", "eyebrows", "eyelashes")
#: Alpha at and above which a fragment belongs to the opaque (alpha-tested) pass.
ALPHA_CUTOFF = 0.5


@dataclass(frozen=True, eq=False)
class ProxyMesh:
    """A proxy's static mesh, uploaded once per renderer.

    Parameters
    ----------
    name : str
    kind : {"hair", "eyebrows", "eyelashes"}
    triangles : (T, 3) int
        Triangles over render corners.
    corner_vertex : (R,) int
        Proxy vertex of each corner (positions are given per proxy vertex).
    uv : (R, 2) float
        Texture coordinates, v up.
    texture : (H, W, 4) uint8
        RGBA in image order (row 0 at the top). Only its brightness variation and alpha
        are used: the colour comes from :attr:`ProxyDraw.color`.
    depth : (V,) float, optional
        0 at the scalp … 1 at the outermost strands, for self-shadowing (default 1).
    """

    name: str
    kind: str
    triangles: np.ndarray
    corner_vertex: np.ndarray
    uv: np.ndarray
    texture: np.ndarray
    depth: np.ndarray | None = None

    def __post_init__(self):
        if self.kind not in PROXY_KINDS:
            raise ValueError(f"proxy kind must be one of {PROXY_KINDS}, got {self.kind!r}")
        tex = np.asarray(self.texture)
        if tex.ndim != 3 or tex.shape[2] != 4 or tex.dtype != np.uint8:
            raise ValueError(f"proxy texture must be (H, W, 4) uint8, got {tex.dtype} {tex.shape}")
        if len(self.uv) != len(self.corner_vertex):
            raise ValueError("proxy uv and corner_vertex must have one row per corner")

    @property
    def vertex_count(self) -> int:
        return int(np.max(self.corner_vertex)) + 1


@dataclass(frozen=True, eq=False)
class ProxyDraw:
    """One proxy in one frame: its mesh, vertex positions (V, 3), sRGB colour and sheen
    (strength of the strand highlights: 1 for straight hair, less for coily hair)."""

    mesh: ProxyMesh
    positions: np.ndarray
    color: tuple[float, float, float]
    sheen: float = 1.0


def shade_texture(texture: np.ndarray) -> np.ndarray:
    """RGBA for upload: RGB = brightness relative to the mean strand (0.5 = mean), A kept.

    MakeHuman's hair textures are near-black strands; the colour comes from the character,
    so only the relative brightness (strand-to-strand variation) is kept. Rows are flipped
    to GL order (row 0 = v = 0).
    """
    rgb = texture[..., :3].astype(np.float32)
    alpha = texture[..., 3]
    lum = rgb @ np.array([0.2126, 0.7152, 0.0722], np.float32)
    solid = alpha > 128
    mean = float(lum[solid].mean()) if solid.any() else float(lum.mean())
    rel = np.clip(lum / max(mean, 1.0), 0.4, 1.6) * 0.5
    out = np.empty(texture.shape, np.uint8)
    out[..., :3] = np.clip(rel * 255 + 0.5, 0, 255).astype(np.uint8)[..., None]
    out[..., 3] = alpha
    return np.ascontiguousarray(out[::-1])


def volume_normals(points: np.ndarray, card_normals: np.ndarray, *, card_weight: float = 0.3) -> np.ndarray:
    """Hair normals from the volume, not the cards: mostly the direction out from the
    head's centre, a little of each card's own (turned outward), so a hairstyle is shaded
    as one smooth mass instead of a patchwork of flat cards."""
    top = points[points[:, 1] >= np.percentile(points[:, 1], 50)]
    centre = top.mean(axis=0) - np.array([0.0, 0.25 * np.ptp(top[:, 1]), 0.0], np.float32)
    out = points - centre
    out /= np.linalg.norm(out, axis=1, keepdims=True) + 1e-12
    card = np.where((np.einsum("ij,ij->i", card_normals, out) < 0)[:, None], -card_normals, card_normals)
    n = (1.0 - card_weight) * out + card_weight * card
    return (n / (np.linalg.norm(n, axis=1, keepdims=True) + 1e-12)).astype(np.float32)


def strand_tangents(positions: np.ndarray, mesh: ProxyMesh, operator=None) -> np.ndarray:
    """Unit strand direction (dP/dv) per corner, averaged over the corner's triangles.

    ``operator`` is :func:`~facsim.render_geometry.normal_operator` of the triangles over
    the corners (it sums per-triangle values onto corners; built here when not given).
    """
    p = positions[mesh.corner_vertex]
    t = mesh.triangles
    e1, e2 = p[t[:, 1]] - p[t[:, 0]], p[t[:, 2]] - p[t[:, 0]]
    uv = mesh.uv
    d1, d2 = uv[t[:, 1]] - uv[t[:, 0]], uv[t[:, 2]] - uv[t[:, 0]]
    det = d1[:, 0] * d2[:, 1] - d2[:, 0] * d1[:, 1]
    det = np.where(np.abs(det) < 1e-12, 1e-12, det)
    # dP/dv = (-d2.u * e1 + d1.u * e2) / det
    tv = (-d2[:, :1] * e1 + d1[:, :1] * e2) / det[:, None]
    tv /= np.linalg.norm(tv, axis=1, keepdims=True) + 1e-12
    if operator is None:
        operator = normal_operator(t, len(p))
    out = np.asarray(operator @ tv, np.float32)
    # One orientation for every card (roots to tips, away from a point above the crown), so
    # the shifted highlights agree from card to card.
    above = positions.mean(axis=0) + np.array([0.0, 1.0, 0.0], np.float32) * np.ptp(positions[:, 1])
    flip = np.einsum("ij,ij->i", out, p - above) < 0
    out[flip] *= -1
    out /= np.linalg.norm(out, axis=1, keepdims=True) + 1e-12
    return out.astype(np.float32)


class ProxyLayer:
    """GL objects for one :class:`ProxyMesh` (owned and released by a Renderer)."""

    def __init__(self, ctx, mesh: ProxyMesh, track):
        self.ctx = ctx
        self.mesh = mesh
        self._triangles = np.ascontiguousarray(mesh.triangles, np.uint32)
        self._n_corners = len(mesh.corner_vertex)
        self._normal_op = normal_operator(self._triangles, self._n_corners)
        depth = np.ones(mesh.vertex_count, np.float32) if mesh.depth is None else np.asarray(mesh.depth, np.float32)
        self._depth = depth[mesh.corner_vertex]
        self._buffer = np.zeros((self._n_corners, 10), np.float32)  # pos, normal, tangent, depth
        self._vbo = track(ctx.buffer(reserve=self._buffer.nbytes, dynamic=True))
        self._uv = track(ctx.buffer(np.ascontiguousarray(mesh.uv, np.float32).tobytes()))
        # Two orders of the same triangles: front to back for the alpha-tested pass (hidden
        # layers then fail the depth test before they are shaded), back to front for blending.
        self._ibo = {"OPAQUE": track(ctx.buffer(self._triangles.tobytes(), dynamic=True)),
                     "BLEND": track(ctx.buffer(self._triangles.tobytes(), dynamic=True))}
        tex = shade_texture(np.asarray(mesh.texture))
        self.texture = track(ctx.texture((tex.shape[1], tex.shape[0]), 4, tex.tobytes()))
        self.texture.build_mipmaps()  # an input texture, never rendered into
        self.texture.filter = (ctx.LINEAR_MIPMAP_LINEAR, ctx.LINEAR)
        self.programs, self.vaos = {}, {}
        self._last = None  # (camera position, vertex positions) of the last upload
        self.look: tuple = ()  # (linear colour, sheen) of this frame
        self._camera_uniforms: tuple = ()  # (view-projection, lights) the programs hold
        self._vertex_triangles = np.asarray(mesh.corner_vertex)[self._triangles]  # ... over vertices
        self._order = np.arange(len(self._triangles))  # back to front, as last sorted
        # A subset of the triangles (front to back) for callers that keep part of the pass as pixels.
        self._ibo["SUBSET"] = track(ctx.buffer(reserve=max(self._triangles.nbytes, 12), dynamic=True))
        for stage in ("OPAQUE", "BLEND"):
            defines = {f"PASS_{stage}": "", f"KIND_{mesh.kind.upper()}": "", "ALPHA_CUTOFF": f"{ALPHA_CUTOFF:.3f}"}
            prog = track(ctx.program(vertex_shader=_shader_source("proxy.vert.glsl", defines),
                                     fragment_shader=_shader_source("proxy.frag.glsl", defines)))
            _set_uniform(prog, "u_texture", 1)
            self.programs[stage] = prog
            self.vaos[stage] = track(ctx.vertex_array(
                prog, [(self._vbo, "3f 3f 3f 1f", "in_pos", "in_normal", "in_tangent", "in_depth"),
                       (self._uv, "2f", "in_uv")],
                index_buffer=self._ibo[stage], index_element_size=4, skip_errors=True))
        self.vaos["SUBSET"] = track(ctx.vertex_array(
            self.programs["OPAQUE"], [(self._vbo, "3f 3f 3f 1f", "in_pos", "in_normal", "in_tangent", "in_depth"),
                                      (self._uv, "2f", "in_uv")],
            index_buffer=self._ibo["SUBSET"], index_element_size=4, skip_errors=True))

    def update(self, draw: ProxyDraw, camera_position: np.ndarray) -> None:
        """Upload this frame's vertices, sorting triangles back to front for the blended pass."""
        positions = np.asarray(draw.positions, np.float32)
        if positions.shape != (self.mesh.vertex_count, 3) or not np.isfinite(positions).all():
            raise ValueError(f"proxy {self.mesh.name!r} positions must be finite ({self.mesh.vertex_count}, 3), "
                             f"got {positions.shape}")
        camera_position = np.asarray(camera_position, np.float32)
        color = tuple(float(x) for x in srgb_to_linear(draw.color))
        if self.look != (color, float(draw.sheen)):
            self.look = (color, float(draw.sheen))
            for prog in self.programs.values():
                _set_uniform(prog, "u_color", color)
                _set_uniform(prog, "u_sheen", float(draw.sheen))
        # Hair mostly sits still (only 51-58 and the brow skin move it): skip the upload and
        # the sort when nothing moved since the last frame.
        if (self._last is not None and np.array_equal(self._last[0], camera_position)
                and np.array_equal(self._last[1], positions)):
            return
        self._last = (camera_position.copy(), positions.copy())
        p = positions[self.mesh.corner_vertex]
        buf = self._buffer
        buf[:, 0:3] = p
        # Normals on welded vertices would mix the two sides of a card; corners are fine here.
        normals = vertex_normals(p, self._triangles, self._normal_op)
        if self.mesh.kind == "hair":
            normals = volume_normals(p, normals)
        buf[:, 3:6] = normals
        buf[:, 6:9] = strand_tangents(positions, self.mesh, self._normal_op)
        buf[:, 9] = self._depth
        self._vbo.write(buf)
        centres = p[self._triangles].mean(axis=1) - np.asarray(camera_position, np.float32)
        order = np.argsort(-np.einsum("ij,ij->i", centres, centres), kind="stable")
        self._ibo["BLEND"].write(self._triangles[order].tobytes())
        self._ibo["OPAQUE"].write(self._triangles[order[::-1]].tobytes())
        self._order = order

    @property
    def positions(self) -> np.ndarray | None:
        """The vertex positions drawn (as last uploaded; replaced, never changed in place)."""
        return None if self._last is None else self._last[1]

    def moved_triangles(self, reference: np.ndarray) -> np.ndarray:
        """(T,) bool: triangles with a vertex not where it is in ``reference`` (V, 3)."""
        moved = np.any(self.positions != reference, axis=1)
        return moved[self._vertex_triangles].any(axis=1)

    def set_uniforms(self, vp_bytes: bytes, lights: dict) -> None:
        key = (vp_bytes, tuple(lights.items()))
        if key == self._camera_uniforms:  # a video's camera and lights hold still
            return
        self._camera_uniforms = key
        for prog in self.programs.values():
            try:
                prog["u_view_proj"].write(vp_bytes)
            except KeyError:
                pass
            for name, value in lights.items():
                _set_uniform(prog, name, value)

    def draw(self, stage: str, triangles: np.ndarray | None = None) -> None:
        """Draw one pass (``"OPAQUE"`` or ``"BLEND"``); ``triangles``, a (T,) bool mask,
        limits the alpha-tested pass to some triangles (still front to back)."""
        self.texture.use(1)
        if triangles is None:
            self.vaos[stage].render(self.ctx.TRIANGLES, vertices=3 * len(self._triangles))
            return
        if stage != "OPAQUE":
            raise ValueError("only the alpha-tested pass draws a subset of the triangles")
        front_to_back = self._order[::-1]
        picked = self._triangles[front_to_back[triangles[front_to_back]]]
        if len(picked):
            self._ibo["SUBSET"].write(np.ascontiguousarray(picked).tobytes())
            self.vaos["SUBSET"].render(self.ctx.TRIANGLES, vertices=3 * len(picked))
