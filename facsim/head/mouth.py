"""The inside of the mouth: the tongue's rest pose and the per-vertex coordinates the
renderer shades teeth, tongue and oral cavity with.

hm08's teeth are two crude bands (``helper-upper-teeth``/``helper-lower-teeth``, 68
vertices each: an outer wall of three rows plus a lingual slope) and its tongue fills
the closed mouth up to the palate. The coordinates are static per vertex (the renderer
uploads them once with the topology); the rest pose (teeth heights, tongue, the
lining behind the skin) is set in the character's rest mesh, so both engines carry it
with the jaw. Per frame, :func:`mouth_light` says where the lips are (a fraction of a
millisecond): the upper lip's shadow on the teeth, the lips' inner surface opening to
the light, the light the parted lips let in onto the tongue.

Examples
--------
>>> from facsim import Face                                      # doctest: +SKIP
>>> face = Face("ava")                                           # doctest: +SKIP
>>> coords = teeth_coordinates(face.head, face.data, face.base_positions)  # doctest: +SKIP
"""
from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

#: Groups of hm08's mouth parts.
UPPER_TEETH, LOWER_TEETH, TONGUE = "helper-upper-teeth", "helper-lower-teeth", "helper-tongue"
#: Teeth coordinates put the lower row's height at this offset (upper -1..1, lower 3..5),
#: so one shader tells the rows apart without another vertex attribute.
LOWER_ROW_OFFSET = 4.0
#: The tongue's dorsum rests this far (dm) below the lower incisors' biting edge. hm08's
#: tongue fills the closed mouth up to the palate, so an open mouth showed a pink mound
#: above the lower teeth; a relaxed tongue lies in the floor of the mouth, behind them.
TONGUE_BELOW_TEETH = 0.012
#: Behind its tip the tongue's dorsum falls toward the root: its height above the tongue's
#: underside shrinks by this fraction between :data:`TONGUE_FALL_ALONG` (0 at the tip, 1 at
#: the root). hm08's dorsum stays level back to the throat, and neither engine drops the
#: root with the jaw (the muscle engine turns the tongue rigidly about the jaw's hinge,
#: behind it), so an open mouth (26, 27, surprise) showed the tongue as a ramp rising to the
#: upper teeth, a pink wall filling the whole opening. In photographs of open mouths the
#: tongue lies low behind the lower teeth and the dark cavity opens above it.
TONGUE_FALL = 0.8
TONGUE_FALL_ALONG = (0.1, 0.5)
#: Behind its front the tongue also sinks as a whole, by up to this much (dm) at the root:
#: its back curves down toward the throat, as the root does toward the hyoid. Squashed toward
#: its underside alone, the back still stood within 10 mm of the upper teeth's edge when the
#: jaw dropped (27: george -10 mm, mei -4.5 mm at the root; the jaw turns the tongue about a
#: hinge behind it, so its back hardly drops), and seen through the opening it filled all of
#: it above the lit front: a dark wall, the "dark inside" of a puppet's mouth. With the root
#: lower the opening shows the palate and the throat above the tongue.
TONGUE_ROOT_DROP = 0.1
#: The upper teeth rest this far (dm) lower than hm08 puts them: young adults first, the
#: oldest last. hm08 hides the upper incisors 1 mm above the lips' meeting line, so a mouth
#: that opened by the jaw alone (26, 27) showed no upper teeth; a relaxed young adult shows
#: 2–3 mm of them below the upper lip once the lips part, and an open mouth shows the upper
#: incisors' edges under the lip. The display shrinks with age as the upper lip lengthens
#: (Vig & Brundo 1978: from ~3.4 mm under 30 to ~0 past 60), so the drop goes from the first
#: value to the second between the ages in :data:`UPPER_TEETH_DROP_AGES`: older faces show
#: less upper and relatively more lower teeth, one of the cues that reads as age. (At 2.2 mm
#: fading to 0, 27 showed no upper teeth on george and 1 px of them on amara at 448 px.)
UPPER_TEETH_DROP = (0.035, 0.015)
UPPER_TEETH_DROP_AGES = (30.0, 60.0)
#: The lower row rests in occlusion with the upper (the bite): its incisors' edges this far
#: (dm) above the upper incisors' (the overbite, 2–3 mm in natural teeth) and their labial
#: face this far behind the upper incisors' edge (the overjet, 2–3 mm). hm08 put the two
#: rows' edges at one depth, overlapping by 0.3–0.5 mm (george: 1.3 mm apart), so the rows
#: cut through each other and a bite (10+25, 6+12+25) showed a jagged dark line between
#: them; with the bite the upper edge lies in front of the lower crowns and shades them.
#: The whole row moves rigidly, so the jaw carries it as before.
OVERBITE = 0.02
OVERJET = 0.02
#: The middle of the dental arch (dm, |x|) whose incisors' edges set the bite.
INCISOR_REACH = 0.02
#: Radius (dm, in plan) within which a tooth vertex's biting edge and root row are looked
#: up: a column's rows lie within 3 mm of each other, columns 5–8 mm apart.
COLUMN_REACH = 0.035
#: A band vertex further than this (dm, in plan) from every root-row vertex is on the
#: lingual slope (the band's inside, 8–13 mm in), not on the outer wall (within 3 mm).
LINGUAL_REACH = 0.05
#: The mouth's lining stays at least this far (dm) behind the skin in front of it. hm08's
#: lining (the vestibule between the upper lip and the gums) climbs to the nose wings; some
#: characters' targets pull the skin there onto it (george: 0.00 mm at rest, 0.2 mm through
#: the skin in a smile), and the lining's dark shading showed as black dots beside the nose.
#: 2 mm holds through every expression's relative motion there (under 1 mm, both engines).
CAVITY_CLEARANCE = 0.02
#: Lining vertices this close (dm) to the lips' inner rim are left alone: there the lining
#: legitimately meets the lips.
RIM_REACH = 0.08


def rest_mouth(base_positions: np.ndarray, data, *, age: float = 25.0) -> np.ndarray:
    """Base positions (19158, 3) with the mouth's parts at rest: the upper teeth lowered by
    :func:`upper_teeth_drop` (less with ``age`` in years), the lower row set in the bite
    under them (:func:`bite_offset`), the tongue lowered into the floor of the mouth, and
    the mouth's lining kept :data:`CAVITY_CLEARANCE` behind the skin.

    The tongue is squashed toward its underside (about its lowest point) until its top
    sits :data:`TONGUE_BELOW_TEETH` under the lower incisors' edge, and further behind the
    tip so its dorsum falls toward the root (:data:`TONGUE_FALL`), its back sunk as a whole
    (:data:`TONGUE_ROOT_DROP`); its tip and sides
    stay where they are in plan, so it still fills the lower arch. Applied to the
    character's neutral mesh before any expression, so both engines carry the parts
    with the skull and the jaw as they carry hm08's own.
    """
    out = np.array(base_positions, np.float32, copy=True)
    lining, skin_triangles = _lining_and_skin(data)
    out[lining] = _behind_skin(out[lining], out[skin_triangles], CAVITY_CLEARANCE)
    upper, lower = data.group_vertices(UPPER_TEETH), data.group_vertices(LOWER_TEETH)
    out[upper, 1] -= upper_teeth_drop(age)
    out[lower] += bite_offset(out[upper], out[lower])
    tongue = data.group_vertices(TONGUE)
    y = out[tongue, 1]
    bottom, top = float(y.min()), float(y.max())
    target = float(out[lower, 1].max()) - TONGUE_BELOW_TEETH
    if top - bottom < 1e-6:
        return out
    scale = float(np.clip((target - bottom) / (top - bottom), 0.4, 1.0))
    z = out[tongue, 2]
    along = (z.max() - z) / max(float(z.max() - z.min()), 1e-6)
    start, end = TONGUE_FALL_ALONG
    fall = np.clip((along - start) / (end - start), 0.0, 1.0)
    fall = fall * fall * (3.0 - 2.0 * fall)
    out[tongue, 1] = bottom + scale * (1.0 - TONGUE_FALL * fall) * (y - bottom) - TONGUE_ROOT_DROP * fall
    return out


def upper_teeth_drop(age: float) -> float:
    """How far (dm) the upper teeth rest below hm08's at ``age`` (years): :data:`UPPER_TEETH_DROP`."""
    young, old = UPPER_TEETH_DROP_AGES
    first, last = UPPER_TEETH_DROP
    return float(np.interp(age, (young, old), (first, last)))


def incisal_edges(upper: np.ndarray, lower: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The front incisors' biting edges: the lowest point of the ``upper`` row's and the
    highest of the ``lower`` row's vertices (each (N, 3)) within :data:`INCISOR_REACH` of the
    midline (the middle of the arch, x = 0)."""
    def edge(p, pick):
        front = p[np.abs(p[:, 0]) <= INCISOR_REACH]
        front = front if len(front) else p
        return front[pick(front[:, 1])]
    return edge(upper, np.argmin), edge(lower, np.argmax)


def bite_offset(upper: np.ndarray, lower: np.ndarray) -> np.ndarray:
    """(3,) translation that puts the ``lower`` row (N, 3) in the bite under the ``upper``:
    its incisors' edges :data:`OVERBITE` above the upper incisors' edges and
    :data:`OVERJET` behind them."""
    top, bottom = incisal_edges(upper, lower)
    return np.array([0.0, top[1] + OVERBITE - bottom[1], top[2] - OVERJET - bottom[2]], np.float32)


def _lining_and_skin(data) -> tuple[np.ndarray, np.ndarray]:
    """Base vertices of the mouth's lining away from the lips' rim, and the (T, 3) base
    triangles of the skin around the mouth and nose (hm08's segmentation, as
    :func:`facsim.head.mesh.build_head` labels the cavity)."""
    from facsim.head.mesh import _label_quads

    quads = np.asarray(data.quads)
    body = data.quad_group == list(data.group_names).index("body")
    mouth = body & _label_quads(data, ("mouth_cavity",))
    cavity = np.unique(quads[mouth])
    skin_quads = quads[body & ~mouth]
    rim = np.intersect1d(cavity, skin_quads)
    base = np.asarray(data.base_vertices)
    far = np.linalg.norm(base[cavity][:, None] - base[rim][None], axis=2).min(axis=1) > RIM_REACH
    lining = cavity[far & ~np.isin(cavity, rim)]
    # Skin quads over the lining in plan (x, y), split in two triangles each.
    lo, hi = base[cavity, :2].min(axis=0) - 0.05, base[cavity, :2].max(axis=0) + 0.05
    corners = base[skin_quads][..., :2]
    near = ((corners >= lo) & (corners <= hi)).all(axis=2).any(axis=1)
    q = skin_quads[near]
    return lining, np.concatenate([q[:, [0, 1, 2]], q[:, [0, 2, 3]]])


def _behind_skin(points: np.ndarray, triangles: np.ndarray, clearance: float) -> np.ndarray:
    """``points`` (N, 3) moved back along -z until each is ``clearance`` behind the
    nearest skin surface in front of it (``triangles`` (T, 3, 3), seen along the face's
    +z); points with no skin in front, or deep enough already, stay."""
    a, b, c = triangles[:, 0], triangles[:, 1], triangles[:, 2]
    e1, e2 = b - a, c - a
    det = e1[:, 0] * e2[:, 1] - e2[:, 0] * e1[:, 1]
    ok = np.abs(det) > 1e-12
    a, e1, e2, det = a[ok], e1[ok], e2[ok], det[ok]
    r = points[:, None, :2] - a[None, :, :2]
    u = (r[..., 0] * e2[:, 1] - e2[:, 0] * r[..., 1]) / det
    w = (e1[:, 0] * r[..., 1] - r[..., 0] * e1[:, 1]) / det
    z = a[:, 2] + u * e1[:, 2] + w * e2[:, 2]
    # Skin in front of the point, or that the point has pushed through (within the clearance).
    hit = (u >= 0) & (w >= 0) & (u + w <= 1) & (z > points[:, None, 2] - clearance)
    front = np.where(hit, z, np.inf).min(axis=1)
    out = points.copy()
    out[:, 2] = np.minimum(points[:, 2], front - clearance)
    return out


def teeth_coordinates(head, data, base_positions: np.ndarray) -> np.ndarray:
    """(N_geo, 2) per teeth vertex: (signed arc length from the midline around the dental
    arch in dm, +x the character's left; height from the biting edge: 0 at the edge, up
    to 1 at the root row on the outer wall, down to -1 at the inner row of the lingual
    slope; plus :data:`LOWER_ROW_OFFSET` on the lower row); zeros elsewhere.

    Measured on the character's neutral base mesh, so the shader's teeth (widths in dm)
    stay put on the bands whatever the jaw does. The height is taken per column (the
    band's edge row climbs toward the back), so every tooth's edge is at 0.
    """
    out = np.zeros((head.vertex_count, 2), np.float32)
    for group, offset in ((UPPER_TEETH, 0.0), (LOWER_TEETH, LOWER_ROW_OFFSET)):
        base = data.group_vertices(group)
        geo = head.geo_of_base[base]
        keep = geo >= 0
        p = np.asarray(base_positions, float)[base[keep]]
        # Arc length on a circle of the arch's front radius: x for the front teeth, growing
        # toward the back; the band's inner and outer faces get nearly the same coordinate.
        radius = max(float(np.abs(p[:, 0]).max()), 1e-3)
        arc = radius * np.arcsin(np.clip(p[:, 0] / radius, -1.0, 1.0))
        # Biting edge and root row of the vertex's column: the extreme heights among band
        # vertices right above or below it (in plan).
        plan_distance = np.linalg.norm(p[:, None, [0, 2]] - p[None, :, [0, 2]], axis=2)
        near = plan_distance <= COLUMN_REACH
        ys = np.where(near, p[None, :, 1], np.nan)
        low, high = np.nanmin(ys, axis=1), np.nanmax(ys, axis=1)
        span = np.maximum(high - low, 1e-4)
        height = (p[:, 1] - low) / span if offset == 0.0 else (high - p[:, 1]) / span
        height = np.clip(height, 0.0, 1.0)
        # The lingual slope: far (in plan) from the root row, which tops the outer wall.
        root = p[height > 0.85][:, [0, 2]]
        plan = np.linalg.norm(p[:, None, [0, 2]] - root[None], axis=2).min(axis=1)
        height = np.where(plan > LINGUAL_REACH, -1.0, height)
        out[geo[keep]] = np.stack([arc, height + offset], axis=1)
    return out


def tongue_coordinates(head, data, base_positions: np.ndarray) -> np.ndarray:
    """(N_geo, 2) per tongue vertex: (x across the tongue, -1 right … +1 left; 0 at the
    tip … 1 at the root along its length); zeros elsewhere. The tongue's shader draws its
    median groove and papillae in these, and darkens it toward the throat."""
    out = np.zeros((head.vertex_count, 2), np.float32)
    base = data.group_vertices(TONGUE)
    geo = head.geo_of_base[base]
    keep = geo >= 0
    p = np.asarray(base_positions, float)[base[keep]]
    half = max(float(np.abs(p[:, 0]).max()), 1e-3)
    front, back = float(p[:, 2].max()), float(p[:, 2].min())
    along = (front - p[:, 2]) / max(front - back, 1e-3)
    out[geo[keep]] = np.stack([p[:, 0] / half, along], axis=1)
    return out


def cavity_coordinates(head, neutral: np.ndarray) -> np.ndarray:
    """(N_geo, 3) per vertex of the mouth's lining: (across, -1 right … +1 left, by the
    lining's half-width; up, -1 … +1 over the back wall's height, 0 at its middle; depth
    behind the lips, 0 at the lips' rim … 1 at the back wall); zeros elsewhere. Measured on the
    character's rest mesh (``neutral``, (N_geo, 3)), so the shader's throat, soft palate and
    uvula stay put on the lining whatever the jaw does. (The back wall: the lining's deepest
    tenth.)"""
    from facsim.head.mesh import REGIONS

    out = np.zeros((head.vertex_count, 3), np.float32)
    lining = np.flatnonzero(head.region == REGIONS.index("mouth_interior"))
    if not len(lining):
        return out
    p = np.asarray(neutral, np.float64)[lining]
    front, back = float(p[:, 2].max()), float(p[:, 2].min())
    depth = (front - p[:, 2]) / max(front - back, 1e-6)
    wall = p[depth > 0.9]
    bottom, top = float(wall[:, 1].min()), float(wall[:, 1].max())
    half = max(float(np.abs(p[:, 0]).max()), 1e-6)
    up = (p[:, 1] - 0.5 * (top + bottom)) / max(0.5 * (top - bottom), 1e-6)
    out[lining] = np.stack([p[:, 0] / half, up, depth], axis=1)
    return out


def mouth_depth_visibility(head, neutral: np.ndarray, *, falloff: float = 0.18):
    """Mouth-interior vertices and a visibility (1 at the lips … ~0 deep inside) that falls
    off with depth behind the lips, so an open mouth shows a dark cavity, not a lit wall.

    ``falloff`` (dm) is the depth over which light drops to 1/e: about a centimetre, as
    the lips, cheeks and teeth shade the cavity from every side.
    """
    from facsim.head.mesh import REGIONS

    interior = np.flatnonzero(head.region == REGIONS.index("mouth_interior"))
    z = np.asarray(neutral)[interior, 2]
    depth = np.clip(z.max() - z, 0.0, None)
    return interior, np.exp(-depth / falloff).astype(np.float32)


#: The lips' mucosa (the smooth, wet, redder lining the lips turn toward each other) covers
#: the skin within the first geodesic distance (dm) of the lips' inner rim and fades out by
#: the second. Where the closed lips touch (2.5-5 mm of surface in from the rim on hm08,
#: then they turn out into the vermilion), the wet-dry line runs: an open mouth shows the
#: mucosa as a darker red band between the lips' red and the dark inside. Without it the
#: vermilion's dry, lined red ran to the opening's edge, "a cut-out hole".
MUCOSA_REACH = (0.025, 0.05)


def lip_mucosa(head) -> np.ndarray:
    """(N_geo,) float32 per vertex: how much of the lips' mucosa it carries (1 at the lips'
    inner rim, the skin bordering the mouth's lining, fading to 0 at
    :data:`MUCOSA_REACH`'s far end, measured along the skin of the base mesh)."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import dijkstra

    from facsim.head.mesh import REGIONS
    from facsim.head.surface import smoothstep

    skin = head.region == REGIONS.index("skin")
    lining = head.region == REGIONS.index("mouth_interior")
    triangles = head.triangles
    rim = np.unique(triangles[lining[triangles].any(axis=1)])
    rim = rim[skin[rim]]
    edges = np.concatenate([triangles[:, [0, 1]], triangles[:, [1, 2]], triangles[:, [2, 0]]])
    edges = edges[skin[edges].all(axis=1)]
    p = head.positions(head.base_vertices)
    length = np.linalg.norm(p[edges[:, 0]] - p[edges[:, 1]], axis=1)
    graph = coo_matrix((length, (edges[:, 0], edges[:, 1])), shape=(len(p), len(p))).tocsr()
    near, far = MUCOSA_REACH
    distance = dijkstra(graph, directed=False, indices=rim, min_only=True, limit=2 * far)
    return np.asarray(smoothstep(far, near, distance), np.float32)


#: Ambient visibility the lips' inner surface reaches once the lips part, per ring of skin
#: vertices from the rim (the wet mucosa the lips turn toward each other): the bake is
#: taken on the closed mouth, where the rim is buried (visibility ~0), so an open mouth
#: showed its lips' inner edge black, a hard outline.
LIP_RING_VISIBILITY = (0.5, 0.65, 0.8)
#: The same for the mouth's lining, ring by ring inward from the rim: just inside the lips
#: it is their mucosa going on toward the gums, lit through the opening (and drawn in the
#: mucosa's red) as the lips part, where the bake on the closed mouth left it in the
#: cavity's dull dark: a dark seam along the lips' inner edge.
LINING_RING_VISIBILITY = (0.9, 0.7)
#: The lips have parted over this range of gap (dm) at a given x: 0.5 mm -> 4 mm.
LIP_PARTING = (0.005, 0.04)
#: Where the lips touch, their inner surface (the rings of :data:`LIP_RING_VISIBILITY`)
#: keeps this fraction of its open visibility: the closed lips' meeting line is a soft,
#: dark red shade, as in photographs. The bake on the closed mouth buries it (visibility
#: ~0), which drew a black outline, 1-2 px at 1024 px, round the lips' parting line.
CLOSED_LIP_VISIBILITY = 0.6
#: Teeth seen through a slit between the lips (parted in the mouth's middle by less than
#: :data:`SLIT_GAP` beyond where their rims sit at rest) lie in the dark the slit lets in:
#: every tooth's height below the lip's edge (-0.5 .. 0.1 dm) is shifted down by this
#: (dm) × how closed the slit is, and the shader draws heights under -0.7 darker than the
#: lip's shadow (the teeth's ``CLOSED_LIPS_DARK``). Lit as under a raised lip, the teeth
#: behind the closed lips' corners showed as grey slivers outlined in black. (All the
#: teeth shift alike: their heights interpolate across the band's 8-mm triangles.)
SLIT_SHIFT = 1.5
#: The slit between the lips opens the teeth to the light as they part this far (dm):
#: 0.5 mm -> 2.5 mm.
SLIT_GAP = (0.005, 0.025)
#: The tongue lies in the dark behind the teeth until the lips part this far (dm) at the
#: midline, and takes the light the mouth lets in when they have parted this far.
TONGUE_LIT_GAP = (0.003, 0.025)
#: Near the mouth's corners the teeth lie in the shade of the lips and cheeks wrapped
#: around them (the buccal corridor): a tooth vertex's height below the upper lip's edge
#: is taken as at most (slope × its distance across the mouth from the nearer corner −
#: offset, dm), so the lip's shadow deepens toward the corners, darkest at them and gone
#: ~12 mm in. Lit evenly to the corners, the back teeth of a wide mouth (20+26) showed as
#: pale slabs filling the commissures; gone 10 mm in (slope 0.3), a smile's teeth stayed
#: bright out to its corners, a white strip filling the crescent.
COMMISSURE_SHADE = (0.25, 0.008)
#: How many rings of skin around the rim count as the upper lip's free margin.
UPPER_LIP_RINGS = 5
#: The commissure: where the lips join at each corner, the skin folds in toward the modiolus, and as
#: the lips part (or a smile draws them apart) the corner becomes a small shaded pit between them, as
#: in photographs. The skin and lips within ``reach`` (dm) of a corner take up to ``depth`` of shade,
#: falling to 0 at the reach as (1 - distance / reach)². Without it the open mouth's red ran round its corners
#: unbroken, lit as evenly as the lips' middle: a smooth ring of rubber (session 24's blind reviewer,
#: "rubbery stretched mouth" in fear and surprise).
COMMISSURE_FOLD = {"reach": 0.045, "depth": 0.75}
#: ... in full once the lips have parted this far (dm) at the mouth's middle: 0.5 mm -> 6 mm.
COMMISSURE_OPENING = (0.005, 0.06)
@dataclass(frozen=True)
class MouthRim:
    """The lips' inner rim and the mouth's parts whose light depends on the lips per frame.

    Attributes
    ----------
    upper, lower : (K,) int
        Geometry indices of the upper and the lower lip's inner rim (skin vertices that
        border the mouth's lining), each sorted by x at rest.
    rings : tuple of (K_i,) int
        The rim (ring 0) and the skin rings just outside it: the lips' inner surface.
    upper_lip : (L,) int
        The upper lip's skin near its rim (:data:`UPPER_LIP_RINGS` rings): its lowest
        point over a tooth is the edge whose shadow the tooth takes (the rim itself lies
        on the lip's inner side, above its free margin).
    upper_teeth, lower_teeth : (T,) int
        Geometry indices of the teeth rows.
    tongue : (G,) int
        Geometry indices of the tongue.
    rest_gap : tuple of (K_i,) float
        Per ring vertex, the gap (dm) between the rims at its x at rest: the lips touch in
        front of their inner rims, which sit apart; only a wider gap parts the lips.
    rest_gap_middle : float
        The same in the mouth's middle.
    lining_rings : tuple of (K_i,) int
        The mouth's lining just inside the rim, ring by ring inward (:data:`LINING_RING_VISIBILITY`).
    lining_rest_gap : tuple of (K_i,) float
        Their rest gaps, as ``rest_gap``.
    lining : (J,) int
        Geometry indices of the whole mouth's lining (:func:`opening_light`).
    commissure : (C,) int
        The skin (lips included) within :data:`COMMISSURE_FOLD`'s reach of either corner at rest.
    commissure_share : (C,) float
        How much of the fold's shade each of them takes: 1 at the corner, 0 at the reach.
    """

    upper: np.ndarray
    lower: np.ndarray
    rings: tuple
    upper_lip: np.ndarray
    upper_teeth: np.ndarray
    lower_teeth: np.ndarray
    tongue: np.ndarray
    rest_gap: tuple = ()
    rest_gap_middle: float = 0.0
    lining_rings: tuple = ()
    lining_rest_gap: tuple = ()
    lining: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))
    commissure: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))
    commissure_share: np.ndarray = field(default_factory=lambda: np.zeros(0, np.float32))


def mouth_rim(head, data, neutral: np.ndarray) -> MouthRim:
    """The lips' inner rim of ``head`` told apart at rest (``neutral``, (N_geo, 3)): the rim
    is a loop through the mouth's corners; its higher half is the upper lip's."""
    from facsim.head.mesh import REGIONS

    region = head.region
    lining = region == REGIONS.index("mouth_interior")
    skin = region == REGIONS.index("skin")
    triangles = head.triangles
    rings, inside = [], lining.copy()
    for _ in range(max(len(LIP_RING_VISIBILITY), UPPER_LIP_RINGS)):
        ring = np.unique(triangles[inside[triangles].any(axis=1)])
        ring = ring[skin[ring] & ~inside[ring]]
        rings.append(ring)
        inside[ring] = True
    p = np.asarray(neutral)
    upper, lower = _split_rim(rings[0], triangles, p)
    # Ring by ring outward, a vertex belongs to the lip whose previous ring it touches (at
    # the corners, where it touches both, to neither): the closed lips touch at rest.
    side = np.zeros(len(region), np.int8)
    corners = np.intersect1d(upper, lower)
    side[np.setdiff1d(upper, corners)], side[np.setdiff1d(lower, corners)] = 1, 2
    for ring in rings[1:UPPER_LIP_RINGS]:
        touching = triangles[np.isin(triangles, ring).any(axis=1)]
        for v in ring:
            near = side[touching[(touching == v).any(axis=1)]]
            up, down = (near == 1).any(), (near == 2).any()
            side[v] = 1 if up and not down else 2 if down and not up else 0
    upper_lip = np.flatnonzero(side == 1)
    lining_rings, reached = [], np.zeros(len(region), bool)
    reached[rings[0]] = True
    for _ in LINING_RING_VISIBILITY:
        ring = np.unique(triangles[reached[triangles].any(axis=1)])
        ring = ring[lining[ring] & ~reached[ring]]
        lining_rings.append(ring)
        reached[ring] = True
    rings = rings[: len(LIP_RING_VISIBILITY)]
    by_x = lambda idx: idx[np.argsort(np.asarray(neutral)[idx, 0])]  # noqa: E731
    rim = MouthRim(upper=by_x(upper), lower=by_x(lower), rings=tuple(rings), upper_lip=upper_lip,
                   upper_teeth=head.group_geometry(data, UPPER_TEETH),
                   lower_teeth=head.group_geometry(data, LOWER_TEETH),
                   tongue=head.group_geometry(data, TONGUE), lining_rings=tuple(lining_rings),
                   lining=np.flatnonzero(lining))
    plane, upper_edge, lower_edge, middle = _lips(rim, p)
    commissure, share = _commissure(p, np.flatnonzero(skin), rim.upper[[0, -1]])

    def gaps(ring_list):
        return tuple(np.maximum(upper_edge(x) - lower_edge(x), 0.0) for x in (plane(ring)[0] for ring in ring_list))
    return replace(rim, rest_gap=gaps(rings), lining_rest_gap=gaps(lining_rings),
                   commissure=commissure, commissure_share=share,
                   rest_gap_middle=float(max(upper_edge(middle) - lower_edge(middle), 0.0)))


def _commissure(p: np.ndarray, skin: np.ndarray, corners: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The ``skin`` points (indices into ``p``, (N, 3) at rest) within :data:`COMMISSURE_FOLD`'s reach of
    either of the two ``corners`` (indices), and their share of the fold's shade (1 at a corner, 0 at the
    reach: (1 - distance / reach)²)."""
    reach = float(COMMISSURE_FOLD["reach"])
    distance = np.min([np.linalg.norm(p[skin] - p[c], axis=1) for c in corners], axis=0)
    near = distance < reach
    return skin[near], ((1.0 - distance[near] / reach) ** 2).astype(np.float32)


def _split_rim(rim: np.ndarray, triangles: np.ndarray, p: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The rim's two chains between the mouth's corners (its extreme x), upper first: the
    closed lips touch at rest, so heights alone cannot tell them apart."""
    from collections import deque

    on = np.isin(triangles, rim)
    links = {int(v): set() for v in rim}
    for tri, mask in zip(triangles[on.sum(axis=1) >= 2], on[on.sum(axis=1) >= 2]):
        ends = [int(v) for v, m in zip(tri, mask) if m]
        for a in ends:
            links[a].update(b for b in ends if b != a)
    left, right = int(rim[np.argmin(p[rim, 0])]), int(rim[np.argmax(p[rim, 0])])

    def path(banned):
        came, todo = {left: None}, deque([left])
        while todo:
            v = todo.popleft()
            for w in links[v]:
                if w not in came and w not in banned:
                    came[w] = v
                    todo.append(w)
        chain, v = [], right
        while v is not None and v in came:
            chain.append(v)
            v = came[v]
        return chain

    first = path(set())
    second = path(set(first[1:-1]))
    chains = [np.array(first), np.array(second)]
    # Rim vertices off both chains (a ragged rim) join the chain nearest them.
    rest = np.setdiff1d(rim, np.concatenate(chains))
    if len(rest):
        both = np.concatenate(chains)
        nearest = both[np.linalg.norm(p[rest][:, None] - p[both][None], axis=2).argmin(axis=1)]
        for i, chain in enumerate(chains):
            chains[i] = np.concatenate([chain, rest[np.isin(nearest, chain)]])
    if p[chains[0], 1].mean() < p[chains[1], 1].mean():
        chains.reverse()
    return chains[0], chains[1]


def _lips(rim: MouthRim, positions: np.ndarray):
    """The lips in the mouth's own frame (x from corner to corner, y up across it):
    ``plane(indices) -> (x, y)``, the upper and the lower rim's height at x, and the x
    of the mouth's middle."""
    p = np.asarray(positions, np.float64)
    x_axis = p[rim.upper[-1]] - p[rim.upper[0]]
    x_axis /= max(np.linalg.norm(x_axis), 1e-9)
    y_axis = np.array([0.0, 1.0, 0.0]) - x_axis[1] * x_axis
    y_axis /= max(np.linalg.norm(y_axis), 1e-9)

    def plane(idx):
        q = p[idx]
        return q @ x_axis, q @ y_axis

    ux, uy = plane(rim.upper)
    lx, ly = plane(rim.lower)
    # Sorted by x at rest; an expression keeps that order nearly, np.interp wants it exactly.
    ou, ol = np.argsort(ux), np.argsort(lx)
    ux, uy, lx, ly = ux[ou], uy[ou], lx[ol], ly[ol]
    return plane, (lambda x: np.interp(x, ux, uy)), (lambda x: np.interp(x, lx, ly)), 0.5 * (ux[0] + ux[-1])


#: The parted lips' opening is about this fraction of the rectangle of its width by its gap
#: in the middle (an ellipse: pi / 4).
OPENING_FILL = 0.78
#: The light in front of the face is brighter than the room's average: the studio's large key
#: and fill face the opening. What passes it lights the lining this many times the opening's
#: share of the whole hemisphere of light.
OPENING_GAIN = 3.0
#: How the light through the opening grows with the rise of the direction to it (sine), and
#: the least share left to lining that looks down at it.
OPENING_RISE = 1.5
OPENING_LOW = 0.15


def opening_light(rim: MouthRim, positions: np.ndarray, lips=None) -> np.ndarray:
    """(J,) for ``rim.lining``: the share of the light from in front of the face that reaches
    each lining vertex through the parted lips (``positions``, (N_geo, 3)): the opening's area
    over pi times its squared distance from the opening's middle (the solid angle the opening
    fills, over the hemisphere's), at most 1; 0 while the lips touch.

    The bake on the closed mouth leaves the lining only a fall-off with depth behind the lips
    (:func:`mouth_depth_visibility`), the same whatever the opening: an open mouth (27,
    surprise) showed the back of its cavity as one flat near-black. Through a wide opening the
    back of the mouth (6-8 cm in) catches the room's light by its distance from it, more below
    the opening than above (:data:`OPENING_RISE`): a gradual fall-off to the throat's dark,
    the palate's shade above. ``lips``: :func:`_lips` of these positions when the caller has it.
    """
    plane, upper_edge, lower_edge, middle = lips or _lips(rim, positions)
    gap = max(float(upper_edge(middle) - lower_edge(middle)) - rim.rest_gap_middle, 0.0)
    if gap <= 0.0 or not len(rim.lining):
        return np.zeros(len(rim.lining), np.float32)
    corners = plane(rim.upper)[0][[0, -1]]
    area = OPENING_FILL * float(abs(corners[1] - corners[0])) * gap
    centre = np.concatenate([positions[rim.upper], positions[rim.lower]]).astype(np.float64).mean(axis=0)
    towards = centre - np.asarray(positions[rim.lining], np.float64)
    distance = np.maximum(np.linalg.norm(towards, axis=1), 1e-4)
    # The light comes mostly from above the face (the key, the sky): lining below the opening
    # looks up through it at them, lining above it (the palate, the top of the throat) down at
    # the floor and the ground, in the shade of the upper teeth and lip.
    rising = towards[:, 1] / distance
    share = np.clip(area / (np.pi * distance ** 2), 0.0, 1.0) * np.clip(0.5 + OPENING_RISE * rising, OPENING_LOW, 1.0)
    # The shader lights the lining by its visibility squared (``mouth_shade``): the square
    # root makes that light the opening's share, times the studio's frontal light's gain.
    return np.sqrt(np.clip(OPENING_GAIN * share, 0.0, 1.0)).astype(np.float32)


def mouth_light(rim: MouthRim, positions: np.ndarray, occlusion: np.ndarray) -> None:
    """Light the mouth by where the lips are in this frame (in place on ``occlusion``,
    (N_geo,), as baked on the closed mouth):

    - the lips' inner surface, and the lining just inside it, open to the light as the
      lips part at its x (the bake buried it: an open mouth's lips had a black inner edge);
    - the whole lining takes the light the opening lets in by its distance from it
      (:func:`opening_light`);
    - each tooth vertex gets its height (dm) below the upper lip's edge at its x, not a
      visibility: interpolated across a triangle it is that height per fragment (the lip's
      edge is close to straight between the teeth's columns), so the teeth's shader draws
      the lip's soft contact shadow right under its edge, millimetres wide, where the
      band's vertices lie 8 mm apart. (The bake under closed lips means nothing for them.)
      Toward the mouth's corners the height is capped (:data:`COMMISSURE_SHADE`): the
      teeth there sit in the lips' and cheeks' shade. The lower row's edge is the upper
      teeth's biting edge where that is lower than the lip's: the upper crowns shade it.
    - the tongue takes the light the parted lips let in (:data:`TONGUE_LIT_GAP`): seen
      through the gaps between barely parted teeth it is dark, not a pink dot.
    - the corners fold into a small shaded pit as the lips part (:data:`COMMISSURE_FOLD`).

    Measured in the mouth's own frame (x from corner to corner, y up across it), so a
    turned or tilted head keeps it.
    """
    from facsim.head.surface import smoothstep

    lips = _lips(rim, positions)
    plane, upper_edge, lower_edge, middle = lips
    lo, hi = LIP_PARTING
    for ring_index, (ring, visibility, rest_gap) in enumerate(zip(
            rim.rings + rim.lining_rings, LIP_RING_VISIBILITY + LINING_RING_VISIBILITY, rim.rest_gap + rim.lining_rest_gap)):
        x, _ = plane(ring)
        # Parted beyond where the lips' inner rims sit at rest (they touch in front of them).
        parted = np.clip((upper_edge(x) - lower_edge(x) - rest_gap - lo) / (hi - lo), 0.0, 1.0)
        parted = parted * parted * (3.0 - 2.0 * parted)
        touching = CLOSED_LIP_VISIBILITY if ring_index < len(rim.rings) else 0.0   # the lips' rings, not the lining's
        occlusion[ring] = np.maximum(occlusion[ring], visibility * (touching + (1.0 - touching) * parted))
    if len(rim.lining):
        occlusion[rim.lining] = np.maximum(occlusion[rim.lining], opening_light(rim, positions, lips))
    gap = upper_edge(middle) - lower_edge(middle) - rim.rest_gap_middle   # beyond the rest gap, mid-mouth
    lo, hi = TONGUE_LIT_GAP
    lit = np.clip((gap - lo) / (hi - lo), 0.0, 1.0)
    occlusion[rim.tongue] = lit * lit * (3.0 - 2.0 * lit)
    opening = smoothstep(*COMMISSURE_OPENING, gap)
    occlusion[rim.commissure] *= 1.0 - float(COMMISSURE_FOLD["depth"]) * opening * rim.commissure_share
    lip_x, lip_y = plane(rim.upper_lip)
    corners = plane(rim.upper)[0][[0, -1]]
    lo, hi = SLIT_GAP
    parted = np.clip((gap - lo) / (hi - lo), 0.0, 1.0)
    closed = 1.0 - parted * parted * (3.0 - 2.0 * parted)
    upper_x, upper_y = plane(rim.upper_teeth)
    for teeth in (rim.upper_teeth, rim.lower_teeth):
        x, y = (upper_x, upper_y) if teeth is rim.upper_teeth else plane(teeth)
        # The upper lip's lowest point within a tooth column's reach of x.
        over = np.abs(x[:, None] - lip_x[None]) < COLUMN_REACH
        edge = np.where(over.any(axis=1), np.where(over, lip_y[None], np.inf).min(axis=1), upper_edge(x))
        if teeth is rim.lower_teeth and len(upper_x):
            # The lower row also lies in the upper teeth's shade: their biting edge (the upper
            # row's lowest point over it) overhangs it in the bite, and a parted smile lit the
            # lower crowns up to that edge: the two rows ran together into one pale grille.
            above = np.abs(x[:, None] - upper_x[None]) < COLUMN_REACH
            edge = np.minimum(edge, np.where(above, upper_y[None], np.inf).min(axis=1))
        from_corner = np.minimum(x - corners.min(), corners.max() - x)
        slope, offset = COMMISSURE_SHADE
        occlusion[teeth] = np.minimum(edge - y, slope * from_corner - offset) - SLIT_SHIFT * closed
