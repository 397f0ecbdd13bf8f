"""Print objective figures for the eyes and teeth as rendered (issue 13), per character.

Each part's pixels are found by rendering the same frame again with that part in a loud
colour and keeping the pixels that changed (as ``tests/test_eye_shading.py`` does).

Teeth, in a 6+12+25 smile at 512²: mean luminance (0–255) and chroma (max − min of RGB) of
the teeth's pixels, and how much bluer (B − R) the biting edge is than the crowns (the
lowest two pixels of each column of the upper row's middle third against the rest).

Eyes, neutral: catch-lights per eye at 320² (connected pixels over iris and pupil brighter
than 120, without anti-aliasing, as in the tests), their area; in the three-quarter-left
view at 512² the pupil's centre less the visible cornea's (px along x; positive toward
the camera side: the refracted iris's parallax); the lower lashes' coverage (summed change,
in pixels, when the lashes are recoloured, in a band 12 px deep under each eye's sclera).

The lids (``--aperture``), at rest, 5E, surprise (1+2+5+26) and fear (1+2+4+5+20+26) at 512²,
front, without anti-aliasing: the sclera bared above and below the iris down its middle column,
in mm (the iris's width in pixels is 11.7 mm); where 5 bares it, the mean luminance of the sclera
over the iris against the sclera's beside the iris's middle rows; the visible iris's top third's mean luminance
over its bottom third's (the upper lid's shade); the sclera's mean luminance.

Open mouth (``--cavity``), surprise (1+2+5+26) at 512², front: within the mouth's opening (the
pixels of teeth, tongue and the mouth's lining), the share that is tongue and the share in deep
shadow (luminance under 30), the share that is tongue in the light (over 30) and its median and
99th-percentile luminance (its wet sheen), the mean luminance
down the midline (5 px wide) at 5, 15 … 95 % of the
opening's height from the upper lip, and the mean luminance of the opening's outer sixth on each
side (the corners of the mouth: the buccal corridor's shade).

The lips' mucosa (``--mucosa``), 6+12+25 and 1+2+5+26 at 512², front: the pixels the mucosa
changes (a render with the detail texture's mucosa channel cleared against the normal one),
their count and median height per column over the lower and the upper lip (the band's width
as seen), their mean sRGB colour (and the same pixels' without the mucosa) against the vermilion's (the lips' other pixels, found by
recolouring the lips), the share of them darker than the vermilion's median, and their 99th
percentile luminance (the wet glint).

The lips (``--lips``), at rest, 6+12+25, 1+2+5+26, 1+2+4+5+20+26 and 20+25+27 at 512², front:
the height (mm) of the upper and the lower lip's red at the mouth's midline as seen (the
recoloured lips' pixels in the 5 columns there, scaled at the lips' depth) and the opening
between them: stretched lips keep their volume, so their red flattens but stays full.

The sclera (``--sclera``), at rest, surprise (1+2+5+26) and fear (1+2+4+5+20+26) at 448², front,
without anti-aliasing: the sclera's median and 95th-percentile luminance against the cheek's
(a grey white well below the skin's read as a glass eye), the iris's median luminance and the
pupil's width over the iris's per eye.

The smile's teeth along the row (``--teeth``), 6+12+25 at 448², front: per column of the
upper teeth's top run of pixels, its mean luminance; the 10th and 90th percentile of those in
the middle half of the row (crowns, their shaded flanks and the embrasures: a flat strip has
them close), and the row's outer sixths' mean over its middle third's (the buccal corridor).

The catch-light and the iris (``--iris``), at rest, front, per eye: at 768 px without
anti-aliasing the catch-light's core (over half-way from the iris's median to its peak)
against the pupil: the gap between them, its centre's offset from the pupil's centre to the
image's right and upward (mm, from the iris's 11.7 mm), its area (mm²); at 448 px (4x MSAA), on
the iris's lower half (clear of the lid's shade and the catch-light), the ciliary zone's spread
(std over mean luminance: its streaks) and the pupillary zone's mean luminance over the ciliary
zone's (a darker ring round the pupil reads as a target's).

Usage::

    python3 scripts/eyes_mouth_figures.py [CHARACTER ...]      (default: amara liam mei george)
    python3 scripts/eyes_mouth_figures.py --cavity [--engine muscle] [--expression 27] [CHARACTER ...]
    python3 scripts/eyes_mouth_figures.py --mucosa [--engine muscle] [CHARACTER ...]
    python3 scripts/eyes_mouth_figures.py --aperture [--engine muscle] [CHARACTER ...]
    python3 scripts/eyes_mouth_figures.py --lips [--engine muscle] [CHARACTER ...]
    python3 scripts/eyes_mouth_figures.py --teeth [--engine muscle] [CHARACTER ...]
    python3 scripts/eyes_mouth_figures.py --sclera [--engine muscle] [CHARACTER ...]
    python3 scripts/eyes_mouth_figures.py --iris [CHARACTER ...]
"""
from __future__ import annotations

import argparse

import numpy as np
from scipy import ndimage

from facsim import Face
from facsim.head.character import preset

LUMINANCE = np.array([0.2126, 0.7152, 0.0722])
WHITE = (1.0, 1.0, 1.0)
#: The lips' heights (``--lips``) at rest, in a smile, surprise, fear and a wide stretched mouth.
LIP_EXPRESSIONS = ("", "6+12+25", "1+2+5+26", "1+2+4+5+20+26", "20+25+27")


def _renders(character, expression, recolours, *, size, view="front", antialias=4, engine="registers"):
    """The frame and the same frame with each of ``recolours`` applied, as float RGB."""
    images = []
    with Face(character, engine=engine) as face:
        deformation = face.deform(expression)
        images.append(face.render(deformation=deformation, size=size, view=view, antialias=antialias,
                                  background=WHITE))
    for colours in recolours:
        with Face(character.with_(colors={**character.colors, **colours}), engine=engine) as face:
            images.append(face.render(deformation=deformation, size=size, view=view, antialias=antialias,
                                      background=WHITE))
    return [image[..., :3].astype(float) for image in images]


def _changed(marked, image):
    return np.abs(marked - image).sum(-1) > 60


def teeth_figures(character, expression="6+12+25", size=512) -> dict:
    image, marked = _renders(character, expression, [{"teeth": "#00ff00"}], size=size)
    teeth = (marked[..., 1] > marked[..., 0] + 20) & (marked[..., 1] > marked[..., 2] + 20)
    pixels = image[teeth]
    ys, xs = np.nonzero(teeth)
    middle = np.abs(xs - xs.mean()) < (xs.max() - xs.min()) / 6
    edge, crown = [], []
    for x in np.unique(xs[middle]):
        column = np.sort(ys[xs == x])
        upper = column[: np.argmax(np.diff(np.r_[column, column[-1] + 2]) > 1) + 1]  # first run from the top
        edge += [image[y, x] for y in upper[-2:]]
        crown += [image[y, x] for y in upper[:-2]]
    edge, crown = np.array(edge), np.array(crown)
    return {"luminance": round(float((pixels @ LUMINANCE).mean()), 1),
            "chroma": round(float((pixels.max(1) - pixels.min(1)).mean()), 1),
            "edge_bluer_by": round(float((edge[:, 2] - edge[:, 0]).mean() - (crown[:, 2] - crown[:, 0]).mean()), 1)}


def teeth_row_figures(character, expression="6+12+25", size=448, engine="registers") -> dict:
    """The upper teeth's row as a row of crowns, not a flat strip: along the row (the teeth's
    pixels in their top run, per column), the spread of the columns' mean luminance in the
    middle half of the row (10th to 90th percentile: crowns, their shaded flanks and the
    embrasures between) and the mean luminance of the row's outer sixths against its middle
    third (the buccal corridor's shade)."""
    image, marked = _renders(character, expression, [{"teeth": "#00ff00"}], size=size, engine=engine)
    teeth = (marked[..., 1] > marked[..., 0] + 20) & (marked[..., 1] > marked[..., 2] + 20)
    luminance = image @ LUMINANCE
    ys, xs = np.nonzero(teeth)
    columns = np.unique(xs)
    means = []
    for x in columns:
        column = np.sort(ys[xs == x])
        top = column[: np.argmax(np.diff(np.r_[column, column[-1] + 2]) > 1) + 1]
        means.append(luminance[top, x].mean())
    means = np.array(means)
    position = (columns - columns.min()) / max(columns.max() - columns.min(), 1)
    middle = means[np.abs(position - 0.5) < 0.25]
    outer = means[np.abs(position - 0.5) > 1 / 3]
    centre = means[np.abs(position - 0.5) < 1 / 6]
    return {"column_luminance_p10_p90": [round(float(q), 1) for q in np.percentile(middle, [10, 90])],
            "outer_over_middle": round(float(outer.mean() / centre.mean()), 2)}


def cavity_figures(character, expression="1+2+5+26", size=512, engine="registers") -> dict:
    from PIL import Image, ImageDraw

    from facsim.render.camera import project

    image, *marks = _renders(character, expression, [{part: colour for part in ("teeth", "tongue", "mouth_interior")}
                                                     for colour in ("#ffffff", "#000000")],
                             size=size, antialias=1, engine=engine)
    marks += _renders(character, expression, [{"tongue": "#ffffff"}, {"tongue": "#000000"}],
                      size=size, antialias=1, engine=engine)[1:]
    inside = np.abs(marks[0] - marks[1]).max(-1) > 3
    tongue = np.abs(marks[2] - marks[3]).max(-1) > 3
    # The opening: inside the lips' inner rim as projected (parts in deep shade barely change
    # when recoloured, so the recolouring alone would miss the darkest cavity).
    with Face(character, engine=engine) as face:
        positions = np.asarray(face.deform(expression).positions)
        rim = face._mouth_rim
        loop = np.concatenate([rim.upper, rim.lower[::-1]])
        points, _ = project(face.camera(size=(size, size)), positions[loop], (size, size))
    outline = Image.new("L", (size, size), 0)
    ImageDraw.Draw(outline).polygon([tuple(p) for p in points], fill=1)
    opening = (np.asarray(outline) > 0) & inside | tongue
    opening |= (np.asarray(outline) > 0) & ((image @ LUMINANCE) < 30)
    luminance = image @ LUMINANCE
    ys, xs = np.nonzero(opening)
    middle = int(round(np.median(xs)))
    column = opening[:, middle - 2: middle + 3].any(axis=1)
    top, bottom = np.flatnonzero(column)[[0, -1]]
    profile = [round(float(luminance[int(top + f * (bottom - top)), middle - 2: middle + 3].mean()), 1)
               for f in np.arange(0.05, 1.0, 0.1)]
    width = xs.max() - xs.min()
    columns = np.arange(size)[None, :]
    corners = [round(float(luminance[opening & side].mean()), 1)
               for side in (columns < xs.min() + width / 6, columns > xs.max() - width / 6)]
    return {"opening_px": int(opening.sum()), "tongue_share": round(float((tongue & opening).sum() / opening.sum()), 3),
            "lit_tongue_share": round(float((tongue & opening & (luminance > 30)).sum() / opening.sum()), 3),
            "dark_share": round(float((luminance[opening] < 30).mean()), 3),
            "tongue_luminance_p50_p99": [round(float(np.percentile(luminance[tongue & opening & (luminance > 30)], q)), 1)
                                         for q in (50, 99)],
            "midline_luminance": profile, "corner_luminance": corners}


def mucosa_figures(character, expression="6+12+25", size=512, engine="registers") -> dict:
    import dataclasses

    with Face(character, engine=engine) as face:
        deformation = face.deform(expression)
        image = face.render(deformation=deformation, size=size, background=WHITE)[..., :3].astype(float)
        detail = face.appearance.detail.copy()
        detail[..., 3] = 0
        face.__dict__["appearance"] = dataclasses.replace(face.appearance, detail=detail)
        dry = face.render(deformation=deformation, size=size, background=WHITE)[..., :3].astype(float)
        positions = np.asarray(deformation.positions)
        from facsim.render.camera import project

        middle, _ = project(face.camera(size=(size, size)), positions[np.r_[face._mouth_rim.upper, face._mouth_rim.lower]],
                            (size, size))
    with Face(character.with_(colors={**character.colors, "lips": "#00ff00"}), engine=engine) as face:
        marked = face.render(deformation=deformation, size=size, background=WHITE)[..., :3].astype(float)
    band = np.abs(image - dry).max(-1) > 3
    lips = (_changed(marked, image) | band) & ~band
    centre_y = middle[:, 1].mean()
    ys, xs = np.nonzero(band)
    central = np.abs(xs - np.median(xs)) < (xs.max() - xs.min()) / 6
    widths = {}
    for name, side in (("lower", ys > centre_y), ("upper", ys <= centre_y)):
        keep = central & side
        counts = np.bincount(xs[keep], minlength=size)[np.unique(xs[keep])]
        widths[name] = float(np.median(counts)) if len(counts) else 0.0
    srgb = lambda pixels: [round(float(c), 1) for c in pixels.mean(axis=0)]  # noqa: E731
    luminance = image @ LUMINANCE
    return {"band_px": int(band.sum()), "width_lower_upper_px": [widths["lower"], widths["upper"]],
            "band_rgb": srgb(image[band]), "band_rgb_without": srgb(dry[band]), "vermilion_rgb": srgb(image[lips]),
            "darker_share": round(float((luminance[band] < np.median(luminance[lips])).mean()), 3),
            "band_luminance_p99": round(float(np.percentile(luminance[band], 99)), 1)}


def lip_figures(character, expression, size=512, engine="registers") -> dict:
    """The lips' red as seen from the front at the mouth's midline: the upper and the lower
    lip's height (mm, pixels of the recoloured lips in the 5 columns at the middle of the
    mouth's inner rim, scaled by the camera at the rim's depth), and the mouth's opening
    there (mm between the lips' red)."""
    from facsim.render.camera import project

    image, marked = _renders(character, expression, [{"lips": "#00ff00"}], size=size, antialias=1, engine=engine)
    # (Closed over a few pixels: a lip furrow or the wet glint can fail the recolouring test.)
    lips = ndimage.binary_closing(_changed(marked, image), structure=np.ones((5, 1)))
    with Face(character, engine=engine) as face:
        positions = np.asarray(face.deform(expression).positions)
        rim = face._mouth_rim
        # The rims' vertices nearest the midline: the lips meet (or part) between them.
        meeting = [rim_side[np.argmin(np.abs(positions[rim_side, 0]))] for rim_side in (rim.upper, rim.lower)]
        centre = positions[meeting].mean(axis=0)
        (a, b), _ = project(face.camera(size=(size, size)), [centre, centre + [0.01, 0.0, 0.0]], (size, size))
    mm_per_px = 1.0 / abs(b[0] - a[0])
    middle, split = int(round(a[0])), int(round(a[1]))
    heights = []
    for column in lips[:, middle - 2: middle + 3].T:
        upper, lower = np.flatnonzero(column[:split]), split + np.flatnonzero(column[split:])
        # Each lip's red is its run of pixels nearest the split (not a stray pixel beyond).
        upper = upper[upper > upper[-1] - np.r_[np.flatnonzero(np.diff(upper[::-1]) < -1), len(upper)][0] - 1]
        lower = lower[lower < lower[0] + np.r_[np.flatnonzero(np.diff(lower) > 1), len(lower)][0] + 1]
        heights.append((len(upper), len(lower), lower[0] - upper[-1] - 1))
    upper, lower, gap = np.median(np.array(heights), axis=0) * mm_per_px
    return {"upper_lip_mm": round(float(upper), 1), "lower_lip_mm": round(float(lower), 1),
            "opening_mm": round(float(gap), 1)}


def catch_light_figures(character, size=320) -> dict:
    image, marked = _renders(character, "", [{"iris": "#ff0000", "pupil": "#ff0000"}], size=size, antialias=1)
    bright = _changed(marked, image) & (image @ LUMINANCE > 120)
    half = size // 2
    counts = [ndimage.label(bright[:, side], structure=np.ones((3, 3)))[1]
              for side in (slice(0, half), slice(half, size))]
    return {"catch_lights_per_eye": counts, "catch_light_px": int(bright.sum())}


def three_quarter_figures(character, size=512) -> dict:
    image, iris_marked, pupil_marked, sclera_marked, lash_marked = _renders(
        character, "", [{"iris": "#ff0000"}, {"pupil": "#0000ff"}, {"sclera": "#00ff00"}, {"lashes": "#00ff00"}],
        size=size, view="three-quarter-left")
    iris = _changed(iris_marked, image)
    sclera = _changed(sclera_marked, image) & ~iris
    pupil = _changed(pupil_marked, image) & ~iris & ~sclera
    cornea, count = ndimage.label(iris | pupil)
    offsets = []
    for k in range(1, count + 1):
        piece = cornea == k
        if (piece & pupil).sum() > 5:
            offsets.append(round(float(np.nonzero(piece & pupil)[1].mean() - np.nonzero(piece)[1].mean()), 2))
    lash = np.abs(lash_marked - image).sum(-1) / 255.0
    below = np.zeros(lash.shape, bool)
    eyes, n_eyes = ndimage.label(ndimage.binary_dilation(sclera | iris | pupil, iterations=3))
    for k in range(1, n_eyes + 1):
        ys, xs = np.nonzero(eyes == k)
        if len(ys) > 20:
            below[ys.max() - 1: ys.max() + 12, xs.min(): xs.max() + 1] = True
    return {"pupil_offset_px": offsets, "lower_lash_cover": round(float(lash[below].sum()), 1)}


IRIS_DIAMETER_MM = 11.7  # facsim/render/shaders/face.frag.glsl IRIS_RADIUS on hm08's eyeball


def aperture_figures(character, expression, size=512, engine="registers") -> dict:
    """Sclera bared above and below the iris, per eye (mm, from the iris's width in pixels); the
    mean luminance of the visible iris's top third over its bottom third (the upper lid's shade
    and the cornea's caustic); the sclera's mean luminance (0-255)."""
    image, iris_marked, sclera_marked = _renders(character, expression, [{"iris": "#ff0000", "pupil": "#ff0000"},
                                                                         {"sclera": "#00ff00"}],
                                                 size=size, antialias=1, engine=engine)
    iris = _changed(iris_marked, image)
    sclera = _changed(sclera_marked, image) & ~iris
    eyes, count = ndimage.label(ndimage.binary_dilation(iris, iterations=2))
    luminance = image @ LUMINANCE
    above, below, shade, bared = [], [], [], []
    for k in sorted(range(1, count + 1), key=lambda k: np.nonzero(eyes == k)[1].mean()):
        ys, xs = np.nonzero(iris & (eyes == k))
        if len(ys) < 20:
            continue
        mm = IRIS_DIAMETER_MM / (xs.max() - xs.min() + 1)
        middle = slice(int(round(xs.mean())) - 1, int(round(xs.mean())) + 2)
        top, bottom = ys[np.abs(xs - xs.mean()) < 1.5].min(), ys[np.abs(xs - xs.mean()) < 1.5].max()
        column = sclera[:, middle].any(axis=1)
        above.append(round(float(column[max(top - 40, 0): top].sum() * mm), 1))
        below.append(round(float(column[bottom + 1: bottom + 41].sum() * mm), 1))
        half = np.zeros_like(sclera)
        half[:, : size // 2] = xs.mean() < size / 2
        half[:, size // 2:] = xs.mean() >= size / 2
        over = sclera & half
        over[top:] = False
        over[:, : xs.min()] = over[:, xs.max() + 1:] = False
        beside = sclera & half & (np.abs(np.arange(size) - ys.mean())[:, None] < 3)
        if over.sum() >= 5 and beside.sum():
            bared.append(round(float(luminance[over].mean() / luminance[beside].mean()), 2))
        visible = np.arange(ys.min(), ys.max() + 1)
        thirds = np.array_split(visible, 3)
        rows = [np.isin(ys, third) for third in (thirds[0], thirds[-1])]
        shade.append(round(float(luminance[ys[rows[0]], xs[rows[0]]].mean() / luminance[ys[rows[1]], xs[rows[1]]].mean()), 2))
    return {"sclera_above_mm": above, "sclera_below_mm": below, "above_over_beside": bared,
            "iris_top_over_bottom": shade,
            "sclera_luminance": round(float(luminance[sclera].mean()), 1)}


def sclera_figures(character, expression, size=448, engine="registers") -> dict:
    """The sclera's median and 95th-percentile luminance (0-255) against the cheek's (the skin
    in a 16 x 40 px patch 45 px under the eyes, left of the face's middle), the iris's median
    luminance and the pupil's width over the iris's (per eye), at ``size`` px, front, without
    anti-aliasing."""
    image, sclera_marked, iris_marked, pupil_marked, skin_marked = _renders(
        character, expression, [{"sclera": "#00ff00"}, {"iris": "#ffffff", "pupil": "#ffffff"},
                                {"pupil": "#ffffff"}, {"skin": "#00ff00"}], size=size, antialias=1, engine=engine)
    iris = _changed(iris_marked, image)
    sclera = _changed(sclera_marked, image) & ~iris
    pupil = _changed(pupil_marked, image)
    skin = _changed(skin_marked, image)
    luminance = image @ LUMINANCE
    below = int(np.nonzero(sclera)[0].mean()) + 45 * size // 448
    cheek = np.zeros_like(skin)
    cheek[below - 8: below + 8, 130 * size // 448: 170 * size // 448] = True
    cheek &= skin
    half = size // 2
    ratios = []
    for side in (slice(0, half), slice(half, size)):
        widths = [np.ptp(np.flatnonzero(mask[:, side].any(axis=0))) + 1 for mask in (pupil, iris)]
        ratios.append(round(float(widths[0] / widths[1]), 2))
    return {"sclera_p50_p95": [round(float(np.percentile(luminance[sclera], q)), 1) for q in (50, 95)],
            "cheek": round(float(np.median(luminance[cheek])), 1),
            "iris_p50": round(float(np.median(luminance[iris & ~pupil])), 1),
            "pupil_over_iris_width": ratios}


def per_eye(size, *masks):
    """Yield, the image's left eye then its right, copies of the (size, size) ``masks`` kept to
    that half of the image."""
    for side in (slice(0, size // 2), slice(size // 2, size)):
        own = [np.zeros_like(mask) for mask in masks]
        for kept, mask in zip(own, masks):
            kept[:, side] = mask[:, side]
        yield own


def iris_zones(luminance, iris, pupil):
    """One eye's ``luminance`` (H, W) over its ciliary zone (0.35-0.8 of the way from the pupil's
    rim to the limbus) and its pupillary zone (0.05-0.3), on the iris's lower half (clear of the
    lid's shade and the catch-light); ``iris`` and ``pupil`` are that eye's masks."""
    ys, xs = np.nonzero(iris)
    py, px = np.nonzero(pupil)
    radius, pupil_radius = (np.ptp(xs) + 1) / 2, (np.ptp(px) + 1) / 2
    t = (np.hypot(ys - py.mean(), xs - (xs.max() + xs.min()) / 2) - pupil_radius) / (radius - pupil_radius)
    below = ys > py.mean()
    zone = luminance[ys, xs]
    return zone[below & (t > 0.35) & (t < 0.8)], zone[below & (t > 0.05) & (t < 0.3)]


def iris_figures(character) -> dict:
    """The catch-light against the pupil at 768 px and the iris's streaks and pupillary ring at
    448 px (module docstring, ``--iris``), per eye, left to right."""
    figures = {"catch_gap_mm": [], "catch_right_mm": [], "catch_up_mm": [], "catch_mm2": [],
               "ciliary_spread": [], "pupillary_over_ciliary": []}
    size = 768
    image, cornea_marked, pupil_marked = _renders(character, "", [{"iris": "#ff0000", "pupil": "#ff0000"},
                                                                  {"pupil": "#00ff00"}], size=size, antialias=1)
    cornea = ndimage.binary_fill_holes(_changed(cornea_marked, image))
    pupil = ndimage.binary_fill_holes(_changed(pupil_marked, image))
    luminance = image @ LUMINANCE
    for eye, own_pupil in per_eye(size, cornea, pupil):
        px_per_mm = (np.ptp(np.flatnonzero(eye.any(axis=0))) + 1) / IRIS_DIAMETER_MM
        core = eye & (luminance > (luminance[eye].max() + np.median(luminance[eye])) / 2)
        (cy, cx), (py, px) = (np.mean(np.nonzero(mask), axis=1) for mask in (core, own_pupil))
        figures["catch_gap_mm"].append(round(float(ndimage.distance_transform_edt(~own_pupil)[core].min() / px_per_mm), 2))
        figures["catch_right_mm"].append(round(float((cx - px) / px_per_mm), 2))
        figures["catch_up_mm"].append(round(float((py - cy) / px_per_mm), 2))
        figures["catch_mm2"].append(round(float(core.sum() / px_per_mm ** 2), 2))
    size = 448
    image, iris_marked, pupil_marked = _renders(character, "", [{"iris": "#ff0000"}, {"pupil": "#00ff00"}], size=size)
    iris = ndimage.binary_erosion(_changed(iris_marked, image))
    pupil = ndimage.binary_fill_holes(_changed(pupil_marked, image))
    luminance = image @ LUMINANCE
    for eye, own_pupil in per_eye(size, iris, pupil):
        ciliary, pupillary = iris_zones(luminance, eye, own_pupil)
        figures["ciliary_spread"].append(round(float(ciliary.std() / ciliary.mean()), 3))
        figures["pupillary_over_ciliary"].append(round(float(pupillary.mean() / ciliary.mean()), 2))
    return figures


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("characters", nargs="*", default=["amara", "liam", "mei", "george"])
    parser.add_argument("--cavity", action="store_true", help="the open mouth's figures only")
    parser.add_argument("--engine", default="registers", choices=["registers", "muscle"])
    parser.add_argument("--expression", default="1+2+5+26", help="the open mouth's expression (--cavity)")
    parser.add_argument("--mucosa", action="store_true", help="the lips' mucosa figures only")
    parser.add_argument("--aperture", action="store_true",
                        help="sclera bared above and below the iris at rest, 5E, surprise and fear only")
    parser.add_argument("--lips", action="store_true", help="the lips' red heights at the midline, per expression")
    parser.add_argument("--teeth", action="store_true", help="the smile's upper teeth along the row at 448 px")
    parser.add_argument("--iris", action="store_true",
                        help="the catch-light against the pupil (768 px) and the iris's streaks (448 px), at rest")
    parser.add_argument("--sclera", action="store_true",
                        help="the sclera's and iris's luminance against the cheek's, and the pupil's width, at 448 px")
    args = parser.parse_args(argv)
    for name in args.characters:
        character = preset(name)
        if args.iris:
            print(name, "neutral", "  ".join(f"{k} {v}" for k, v in iris_figures(character).items()), flush=True)
            continue
        if args.sclera:
            for expression in ("", "1+2+5+26", "1+2+4+5+20+26"):
                figures = sclera_figures(character, expression, engine=args.engine)
                print(name, args.engine, expression or "neutral", "  ".join(f"{k} {v}" for k, v in figures.items()),
                      flush=True)
            continue
        if args.teeth:
            figures = teeth_row_figures(character, engine=args.engine)
            print(name, args.engine, "6+12+25", "  ".join(f"{k} {v}" for k, v in figures.items()), flush=True)
            continue
        if args.lips:
            for expression in LIP_EXPRESSIONS:
                figures = lip_figures(character, expression, engine=args.engine)
                print(name, args.engine, expression or "neutral", "  ".join(f"{k} {v}" for k, v in figures.items()),
                      flush=True)
            continue
        if args.mucosa:
            for expression in ("6+12+25", "1+2+5+26"):
                figures = mucosa_figures(character, expression, engine=args.engine)
                print(name, args.engine, expression, "  ".join(f"{k} {v}" for k, v in figures.items()), flush=True)
            continue
        if args.aperture:
            for expression in ("", "5E", "1+2+5+26", "1+2+4+5+20+26"):
                figures = aperture_figures(character, expression, engine=args.engine)
                print(name, args.engine, expression or "neutral", "  ".join(f"{k} {v}" for k, v in figures.items()),
                      flush=True)
            continue
        if args.cavity:
            figures = cavity_figures(character, args.expression, engine=args.engine)
            print(name, args.engine, args.expression, "  ".join(f"{k} {v}" for k, v in figures.items()), flush=True)
            continue
        figures = {**teeth_figures(character), **catch_light_figures(character), **three_quarter_figures(character)}
        print(name, "  ".join(f"{k} {v}" for k, v in figures.items()), flush=True)


if __name__ == "__main__":
    main()
