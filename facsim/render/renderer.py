"""Headless OpenGL renderer for face stimuli: geometry + appearance + camera -> RGBA image.

The renderer takes any mesh through :class:`RenderTopology` (static, uploaded once) and
per-frame geometry-vertex positions; it computes smooth normals in numpy (a precomputed
sparse face -> vertex matrix), uploads one dynamic vertex buffer, draws each region with
its own shader variant (built with #defines, not branches: on llvmpipe a branch that
is switched off still costs), resolves the anti-aliasing and reads back one image. Skin
and eyeballs are drawn with back faces culled (winding checked on the first frame).

Colour conventions: :class:`Appearance` colours are display sRGB values in [0, 1] (what a
colour picker shows); shading is done in linear light and the output is sRGB-encoded 8-bit,
top row first. ``background`` is an sRGB colour too, reproduced exactly (to rounding) where
nothing is drawn; ``background=None`` gives a transparent background with straight
(un-premultiplied) alpha.

Light rig (:class:`Lighting`): soft studio lighting fixed to the CAMERA, so every view
gets the same flattering key (upper camera-left), fill (camera-right, weaker), rim
(behind, above) and a hemispheric ambient (world up brighter than down, warm bounce).
The key casts soft shadows (a depth map drawn from it each frame, :mod:`facsim.render.shadows`)
on the skin, eyeballs, lashes and garment; :func:`bake_occlusion` gives the per-vertex ambient
occlusion to pass in for the rest (sockets, creases, the fill and the room's light).

OpenGL: one context per process (EGL, created lazily on first use, reused by every
Renderer and recreated in a forked child). A Renderer holds GL objects; release them with
:meth:`Renderer.close` or a ``with`` block. Use a renderer from one thread. The paint
texture and colours are uploaded again only when a different :class:`Appearance` object
is passed (in-place edits of ``appearance.paint`` are not detected).

Modules: this one holds :class:`Renderer` and its draw passes; what it is given
(:class:`RenderTopology`, :class:`Appearance`, :class:`Lighting`, :data:`REGIONS`...) is in
:mod:`facsim.render.inputs`, the numpy geometry (normals, creases, lashes) in
:mod:`facsim.render.geometry`, the GL context and shader loading in :mod:`facsim.render.gl`,
occlusion baking in :mod:`facsim.render.occlusion` and :func:`write_png` in
:mod:`facsim.media.images`. All their public names can be imported from here.

Examples
--------
>>> from facsim.render.renderer import Renderer, Appearance           # doctest: +SKIP
>>> with Renderer(topology, size=512) as r:                  # doctest: +SKIP
...     image = r.render(positions, appearance=Appearance(DEFAULT_COLORS, paint), camera=cam)
>>> write_png("face.png", image)                             # doctest: +SKIP
"""
from __future__ import annotations

from contextlib import contextmanager

import numpy as np

from facsim.render.camera import Camera, projection_matrix, view_matrix, _size_pair
from facsim.media.images import write_png
from facsim.render.geometry import (CREASES_PER_DM, _faces_touching, _orientation, crease_phase, eye_rotation, lash_coordinates,
                              normal_operator, region_components, scattered_normals, smoothing_operator,
                              sphere_centre, sphere_directions, surface_curvature, teeth_normal_operator,
                              vertex_normals)
from facsim.render.gl import RenderError, _set_uniform, _shader_source, compile_program, gl_context
from facsim.render.inputs import (COLOR_NAMES, DEFAULT_BROW_UV_FRAME, DEFAULT_COLORS, HM08_BROW_UV_FRAME, REGIONS,
                            Appearance, Lighting, RenderTopology, brow_uv_frame, srgb_to_linear)
from facsim.render.occlusion import bake_occlusion
from facsim.render.shadows import KeyShadow, linear_map

__all__ = [
    "REGIONS", "COLOR_NAMES", "DEFAULT_COLORS", "RenderTopology", "Appearance", "Lighting",
    "Renderer", "RenderError", "normal_operator", "vertex_normals", "srgb_to_linear",
    "write_png", "gl_context", "region_components", "sphere_centre", "lash_coordinates",
    "crease_phase", "CREASES_PER_DM", "AA_METHODS", "HM08_BROW_UV_FRAME", "DEFAULT_BROW_UV_FRAME",
    "brow_uv_frame", "bake_occlusion", "sphere_directions",
]

#: Anti-aliasing methods: multisampling (``antialias`` = samples) or supersampling
#: (``antialias`` = factor per axis, then a box-filter downsampling pass).
AA_METHODS = ("msaa", "ssaa", "fxaa")

#: The depth-only pass that lets hair cards and skin hide each other before shading.
_DEPTH_VERTEX = """#version 330 core
in vec3 in_pos;
uniform mat4 u_view_proj;
void main() { gl_Position = u_view_proj * vec4(in_pos, 1.0); }
"""
_DEPTH_FRAGMENT = """#version 330 core
void main() {}
"""

#: Largest share of the hair's cards that may move from frame to frame for the rest to be
#: kept as pixels (a facial expression moves a few sideburn cards; head motion moves all).
HAIR_KEPT_MOVING = 0.25

#: Pixels around the drawn geometry's screen box that FXAA still filters (it reads one
#: pixel around each pixel; the rest of the frame is copied as it is).
CONTENT_MARGIN = 3

#: Lid elevations (degrees) of eyeball vertices when no lids are given: far from both margins.
_NO_LIDS = (90.0, 90.0)

#: Smallest image side (pixels, after supersampling) at which skin pores are shaded.
PORES_MIN_SIZE = 1024

#: Draw groups in drawing order, each with its shader variant's #defines. Skin triangles
#: under painted brows get the brow-hair code; others skip it (on llvmpipe a skipped branch
#: still costs, so variants are cheaper than branches). Lashes are blended, hence last.
_PASSES = {
    "skin": ("REGION_SKIN", "USE_UV", "USE_WRINKLE"),
    "skin_brows": ("REGION_SKIN", "USE_UV", "USE_WRINKLE", "USE_BROWS"),
    "mouth_interior": ("REGION_MOUTH_INTERIOR", "USE_EYE"),   # v_eye: the lining's place (Face.topology)
    "teeth": ("REGION_TEETH", "USE_UV"),
    "tongue": ("REGION_TONGUE", "USE_UV"),
    "eyeball": ("REGION_EYEBALL", "USE_EYE", "USE_LIDS"),
    "garment": ("REGION_GARMENT", "USE_UV"),
    "lashes": ("REGION_LASHES", "USE_LASH"),
}
#: Shader variants for frames without creases (no wrinkle field): the skin skips the crease
#: code, which llvmpipe would otherwise run on every skin fragment.
_CREASE_FREE = {name: name + "_plain" for name in ("skin", "skin_brows")}
_VARIANTS = {**_PASSES, **{plain: tuple(d for d in _PASSES[name] if d != "USE_WRINKLE")
                           for name, plain in _CREASE_FREE.items()}}
#: Groups drawn with back faces culled (closed, outward-wound after _fix_winding); the rest
#: are two-sided (teeth bands, lash cards, the inside of the mouth).
_CULLED = ("skin", "skin_brows", "eyeball")
#: Floats per vertex in the dynamic buffer (see Renderer.__init__), and its layout for passes
#: that read only the position.
_VERTEX_FLOATS = 13
_POSITION_ONLY = f"3f {4 * (_VERTEX_FLOATS - 3)}x"
#: Groups shaded with the key's cast shadow (USE_SHADOW). The mouth's parts are not: what light
#: the lips let in reaches them per frame from facsim.head.mouth (mouth_light), and the lips'
#: thin edges are finer than the shadow map's texels.
_SHADOW_RECEIVERS = ("skin", "skin_brows", "eyeball", "garment", "lashes")
#: Groups that cast it: not the lashes' blended strands, nor the mouth's parts (inside the
#: lips, they could only shade one another).
_SHADOW_CASTERS = ("skin", "skin_brows", "eyeball", "garment")
#: Texture units of the shadow map's depth and its casters' opacity.
_SHADOW_UNIT = 5
_SHADOW_OPACITY_UNIT = 6
_SINGLE_COLOR = {"mouth_interior": "mouth_interior", "teeth": "teeth", "tongue": "tongue",
                 "lashes": "lashes", "garment": "garment"}


# --------------------------------------------------------------------------------------------
# Renderer
# --------------------------------------------------------------------------------------------

class Renderer:
    """Renders one mesh topology; a GL resource (``close()`` it, or use ``with``).

    Parameters
    ----------
    topology : RenderTopology
    size : int or (width, height)
        Output image size in pixels.
    antialias : int
        ``aa_method="msaa"``: samples per pixel (1 = off; capped at the driver's maximum).
        ``"ssaa"``: supersampling factor per axis (1..4). ``"fxaa"``: ignored.
    aa_method : {"msaa", "ssaa", "fxaa"}
        ``"fxaa"`` shades one sample per pixel and smooths edges in a post pass: about the
        cost of no AA, for video frames where 4x MSAA would not keep up.
        Measured on llvmpipe (2 cores, 512 px, the 12.7k-triangle head): 4x MSAA 48 ms,
        2x2 SSAA 56 ms, no AA 24 ms per frame. llvmpipe shades every sample and only has
        4x MSAA (a request for 2 samples gets 4, at the same cost), so the default is
        ``msaa``/4. The shaders filter their own procedural detail (iris edges, brow
        strands, creases), so ``antialias=1`` is a fair fast preview.
    background : (r, g, b) display sRGB in [0, 1], or None for transparent.
    lighting : Lighting
        Default rig; :meth:`render` can override it per call.
    wrinkle_depth : float
        Crease depth (decimetres) per unit of ``wrinkle``: the normals are computed on the
        surface pushed inward by ``wrinkle_depth * wrinkle``, giving furrow shading.
    wrinkle_darken : float
        Cavity darkening at ``wrinkle >= 1``: 0.35 of it over the compressed skin, up to 1.95 of
        it on a furrow's valley floor (0 = none; keep it under 0.5).
    brow_uv_frame : (2, 2) array_like
        Maps skin UV to eyebrow-stroke space: row 0 gives the coordinate along the hairs
        (1 unit ~ one stroke length), row 1 across them (1 unit ~ one strand width). The
        default fits facsim's head (hm08 UVs normalised to its paint box); for other
        layouts see :func:`brow_uv_frame` and :data:`HM08_BROW_UV_FRAME`.
    hair_fringe : bool
        Draw the hair's soft fringe (alpha below the cutoff) and its loose strands (proxy kind
        ``"wisps"``) blended, back to front. ``False`` saves ~10-15 % of a 512² frame on
        llvmpipe but leaves a hard, cut-out hairline. Brows and lashes always get theirs.
    shadows : bool
        Cast the key light's soft shadows (the nose's beside the nostril, the hair's on the
        forehead and temples, the chin's on the neck) with a shadow map drawn each frame;
        ``False`` leaves only the baked occlusion (about 7 % less CPU per 512² FXAA frame on
        llvmpipe).
    cull_backfaces : bool
        Skip skin and eyeball triangles facing away (about 1.5x faster). Needs those
        surfaces closed (cap the neck); the winding is checked on the first frame and
        flipped if the mesh is wound clockwise. ``False`` draws everything two-sided.
    """

    def __init__(self, topology: RenderTopology, *, size=512, antialias: int = 4,
                 aa_method: str = "msaa", background=(0.5, 0.5, 0.5),
                 lighting: Lighting | None = None, wrinkle_depth: float = 0.012,
                 wrinkle_darken: float = 0.15, brow_uv_frame=DEFAULT_BROW_UV_FRAME,
                 cull_backfaces: bool = True, hair_fringe: bool = True, shadows: bool = True):
        if not isinstance(topology, RenderTopology):
            raise TypeError(f"topology must be a RenderTopology, got {type(topology).__name__}")
        if aa_method not in AA_METHODS:
            raise ValueError(f"aa_method must be one of {AA_METHODS}, got {aa_method!r}")
        self._closed = True  # until construction succeeds
        self._gl_objects: list = []
        self.topology = topology
        self.size = _size_pair(size)
        self.aa_method = aa_method
        self.background = None if background is None else _color3(background, "background")
        self.lighting = lighting if lighting is not None else Lighting()
        self.wrinkle_depth = float(wrinkle_depth)
        self.wrinkle_darken = float(wrinkle_darken)
        self.brow_uv_frame = np.asarray(brow_uv_frame, dtype=float)
        if self.brow_uv_frame.shape != (2, 2) or not np.isfinite(self.brow_uv_frame).all():
            raise ValueError(f"brow_uv_frame must be a finite 2x2 matrix, got {brow_uv_frame!r}")
        ctx = gl_context()
        self._ctx = ctx
        antialias = int(antialias)
        if aa_method == "msaa":
            if antialias < 1:
                raise ValueError(f"antialias must be >= 1 sample, got {antialias}")
            antialias = min(antialias, max(int(ctx.max_samples), 1))
        elif not 1 <= antialias <= 4:
            raise ValueError(f"antialias (supersampling factor) must be 1..4, got {antialias}")
        self.antialias = antialias

        #: Seconds spent per stage of :meth:`render` as ``{stage: (wall, CPU of every thread)}``
        #: while this is a dict (set it to ``{}`` to profile; None, the default, measures nothing).
        self.timings: dict | None = None
        self.cull_backfaces = bool(cull_backfaces)
        self.shadows = bool(shadows)
        # The hair's blended fringe (the soft wisps at the hairline) costs ~10-15 % of a 512²
        # video frame on llvmpipe; without it the hairline is a hard cut-out edge, so it stays
        # on unless asked otherwise.
        self.hair_fringe = bool(hair_fringe)
        # Skin pores are drawn only where they are bigger than a pixel: large images.
        scale = self.antialias if aa_method == "ssaa" else 1
        self._pores = min(self.size) * scale >= PORES_MIN_SIZE

        # Static geometry: the normals operator on geometry vertices; triangles are drawn in
        # groups, one shader variant per group (see _PASSES), skin split by brow coverage.
        self._n_geo = topology.n_geo
        self._faces = topology.faces.copy()
        self._geo_faces = np.ascontiguousarray(topology.geo_faces)
        self._normal_op = teeth_normal_operator(topology, self._geo_faces, self._n_geo)
        self._smoothing_op = smoothing_operator(self._geo_faces, self._n_geo)
        self._render_op = None  # face -> render vertex sums, built when wrinkles first come
        self._face_region = topology.face_regions()
        self._face_uv = topology.uv[topology.faces]             # (M, 3, 2) for brow coverage
        self._brow_faces = np.zeros(len(self._faces), dtype=bool)
        self._winding_checked = False
        self._draws: list[tuple[str, int, int]] = []
        # Per-frame vertex data: position (3), normal (3), wrinkle, occlusion, crease phase,
        # the normal as light scattered under the skin sees it (3), the surface's curvature.
        self._geo_buffer = np.zeros((self._n_geo, _VERTEX_FLOATS), dtype=np.float32)
        self._render_buffer = np.zeros((topology.n_render, _VERTEX_FLOATS), dtype=np.float32)
        self._appearance = None
        self._proxy_layers: dict = {}  # ProxyMesh -> ProxyLayer, created on first use
        self._proxy_draws: tuple = ()
        # The hair's alpha-tested pass, kept as pixels (colour + depth) while the hair holds
        # still (see _prepare_hair_layer).
        self._in_sequence = False  # frames of one video (see sequence())
        self._hair_fbo = None
        self._hair_kept = None    # {"key", "positions", "moving"} of the kept pixels
        self._hair_last = None    # (key, positions) of the last frame's hair
        self._hair_moving = None  # this frame: {layer: cards drawn over the kept pixels}, or None
        self._eyes = region_components(topology, "eyeball")
        self._eye_render = np.flatnonzero(topology.region == REGIONS.index("eyeball"))
        self._eye_frames = _eye_frame_coordinates(topology, self._eyes)
        self._lashes = region_components(topology, "lashes")
        self._lash_vertices = (np.concatenate(self._lashes) if self._lashes
                               else np.zeros(0, dtype=np.int64))

        try:
            self._setup_gl(topology)
        except Exception:
            self._release_all()
            raise
        self._closed = False

    # -- GL setup ------------------------------------------------------------------------
    def _track(self, obj):
        self._gl_objects.append(obj)
        return obj

    def _program(self, name: str):
        """The compiled variant for a draw group, compiled on first use."""
        if name in self._programs:
            return self._programs[name], self._vaos[name]
        ctx = self._ctx
        defines = dict.fromkeys(_VARIANTS[name], "")
        if name.startswith("skin") and self._pores:
            defines["USE_PORES"] = ""
        if self.shadows and _group(name) in _SHADOW_RECEIVERS:
            defines["USE_SHADOW"] = ""
        prog = self._track(compile_program(ctx, _shader_source("face.vert.glsl", defines),
                                               _shader_source("face.frag.glsl", defines)))
        vao = self._track(ctx.vertex_array(
            prog, [(self._vbo_dynamic, "3f 3f 1f 1f 1f 3f 1f", "in_pos", "in_normal", "in_wrinkle",
                    "in_occlusion", "in_crease", "in_scatter_normal", "in_curvature"),
                   (self._vbo_static, "2f 3f", "in_uv", "in_eye")],
            index_buffer=self._ibo, index_element_size=4, skip_errors=True))
        _set_uniform(prog, "u_paint", 0)
        _set_uniform(prog, "u_detail", 2)
        _set_uniform(prog, "u_tone", 3)
        _set_uniform(prog, "u_folds", 4)
        _set_uniform(prog, "u_shadow", _SHADOW_UNIT)
        _set_uniform(prog, "u_shadow_opacity", _SHADOW_OPACITY_UNIT)
        _set_uniform(prog, "u_wrinkle_darken", self.wrinkle_darken)
        try:
            prog["u_brow_frame"].write(self.brow_uv_frame.T.astype(np.float32).tobytes())
        except KeyError:
            pass
        self._programs[name], self._vaos[name] = prog, vao
        if self._appearance is not None:
            self._set_colors(name, self._appearance)
        return prog, vao

    def _variant(self, name: str) -> str:
        """The program that draws group ``name`` this frame."""
        return name if self._creased else _CREASE_FREE.get(name, name)

    def _rebuild_draws(self) -> None:
        """Sort the triangles into draw groups and upload the index buffer."""
        names = list(_PASSES)
        group = np.array([names.index(REGIONS[r]) for r in range(len(REGIONS))])[self._face_region]
        group[self._brow_faces & (self._face_region == 0)] = names.index("skin_brows")
        order = np.argsort(group, kind="stable")
        self._ibo.write(np.ascontiguousarray(self._faces[order]).tobytes())
        counts = np.bincount(group, minlength=len(names))
        starts = np.concatenate([[0], np.cumsum(counts)[:-1]])
        self._draws = [(names[i], int(starts[i]), int(counts[i]))
                       for i in range(len(names)) if counts[i]]
        for name, _, _ in self._draws:
            self._program(self._variant(name))

    def _fix_winding(self, p: np.ndarray) -> None:
        """Make skin and eyeballs wound counter-clockwise seen from outside (for culling).

        Decided once, on the first frame: a mesh's orientation does not change with
        deformation. Shading does not depend on it (normals follow the winding and the
        shaders face them toward the viewer); only back-face culling does.
        """
        skin = self._face_region == 0
        if skin.any() and _orientation(p, self._geo_faces[skin]) < 0:
            self._faces = np.ascontiguousarray(self._faces[:, ::-1])
            self._geo_faces = np.ascontiguousarray(self._geo_faces[:, ::-1])
        eye_region = REGIONS.index("eyeball")
        for piece in self._eyes:
            sel = (self._face_region == eye_region) & np.isin(self._geo_faces[:, 0], piece)
            if sel.any() and _orientation(p, self._geo_faces[sel]) < 0:
                self._faces[sel] = self._faces[sel][:, ::-1]
                self._geo_faces[sel] = self._geo_faces[sel][:, ::-1]
        self._winding_checked = True

    def _setup_gl(self, topology: RenderTopology) -> None:
        ctx = self._ctx
        static = np.concatenate([topology.uv, topology.eye_coord], axis=1).astype(np.float32)
        self._vbo_static = self._track(ctx.buffer(static.tobytes()))
        self._vbo_dynamic = self._track(ctx.buffer(reserve=self._render_buffer.nbytes,
                                                   dynamic=True))
        self._ibo = self._track(ctx.buffer(reserve=self._faces.nbytes))
        self._programs, self._vaos = {}, {}
        self._creased = False
        self._paint_tex = None
        self._detail_tex = None
        self._tone_tex = None
        self._folds_tex = None
        self._depth_vao = self._depth_prog = None
        self._key_shadow = KeyShadow(ctx, self._track, _POSITION_ONLY) if self.shadows else None
        self._vp_bytes = b""
        self._lights: dict = {}
        self._camera_uniforms: dict = {}  # program name -> (view-projection, lights) it holds
        self._content_box = None
        self._rebuild_draws()

        w, h = self.size
        if self.aa_method == "msaa":
            s = self.antialias if self.antialias > 1 else 0
            self._scene_fbo = self._track(ctx.framebuffer(
                color_attachments=[self._track(ctx.renderbuffer((w, h), 4, samples=s))],
                depth_attachment=self._track(ctx.depth_renderbuffer((w, h), samples=s))))
            if s:
                self._out_fbo = self._track(ctx.framebuffer(
                    color_attachments=[self._track(ctx.renderbuffer((w, h), 4))]))
            else:
                self._out_fbo = self._scene_fbo
            self._downsample = None
        else:
            k = self.antialias if self.aa_method == "ssaa" else 1
            self._scene_tex = self._track(ctx.texture((w * k, h * k), 4))
            # Never mipmapped (a render target); FXAA reads between texels.
            self._scene_tex.filter = (ctx.LINEAR, ctx.LINEAR) if self.aa_method == "fxaa" else (ctx.NEAREST, ctx.NEAREST)
            # FXAA reads around each pixel: at the frame's edge it must see that edge, not the
            # opposite one (a repeating texture smeared the neck into the top row).
            self._scene_tex.repeat_x = self._scene_tex.repeat_y = False
            self._scene_fbo = self._track(ctx.framebuffer(
                color_attachments=[self._scene_tex],
                depth_attachment=self._track(ctx.depth_renderbuffer((w * k, h * k)))))
            self._out_fbo = self._track(ctx.framebuffer(
                color_attachments=[self._track(ctx.renderbuffer((w, h), 4))]))
            defines = {"FACTOR": k}
            if self.background is None:
                defines["UNPREMULTIPLY"] = ""
            prog = self._track(compile_program(
                ctx, _shader_source("fullscreen.vert.glsl", {}),
                _shader_source(f"{'fxaa' if self.aa_method == 'fxaa' else 'downsample'}.frag.glsl", defines)))
            _set_uniform(prog, "u_image", 0)
            self._downsample = self._track(ctx.vertex_array(prog, []))
        self._readback = bytearray(w * h * 4)

    def _upload_appearance(self, appearance: Appearance) -> None:
        ctx = self._ctx
        paint = appearance.paint
        if paint is None:
            paint = np.zeros((1, 1, 4), dtype=np.uint8)
        paint = np.ascontiguousarray(paint)  # row 0 = v = 0 already (GL order)
        ph, pw = paint.shape[:2]
        tex = self._paint_tex
        if tex is None or tex.size != (pw, ph):
            if tex is not None:
                self._gl_objects.remove(tex)
                tex.release()
            tex = self._paint_tex = self._track(ctx.texture((pw, ph), 4, paint.tobytes()))
            tex.repeat_x = tex.repeat_y = False
        else:
            tex.write(paint.tobytes())
        tex.build_mipmaps()  # an input texture, never rendered into: mipmaps are safe here
        tex.filter = (ctx.LINEAR_MIPMAP_LINEAR, ctx.LINEAR)
        # Skin detail (redness, beard area, oiliness), tone maps (periorbital darkening,
        # translucency, pores, sun) and folds (lines, under-eye lines, fold shade, where the
        # lines are drawn): neutral when not given.
        self._detail_tex = self._upload_map(self._detail_tex, appearance.detail, (0, 0, 90, 0))
        self._tone_tex = self._upload_map(self._tone_tex, appearance.tone, (0, 0, 128, 0))
        self._folds_tex = self._upload_map(self._folds_tex, appearance.folds, (0, 0, 0, 0))
        self._appearance = appearance
        for name in self._programs:
            self._set_colors(name, appearance)
        brows = (np.zeros(len(self._faces), dtype=bool) if appearance.paint is None
                 else _faces_touching(self._face_uv, appearance.paint[..., 0] > 0))
        if not np.array_equal(brows, self._brow_faces):
            self._brow_faces = brows
            self._rebuild_draws()

    def _upload_map(self, texture, data: np.ndarray | None, neutral: tuple) -> object:
        """A mipmapped RGBA texture of ``data`` (one texel of ``neutral`` when None), replacing ``texture``."""
        data = np.array([[neutral]], dtype=np.uint8) if data is None else np.ascontiguousarray(data)
        if texture is not None:
            self._gl_objects.remove(texture)
            texture.release()
        texture = self._track(self._ctx.texture((data.shape[1], data.shape[0]), 4, data.tobytes()))
        texture.repeat_x = texture.repeat_y = False
        texture.build_mipmaps()  # an input texture, never rendered into: mipmaps are safe here
        texture.filter = (self._ctx.LINEAR_MIPMAP_LINEAR, self._ctx.LINEAR)
        return texture

    def _set_colors(self, name: str, appearance: Appearance) -> None:
        prog = self._programs[name]
        colors = appearance.colors
        lin = lambda key: tuple(float(x) for x in srgb_to_linear(colors[key]))  # noqa: E731
        if name.startswith("skin"):
            for key in ("skin", "lips", "brows", "eyelid", "cheek"):
                _set_uniform(prog, f"u_{key}", lin(key))
            _set_uniform(prog, "u_beard", appearance.beard)
            _set_uniform(prog, "u_beard_grey", appearance.beard_grey)
            _set_uniform(prog, "u_age", appearance.age)
            _set_uniform(prog, "u_freckles", appearance.freckles)
            _set_uniform(prog, "u_redness", appearance.redness)
            _set_uniform(prog, "u_skin_seed", appearance.seed)
        elif name == "eyeball":
            for key in ("sclera", "iris", "pupil"):
                _set_uniform(prog, f"u_{key}", lin(key))
            _set_uniform(prog, "u_age", appearance.age)   # (the pupil narrows with age)
        else:
            _set_uniform(prog, "u_albedo", lin(_SINGLE_COLOR[name]))
            if name == "mouth_interior":   # its rim is the lips' mucosa, as dark as the lips are
                _set_uniform(prog, "u_lips", lin("lips"))

    # -- per frame -----------------------------------------------------------------------
    def render(self, positions: np.ndarray, *, appearance: Appearance, camera: Camera,
               wrinkle: np.ndarray | None = None, crease_phase: np.ndarray | None = None,
               occlusion: np.ndarray | None = None, lighting: Lighting | None = None,
               proxies=(), lids: np.ndarray | None = None) -> np.ndarray:
        """Render one frame.

        Parameters
        ----------
        positions : (N_geo, 3) float
            Geometry-vertex positions (N_geo >= ``topology.n_geo``; extra rows are unused).
        appearance : Appearance
        camera : Camera
        wrinkle : (N_geo,) float >= 0, optional
            Skin compression; creases and cavity darkening are drawn where it is > 0.
        crease_phase : (N_geo,) float, optional
            Where across its creases each vertex lies, in crease spacings (a crease is drawn
            at each whole number), e.g. a muscle-engine Deformation's ``crease_phase``. Default:
            creases along the contours of ``wrinkle`` (:func:`crease_phase`).
        occlusion : (N_geo,) float in [0, 1], optional
            Ambient visibility per geometry vertex (1 = open), e.g. from
            :func:`bake_occlusion` on the neutral pose; it darkens sockets and creases on
            skin, eyeballs and lashes. The mouth's parts read it per frame from
            :func:`facsim.head.mouth.mouth_light` (teeth: their height below the upper lip's
            edge; tongue: the light the parted lips let in) and the mouth interior from
            :func:`facsim.head.mouth.mouth_depth_visibility`. Default: all 1.
        lighting : Lighting, optional
            Overrides the renderer's rig for this frame.
        proxies : sequence of :class:`~facsim.render.proxies.ProxyDraw`
            Hair, eyebrow and eyelash cards drawn with their alpha textures (an
            alpha-tested pass, then the soft fringe blended back to front).
        lids : (N_geo, 2) float, optional
            Per eyeball vertex, degrees of arc below the upper lid's margin and above the
            lower's (:func:`~facsim.render.geometry.lid_elevations`): the eyeballs get the
            lash line's shadow and the wet lower rim along the lids. Default: no lids.

        Returns
        -------
        (H, W, 4) uint8 RGBA, top row first, display sRGB, straight alpha.
        """
        if self._closed:
            raise RenderError("this Renderer is closed")
        self._lap(None)
        if not isinstance(appearance, Appearance):
            raise TypeError(f"appearance must be an Appearance, got {type(appearance).__name__}")
        if not isinstance(camera, Camera):
            raise TypeError(f"camera must be a Camera, got {type(camera).__name__}")
        p_all = np.asarray(positions, dtype=np.float32)
        if p_all.ndim != 2 or p_all.shape[1] != 3 or p_all.shape[0] < self._n_geo:
            raise ValueError(f"positions must be (N_geo, 3) with N_geo >= {self._n_geo}, "
                             f"got {p_all.shape}")
        p = p_all[: self._n_geo]
        if not np.isfinite(p).all():
            raise ValueError("positions contain NaN or infinity")
        w_geo = _per_vertex("wrinkle", wrinkle, len(p_all), self._n_geo)
        if w_geo is not None:
            w_geo = np.maximum(w_geo, 0.0)
        phase = _per_vertex("crease_phase", crease_phase, len(p_all), self._n_geo)
        occ = _per_vertex("occlusion", occlusion, len(p_all), self._n_geo)
        if lids is not None:
            lids = np.asarray(lids, dtype=np.float32)
            if lids.shape != (len(p_all), 2):
                raise ValueError(f"lids must be (N_geo, 2) like positions, got {lids.shape}")
            lids = lids[: self._n_geo]
        if not self._winding_checked:
            self._fix_winding(p)
            self._rebuild_draws()
        self._update_vertices(p, w_geo, phase, occ, lids)
        self._set_eye_centres(p)
        self._creased = w_geo is not None and bool(w_geo.any())
        if appearance is not self._appearance:
            self._upload_appearance(appearance)
        for name, _, _ in self._draws:
            self._program(self._variant(name))  # compiled before the camera's uniforms are set
        self._set_camera(camera, lighting or self.lighting)
        if self.aa_method == "fxaa":
            self._content_box = self._screen_box([p] + [np.asarray(d.positions, np.float32) for d in proxies])
        self._lap("vertices")
        self._prepare_proxies(proxies, camera, lighting or self.lighting)
        self._lap("proxies")
        self._draw_key_shadow()
        self._lap("shadow")
        # (after the shadow map: the kept hair pixels are shaded with this frame's)
        if proxies:
            self._prepare_hair_layer(self._vp_bytes, self._lights)
            self._lap("proxies")
        self._draw()
        self._lap("draw")
        self._resolve()
        self._lap("antialias")
        image = self._read()
        self._lap("readback")
        return image

    def _lap(self, stage: str | None) -> None:
        """With :attr:`timings` a dict, add the time since the last lap to ``stage`` (None: start).

        Each lap waits for the GL work issued so far (``finish``), so the stages are
        measured apart but not overlapped: for profiling (benchmarks/bench_video.py), not
        for speed.
        """
        if self.timings is None:
            return
        import time

        if stage is not None:
            self._ctx.finish()
        now = (time.perf_counter(), time.process_time())
        if stage is not None:
            wall, cpu = self.timings.get(stage, (0.0, 0.0))
            self.timings[stage] = (wall + now[0] - self._lap_start[0], cpu + now[1] - self._lap_start[1])
        self._lap_start = now

    def _screen_box(self, point_sets) -> tuple[int, int, int, int] | None:
        """(x, y, width, height), GL pixel coordinates, of a box around everything drawn, with
        :data:`CONTENT_MARGIN` pixels to spare; None where it would be the whole image."""
        w, h = self.size
        vp = np.frombuffer(self._vp_bytes, np.float32).reshape(4, 4)  # transposed (column-major)
        lo, hi = np.array([np.inf, np.inf]), np.array([-np.inf, -np.inf])
        for points in point_sets:
            if not len(points):
                continue
            clip = points @ vp[:3] + vp[3]
            if not (clip[:, 3] > 1e-6).all():  # behind the camera: no box
                return None
            xy = clip[:, :2] / clip[:, 3:4]
            lo, hi = np.minimum(lo, xy.min(axis=0)), np.maximum(hi, xy.max(axis=0))
        if not np.isfinite(lo).all():
            return None
        x0, y0 = np.floor((lo * 0.5 + 0.5) * (w, h)).astype(int) - CONTENT_MARGIN
        x1, y1 = np.ceil((hi * 0.5 + 0.5) * (w, h)).astype(int) + CONTENT_MARGIN
        x0, y0, x1, y1 = max(x0, 0), max(y0, 0), min(x1, w), min(y1, h)
        if x1 <= x0 or y1 <= y0:
            return (0, 0, 0, 0)
        if (x0, y0, x1, y1) == (0, 0, w, h):
            return None
        return int(x0), int(y0), int(x1 - x0), int(y1 - y0)

    def _prepare_proxies(self, proxies, camera: Camera, lighting: Lighting) -> None:
        from facsim.render.proxies import ProxyDraw, ProxyLayer

        for draw in proxies:
            if not isinstance(draw, ProxyDraw):
                raise TypeError(f"proxies must be ProxyDraw objects, got {type(draw).__name__}")
            if draw.mesh not in self._proxy_layers:
                self._proxy_layers[draw.mesh] = ProxyLayer(
                    self._ctx, draw.mesh, self._track,
                    shadow_units=(_SHADOW_UNIT, _SHADOW_OPACITY_UNIT) if self.shadows else None)
        self._proxy_draws = tuple(proxies)
        if not proxies:
            self._hair_last, self._hair_moving = None, None
            return
        vp_bytes, lights = self._vp_bytes, self._lights  # this frame's (see _set_camera)
        position = camera.position
        for draw in proxies:
            layer = self._proxy_layers[draw.mesh]
            layer.update(draw, position)
            layer.set_uniforms(vp_bytes, lights, self._scene_fbo.size)

    @contextmanager
    def sequence(self):
        """Render the frames of one video in this ``with`` block (the renderer is yielded).

        Within it, hair that holds still from frame to frame is kept as pixels instead of
        being drawn again (see :meth:`_prepare_hair_layer`): the kept cards keep the shading of
        the frame they were drawn in, which the motion of a few other cards (sideburns over a
        smiling cheek) changes by a level or two of 255 at most. Each sequence starts afresh,
        so a video does not depend on what the renderer drew before it, and a single
        :meth:`render` outside a sequence draws everything.
        """
        self._forget_hair()
        self._in_sequence = True
        try:
            yield self
        finally:
            self._in_sequence = False
            self._forget_hair()

    def _forget_hair(self) -> None:
        self._hair_kept = self._hair_last = self._hair_moving = None

    def _hair_layers(self) -> list:
        return [self._proxy_layers[d.mesh] for d in self._proxy_draws if d.mesh.kind == "hair"]

    def _prepare_hair_layer(self, vp_bytes: bytes, lights: dict) -> None:
        """Keep the hair's alpha-tested pass as pixels while the hair holds still.

        Hair moves with the head (AUs 51-58), the face's shape and the camera; a facial
        expression moves only the few cards bound to skin that moves (sideburns over the
        cheeks). The alpha-tested pass of the cards that hold still (the costliest proxy
        pass on llvmpipe) does not depend on the face, so it is drawn once into a frame
        buffer of its own, without the head's depth, and each frame starts from a copy of
        it (colour and depth) instead of a clear; the cards that moved are drawn over it,
        then the head hides what it covers by the depth test, as it does when all cards
        are drawn over the head's depth pre-pass. The kept pixels are drawn when the
        camera, lights and hair colour are those of the last frame and at most
        :data:`HAIR_KEPT_MOVING` of the cards moved since; they are used while the cards
        outside the moving set stay where they were. Pixels that can differ from drawing
        everything: the kept cards' shading, which the moving cards shift by a level or two
        (the hair's volume normals look at every card), and exact depth ties between cards.
        """
        layers = self._hair_layers()
        if not layers or not self._in_sequence:
            self._hair_last, self._hair_moving = None, None
            return
        key = (vp_bytes, tuple(sorted(lights.items())), tuple((id(layer), layer.look) for layer in layers))
        now = {layer: layer.positions for layer in layers}
        kept = self._hair_kept
        moving = None
        if kept is not None and kept["key"] == key:
            moved = {layer: layer.moved_triangles(kept["positions"][layer]) for layer in layers}
            if not any((moved[layer] & ~kept["moving"][layer]).any() for layer in layers):
                moving = kept["moving"]
        if self._hair_last is not None and self._hair_last[0] == key:
            moved = {layer: layer.moved_triangles(self._hair_last[1][layer]) for layer in layers}
            redraw = None
            if all(m.mean() <= HAIR_KEPT_MOVING for m in moved.values()):
                if moving is None:
                    redraw = moved
                    if kept is not None and kept["key"] == key:  # once moving, a card is kept out...
                        redraw = {layer: moved[layer] | kept["moving"][layer] for layer in layers}
                elif not any(m.any() for m in moved.values()) and any(m.any() for m in moving.values()):
                    redraw = moved  # ... until every card holds still (an expression's apex)
            if redraw is not None:
                self._draw_hair_layer(layers, redraw)
                self._hair_kept = kept = {"key": key, "positions": now, "moving": redraw}
                moving = redraw
        self._hair_last = (key, now)
        self._hair_moving = moving

    def _draw_hair_layer(self, layers, moving: dict) -> None:
        """The alpha-tested pass of the hair cards not in ``moving``, into the kept frame buffer."""
        ctx = self._ctx
        if self._hair_fbo is None:
            scene = self._scene_fbo
            size, samples = scene.size, scene.samples
            self._hair_fbo = self._track(ctx.framebuffer(
                color_attachments=[self._track(ctx.renderbuffer(size, 4, samples=samples))],
                depth_attachment=self._track(ctx.depth_renderbuffer(size, samples=samples))))
        fbo = self._hair_fbo
        fbo.use()
        self._clear(fbo)
        ctx.enable_only(ctx.DEPTH_TEST)
        ctx.depth_func = "<"
        for layer in layers:
            layer.draw("OPAQUE", ~moving[layer])

    def _draw_head_depth(self, fbo) -> None:
        """Depth only (colour writes off, a trivial shader) of the culled, closed groups."""
        ctx = self._ctx
        if self._depth_vao is None:
            prog = self._track(compile_program(ctx, _DEPTH_VERTEX, _DEPTH_FRAGMENT))
            self._depth_prog = prog
            self._depth_vao = self._track(ctx.vertex_array(
                prog, [(self._vbo_dynamic, _POSITION_ONLY, "in_pos")], index_buffer=self._ibo, index_element_size=4))
        self._depth_prog["u_view_proj"].write(self._vp_bytes)
        fbo.color_mask = (False, False, False, False)
        if self.cull_backfaces:
            ctx.enable(ctx.CULL_FACE)
            ctx.cull_face = "back"
        for name, first, count in self._draws:
            if name in _CULLED:
                self._depth_vao.render(ctx.TRIANGLES, vertices=3 * count, first=3 * first)
        fbo.color_mask = (True, True, True, True)
        ctx.disable(ctx.CULL_FACE)

    def _draw_proxies_opaque(self, hair_moving: dict | None = None) -> None:
        """Proxy cards' alpha-tested pass. Drawn before the head, so the skin hidden under
        the hair fails the depth test before it is shaded (on llvmpipe shading is the cost).
        With ``hair_moving``, only those hair cards (the rest is in the kept pixels)."""
        ctx = self._ctx
        ctx.disable(ctx.CULL_FACE)
        for draw in self._proxy_draws:
            layer = self._proxy_layers[draw.mesh]
            if not layer.has_opaque_pass:
                continue
            if hair_moving is None or draw.mesh.kind != "hair":
                layer.draw("OPAQUE")
            elif hair_moving[layer].any():
                layer.draw("OPAQUE", hair_moving[layer])
        if self._paint_tex is not None:
            self._paint_tex.use(0)

    def _draw_proxies(self, fbo) -> None:
        """Proxy cards' soft fringes, blended back to front over everything (no depth writes)."""
        ctx = self._ctx
        ctx.disable(ctx.CULL_FACE)
        layers = [self._proxy_layers[d.mesh] for d in self._proxy_draws
                  if self.hair_fringe or d.mesh.kind not in ("hair", "wisps")]
        ctx.enable(ctx.BLEND)
        ctx.blend_func = (ctx.SRC_ALPHA, ctx.ONE_MINUS_SRC_ALPHA, ctx.ONE, ctx.ONE_MINUS_SRC_ALPHA)
        fbo.depth_mask = False
        # Strictly in front: a card's own alpha-tested fragments (the depth they wrote) fail
        # the test before the shader fetches their texture only to discard them.
        ctx.depth_func = "<"
        for layer in layers:
            if layer.culled:
                ctx.enable(ctx.CULL_FACE)
                ctx.cull_face = "back"
            layer.draw("BLEND")
            ctx.disable(ctx.CULL_FACE)
        ctx.depth_func = "<="  # what the head's groups after the proxies use
        fbo.depth_mask = True
        ctx.disable(ctx.BLEND)
        if self._paint_tex is not None:
            self._paint_tex.use(0)

    def _update_vertices(self, p: np.ndarray, wrinkle: np.ndarray | None, phase: np.ndarray | None,
                         occlusion: np.ndarray | None, lids: np.ndarray | None = None) -> None:
        geo = self._geo_buffer
        normals = vertex_normals(p, self._geo_faces, self._normal_op)
        if wrinkle is not None and wrinkle.any():
            if self.wrinkle_depth > 0:
                sunk = p - (self.wrinkle_depth * wrinkle)[:, None] * normals
                normals = vertex_normals(sunk, self._geo_faces, self._normal_op)
            geo[:, 6] = wrinkle
        else:
            geo[:, 6] = 0.0
        if len(self._lash_vertices):  # lashes reuse the wrinkle slot for root-to-tip
            geo[self._lash_vertices, 6] = lash_coordinates(p, self._eyes, self._lashes)
        geo[:, 7] = 1.0 if occlusion is None else occlusion
        geo[:, 0:3] = p
        geo[:, 3:6] = normals
        geo[:, 9:12] = scattered_normals(normals, self._smoothing_op)
        geo[:, 12] = surface_curvature(p, normals, self._smoothing_op)
        out = self._render_buffer
        np.take(geo, self.topology.render_to_geo, axis=0, out=out)
        if wrinkle is not None and wrinkle.any() and phase is not None:
            out[:, 8] = phase[self.topology.render_to_geo]
        elif wrinkle is not None and wrinkle.any():
            if self._render_op is None:
                self._render_op = normal_operator(self._faces, self.topology.n_render)
            out[:, 8] = crease_phase(out[:, 0:3], self.topology.uv, self._faces, out[:, 6],
                                     self._render_op)
        else:
            out[:, 8] = 0.0
        # The eyeballs' wrinkle and crease slots carry their distance below the upper lid and
        # above the lower (USE_LIDS; nothing else reads those slots there).
        eye = self._eye_render
        if len(eye):
            gap = _NO_LIDS if lids is None else lids[self.topology.render_to_geo[eye]]
            out[eye, 6] = gap[..., 0] if lids is not None else gap[0]
            out[eye, 8] = gap[..., 1] if lids is not None else gap[1]
        self._vbo_dynamic.write(out)

    def _set_eye_centres(self, p: np.ndarray) -> None:
        """The eyeballs' centres and radius this frame, for what the eyeball shader draws fixed
        to the socket rather than to the turning eye (the caruncle, the canthi's shade)."""
        if len(self._eyes) != 2 or "eyeball" not in self._programs:
            return
        centres = [p[eye].astype(np.float64).mean(axis=0) for eye in self._eyes]
        radius = max(float(np.linalg.norm(p[eye] - c, axis=1).max()) for eye, c in zip(self._eyes, centres))
        prog = self._programs["eyeball"]
        _set_uniform(prog, "u_eye_a", tuple(float(x) for x in centres[0]))
        _set_uniform(prog, "u_eye_b", tuple(float(x) for x in centres[1]))
        _set_uniform(prog, "u_eye_radius", radius)
        # Each eye's turn (its own frame -> world) for the cornea's refraction and bulge.
        for uniform, eye, coords, centre in zip(("u_eye_rot_a", "u_eye_rot_b"), self._eyes, self._eye_frames, centres):
            rotation = eye_rotation(coords, p[eye].astype(np.float64) - centre)
            _set_uniform(prog, uniform, tuple(float(x) for x in rotation.T.reshape(-1)))  # column-major

    def _set_camera(self, camera: Camera, lighting: Lighting) -> None:
        w, h = self.size
        vp = projection_matrix(camera, w / h) @ view_matrix(camera)
        vp_bytes = vp.T.astype(np.float32).tobytes()  # GLSL matrices are column-major
        self._vp_bytes = vp_bytes
        lights = self._lights = lighting.world_uniforms(camera)
        key = (vp_bytes, tuple(lights.items()))
        for name, prog in self._programs.items():
            if self._camera_uniforms.get(name) == key:  # a video's camera and lights hold still
                continue
            self._camera_uniforms[name] = key
            try:
                prog["u_view_proj"].write(vp_bytes)
            except KeyError:
                pass
            for name, value in lights.items():
                _set_uniform(prog, name, value)

    def _draw_key_shadow(self) -> None:
        """This frame's shadow map from the key (the head, the body and the hair cards cast),
        and its uniforms on the programs that receive it."""
        shadow = self._key_shadow
        if shadow is None:
            return
        hair = self._hair_layers() if self._proxy_draws else []
        points = np.concatenate([self._render_buffer[:, :3]] + [layer.positions for layer in hair])
        draws = [(first, count) for name, first, count in self._draws if name in _SHADOW_CASTERS]
        vp = np.frombuffer(self._vp_bytes, np.float32).reshape(4, 4).T  # stored column-major
        x, y, z, w = linear_map(points, vp)
        seen = (np.abs(x) <= w) & (np.abs(y) <= w) & (np.abs(z) <= w)
        shadow.draw(self._lights["u_key_dir"], points, self._vbo_dynamic, self._ibo, draws, hair, seen)
        uniforms = shadow.uniforms()
        shadow.use(_SHADOW_UNIT, _SHADOW_OPACITY_UNIT)
        for draw in self._proxy_draws:
            self._proxy_layers[draw.mesh].set_shadow_uniforms(uniforms)
        for name, prog in self._programs.items():
            if _group(name) not in _SHADOW_RECEIVERS:
                continue
            for key, value in uniforms.items():
                if isinstance(value, bytes):
                    try:
                        prog[key].write(value)
                    except KeyError:
                        pass
                else:
                    _set_uniform(prog, key, value)

    def _draw(self) -> None:
        ctx = self._ctx
        fbo = self._scene_fbo
        kept = self._hair_moving is not None and bool(self._proxy_draws)
        if kept:
            ctx.copy_framebuffer(fbo, self._hair_fbo)  # the background with the still hair on it
        fbo.use()
        ctx.enable_only(ctx.DEPTH_TEST)
        ctx.depth_func = "<"
        if not kept:
            self._clear(fbo)
        if self._paint_tex is not None:
            self._paint_tex.use(0)
        if self._detail_tex is not None:
            self._detail_tex.use(2)
        if self._tone_tex is not None:
            self._tone_tex.use(3)
        if self._folds_tex is not None:
            self._folds_tex.use(4)
        if self._key_shadow is not None:
            self._key_shadow.use(_SHADOW_UNIT, _SHADOW_OPACITY_UNIT)
        ctx.front_face = "ccw"
        if self._proxy_draws:
            # Depth of the closed head first (no shading), so hair behind the head fails the
            # depth test; then the hair's alpha-tested cards, so the skin under the hair does;
            # then the head, shaded only where it shows.
            if kept:  # still hair already there: the head hides it where it is in front
                self._draw_proxies_opaque(self._hair_moving)
            else:
                self._draw_head_depth(fbo)
                self._draw_proxies_opaque()
            ctx.depth_func = "<="
        proxies_drawn = not self._proxy_draws
        for name, first, count in self._draws:
            if name == "lashes" and not proxies_drawn:
                self._draw_proxies(fbo)
                proxies_drawn = True
            if name == "lashes":  # drawn last (_PASSES order): blended strands, no depth writes
                ctx.enable(ctx.BLEND)
                ctx.blend_func = (ctx.SRC_ALPHA, ctx.ONE_MINUS_SRC_ALPHA,
                                  ctx.ONE, ctx.ONE_MINUS_SRC_ALPHA)
                fbo.depth_mask = False
            if self.cull_backfaces and name in _CULLED:
                ctx.enable(ctx.CULL_FACE)
                ctx.cull_face = "back"
            else:
                ctx.disable(ctx.CULL_FACE)
            self._vaos[self._variant(name)].render(ctx.TRIANGLES, vertices=3 * count, first=3 * first)
        if not proxies_drawn:
            self._draw_proxies(fbo)
        fbo.depth_mask = True
        ctx.depth_func = "<"
        ctx.disable(ctx.BLEND | ctx.CULL_FACE)

    def _resolve(self) -> None:
        """The drawn scene into the output image: FXAA, supersampling's filter or the MSAA resolve."""
        ctx = self._ctx
        if self._downsample is not None:
            box = self._content_box if self.aa_method == "fxaa" else None
            self._out_fbo.use()
            if box is not None:
                # FXAA leaves a pixel as it is where its neighbours match it: everywhere
                # further than a pixel from what was drawn, which is the background there.
                # Clear to it (cheaper than copying the frame on llvmpipe), filter only the box.
                self._clear(self._out_fbo)
            ctx.disable(ctx.DEPTH_TEST)
            self._out_fbo.scissor = box
            self._scene_tex.use(0)
            self._downsample.render(ctx.TRIANGLES, vertices=3)
            self._out_fbo.scissor = None
        elif self._out_fbo is not self._scene_fbo:
            ctx.copy_framebuffer(self._out_fbo, self._scene_fbo)

    def _clear(self, fbo) -> None:
        if self.background is None:
            fbo.clear(0.0, 0.0, 0.0, 0.0, depth=1.0)
        else:
            fbo.clear(*self.background, 1.0, depth=1.0)

    def _read(self) -> np.ndarray:
        w, h = self.size
        self._out_fbo.read_into(self._readback, components=4, alignment=1)
        img = np.frombuffer(self._readback, dtype=np.uint8).reshape(h, w, 4)[::-1].copy()
        if self.background is None and self.aa_method == "msaa" and self.antialias > 1:
            _unpremultiply(img)
        return img

    # -- resource ------------------------------------------------------------------------
    def _release_all(self) -> None:
        for obj in reversed(self._gl_objects):
            try:
                obj.release()
            except Exception:  # already gone with the context; nothing left to free
                pass
        self._gl_objects.clear()

    def close(self) -> None:
        """Release the GL objects; safe to call more than once."""
        if self._closed:
            return
        self._closed = True
        self._release_all()
        self._appearance = None

    @property
    def closed(self) -> bool:
        return self._closed

    def __enter__(self) -> "Renderer":
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def __repr__(self) -> str:
        state = "closed" if self._closed else "open"
        return (f"Renderer({self.topology.n_render} vertices, {len(self.topology.faces)} faces, "
                f"size={self.size}, {self.aa_method} x{self.antialias}, {state})")


def _group(variant: str) -> str:
    """The draw group a shader variant draws (``"skin_plain"`` -> ``"skin"``)."""
    for name, plain in _CREASE_FREE.items():
        if variant == plain:
            return name
    return variant


def _eye_frame_coordinates(topology: RenderTopology, eyes: list) -> list:
    """Per eyeball (geometry vertex indices), each vertex's direction in the eye's own frame."""
    frames = []
    for eye in eyes:
        coords = np.zeros((len(eye), 3))
        rows = np.flatnonzero(np.isin(topology.render_to_geo, eye))
        coords[np.searchsorted(eye, topology.render_to_geo[rows])] = topology.eye_coord[rows]
        frames.append(coords)
    return frames


def _per_vertex(name: str, value, n_rows: int, n_used: int) -> np.ndarray | None:
    """Validate an optional per-geometry-vertex array; the rows the topology uses."""
    if value is None:
        return None
    arr = np.asarray(value, dtype=np.float32).reshape(-1)
    if arr.shape[0] != n_rows:
        raise ValueError(f"{name} must have one value per geometry vertex ({n_rows}), "
                         f"got {arr.shape}")
    arr = arr[:n_used]
    if not np.isfinite(arr).all():
        raise ValueError(f"{name} contains NaN or infinity")
    return arr


def _unpremultiply(img: np.ndarray) -> None:
    """In place: MSAA over a transparent clear leaves coverage-weighted colours at edges."""
    a = img[..., 3]
    edge = (a > 0) & (a < 255)
    if edge.any():
        px = img[edge].astype(np.float32)
        px[:, :3] = np.minimum(px[:, :3] * 255.0 / px[:, 3:4] + 0.5, 255.0)
        img[edge] = px.astype(np.uint8)


def _color3(value, name: str) -> tuple[float, float, float]:
    c = np.asarray(value, dtype=float).reshape(-1)
    if c.shape != (3,) or not np.all((c >= 0) & (c <= 1)):
        raise ValueError(f"{name} must be (r, g, b) in [0, 1] or None, got {value!r}")
    return tuple(float(x) for x in c)
