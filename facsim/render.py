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
No cast shadows: :func:`bake_occlusion` gives per-vertex ambient occlusion to pass in.

OpenGL: one context per process (EGL, created lazily on first use, reused by every
Renderer and recreated in a forked child). A Renderer holds GL objects; release them with
:meth:`Renderer.close` or a ``with`` block. Use a renderer from one thread. The paint
texture and colours are uploaded again only when a different :class:`Appearance` object
is passed (in-place edits of ``appearance.paint`` are not detected).

Examples
--------
>>> from facsim.render import Renderer, Appearance           # doctest: +SKIP
>>> with Renderer(topology, size=512) as r:                  # doctest: +SKIP
...     image = r.render(positions, appearance=Appearance(DEFAULT_COLORS, paint), camera=cam)
>>> write_png("face.png", image)                             # doctest: +SKIP
"""
from __future__ import annotations

import math
import os
import tempfile
import threading
from dataclasses import dataclass, field
from pathlib import Path
from types import MappingProxyType
from typing import Mapping

import numpy as np
import scipy.sparse as sp

from .camera import Camera, camera_basis, projection_matrix, view_matrix, _size_pair

__all__ = [
    "REGIONS", "COLOR_NAMES", "DEFAULT_COLORS", "RenderTopology", "Appearance", "Lighting",
    "Renderer", "RenderError", "normal_operator", "vertex_normals", "srgb_to_linear",
    "write_png", "gl_context", "region_components", "sphere_centre", "lash_coordinates",
    "crease_phase", "AA_METHODS", "HM08_BROW_UV_FRAME", "DEFAULT_BROW_UV_FRAME", "brow_uv_frame",
    "bake_occlusion",
]

#: Region names; ``RenderTopology.region`` holds indices into this tuple.
REGIONS = ("skin", "mouth_interior", "teeth", "tongue", "eyeball", "lashes")

#: Colour names an :class:`Appearance` must give (display sRGB, 0..1).
COLOR_NAMES = ("skin", "lips", "brows", "lashes", "sclera", "iris", "pupil", "teeth", "tongue",
               "mouth_interior", "eyelid", "cheek")

#: A plausible default appearance (light-medium skin, brown eyes), display sRGB.
DEFAULT_COLORS: Mapping[str, tuple[float, float, float]] = MappingProxyType({
    "skin": (0.85, 0.68, 0.60),
    "lips": (0.72, 0.42, 0.40),
    "brows": (0.22, 0.15, 0.11),
    "lashes": (0.07, 0.05, 0.04),
    "sclera": (0.90, 0.88, 0.85),
    "iris": (0.36, 0.24, 0.14),
    "pupil": (0.02, 0.02, 0.02),
    "teeth": (0.90, 0.87, 0.78),
    "tongue": (0.76, 0.40, 0.40),
    "mouth_interior": (0.36, 0.11, 0.11),
    "eyelid": (0.78, 0.58, 0.52),
    "cheek": (0.90, 0.56, 0.52),
})

#: Anti-aliasing methods: multisampling (``antialias`` = samples) or supersampling
#: (``antialias`` = factor per axis, then a box-filter downsampling pass).
AA_METHODS = ("msaa", "ssaa", "fxaa")

#: Eyebrow strokes for hm08's raw UV layout, where the head's island is turned 90 degrees:
#: the brows run along v (strokes ~3 mm long) and u runs up the face (strands ~0.5 mm apart).
HM08_BROW_UV_FRAME = ((0.0, 160.0), (1600.0, 0.0))


def brow_uv_frame(uv_box=None, frame=HM08_BROW_UV_FRAME) -> np.ndarray:
    """The brow-stroke frame for UVs normalised to ``uv_box = (u0, v0, u1, v1)``.

    A head whose UVs are ``u' = (u - u0) / (u1 - u0)`` (same for v) needs the raw frame's
    columns scaled by the box's size; ``uv_box=None`` returns the raw frame.
    """
    m = np.asarray(frame, dtype=float)
    if uv_box is None:
        return m
    u0, v0, u1, v1 = (float(x) for x in uv_box)
    return m * np.array([u1 - u0, v1 - v0])[None, :]


#: The default: facsim's head model, whose UVs are normalised to ``facsim.assets.PAINT_UV_BOX``
#: (0.60, 0.10, 1.00, 0.90) (a test checks the two agree).
DEFAULT_BROW_UV_FRAME = ((0.0, 128.0), (640.0, 0.0))

_SHADER_DIR = Path(__file__).with_name("shaders")
#: Draw groups in drawing order, each with its shader variant's #defines. Skin triangles
#: under painted brows get the brow-hair code; others skip it (on llvmpipe a skipped branch
#: still costs, so variants are cheaper than branches). Lashes are blended, hence last.
_PASSES = {
    "skin": ("REGION_SKIN", "USE_UV", "USE_WRINKLE"),
    "skin_brows": ("REGION_SKIN", "USE_UV", "USE_WRINKLE", "USE_BROWS"),
    "mouth_interior": ("REGION_MOUTH_INTERIOR",),
    "teeth": ("REGION_TEETH",),
    "tongue": ("REGION_TONGUE",),
    "eyeball": ("REGION_EYEBALL", "USE_EYE"),
    "lashes": ("REGION_LASHES", "USE_LASH"),
}
#: Groups drawn with back faces culled (closed, outward-wound after _fix_winding); the rest
#: are two-sided (teeth bands, lash cards, the inside of the mouth).
_CULLED = ("skin", "skin_brows", "eyeball")
_SINGLE_COLOR = {"mouth_interior": "mouth_interior", "teeth": "teeth", "tongue": "tongue",
                 "lashes": "lashes"}


class RenderError(RuntimeError):
    """OpenGL could not be set up or used (no driver, context creation failed, ...)."""


# --------------------------------------------------------------------------------------------
# Inputs
# --------------------------------------------------------------------------------------------

@dataclass(frozen=True, eq=False)
class RenderTopology:
    """Static mesh description, uploaded once per :class:`Renderer`.

    Parameters
    ----------
    faces : (M, 3) uint32
        Triangles as indices into render vertices.
    render_to_geo : (R,) int
        Render vertex -> geometry vertex. Render vertices are split at UV seams; normals are
        computed on geometry vertices so seams do not show.
    uv : (R, 2) float32
        Skin UVs (MakeHuman layout, v up, [0, 1]); unused (zeros, say) for non-skin.
    region : (R,) uint8
        Index into :data:`REGIONS` per render vertex. A triangle takes the region most of
        its vertices have (the first vertex's when all three differ).
    eye_coord : (R, 3) float32
        For eyeball vertices, the unit direction from the eye centre in the eye's own
        (unrotated) frame, +Z = gaze; zeros elsewhere.
    """

    faces: np.ndarray
    render_to_geo: np.ndarray
    uv: np.ndarray
    region: np.ndarray
    eye_coord: np.ndarray

    def __post_init__(self):
        faces = np.ascontiguousarray(self.faces, dtype=np.uint32)
        r2g = np.ascontiguousarray(self.render_to_geo, dtype=np.int64)
        if faces.ndim != 2 or faces.shape[1] != 3 or len(faces) == 0:
            raise ValueError(f"faces must be a non-empty (M, 3) array, got shape {faces.shape}")
        if r2g.ndim != 1 or len(r2g) == 0:
            raise ValueError(f"render_to_geo must be a non-empty (R,) array, got {r2g.shape}")
        n = len(r2g)
        if faces.max() >= n:
            raise ValueError(f"faces index render vertex {faces.max()}, but there are only "
                             f"{n} (len(render_to_geo))")
        if r2g.min() < 0:
            raise ValueError("render_to_geo must be >= 0")
        uv = np.ascontiguousarray(self.uv, dtype=np.float32)
        region = np.ascontiguousarray(self.region, dtype=np.uint8)
        eye = np.ascontiguousarray(self.eye_coord, dtype=np.float32)
        for name, arr, shape in (("uv", uv, (n, 2)), ("region", region, (n,)),
                                 ("eye_coord", eye, (n, 3))):
            if arr.shape != shape:
                raise ValueError(f"{name} must have shape {shape} (one row per render vertex), "
                                 f"got {arr.shape}")
        if region.max() >= len(REGIONS):
            raise ValueError(f"region values must index REGIONS (0..{len(REGIONS) - 1}), "
                             f"got {region.max()}")
        for name, arr in (("faces", faces), ("render_to_geo", r2g), ("uv", uv),
                          ("region", region), ("eye_coord", eye)):
            arr.setflags(write=False)
            object.__setattr__(self, name, arr)

    @property
    def n_render(self) -> int:
        """Number of render vertices R."""
        return len(self.render_to_geo)

    @property
    def n_geo(self) -> int:
        """Number of geometry vertices referenced (positions need at least this many rows)."""
        return int(self.render_to_geo.max()) + 1

    @property
    def geo_faces(self) -> np.ndarray:
        """(M, 3) the triangles as geometry-vertex indices."""
        return self.render_to_geo[self.faces]

    def face_regions(self) -> np.ndarray:
        """(M,) region index of each triangle (majority of its vertices)."""
        r = self.region[self.faces]
        return np.where((r[:, 1] == r[:, 2]) & (r[:, 0] != r[:, 1]), r[:, 1], r[:, 0])


@dataclass(frozen=True, eq=False)
class Appearance:
    """How a character looks: colours and a paint texture in skin-UV space.

    Parameters
    ----------
    colors : mapping name -> (r, g, b)
        Display sRGB in [0, 1] for every name in :data:`COLOR_NAMES` (extra names are an
        error, to catch typos). See :data:`DEFAULT_COLORS`.
    paint : (H, W, 4) uint8, optional
        R = eyebrow hair density, G = lip mask, B = eyelid mask, A = cheek/blush mask.
        Rows run with v UPWARD: row 0 is v = 0 (GL texture order, as ``facsim.assets``
        stores its masks; flip an image file's rows with ``paint[::-1]``). Each mask is the
        weight of its colour over the skin colour (255 = the colour itself), so the blush
        or eyelid strength is painted into the mask. ``None`` = no paint.
    """

    colors: Mapping[str, tuple[float, float, float]] = field(default_factory=lambda: DEFAULT_COLORS)
    paint: np.ndarray | None = None

    def __post_init__(self):
        colors = dict(self.colors)
        missing = [k for k in COLOR_NAMES if k not in colors]
        extra = [k for k in colors if k not in COLOR_NAMES]
        if missing or extra:
            raise ValueError(f"colors must give exactly {COLOR_NAMES}; missing {missing}, "
                             f"unknown {extra}")
        clean = {}
        for k in COLOR_NAMES:
            c = np.asarray(colors[k], dtype=float).reshape(-1)
            if c.shape != (3,) or not np.all((c >= 0) & (c <= 1)):
                raise ValueError(f"colors[{k!r}] must be 3 numbers in [0, 1], got {colors[k]!r}")
            clean[k] = tuple(float(v) for v in c)
        object.__setattr__(self, "colors", MappingProxyType(clean))
        if self.paint is not None:
            paint = np.asarray(self.paint)
            if paint.ndim != 3 or paint.shape[2] != 4 or paint.dtype != np.uint8:
                raise ValueError(f"paint must be an (H, W, 4) uint8 array, got "
                                 f"{paint.dtype} {paint.shape}")
            object.__setattr__(self, "paint", paint)


@dataclass(frozen=True)
class Lighting:
    """A studio light rig fixed to the camera.

    Directions are in CAMERA space (x right, y up, z from the subject toward the camera)
    and point toward the light; they need not be unit length. Colours are linear RGB with
    the intensity folded in. ``sky``/``ground`` are the hemispheric ambient for world-up and
    world-down facing surfaces. ``exposure`` scales everything before tone mapping.
    """

    key_direction: tuple[float, float, float] = (-0.6, 0.55, 0.6)
    key_color: tuple[float, float, float] = (1.3, 1.24, 1.15)
    fill_direction: tuple[float, float, float] = (0.8, -0.05, 0.6)
    fill_color: tuple[float, float, float] = (0.22, 0.21, 0.22)
    rim_direction: tuple[float, float, float] = (0.35, 0.55, -0.75)
    rim_color: tuple[float, float, float] = (0.55, 0.55, 0.58)
    sky: tuple[float, float, float] = (0.22, 0.22, 0.23)
    ground: tuple[float, float, float] = (0.11, 0.08, 0.065)
    exposure: float = 1.0

    def world_uniforms(self, camera: Camera) -> dict[str, tuple[float, ...]]:
        """The ``u_*`` shader uniforms for this rig seen from ``camera``."""
        right, up, back = camera_basis(camera.yaw, camera.pitch)
        rot = np.stack([right, up, back], axis=1)  # camera -> world

        def direction(d):
            w = rot @ np.asarray(d, dtype=float)
            return tuple(float(x) for x in w / np.linalg.norm(w))

        return {
            "u_key_dir": direction(self.key_direction), "u_key_col": tuple(self.key_color),
            "u_fill_dir": direction(self.fill_direction), "u_fill_col": tuple(self.fill_color),
            "u_rim_dir": direction(self.rim_direction), "u_rim_col": tuple(self.rim_color),
            "u_sky_col": tuple(self.sky), "u_ground_col": tuple(self.ground),
            "u_exposure": float(self.exposure),
            "u_cam_pos": tuple(float(x) for x in camera.position),
        }


# --------------------------------------------------------------------------------------------
# Pure helpers (no GL)
# --------------------------------------------------------------------------------------------

def srgb_to_linear(c) -> np.ndarray:
    """Display sRGB in [0, 1] -> linear light (the exact IEC 61966-2-1 curve)."""
    c = np.asarray(c, dtype=float)
    return np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)


def normal_operator(faces: np.ndarray, n_vertices: int) -> sp.csr_matrix:
    """Sparse (n_vertices, M) float32 matrix summing each face's value onto its 3 vertices.

    ``operator @ face_normals`` with unnormalised face normals (cross products, length =
    twice the area) gives area-weighted vertex normals.
    """
    faces = np.asarray(faces, dtype=np.int64)
    m = len(faces)
    rows = faces.reshape(-1)
    cols = np.repeat(np.arange(m), 3)
    data = np.ones(len(rows), dtype=np.float32)
    return sp.csr_matrix((data, (rows, cols)), shape=(n_vertices, m), dtype=np.float32)


def vertex_normals(positions: np.ndarray, faces: np.ndarray,
                   operator: sp.csr_matrix | None = None) -> np.ndarray:
    """Area-weighted unit vertex normals.

    Parameters
    ----------
    positions : (N, 3) float
    faces : (M, 3) int, indices into positions
    operator : the :func:`normal_operator` of ``faces`` (pass it to avoid rebuilding)

    Returns
    -------
    (N, 3) float32; vertices on no face (or only degenerate ones) get (0, 0, 1).
    """
    p = np.asarray(positions, dtype=np.float32)
    if operator is None:
        operator = normal_operator(faces, len(p))
    a = p[faces[:, 0]]
    e1 = p[faces[:, 1]] - a
    e2 = p[faces[:, 2]] - a
    fn = np.empty_like(e1)
    fn[:, 0] = e1[:, 1] * e2[:, 2] - e1[:, 2] * e2[:, 1]
    fn[:, 1] = e1[:, 2] * e2[:, 0] - e1[:, 0] * e2[:, 2]
    fn[:, 2] = e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0]
    vn = operator @ fn
    length = np.sqrt(np.einsum("ij,ij->i", vn, vn))
    bad = length < 1e-20
    length[bad] = 1.0
    vn /= length[:, None]
    if bad.any():
        vn[bad] = (0.0, 0.0, 1.0)
    return vn.astype(np.float32, copy=False)


def region_components(topology: RenderTopology, region: str) -> list[np.ndarray]:
    """Geometry-vertex index arrays of the connected pieces of one region (e.g. each eyeball)."""
    from scipy.sparse.csgraph import connected_components

    faces = topology.geo_faces[topology.face_regions() == REGIONS.index(region)]
    if len(faces) == 0:
        return []
    verts, local = np.unique(faces, return_inverse=True)
    local = local.reshape(-1, 3)
    edges = np.concatenate([local[:, [0, 1]], local[:, [1, 2]], local[:, [2, 0]]])
    graph = sp.coo_matrix((np.ones(len(edges)), (edges[:, 0], edges[:, 1])),
                          shape=(len(verts), len(verts)))
    n, labels = connected_components(graph, directed=False)
    return [verts[labels == i] for i in range(n)]


def sphere_centre(points: np.ndarray) -> np.ndarray:
    """Least-squares centre of a sphere through ``points`` (N >= 4, not coplanar)."""
    p = np.asarray(points, dtype=float)
    a = np.c_[2.0 * p, np.ones(len(p))]
    b = np.einsum("ij,ij->i", p, p)
    sol, *_ = np.linalg.lstsq(a, b, rcond=None)
    return sol[:3]


def lash_coordinates(positions: np.ndarray, eyes: list[np.ndarray],
                     lashes: list[np.ndarray]) -> np.ndarray:
    """Root-to-tip coordinate (0 at the lid, 1 at the tip) of every lash vertex.

    Each lash piece is measured from the centre of the nearest eyeball (a sphere fitted to
    its vertices) and normalised over the piece.

    Returns
    -------
    (K,) float32 for ``np.concatenate(lashes)``; zeros when there are no eyeballs.
    """
    if not lashes:
        return np.zeros(0, dtype=np.float32)
    if not eyes:
        return np.zeros(sum(len(piece) for piece in lashes), dtype=np.float32)
    p = np.asarray(positions, dtype=np.float64)
    centres = np.array([sphere_centre(p[e]) if len(e) >= 4 else p[e].mean(0) for e in eyes])
    out = []
    for piece in lashes:
        q = p[piece]
        c = centres[np.argmin(np.linalg.norm(centres - q.mean(0), axis=1))]
        d = np.linalg.norm(q - c, axis=1)
        span = d.max() - d.min()
        out.append((d - d.min()) / span if span > 0 else np.zeros_like(d))
    return np.concatenate(out).astype(np.float32)


def crease_phase(positions: np.ndarray, uv: np.ndarray, faces: np.ndarray,
                 wrinkle: np.ndarray, operator: sp.csr_matrix | None = None) -> np.ndarray:
    """Where across a crease each vertex lies, so creases can run along the contours of
    ``wrinkle``: the distance (decimetres) from the UV centre along the direction in which
    the wrinkle changes most.

    Worked out in UV space, where the face is flat (a 3-D distance would bend the lines
    over the curved forehead): the direction is the principal axis of the area-weighted
    structure tensor of the wrinkle's UV gradient around each vertex (sign-free, so it
    holds on a crease's crest, where the gradient flips), and UV distance is converted to
    surface distance with the mesh's local UV metric. The origin is fixed, so the lines do
    not swim as the wrinkle grows.

    Parameters
    ----------
    positions : (R, 3) render-vertex positions
    uv : (R, 2) render-vertex UVs
    faces : (M, 3) render triangles
    wrinkle : (R,) render-vertex wrinkle
    operator : :func:`normal_operator` of ``faces`` (face -> vertex sums)

    Returns
    -------
    (R,) float32, unsigned; 0 where the wrinkle is 0 all around or the UVs are degenerate.
    """
    p = np.asarray(positions, dtype=np.float64)
    t = np.asarray(uv, dtype=np.float64)
    w = np.asarray(wrinkle, dtype=np.float64)
    faces = np.asarray(faces)
    phase = np.zeros(len(p), dtype=np.float32)
    live = np.flatnonzero((w[faces] > 0).any(axis=1))
    if len(live) == 0:
        return phase
    f = faces[live]
    du1, du2 = t[f[:, 1]] - t[f[:, 0]], t[f[:, 2]] - t[f[:, 0]]
    det = du1[:, 0] * du2[:, 1] - du2[:, 0] * du1[:, 1]
    ok = np.abs(det) > 1e-12
    f, du1, du2, det, live = f[ok], du1[ok], du2[ok], det[ok], live[ok]
    if len(f) == 0:
        return phase
    # Gradients per unit u and v: invert [[du1.u, du2.u], [du1.v, du2.v]] by hand (batched
    # einsum on 2x2s is slow): d/du = (e1 du2.v - e2 du1.v) / det,
    # d/dv = (e2 du1.u - e1 du2.u) / det.
    cu1, cv1 = du1[:, 0] / det, du1[:, 1] / det
    cu2, cv2 = du2[:, 0] / det, du2[:, 1] / det
    dw1, dw2 = w[f[:, 1]] - w[f[:, 0]], w[f[:, 2]] - w[f[:, 0]]
    g = np.stack([dw1 * cv2 - dw2 * cv1, dw2 * cu1 - dw1 * cu2], axis=1)   # dw/d(u, v)
    e1, e2 = p[f[:, 1]] - p[f[:, 0]], p[f[:, 2]] - p[f[:, 0]]
    ju = e1 * cv2[:, None] - e2 * cv1[:, None]                            # d(xyz)/du
    jv = e2 * cu1[:, None] - e1 * cu2[:, None]                            # d(xyz)/dv
    metric = np.stack([(ju * ju).sum(1), (jv * jv).sum(1), (ju * jv).sum(1)], axis=1)
    area = 0.5 * np.abs(det)                                      # UV area as the weight
    rows = np.zeros((len(faces), 7))
    rows[live] = area[:, None] * np.stack([
        g[:, 0] ** 2, g[:, 1] ** 2, g[:, 0] * g[:, 1],
        metric[:, 0], metric[:, 1], metric[:, 2], np.ones(len(f))], axis=1)
    if operator is None:
        operator = normal_operator(faces, len(p))
    acc = operator @ rows
    verts = np.flatnonzero(acc[:, 0] + acc[:, 1] > 0)
    a = acc[verts]
    angle = 0.5 * np.arctan2(2.0 * a[:, 2], a[:, 0] - a[:, 1])  # principal axis of [[a0 a2][a2 a1]]
    d = np.stack([np.cos(angle), np.sin(angle)], 1)
    g00, g11, g01 = a[:, 3] / a[:, 6], a[:, 4] / a[:, 6], a[:, 5] / a[:, 6]
    scale = np.sqrt(np.maximum(d[:, 0] ** 2 * g00 + 2 * d[:, 0] * d[:, 1] * g01
                               + d[:, 1] ** 2 * g11, 0.0))        # dm per UV unit along d
    phase[verts] = np.abs(((t[verts] - 0.5) * d).sum(axis=1)) * scale
    return phase


def write_png(path, image: np.ndarray) -> Path:
    """Write an (H, W, 3|4) uint8 image as PNG atomically (temp file, then ``os.replace``)."""
    from PIL import Image

    arr = np.asarray(image)
    if arr.dtype != np.uint8 or arr.ndim != 3 or arr.shape[2] not in (3, 4):
        raise ValueError(f"image must be (H, W, 3 or 4) uint8, got {arr.dtype} {arr.shape}")
    path = Path(path)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent or ".")
    try:
        with os.fdopen(fd, "wb") as fh:
            Image.fromarray(arr, "RGBA" if arr.shape[2] == 4 else "RGB").save(fh, format="PNG")
        os.replace(tmp, path)
    except BaseException:
        try:
            os.unlink(tmp)
        except OSError:
            pass
        raise
    return path


# --------------------------------------------------------------------------------------------
# OpenGL context and shaders
# --------------------------------------------------------------------------------------------

_CTX = None
_CTX_PID = None
_CTX_LOCK = threading.Lock()


def gl_context():
    """The process's shared moderngl context (EGL, GL >= 3.3), created on first use."""
    global _CTX, _CTX_PID
    with _CTX_LOCK:
        if _CTX is None or _CTX_PID != os.getpid():
            _CTX = _create_context()
            _CTX_PID = os.getpid()
        return _CTX


def _create_context():
    import moderngl

    errors = []
    for kwargs in ({"backend": "egl"}, {}):  # EGL: headless Linux; {}: the platform default
        try:
            return moderngl.create_context(standalone=True, require=330, **kwargs)
        except Exception as exc:  # moderngl raises bare Exception subclasses per backend
            errors.append(f"{kwargs.get('backend', 'default')}: {exc}")
    raise RenderError("could not create an OpenGL 3.3 context (" + "; ".join(errors) + "). On "
                      "Debian/Ubuntu install libegl1 libgl1 libgl1-mesa-dri for headless Mesa.")


def _shader_source(name: str, defines: dict[str, object]) -> str:
    text = (_SHADER_DIR / name).read_text()
    include = '#include "common.glsl"'
    if include in text:
        text = text.replace(include, (_SHADER_DIR / "common.glsl").read_text())
    head = ["#version 330 core"] + [f"#define {k} {v}".rstrip() for k, v in defines.items()]
    return "\n".join(head) + "\n#line 1\n" + text


def _set_uniform(program, name: str, value) -> None:
    """Set a uniform if the compiler kept it (moderngl raises KeyError for removed ones)."""
    try:
        uniform = program[name]
    except KeyError:
        return
    uniform.value = value


# --------------------------------------------------------------------------------------------
# Ambient occlusion baking
# --------------------------------------------------------------------------------------------

_DEPTH_VS = """
in vec3 in_pos;
uniform mat4 u_view_proj;
uniform vec3 u_dir;     // toward the viewer (the sky direction being tested)
out float v_depth;
void main() {
    v_depth = -dot(in_pos, u_dir);            // larger = farther from the viewer
    gl_Position = u_view_proj * vec4(in_pos, 1.0);
}
"""
_DEPTH_FS = """
in float v_depth;
out float f_depth;
void main() { f_depth = v_depth; }
"""


def sphere_directions(n: int) -> np.ndarray:
    """(n, 3) unit vectors spread evenly over the sphere (Fibonacci lattice)."""
    i = np.arange(n) + 0.5
    z = 1.0 - 2.0 * i / n
    phi = i * math.pi * (3.0 - math.sqrt(5.0))
    r = np.sqrt(1.0 - z * z)
    return np.stack([r * np.cos(phi), r * np.sin(phi), z], axis=1)


def bake_occlusion(topology: RenderTopology, positions: np.ndarray, *, directions: int = 96,
                   resolution: int = 384, bias: float = 0.004) -> np.ndarray:
    """Ambient visibility per geometry vertex, for ``Renderer.render(occlusion=...)``.

    For each of ``directions`` directions over the sphere the whole mesh is drawn as a
    depth map; a vertex counts as lit from a direction when nothing lies in front of it
    there. Visibility is averaged with cosine weights over the hemisphere around the vertex
    normal: 1 = open sky, 0 = fully enclosed. About 0.5-0.8 s for the head on llvmpipe:
    bake once on the neutral pose (sockets and creases change little with expression), or
    per frame where that matters.

    Parameters
    ----------
    topology : RenderTopology
    positions : (N_geo, 3) float
    directions : int
        Number of sample directions (more = smoother).
    resolution : int
        Depth-map size in pixels over the mesh's bounding sphere.
    bias : float
        Depth tolerance in world units (decimetres) against self-occlusion.

    Returns
    -------
    (N_geo,) float32 in [0, 1]; rows past ``topology.n_geo`` are 1.
    """
    p_all = np.asarray(positions, dtype=np.float32)
    n_geo = topology.n_geo
    if p_all.ndim != 2 or p_all.shape[1] != 3 or len(p_all) < n_geo:
        raise ValueError(f"positions must be (N_geo, 3) with N_geo >= {n_geo}, got {p_all.shape}")
    p = np.ascontiguousarray(p_all[:n_geo])
    faces = np.ascontiguousarray(topology.geo_faces.astype(np.uint32))
    normals = vertex_normals(p, faces.astype(np.int64))
    centre = 0.5 * (p.min(0) + p.max(0))
    radius = float(np.linalg.norm(p - centre, axis=1).max()) * 1.01 + 1e-6
    ctx = gl_context()
    objs = []
    try:
        prog = ctx.program(vertex_shader="#version 330 core\n" + _DEPTH_VS,
                           fragment_shader="#version 330 core\n" + _DEPTH_FS)
        objs.append(prog)
        vbo = ctx.buffer(p.tobytes()); objs.append(vbo)
        ibo = ctx.buffer(faces.tobytes()); objs.append(ibo)
        vao = ctx.vertex_array(prog, [(vbo, "3f", "in_pos")], index_buffer=ibo,
                               index_element_size=4)
        objs.append(vao)
        color = ctx.renderbuffer((resolution, resolution), 1, dtype="f4"); objs.append(color)
        depth = ctx.depth_renderbuffer((resolution, resolution)); objs.append(depth)
        fbo = ctx.framebuffer(color_attachments=[color], depth_attachment=depth); objs.append(fbo)
        fbo.use()
        ctx.enable_only(ctx.DEPTH_TEST)
        ctx.depth_func = "<"
        seen = np.zeros(n_geo)
        weight = np.zeros(n_geo)
        half = resolution / 2.0
        for d in sphere_directions(directions):
            helper = np.array([0.0, 1.0, 0.0]) if abs(d[1]) < 0.9 else np.array([1.0, 0.0, 0.0])
            right = np.cross(helper, d); right /= np.linalg.norm(right)
            up = np.cross(d, right)
            # Orthographic view along -d, covering the bounding sphere.
            rot = np.stack([right, up, d])
            view = np.eye(4); view[:3, :3] = rot; view[:3, 3] = -rot @ (centre + 2 * radius * d)
            proj = np.diag([1 / radius, 1 / radius, -1 / (2 * radius), 1.0])
            proj[2, 3] = -1.0  # camera-space z in [-4r, 0] -> NDC [1, -1]
            prog["u_view_proj"].write((proj @ view).T.astype(np.float32).tobytes())
            prog["u_dir"].value = tuple(float(x) for x in d)
            fbo.clear(1e9, 0.0, 0.0, 0.0, depth=1.0)
            vao.render(ctx.TRIANGLES)
            dmap = np.frombuffer(fbo.read(components=1, dtype="f4"), dtype=np.float32)
            dmap = dmap.reshape(resolution, resolution)
            rel = p - centre
            col = np.clip(((rel @ right) / radius + 1) * half - 0.5, 0, resolution - 1)
            row = np.clip(((rel @ up) / radius + 1) * half - 0.5, 0, resolution - 1)
            c0 = np.floor(col).astype(int); r0 = np.floor(row).astype(int)
            c1 = np.minimum(c0 + 1, resolution - 1); r1 = np.minimum(r0 + 1, resolution - 1)
            # The farthest of the 4 neighbouring texels: lenient at silhouettes and edges.
            front = np.maximum(np.maximum(dmap[r0, c0], dmap[r0, c1]),
                               np.maximum(dmap[r1, c0], dmap[r1, c1]))
            own = -(p @ d)
            w = np.clip(normals @ d, 0.0, None)
            seen += w * (own <= front + bias)
            weight += w
    finally:
        for obj in reversed(objs):
            obj.release()
    occ = np.ones(len(p_all), dtype=np.float32)
    occ[:n_geo] = np.where(weight > 0, seen / np.maximum(weight, 1e-12), 1.0)
    return occ


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
        Cavity darkening at ``wrinkle >= 1`` (0 = none, 1 = black).
    brow_uv_frame : (2, 2) array_like
        Maps skin UV to eyebrow-stroke space: row 0 gives the coordinate along the hairs
        (1 unit ~ one stroke length), row 1 across them (1 unit ~ one strand width). The
        default fits facsim's head (hm08 UVs normalised to its paint box); for other
        layouts see :func:`brow_uv_frame` and :data:`HM08_BROW_UV_FRAME`.
    cull_backfaces : bool
        Skip skin and eyeball triangles facing away (about 1.5x faster). Needs those
        surfaces closed (cap the neck); the winding is checked on the first frame and
        flipped if the mesh is wound clockwise. ``False`` draws everything two-sided.
    """

    def __init__(self, topology: RenderTopology, *, size=512, antialias: int = 4,
                 aa_method: str = "msaa", background=(0.5, 0.5, 0.5),
                 lighting: Lighting | None = None, wrinkle_depth: float = 0.012,
                 wrinkle_darken: float = 0.15, brow_uv_frame=DEFAULT_BROW_UV_FRAME,
                 cull_backfaces: bool = True):
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

        self.cull_backfaces = bool(cull_backfaces)

        # Static geometry: the normals operator on geometry vertices; triangles are drawn in
        # groups, one shader variant per group (see _PASSES), skin split by brow coverage.
        self._n_geo = topology.n_geo
        self._faces = topology.faces.copy()
        self._geo_faces = np.ascontiguousarray(topology.geo_faces)
        self._normal_op = normal_operator(self._geo_faces, self._n_geo)
        self._render_op = None  # face -> render vertex sums, built when wrinkles first come
        self._face_region = topology.face_regions()
        self._face_uv = topology.uv[topology.faces]             # (M, 3, 2) for brow coverage
        self._brow_faces = np.zeros(len(self._faces), dtype=bool)
        self._winding_checked = False
        self._draws: list[tuple[str, int, int]] = []
        # Per-frame vertex data: position (3), normal (3), wrinkle, occlusion, crease phase.
        self._geo_buffer = np.zeros((self._n_geo, 9), dtype=np.float32)
        self._render_buffer = np.zeros((topology.n_render, 9), dtype=np.float32)
        self._appearance = None
        self._eyes = region_components(topology, "eyeball")
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
        defines = dict.fromkeys(_PASSES[name], "")
        prog = self._track(ctx.program(
            vertex_shader=_shader_source("face.vert.glsl", defines),
            fragment_shader=_shader_source("face.frag.glsl", defines)))
        vao = self._track(ctx.vertex_array(
            prog, [(self._vbo_dynamic, "3f 3f 1f 1f 1f", "in_pos", "in_normal", "in_wrinkle",
                    "in_occlusion", "in_crease"),
                   (self._vbo_static, "2f 3f", "in_uv", "in_eye")],
            index_buffer=self._ibo, index_element_size=4, skip_errors=True))
        _set_uniform(prog, "u_paint", 0)
        _set_uniform(prog, "u_wrinkle_darken", self.wrinkle_darken)
        try:
            prog["u_brow_frame"].write(self.brow_uv_frame.T.astype(np.float32).tobytes())
        except KeyError:
            pass
        self._programs[name], self._vaos[name] = prog, vao
        if self._appearance is not None:
            self._set_colors(name, self._appearance)
        return prog, vao

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
            self._program(name)

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
        self._paint_tex = None
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
            self._scene_fbo = self._track(ctx.framebuffer(
                color_attachments=[self._scene_tex],
                depth_attachment=self._track(ctx.depth_renderbuffer((w * k, h * k)))))
            self._out_fbo = self._track(ctx.framebuffer(
                color_attachments=[self._track(ctx.renderbuffer((w, h), 4))]))
            defines = {"FACTOR": k}
            if self.background is None:
                defines["UNPREMULTIPLY"] = ""
            prog = self._track(ctx.program(
                vertex_shader=_shader_source("fullscreen.vert.glsl", {}),
                fragment_shader=_shader_source(f"{'fxaa' if self.aa_method == 'fxaa' else 'downsample'}.frag.glsl",
                                               defines)))
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
        self._appearance = appearance
        for name in self._programs:
            self._set_colors(name, appearance)
        brows = (np.zeros(len(self._faces), dtype=bool) if appearance.paint is None
                 else _faces_touching(self._face_uv, appearance.paint[..., 0] > 0))
        if not np.array_equal(brows, self._brow_faces):
            self._brow_faces = brows
            self._rebuild_draws()

    def _set_colors(self, name: str, appearance: Appearance) -> None:
        prog = self._programs[name]
        colors = appearance.colors
        lin = lambda key: tuple(float(x) for x in srgb_to_linear(colors[key]))  # noqa: E731
        if name.startswith("skin"):
            for key in ("skin", "lips", "brows", "eyelid", "cheek"):
                _set_uniform(prog, f"u_{key}", lin(key))
        elif name == "eyeball":
            for key in ("sclera", "iris", "pupil"):
                _set_uniform(prog, f"u_{key}", lin(key))
        else:
            _set_uniform(prog, "u_albedo", lin(_SINGLE_COLOR[name]))

    # -- per frame -----------------------------------------------------------------------
    def render(self, positions: np.ndarray, *, appearance: Appearance, camera: Camera,
               wrinkle: np.ndarray | None = None, occlusion: np.ndarray | None = None,
               lighting: Lighting | None = None) -> np.ndarray:
        """Render one frame.

        Parameters
        ----------
        positions : (N_geo, 3) float
            Geometry-vertex positions (N_geo >= ``topology.n_geo``; extra rows are unused).
        appearance : Appearance
        camera : Camera
        wrinkle : (N_geo,) float >= 0, optional
            Skin compression; creases and cavity darkening are drawn where it is > 0.
        occlusion : (N_geo,) float in [0, 1], optional
            Ambient visibility per geometry vertex (1 = open), e.g. from
            :func:`bake_occlusion` on the neutral pose; it darkens sockets and creases on
            skin, eyeballs and lashes, and dims teeth, tongue and mouth interior only down
            to a floor (55 / 45 / 35 %), so occlusion baked on a closed mouth still lets an
            open one show. Default: all 1.
        lighting : Lighting, optional
            Overrides the renderer's rig for this frame.

        Returns
        -------
        (H, W, 4) uint8 RGBA, top row first, display sRGB, straight alpha.
        """
        if self._closed:
            raise RenderError("this Renderer is closed")
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
        occ = _per_vertex("occlusion", occlusion, len(p_all), self._n_geo)
        if not self._winding_checked:
            self._fix_winding(p)
            self._rebuild_draws()
        self._update_vertices(p, w_geo, occ)
        if appearance is not self._appearance:
            self._upload_appearance(appearance)
        self._set_camera(camera, lighting or self.lighting)
        self._draw()
        return self._read()

    def _update_vertices(self, p: np.ndarray, wrinkle: np.ndarray | None,
                         occlusion: np.ndarray | None) -> None:
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
        out = self._render_buffer
        np.take(geo, self.topology.render_to_geo, axis=0, out=out)
        if wrinkle is not None and wrinkle.any():
            if self._render_op is None:
                self._render_op = normal_operator(self._faces, self.topology.n_render)
            out[:, 8] = crease_phase(out[:, 0:3], self.topology.uv, self._faces, out[:, 6],
                                     self._render_op)
        else:
            out[:, 8] = 0.0
        self._vbo_dynamic.write(out)

    def _set_camera(self, camera: Camera, lighting: Lighting) -> None:
        w, h = self.size
        vp = projection_matrix(camera, w / h) @ view_matrix(camera)
        vp_bytes = vp.T.astype(np.float32).tobytes()  # GLSL matrices are column-major
        lights = lighting.world_uniforms(camera)
        for prog in self._programs.values():
            try:
                prog["u_view_proj"].write(vp_bytes)
            except KeyError:
                pass
            for name, value in lights.items():
                _set_uniform(prog, name, value)

    def _draw(self) -> None:
        ctx = self._ctx
        fbo = self._scene_fbo
        fbo.use()
        ctx.enable_only(ctx.DEPTH_TEST)
        ctx.depth_func = "<"
        if self.background is None:
            fbo.clear(0.0, 0.0, 0.0, 0.0, depth=1.0)
        else:
            fbo.clear(*self.background, 1.0, depth=1.0)
        if self._paint_tex is not None:
            self._paint_tex.use(0)
        ctx.front_face = "ccw"
        for name, first, count in self._draws:
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
            self._vaos[name].render(ctx.TRIANGLES, vertices=3 * count, first=3 * first)
        fbo.depth_mask = True
        ctx.disable(ctx.BLEND | ctx.CULL_FACE)
        if self._downsample is not None:
            self._out_fbo.use()
            ctx.disable(ctx.DEPTH_TEST)
            self._scene_tex.use(0)
            self._downsample.render(ctx.TRIANGLES, vertices=3)
        elif self._out_fbo is not self._scene_fbo:
            ctx.copy_framebuffer(self._out_fbo, self._scene_fbo)

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


def _orientation(p: np.ndarray, faces: np.ndarray) -> float:
    """> 0 when the triangles' winding normals point away from their centroid (outward)."""
    a, b, c = p[faces[:, 0]], p[faces[:, 1]], p[faces[:, 2]]
    normals = np.cross(b - a, c - a)
    centres = (a + b + c) / 3.0
    area = np.linalg.norm(normals, axis=1)
    centroid = (centres * area[:, None]).sum(0) / max(area.sum(), 1e-30)
    return float(np.einsum("ij,ij->", centres - centroid, normals))


def _faces_touching(face_uv: np.ndarray, mask: np.ndarray) -> np.ndarray:
    """(M,) whether each triangle's UV bounding box covers any set texel of ``mask``.

    ``mask`` is (H, W) in GL row order (row 0 = v = 0); a summed-area table answers each
    box in four look-ups. Conservative: a box may hold set texels the triangle misses.
    """
    h, w = mask.shape
    sat = np.zeros((h + 1, w + 1), dtype=np.int64)
    sat[1:, 1:] = np.cumsum(np.cumsum(mask, axis=0), axis=1)
    lo = face_uv.min(axis=1)
    hi = face_uv.max(axis=1)
    c0 = np.clip(np.floor(lo[:, 0] * w).astype(np.int64) - 1, 0, w)
    c1 = np.clip(np.ceil(hi[:, 0] * w).astype(np.int64) + 1, 0, w)
    r0 = np.clip(np.floor(lo[:, 1] * h).astype(np.int64) - 1, 0, h)
    r1 = np.clip(np.ceil(hi[:, 1] * h).astype(np.int64) + 1, 0, h)
    count = sat[r1, c1] - sat[r0, c1] - sat[r1, c0] + sat[r0, c0]
    return count > 0


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
