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
from facsim.render.gl import _set_uniform, _shader_source, compile_program
from facsim.render.inputs import srgb_to_linear

PROXY_KINDS = ("hair", "eyebrows", "eyelashes", "scalp", "wisps")
#: Proxy kinds shaded with the key light's cast shadow (the hair's mass shadows itself, and
#: the head and the cards above shadow the scalp's fine hair). Brows, lashes and loose strands
#: are finer than the shadow map's texels.
SHADOW_RECEIVERS = ("hair", "scalp")
#: Alpha at and above which a fragment belongs to the opaque (alpha-tested) pass.
ALPHA_CUTOFF = 0.5


@dataclass(frozen=True, eq=False)
class ProxyMesh:
    """A proxy's static mesh, uploaded once per renderer.

    Parameters
    ----------
    name : str
    kind : {"hair", "eyebrows", "eyelashes", "scalp"}
        ``"scalp"``: the fine hair on the skin under a hairstyle (facsim.head.scalp), drawn
        blended before every card, its texture a tile repeated along the strands.
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
        Hair: 0 under the other layers … 1 in the open, for self-shadowing (default 1).
        Scalp: the hair's density on the skin (0 bare … 1 full cover).
    rest : (V, 3) float, optional
        Hair: vertex positions at rest (the neutral face). Which cards neighbour which is
        read from them once, so a frame's shading never depends on the frames before it.
        Without them strand directions are not averaged across cards. A close crop's or coily
        hair's scalp layer: where its coils lie (they move with the skin).
    cover : (V,) float, optional
        Hair: the scalp's hair density under each vertex (1 full … 0 bare; default 1).
        Cards over a thinning hairline break up into strands, so they fade into the scalp
        layer's fine hairs instead of ending in a cut edge.
    coily : bool
        Hair and scalp: drawn with the coily-hair shader variant (curls instead of strands;
        :attr:`ProxyDraw.coil` sets how strongly).
    strand_points, strand_width : int, float
        ``"wisps"``: loose strands (facsim.head.wisps), ``strand_points`` points each, laid
        out strand by strand, root first, two corners per point (u 0 and 1 across); drawn
        as ribbons ``strand_width`` dm wide at the root (at least a pixel, fainter where
        widened) turned toward the camera, tapering to the tip. ``depth``: 0 at the root …
        1 at the tip.
    crop : bool
        Scalp: the hair itself, a close crop with no cards over it (``crops:`` in
        ``facsim/data/hair.yaml``): lit in the open and covering the skin fully inside its hairline.
    end_height : float, optional
        Hair and wisps: the height (y on the neutral face, dm) where the hair ends. MakeHuman's
        long styles hang on through where the shoulders are; below ``END_FADE`` over this
        height their strands end one by one at different lengths, tapering, instead of being
        cut by the shoulders or the image's edge. None: the hair is drawn to its cards' ends.
    hairline : (V,) float, optional
        A crop's scalp layer: each vertex's distance inside the crop's hairline in widths of the
        band over which its hair thins (facsim.head.scalp.crop_hairline; linear across the
        skin's triangles): the shader thins the hair over 0 … 1 per pixel, so the hairline is a
        smooth, soft curve however coarse the triangles. Other scalp layers: the height above
        the hairline in those widths (facsim.head.scalp.ScalpLayer.hairline): the hairs near it
        are lit in the open.
    """

    name: str
    kind: str
    triangles: np.ndarray
    corner_vertex: np.ndarray
    uv: np.ndarray
    texture: np.ndarray
    depth: np.ndarray | None = None
    rest: np.ndarray | None = None
    cover: np.ndarray | None = None
    coily: bool = False
    strand_points: int = 0
    strand_width: float = 0.0
    end_height: float | None = None
    crop: bool = False
    hairline: np.ndarray | None = None

    def __post_init__(self):
        if self.kind not in PROXY_KINDS:
            raise ValueError(f"proxy kind must be one of {PROXY_KINDS}, got {self.kind!r}")
        tex = np.asarray(self.texture)
        if tex.ndim != 3 or tex.shape[2] != 4 or tex.dtype != np.uint8:
            raise ValueError(f"proxy texture must be (H, W, 4) uint8, got {tex.dtype} {tex.shape}")
        if len(self.uv) != len(self.corner_vertex):
            raise ValueError("proxy uv and corner_vertex must have one row per corner")
        if self.kind == "wisps" and (self.strand_points < 2 or self.vertex_count % self.strand_points
                                     or not self.strand_width > 0):
            raise ValueError(f"wisps need strand_points >= 2 dividing their {self.vertex_count} points and a "
                             f"strand_width > 0, got {self.strand_points} and {self.strand_width}")

    @property
    def vertex_count(self) -> int:
        return int(np.max(self.corner_vertex)) + 1


@dataclass(frozen=True, eq=False)
class ProxyDraw:
    """One proxy in one frame: its mesh, vertex positions (V, 3), sRGB colour, sheen
    (strength of the strand highlights: 1 for straight hair, less for coily hair),
    density (brows and lashes: how much of the skin their hairs cover, 0 … 1) and coil
    (hair: 0 straight … 1 coily, which shows fine even curls instead of strands and clumps),
    and for greying hair its strands' two colours and the fraction of white ones."""

    mesh: ProxyMesh
    positions: np.ndarray
    color: tuple[float, float, float]
    sheen: float = 1.0
    density: float = 1.0
    coil: float = 0.0
    #: Greying hair (hair and scalp): the sRGB colours of its pigmented and white strands and
    #: the fraction of white ones; ``color`` is their mean. Drawn strand by strand (salt and
    #: pepper) where strands are resolved, as their mean where they are finer than a pixel.
    pigment: tuple[float, float, float] | None = None
    white: tuple[float, float, float] | None = None
    grey: float = 0.0


def shade_texture(texture: np.ndarray, *, directions: bool = False, strands_only: bool = False) -> np.ndarray:
    """RGBA for upload: R = brightness relative to the mean strand (0.5 = mean), GB = the
    strands' direction in UV (:func:`strand_directions`, as 0.5 + 0.5 (u, v); with
    ``directions=False``, along v everywhere), A kept.

    MakeHuman's hair textures are near-black strands; the colour comes from the character,
    so only the relative brightness (strand-to-strand variation) is kept. Rows are flipped
    to GL order (row 0 = v = 0).

    ``strands_only`` keeps only the strand- and clump-scale variation: the textures also
    carry painted light (a highlight arc near the roots, tips darker than roots), which on
    overlapping cards stacks into bands that change from card to card (the "helmet of
    cards" look). Dividing by the alpha-weighted local mean removes it; the shader lights
    the hair as one volume instead. For textures whose strands run along v the mean is taken
    across the strands (wide in u, short in v), so clumps side by side survive.
    """
    rgb = texture[..., :3].astype(np.float32)
    alpha = texture[..., 3]
    lum = rgb @ np.array([0.2126, 0.7152, 0.0722], np.float32)
    solid = alpha > 128
    half = None
    if directions:  # the field is smooth: found at half resolution (4x cheaper), then repeated
        half = strand_directions(lum[::-1][::2, ::2], sigma=3.0)
    if strands_only:
        lum = strand_detail(lum, alpha, along_v=half is None or _runs_along_v(half, solid[::-1][::2, ::2]))
        mean = float(lum[solid].mean()) if solid.any() else float(lum.mean())
        rel = np.clip(lum / max(mean, 1e-3), 0.3, 1.7) * 0.5
    else:
        mean = float(lum[solid].mean()) if solid.any() else float(lum.mean())
        rel = np.clip(lum / max(mean, 1.0), 0.4, 1.6) * 0.5
    # Transparent texels' colour is arbitrary (often white): toward the edge of the strands,
    # fade to the mean, so filtering never draws light outlines around the cards.
    rel = 0.5 + (rel - 0.5) * (alpha.astype(np.float32) / 255.0)
    out = np.empty(texture.shape, np.uint8)
    out[..., 0] = np.clip(rel * 255 + 0.5, 0, 255).astype(np.uint8)
    if half is not None:
        direction = np.repeat(np.repeat(half, 2, axis=0), 2, axis=1)[: lum.shape[0], : lum.shape[1]][::-1]
    else:
        direction = np.broadcast_to(np.array([0.0, 1.0], np.float32), (*lum.shape, 2))
    out[..., 1:3] = np.clip((0.5 + 0.5 * direction) * 255 + 0.5, 0, 255).astype(np.uint8)
    out[..., 3] = alpha
    return np.ascontiguousarray(out[::-1])


def _runs_along_v(direction: np.ndarray, solid: np.ndarray) -> bool:
    """Whether most solid texels' strands run along v (|dv| > 0.9)."""
    dv = np.abs(direction[..., 1][solid]) if solid.any() else np.ones(1)
    return bool(np.median(dv) >= 0.9)


def strand_detail(luminance: np.ndarray, alpha: np.ndarray, *, along_v: bool = True) -> np.ndarray:
    """Luminance (H, W) divided by its alpha-weighted local mean: strand- and clump-scale
    variation around 1 with the painted low-frequency light removed (see :func:`shade_texture`).

    The local mean is wide across the strands and short along them when they run along v
    (image rows are v), round otherwise (coily hair, a ponytail's radiating crown).
    """
    from scipy.ndimage import gaussian_filter

    w = alpha.astype(np.float32) / 255.0
    sigma = (3.0, 14.0) if along_v else (7.0, 7.0)  # (rows = v, columns = u), texels
    num = gaussian_filter(np.asarray(luminance, np.float32) * w, sigma, mode="nearest")
    den = gaussian_filter(w, sigma, mode="nearest")
    local = num / np.maximum(den, 1e-3)
    # Near-black texels (the darkest strands of a black texture) keep a floor, so dividing
    # does not blow noise up into speckle.
    return np.asarray(luminance, np.float32) / np.maximum(local, 0.02 * float(luminance.max()) + 1.0)


def strand_directions(luminance: np.ndarray, *, sigma: float = 6.0) -> np.ndarray:
    """(H, W, 2) unit strand direction (du, dv) per texel of a GL-order (row 0 = v = 0)
    luminance image, from its structure tensor: strands run across the brightness gradient.

    Hair textures do not all run along v (a ponytail's cap radiates from the crown), so the
    strand shading reads the direction from the texture itself. Signs are chosen with
    dv >= 0; where the texture has no clear direction, strands run along v.
    """
    from scipy.ndimage import gaussian_filter, sobel

    lum = np.asarray(luminance, np.float32)
    gu, gv = sobel(lum, axis=1), sobel(lum, axis=0)
    juu, jvv, juv = (gaussian_filter(a, sigma) for a in (gu * gu, gv * gv, gu * gv))
    # The gradient's mean orientation (doubled angle); strands run perpendicular to it.
    c2, s2 = juu - jvv, 2.0 * juv
    strength = np.hypot(c2, s2)
    coherent = strength > 0.2 * (juu + jvv) + 1e-6
    theta = 0.5 * np.arctan2(s2, c2) + 0.5 * np.pi
    d = np.stack([np.cos(theta), np.sin(theta)], axis=-1)
    d[~coherent] = (0.0, 1.0)
    d[d[..., 1] < 0] *= -1
    return d.astype(np.float32)


def triangle_strand_directions(mesh: "ProxyMesh", shaded: np.ndarray) -> np.ndarray:
    """(T, 2) strand direction in UV at each triangle's UV centroid (``shaded``: the
    :func:`shade_texture` output, GL row order)."""
    h, w = shaded.shape[:2]
    uv = mesh.uv[mesh.triangles].mean(axis=1)
    col = np.clip((uv[:, 0] * w).astype(np.int64), 0, w - 1)
    row = np.clip((uv[:, 1] * h).astype(np.int64), 0, h - 1)
    d = shaded[row, col, 1:3].astype(np.float32) / 127.5 - 1.0
    return d / (np.linalg.norm(d, axis=1, keepdims=True) + 1e-12)


#: Height (dm) over which long hair's strands end (:attr:`ProxyMesh.end_height`).
END_FADE = 0.6

#: Radius (dm) of the rounded top of the hair volume (about a head's half width).
VOLUME_RADIUS = 0.9


def volume_normals(points: np.ndarray, card_normals: np.ndarray, *, card_weight: float = 0.3) -> np.ndarray:
    """Hair normals from the volume, not the cards: mostly the direction out from the
    hair's volume, a little of each card's own (turned outward), so a hairstyle is shaded as
    one smooth mass instead of a patchwork of flat cards.

    The volume is a capsule: a dome of :data:`VOLUME_RADIUS` under the crown and a vertical
    axis below it, so hair hanging past the jaw faces sideways and back like a sheet, not
    down like the bottom of a ball. The axis comes from the crown (the highest tenth of the
    points) alone: cards bound to moving skin (sideburns over a smiling cheek) never move it,
    so still cards keep their shading exactly (the renderer keeps still hair as pixels
    between the frames of a video).
    """
    axis, top = _crown_axis(points)
    q = np.empty_like(points)
    q[:, 0], q[:, 2] = axis[0], axis[2]
    q[:, 1] = np.minimum(points[:, 1], top - VOLUME_RADIUS)
    out = points - q
    out /= np.linalg.norm(out, axis=1, keepdims=True) + 1e-12
    card = np.where((np.einsum("ij,ij->i", card_normals, out) < 0)[:, None], -card_normals, card_normals)
    n = (1.0 - card_weight) * out + card_weight * card
    return (n / (np.linalg.norm(n, axis=1, keepdims=True) + 1e-12)).astype(np.float32)


def hair_apex(points: np.ndarray) -> np.ndarray:
    """(3,) a point a quarter of :data:`VOLUME_RADIUS` above the crown of hair ``points``
    (N, 3), on the axis of :func:`volume_normals`' volume: strands flow down and out from it
    over the volume's surface (the shader's strand highlight follows that flow)."""
    axis, top = _crown_axis(points)
    return np.array([axis[0], top + 0.25 * VOLUME_RADIUS, axis[2]], np.float32)


def _crown_axis(points: np.ndarray) -> tuple[np.ndarray, float]:
    """The hair volume's axis, the mean of the crown's points (the highest tenth of ``points``
    (N, 3); only its x and z matter), and the crown's height."""
    y = points[:, 1]
    return points[y >= np.percentile(y, 90)].mean(axis=0), float(y.max())


def along_volume(tangents: np.ndarray, normals: np.ndarray) -> np.ndarray:
    """Unit strand directions (N, 3) laid into the hair volume's surface (``normals`` (N, 3):
    :func:`volume_normals` with no card weight): each card keeps its strands' direction
    along the surface, but not its tilt out of it.

    Cards overlap like shingles, each tilted out of the volume's surface by its own
    amount: a strand highlight computed with the tilted directions lands at the same place
    on every card of a row, so long01's crown showed rows of bright bands, one per row of
    cards. Laid into the surface, the directions of neighbouring rows agree and the
    highlight runs across the hair as one band. Strands that run mostly out of the surface
    (under-layers curling in toward the face) keep their own direction: laid into the
    surface, what is left of them points anywhere.
    """
    from facsim.head.surface import smoothstep

    t = np.asarray(tangents, np.float32)
    laid = t - np.einsum("ij,ij->i", t, normals)[:, None] * normals
    length = np.linalg.norm(laid, axis=1, keepdims=True)
    w = smoothstep(0.5, 0.8, length).astype(np.float32)
    out = w * laid / (length + 1e-12) + (1.0 - w) * t
    return (out / (np.linalg.norm(out, axis=1, keepdims=True) + 1e-12)).astype(np.float32)


def strand_tangents(positions: np.ndarray, mesh: ProxyMesh, operator=None, directions=None) -> np.ndarray:
    """Unit strand direction per corner, averaged over the corner's triangles.

    ``directions`` (T, 2) gives each triangle's strand direction in UV
    (:func:`triangle_strand_directions`); by default strands run along v (dP/dv).
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
    # dP/dv = (-d2.u * e1 + d1.u * e2) / det, dP/du = (d2.v * e1 - d1.v * e2) / det
    tv = (-d2[:, :1] * e1 + d1[:, :1] * e2) / det[:, None]
    if directions is not None:
        tu = (d2[:, 1:] * e1 - d1[:, 1:] * e2) / det[:, None]
        tv = directions[:, :1] * tu + directions[:, 1:] * tv
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


def card_outline(triangles: np.ndarray) -> np.ndarray:
    """(V,) float32: 1 at vertices on the outline of a card (an edge with one triangle), else 0.

    ``triangles`` (T, 3) index proxy vertices (not render corners), so UV seams inside a
    card do not count as outline.
    """
    t = np.asarray(triangles, np.int64)
    n = int(t.max()) + 1 if len(t) else 0
    edges = np.sort(np.concatenate([t[:, [0, 1]], t[:, [1, 2]], t[:, [2, 0]]]), axis=1)
    unique, count = np.unique(edges, axis=0, return_counts=True)
    out = np.zeros(n, np.float32)
    out[unique[count == 1].ravel()] = 1.0
    # Cards of one or two quads (afro01's tufts) are all outline: fraying them would erase
    # them, and their texture already draws loose strands. Only cards with an inside fray.
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    _, card = connected_components(coo_matrix((np.ones(len(edges)), (edges[:, 0], edges[:, 1])), shape=(n, n)),
                                   directed=False)
    inside = np.bincount(card, weights=1.0 - out, minlength=card.max() + 1) > 0
    out[~inside[card]] = 0.0
    return out


#: Radius (dm) over which hair strand directions are averaged across cards.
STRAND_SMOOTHING = 0.15


def neighbour_mean_operator(points: np.ndarray, radius: float):
    """Sparse (P, P) matrix averaging each point's rows over the points within ``radius``
    (Gaussian weights, sigma = radius / 2). Built once per hair layer: hair moves rigidly
    with the head, so who neighbours whom does not change."""
    from scipy.sparse import csr_matrix
    from scipy.spatial import cKDTree

    pairs = cKDTree(points).query_pairs(radius, output_type="ndarray")
    i = np.concatenate([pairs[:, 0], pairs[:, 1], np.arange(len(points))])
    j = np.concatenate([pairs[:, 1], pairs[:, 0], np.arange(len(points))])
    d2 = np.sum((points[i] - points[j]) ** 2, axis=1)
    w = np.exp(-d2 / (2.0 * (0.5 * radius) ** 2)).astype(np.float32)
    m = csr_matrix((w, (i, j)), shape=(len(points), len(points)))
    return csr_matrix(m.multiply(1.0 / np.asarray(m.sum(axis=1))))


def _weld_operator(corner_vertex: np.ndarray):
    """Sparse (V, R) matrix summing corners onto their proxy vertex; None if no vertex is split."""
    from scipy.sparse import csr_matrix

    corner_vertex = np.asarray(corner_vertex, np.int64)
    n_vertices = int(corner_vertex.max()) + 1 if len(corner_vertex) else 0
    if n_vertices == len(corner_vertex):
        return None
    ones = np.ones(len(corner_vertex), np.float32)
    return csr_matrix((ones, (corner_vertex, np.arange(len(corner_vertex)))), shape=(n_vertices, len(corner_vertex)))


class ProxyLayer:
    """GL objects for one :class:`ProxyMesh` (owned and released by a Renderer)."""

    def __init__(self, ctx, mesh: ProxyMesh, track, *, shadow_units: tuple[int, int] | None = None):
        self.ctx = ctx
        self.mesh = mesh
        # Hair and the scalp's hair receive the key light's cast shadow (facsim.render.shadows)
        # when given the texture units of its depth and caster opacity.
        self.receives_shadow = shadow_units is not None and mesh.kind in SHADOW_RECEIVERS
        self._triangles = np.ascontiguousarray(mesh.triangles, np.uint32)
        self._n_corners = len(mesh.corner_vertex)
        self._normal_op = normal_operator(self._triangles, self._n_corners)
        # Corners of one proxy vertex (split by a UV seam, e.g. a hair cap's parting) get the
        # vertex's mean normal, so the shading does not step along the seam.
        self._weld = _weld_operator(mesh.corner_vertex)
        depth = np.ones(mesh.vertex_count, np.float32) if mesh.depth is None else np.asarray(mesh.depth, np.float32)
        self._depth = depth[mesh.corner_vertex]
        self._buffer = np.zeros((self._n_corners, 11), np.float32)  # pos, normal, tangent, depth, edge
        # Hair: 1 on a card's outline, 0 inside (the shader frays the cards' edges into strands).
        self._buffer[:, 10] = (card_outline(np.asarray(mesh.corner_vertex)[self._triangles])[mesh.corner_vertex]
                               if mesh.kind == "hair" else 0.0)
        if mesh.kind == "wisps":  # which side of the strand's ribbon (-1, 1): the shader widens it
            self._buffer[:, 10] = 2.0 * np.asarray(mesh.uv, np.float32)[:, 0] - 1.0
        self._vbo = track(ctx.buffer(reserve=self._buffer.nbytes, dynamic=True))
        cover = np.ones(mesh.vertex_count, np.float32) if mesh.cover is None else np.asarray(mesh.cover, np.float32)
        if mesh.hairline is not None:  # (the scalp layer has no cards to cover: the slot carries its hairline)
            cover = np.asarray(mesh.hairline, np.float32)
        # Where each corner was on the neutral face: coily hair's curls are placed in this space
        # (isotropic, so any orientation will do), running on across the cards' edges and the
        # texture's mirrored layout, and moving with the hair.
        rest = (np.zeros((mesh.vertex_count, 3), np.float32) if mesh.rest is None
                else np.asarray(mesh.rest, np.float32))
        # Two orders of the same triangles: front to back for the alpha-tested pass (hidden
        # layers then fail the depth test before they are shaded), back to front for blending.
        self._ibo = {"OPAQUE": track(ctx.buffer(self._triangles.tobytes(), dynamic=True)),
                     "BLEND": track(ctx.buffer(self._triangles.tobytes(), dynamic=True))}
        if mesh.kind in ("scalp", "wisps"):  # made for the renderer already (facsim.head.scalp, .wisps)
            tex = np.ascontiguousarray(np.asarray(mesh.texture)[::-1])
        else:
            tex = shade_texture(np.asarray(mesh.texture), directions=mesh.kind == "hair",
                                strands_only=mesh.kind == "hair")
        # Strand direction in UV: most styles' textures run along v throughout (their
        # root bands' cross-wise features would only mislead the texture's own direction
        # field); where they do not (a ponytail's radiating crown), the field steers the
        # strand tangents and the shader's strand breakup.
        self._along_v = 1.0
        self._directions = None
        if mesh.kind == "hair":
            solid = tex[..., 3] > 128
            along = np.abs(tex[..., 2][solid].astype(np.float32) / 127.5 - 1.0) if solid.any() else np.ones(1)
            if np.median(along) < 0.9:
                self._along_v = 0.0
                self._directions = triangle_strand_directions(mesh, tex)
        self._smooth = None  # hair: neighbour-averaging operator over corners (from mesh.rest)
        # Hair: the strands' direction there (as drawn on the neutral face), along which the
        # shader's strand breakup is stretched (placed on the neutral face, it moves with the hair).
        rest_tangents = np.zeros((self._n_corners, 3), np.float32)
        if mesh.kind == "hair" and mesh.rest is not None:
            rest_tangents = self._strand_tangents(np.asarray(mesh.rest, np.float32))
        # (the apex the strands flow from on the neutral face: the shader's strand streaks run from it)
        self._apex_rest = (tuple(float(x) for x in hair_apex(rest)) if mesh.kind == "hair" and mesh.rest is not None
                           else (0.0, 0.0, 0.0))
        static = np.column_stack([np.asarray(mesh.uv, np.float32), cover[mesh.corner_vertex],
                                  rest[mesh.corner_vertex], rest_tangents])
        self._uv = track(ctx.buffer(np.ascontiguousarray(static, np.float32).tobytes()))
        self.texture = track(ctx.texture((tex.shape[1], tex.shape[0]), 4, tex.tobytes()))
        self.texture.build_mipmaps()  # an input texture, never rendered into
        self.texture.filter = (ctx.LINEAR_MIPMAP_LINEAR, ctx.LINEAR)
        self.texture.repeat_x = self.texture.repeat_y = mesh.kind == "scalp"
        # The scalp layer lies on the skin, under every card: blended only, back faces culled.
        self.has_opaque_pass = mesh.kind not in ("scalp", "wisps")
        self.culled = mesh.kind == "scalp"
        self.programs, self.vaos = {}, {}
        self._last = None  # (camera position, vertex positions) of the last upload
        self.look: tuple = ()  # (linear colour, sheen, density, coil) of this frame
        self._camera_uniforms: tuple = ()  # (view-projection, lights) the programs hold
        self._vertex_triangles = np.asarray(mesh.corner_vertex)[self._triangles]  # ... over vertices
        self._order = np.arange(len(self._triangles))  # back to front, as last sorted
        # A subset of the triangles (front to back) for callers that keep part of the pass as pixels.
        self._ibo["SUBSET"] = track(ctx.buffer(reserve=max(self._triangles.nbytes, 12), dynamic=True))
        for stage in ("OPAQUE", "BLEND"):
            defines = {f"PASS_{stage}": "", f"KIND_{mesh.kind.upper()}": "", "ALPHA_CUTOFF": f"{ALPHA_CUTOFF:.3f}",
                       **({"COILY": ""} if mesh.coily else {}), **({"CROP": ""} if mesh.crop else {}),
                       **({"USE_SHADOW": ""} if self.receives_shadow else {})}
            prog = track(compile_program(ctx, _shader_source("proxy.vert.glsl", defines),
                                         _shader_source("proxy.frag.glsl", defines)))
            _set_uniform(prog, "u_texture", 1)
            _set_uniform(prog, "u_along_v", self._along_v)
            _set_uniform(prog, "u_hair_apex_rest", self._apex_rest)
            _set_uniform(prog, "u_strand_width", float(mesh.strand_width))
            _set_uniform(prog, "u_end_height", -1e3 if mesh.end_height is None else float(mesh.end_height))
            _set_uniform(prog, "u_end_fade", END_FADE)
            if self.receives_shadow:
                _set_uniform(prog, "u_shadow", shadow_units[0])
                _set_uniform(prog, "u_shadow_opacity", shadow_units[1])
            self.programs[stage] = prog
            self.vaos[stage] = track(ctx.vertex_array(
                prog, [(self._vbo, "3f 3f 3f 1f 1f", "in_pos", "in_normal", "in_tangent", "in_depth", "in_edge"),
                       (self._uv, "2f 1f 3f 3f", "in_uv", "in_cover", "in_rest", "in_rest_tangent")],
                index_buffer=self._ibo[stage], index_element_size=4, skip_errors=True))
        self.vaos["SUBSET"] = track(ctx.vertex_array(
            self.programs["OPAQUE"], [(self._vbo, "3f 3f 3f 1f 1f", "in_pos", "in_normal", "in_tangent", "in_depth", "in_edge"),
                                      (self._uv, "2f 1f 3f 3f", "in_uv", "in_cover", "in_rest", "in_rest_tangent")],
            index_buffer=self._ibo["SUBSET"], index_element_size=4, skip_errors=True))

    def update(self, draw: ProxyDraw, camera_position: np.ndarray) -> None:
        """Upload this frame's vertices, sorting triangles back to front for the blended pass."""
        positions = np.asarray(draw.positions, np.float32)
        if positions.shape != (self.mesh.vertex_count, 3) or not np.isfinite(positions).all():
            raise ValueError(f"proxy {self.mesh.name!r} positions must be finite ({self.mesh.vertex_count}, 3), "
                             f"got {positions.shape}")
        camera_position = np.asarray(camera_position, np.float32)
        color = tuple(float(x) for x in srgb_to_linear(draw.color))
        grey = float(draw.grey) if draw.pigment is not None and draw.white is not None else 0.0
        pigment = tuple(float(x) for x in srgb_to_linear(draw.pigment)) if grey > 0 else color
        white = tuple(float(x) for x in srgb_to_linear(draw.white)) if grey > 0 else color
        look = (color, float(draw.sheen), float(draw.density), float(draw.coil), pigment, white, grey)
        if self.look != look:
            self.look = look
            for prog in self.programs.values():
                _set_uniform(prog, "u_color", color)
                _set_uniform(prog, "u_sheen", look[1])
                _set_uniform(prog, "u_density", look[2])
                _set_uniform(prog, "u_coil", look[3])
                _set_uniform(prog, "u_pigment", pigment)
                _set_uniform(prog, "u_white", white)
                _set_uniform(prog, "u_grey", grey)
        # Hair mostly sits still (only 51-58 and the brow skin move it): skip the upload and
        # the sort when nothing moved since the last frame.
        if (self._last is not None and np.array_equal(self._last[0], camera_position)
                and np.array_equal(self._last[1], positions)):
            return
        self._last = (camera_position.copy(), positions.copy())
        if self.mesh.kind in ("hair", "wisps"):   # (wisps: coily hair's outline, proxy.frag.glsl)
            apex = tuple(float(x) for x in hair_apex(positions))
            for prog in self.programs.values():
                _set_uniform(prog, "u_hair_apex", apex)
        p = positions[self.mesh.corner_vertex]
        buf = self._buffer
        buf[:, 0:3] = p
        # Normals on welded vertices would mix the two sides of a card; corners are fine here.
        if self.mesh.kind == "wisps":
            # Loose strands: the volume's normal (no surface of their own) and the direction
            # along each strand.
            buf[:, 3:6] = volume_normals(p, np.zeros_like(p), card_weight=0.0)
            along = np.gradient(positions.reshape(-1, self.mesh.strand_points, 3), axis=1).reshape(-1, 3)
            along /= np.linalg.norm(along, axis=1, keepdims=True) + 1e-12
            tangents = along[self.mesh.corner_vertex]
        else:
            normals = vertex_normals(p, self._triangles, self._normal_op)
            if self.mesh.kind == "hair":
                normals = volume_normals(p, normals)
            buf[:, 3:6] = self._welded(normals)
            tangents = (self._strand_tangents(positions, normals) if self.mesh.kind == "hair"
                        else strand_tangents(positions, self.mesh, self._normal_op, self._directions))
        buf[:, 6:9] = tangents
        buf[:, 9] = self._depth
        self._vbo.write(buf)
        centres = p[self._triangles].mean(axis=1) - np.asarray(camera_position, np.float32)
        order = np.argsort(-np.einsum("ij,ij->i", centres, centres), kind="stable")
        self._ibo["BLEND"].write(self._triangles[order].tobytes())
        self._ibo["OPAQUE"].write(self._triangles[order[::-1]].tobytes())
        self._order = order

    def _strand_tangents(self, positions: np.ndarray, normals: np.ndarray | None = None) -> np.ndarray:
        """(corners, 3) hair strand directions for vertex ``positions`` (``normals``: the corners'
        volume normals, found when not given)."""
        p = positions[self.mesh.corner_vertex]
        if normals is None:
            normals = volume_normals(p, vertex_normals(p, self._triangles, self._normal_op))
        # Tangents stay per corner: strands really do flow apart on the two sides of a parting.
        tangents = strand_tangents(positions, self.mesh, self._normal_op, self._directions)
        if self.mesh.rest is not None:
            # Neighbouring cards' strands run the same way: averaged over the cards within a
            # centimetre or two, the highlight runs on across the cards instead of lighting
            # some and not their neighbours (a patchwork on the crown).
            if self._smooth is None:
                rest = np.asarray(self.mesh.rest, np.float32)[self.mesh.corner_vertex]
                self._smooth = neighbour_mean_operator(rest, STRAND_SMOOTHING)
            tangents = np.asarray(self._smooth @ tangents, np.float32)
        return along_volume(tangents, volume_normals(p, normals, card_weight=0.0))

    @property
    def positions(self) -> np.ndarray | None:
        """The vertex positions drawn (as last uploaded; replaced, never changed in place)."""
        return None if self._last is None else self._last[1]

    def moved_triangles(self, reference: np.ndarray) -> np.ndarray:
        """(T,) bool: triangles with a vertex not where it is in ``reference`` (V, 3)."""
        moved = np.any(self.positions != reference, axis=1)
        return moved[self._vertex_triangles].any(axis=1)

    def _welded(self, per_corner: np.ndarray) -> np.ndarray:
        """Unit vectors averaged over the corners of each proxy vertex."""
        if self._weld is None:
            return per_corner
        mean = np.asarray(self._weld @ per_corner)[self.mesh.corner_vertex]
        return (mean / (np.linalg.norm(mean, axis=1, keepdims=True) + 1e-12)).astype(np.float32)

    def set_uniforms(self, vp_bytes: bytes, lights: dict, viewport: tuple[int, int] = (512, 512)) -> None:
        """The camera's view-projection, the lights and the frame buffer's size in pixels."""
        key = (vp_bytes, tuple(lights.items()), tuple(viewport))
        if key == self._camera_uniforms:  # a video's camera and lights hold still
            return
        self._camera_uniforms = key
        for prog in self.programs.values():
            _set_uniform(prog, "u_viewport", tuple(float(v) for v in viewport))
            try:
                prog["u_view_proj"].write(vp_bytes)
            except KeyError:
                pass
            for name, value in lights.items():
                _set_uniform(prog, name, value)

    def set_shadow_uniforms(self, uniforms: dict) -> None:
        """This frame's shadow map uniforms (:meth:`facsim.render.shadows.KeyShadow.uniforms`)."""
        if not self.receives_shadow:
            return
        for prog in self.programs.values():
            for name, value in uniforms.items():
                if isinstance(value, bytes):
                    try:
                        prog[name].write(value)
                    except KeyError:
                        pass
                else:
                    _set_uniform(prog, name, value)

    def caster_vertex_array(self, program):
        """A vertex array of this layer's cards for ``program`` (inputs ``in_pos``, ``in_uv``,
        ``in_rest``), e.g. a shadow map's depth pass; the caller releases it."""
        return self.ctx.vertex_array(
            program, [(self._vbo, "3f 32x", "in_pos"), (self._uv, "2f 4x 3f 12x", "in_uv", "in_rest")],
            index_buffer=self._ibo["OPAQUE"], index_element_size=4, skip_errors=True)

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
