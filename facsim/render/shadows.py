"""The key light's cast shadows: a depth map drawn from the key, read by the shaders with soft PCF.

A portrait studio's key is a large softbox above the camera: the nose, the brows, the hair
and the chin cast soft shadows several millimetres across at their edges, never hard ones.
:class:`KeyShadow` draws the depth of what casts (the head's skin and eyeballs, the body, the
hair cards alpha-tested by their texture) in an orthographic view along the key's direction,
fitted each frame to what the camera sees, with texels of :data:`SHADOW_TEXEL` (so the
penumbra has the same width whatever the framing); the face shaders (``shadow.glsl``) compare
against it with a 3x3-texel tent filter in four bilinear taps (a smooth penumbra about three
texels wide). Beside the depth the map holds how much of the key its nearest caster stops:
all of it for skin, less for hair (:func:`hair_opacity`).

:func:`light_frame` is the numpy half (the light's view-projection for a set of points),
testable without GL.
"""
from __future__ import annotations

import numpy as np

from facsim.render.gl import compile_program
from facsim.render.proxies import ALPHA_CUTOFF, END_FADE

#: World size (decimetres) of one shadow-map texel: 2.6 mm, so the 3-texel filter gives the
#: soft key's penumbra of about 8 mm (a softbox a metre across at 1.5 m shades with an edge of
#: about a centimetre from features one or two centimetres off the skin: the nose, the chin).
#: (1.6 mm until session 25: the nose's shadow had a drawn edge, a grey shape laid on the lip.)
SHADOW_TEXEL = 0.026
#: Largest shadow map side (texels); a caster set wider than this many texels gets coarser ones.
SHADOW_MAP_MAX = 1024
#: Map sides are rounded up to a multiple of this (a video's frames then share one map).
SHADOW_MAP_STEP = 128
#: How much of the key a hair layer stops, (dark hair, white hair): hair cards stand for a
#: mass of strands that lets some light through and scatters more of it the lighter it is
#: (cast at full strength, the skin seen between grey cards was dark holes).
HAIR_SHADOW_OPACITY = (0.8, 0.5)

_CASTER_VERTEX = """#version 330 core
in vec3 in_pos;
uniform mat4 u_light_view_proj;
void main() { gl_Position = u_light_view_proj * vec4(in_pos, 1.0); }
"""
_CASTER_FRAGMENT = """#version 330 core
out float f_opacity;
void main() { f_opacity = 1.0; }
"""
#: Hair cards cast where their texture is solid (the alpha-tested pass's cut-out), and not
#: below where long hair ends (facsim.render.proxies: END_FADE over u_end_height).
_CARD_VERTEX = """#version 330 core
in vec3 in_pos;
in vec2 in_uv;
in vec3 in_rest;
uniform mat4 u_light_view_proj;
out vec2 v_uv;
out float v_rest_y;
void main() {
    v_uv = in_uv;
    v_rest_y = in_rest.y;
    gl_Position = u_light_view_proj * vec4(in_pos, 1.0);
}
"""
_CARD_FRAGMENT = f"""#version 330 core
in vec2 v_uv;
in float v_rest_y;
uniform sampler2D u_texture;
uniform float u_end_height;
uniform float u_opacity;
out float f_opacity;
void main() {{
    if (texture(u_texture, v_uv).a < {ALPHA_CUTOFF:.3f}) discard;
    if ((v_rest_y - u_end_height) / {END_FADE:.6f} < 0.45) discard;
    f_opacity = u_opacity;
}}
"""


def light_frame(direction, points: np.ndarray, *, texel: float = SHADOW_TEXEL,
                max_size: int = SHADOW_MAP_MAX, step: int = SHADOW_MAP_STEP,
                seen: np.ndarray | None = None) -> tuple[np.ndarray, int, float]:
    """The orthographic view-projection along ``direction`` (toward the light) fitted to ``points``.

    ``seen`` (bool per point), where given, narrows the map across the light to the points
    the camera sees: only they receive shadows, and only what lies along the light's rays
    through them can cast one (its depth range still spans every point, so nothing between
    them and the light is clipped). A torso below the frame then costs no texels.

    Returns ``(matrix, size, texel)``: the (4, 4) matrix taking world points to shadow-map
    coordinates in [0, 1]³ (x, y across the map, z the depth: 0 nearest the light), the map's
    side in texels and the world size of one texel (``texel``, or larger where the points
    need more than ``max_size`` texels). The box is snapped to whole texels, so a still
    caster's shadow does not shimmer as other points move.
    """
    d = np.asarray(direction, dtype=float)
    d = d / np.linalg.norm(d)
    helper = np.array([0.0, 1.0, 0.0]) if abs(d[1]) < 0.9 else np.array([1.0, 0.0, 0.0])
    right = np.cross(helper, d)
    right /= np.linalg.norm(right)
    up = np.cross(d, right)
    basis = np.stack([right, up, d])                      # world -> light (x, y, toward the light)
    p = linear_map(points, basis)                         # (3, N): x, y, toward the light
    lo = np.array([float(c.min()) for c in p])
    hi = np.array([float(c.max()) for c in p])
    if seen is not None and np.any(seen):
        for i in (0, 1):
            lo[i] = float(np.where(seen, p[i], np.inf).min())
            hi[i] = float(np.where(seen, p[i], -np.inf).max())
    margin = 4 * texel                                    # the filter's reach at the border
    extent = float(max(hi[0] - lo[0], hi[1] - lo[1])) + 2 * margin
    size = int(min(max_size, step * np.ceil(extent / texel / step)))
    texel = max(texel, extent / size)
    centre = np.round(0.5 * (lo[:2] + hi[:2]) / texel) * texel
    half = 0.5 * size * texel
    depth_lo, depth_hi = lo[2] - margin, hi[2] + margin
    m = np.zeros((4, 4))
    m[0, :3] = basis[0] / (2 * half)
    m[0, 3] = 0.5 - centre[0] / (2 * half)
    m[1, :3] = basis[1] / (2 * half)
    m[1, 3] = 0.5 - centre[1] / (2 * half)
    m[2, :3] = -basis[2] / (depth_hi - depth_lo)          # nearest the light -> 0
    m[2, 3] = depth_hi / (depth_hi - depth_lo)
    m[3, 3] = 1.0
    return m, size, texel


def hair_opacity(color) -> float:
    """How much of the key a hair layer of linear colour ``color`` stops (HAIR_SHADOW_OPACITY)."""
    luminance = float(np.dot(np.clip(color, 0.0, 1.0), (0.2126, 0.7152, 0.0722)))
    dark, white = HAIR_SHADOW_OPACITY
    return dark + (white - dark) * float(np.sqrt(luminance))


def linear_map(points: np.ndarray, matrix: np.ndarray) -> np.ndarray:
    """``(points @ matrix[:, :3].T + matrix[:, 3]).T`` for (N, 3) points as (rows, N) float32,
    each output row contiguous: numpy hands a 3-wide matrix product to BLAS, whose threads
    cost ~20x more here, and reduces across (N, 3) columns slowly."""
    p = np.asarray(points, dtype=np.float32).reshape(-1, 3)
    x, y, z = p[:, 0].copy(), p[:, 1].copy(), p[:, 2].copy()
    m = np.asarray(matrix, dtype=np.float32)
    out = np.empty((len(m), len(p)), np.float32)
    for i, row in enumerate(m):
        np.multiply(x, row[0], out=out[i])
        out[i] += y * row[1]
        out[i] += z * row[2]
        if len(row) > 3:
            out[i] += row[3]
    return out


class KeyShadow:
    """The key light's shadow map: GL objects owned by a Renderer (``track`` registers them)."""

    def __init__(self, ctx, track, position_format: str = "3f"):
        self.ctx = ctx
        self._position_format = position_format  # the vertex buffer's layout, position first
        self._track = track
        self.texture = None
        self.opacity = None
        self._fbo = None
        self.size = 0
        self.texel = SHADOW_TEXEL
        self.matrix = np.eye(4)
        self.depth_range = 1.0
        self._program = track(compile_program(ctx, _CASTER_VERTEX, _CASTER_FRAGMENT))
        self._card_program = track(compile_program(ctx, _CARD_VERTEX, _CARD_FRAGMENT))
        self._card_program["u_texture"].value = 1
        self._vao = None
        self._card_vaos: dict = {}

    def _target(self, size: int) -> None:
        if size == self.size:
            return
        ctx = self.ctx
        for old in (self._fbo, self.opacity, self.texture):   # the last size's (the owner's release skips them)
            if old is not None:
                old.release()
        self.texture = self._track(ctx.depth_texture((size, size)))
        # Hardware comparison with bilinear filtering: each tap is a 2x2 PCF already.
        self.texture.compare_func = "<="
        self.texture.filter = (ctx.LINEAR, ctx.LINEAR)
        self.texture.repeat_x = self.texture.repeat_y = False
        # Beside the depth, how much of the key the nearest caster stops (1 skin, less for hair).
        self.opacity = self._track(ctx.texture((size, size), 1, dtype="f1"))
        self.opacity.filter = (ctx.LINEAR, ctx.LINEAR)
        self.opacity.repeat_x = self.opacity.repeat_y = False
        self._fbo = self._track(ctx.framebuffer(color_attachments=[self.opacity], depth_attachment=self.texture))
        self.size = size

    def draw(self, direction, points: np.ndarray, vbo, ibo, draws, hair_layers=(), seen=None) -> None:
        """Draw the casters' depth from ``direction`` (world, toward the light).

        ``points`` bound the casters; ``vbo``/``ibo`` are the renderer's vertex buffer (laid out
        as the ``position_format`` given at construction) and index buffer, ``draws`` the (first
        triangle, count) ranges that cast; ``hair_layers`` the ProxyLayers of the hair cards;
        ``seen`` which points the camera sees (see :func:`light_frame`).
        """
        ctx = self.ctx
        matrix, size, texel = light_frame(direction, points, seen=seen)
        self._target(size)
        self.matrix, self.texel = matrix, texel
        self.depth_range = 1.0 / float(np.linalg.norm(matrix[2, :3]))
        # The matrix maps to [0, 1]; the rasteriser wants [-1, 1] clip coordinates.
        clip = np.diag([2.0, 2.0, 2.0, 1.0]) @ matrix
        clip[:3, 3] -= 1.0
        clip_bytes = clip.T.astype(np.float32).tobytes()
        if self._vao is None:
            self._vao = self._track(ctx.vertex_array(self._program, [(vbo, self._position_format, "in_pos")],
                                                     index_buffer=ibo, index_element_size=4))
        self._fbo.use()
        self._fbo.clear(0.0, 0.0, 0.0, 0.0, depth=1.0)
        ctx.enable_only(ctx.DEPTH_TEST)
        ctx.depth_func = "<"
        self._program["u_light_view_proj"].write(clip_bytes)
        for first, count in draws:
            self._vao.render(ctx.TRIANGLES, vertices=3 * count, first=3 * first)
        if hair_layers:
            self._card_program["u_light_view_proj"].write(clip_bytes)
            for layer in hair_layers:
                vao = self._card_vaos.get(layer)
                if vao is None:
                    vao = self._card_vaos[layer] = self._track(layer.caster_vertex_array(self._card_program))
                end = layer.mesh.end_height
                self._card_program["u_end_height"].value = -1e3 if end is None else float(end)
                self._card_program["u_opacity"].value = hair_opacity(layer.look[0] if layer.look else (0.0, 0.0, 0.0))
                layer.texture.use(1)
                vao.render(ctx.TRIANGLES)

    def use(self, depth_unit: int, opacity_unit: int) -> None:
        """Bind the map's depth and caster opacity to texture units."""
        self.texture.use(depth_unit)
        self.opacity.use(opacity_unit)

    def uniforms(self) -> dict:
        """The receivers' ``u_shadow_*`` uniforms for this frame's map."""
        return {"u_shadow_matrix": self.matrix.T.astype(np.float32).tobytes(),
                "u_shadow_size": float(self.size),
                "u_shadow_texel": float(self.texel),
                "u_shadow_depth_range": float(self.depth_range)}
