"""Print objective figures for the skin, eyes and lips as rendered, per character.

Front view at 512², neutral face, the renderer's default anti-aliasing.

Skin (and lips): the specular share of the light leaving the skin, per region. The frame is
rendered twice, the second time with the skin's colours (skin, cheek, eyelid, lips) at half
their linear reflectance; the display transform (sRGB, the filmic curve) is inverted per
pixel, so each pixel's linear radiance L = D + S splits into diffuse D = 2 (L1 - L2) and
specular S = L1 - D (luminance). Regions are small boxes at landmarks (both sides pooled):

- ``cheek``: mean S / L on the cheeks (a photograph of skin: a few per cent);
- ``cheek S/D``: the same boxes' specular over their diffuse light (how far the sheen
  stands out of the skin's own colour: dark skin's is larger for the same sheen);
- ``forehead``, ``nose``, ``lower lip``: the same over the forehead's centre, the nose tip, the
  lower lip;
- ``hl area``: the share of the face's skin pixels (between the brows' outer ends and the
  chin) where S is over 30 % of L: how much of the face reads as highlight;
- ``speckle``: over the forehead box, the mean absolute difference of S between neighbouring
  pixels over the mean S: a broad soft sheen is near 0, a glittering film of specks high.
- ``L*``, ``C*``, ``hue``: the cheeks' colour as displayed (the median over the same boxes'
  pixels, CIELAB under D65: lightness, chroma, hue angle in degrees). Skin measured in vivo
  lies near C* 17-23 and hue 50-65 degrees whatever its lightness (light skin about L* 65, a*
  11, b* 15; dark skin about L* 40, a* 11, b* 18); scikit-image's studio portrait of Eileen
  Collins (``skimage.data.astronaut()``) shows her cheeks at L* 76-81, C* 19, hue 66-70.
- ``sheen grain``, ``tone grain``: the pixel-scale grain (pores and fine lines in aggregate) of
  the specular S over the forehead and nose boxes and of the diffuse D over the larger cheek
  boxes: each over itself blurred by 1.5 px, its standard deviation in per cent.
- ``px step``: the displayed grey level's mean step between neighbouring pixels over the forehead
  box (a studio portrait's skin, ``skimage.data.astronaut()``, at ~1 px per mm: 3.4-4.5).
- ``mid tone`` and ``mid hue``: the skin's unevenness between ~3 and ~20 mm on the cheeks (boxes
  16 mm across), what a face at 448-512 px shows most: the image (made linear) blurred over 1.5
  mm less it blurred over 6 mm, both within the face, as robust standard deviations
  (interquartile range / 1.349, so a mole does not count) in per cent of its luminance's log and of
  its hue (R - G) / (R + G). ``--astronaut`` prints the same for the studio portrait's cheeks
  (``skimage.data.astronaut()``, ~1.4 mm per px: mid tone 5.5, mid hue 1.8; its smile's raised
  cheeks add to its tone).
- ``fine tone``: the same over the same boxes between ~2 and ~10 mm (blurred over 0.7 mm less blurred
  over 3 mm): the skin's mottling, which a face at 448-512 px shows pixel by pixel (main 67a54cb: ava
  2.4, mei 2.4, liam 1.6 at 448 px; george, 72, 3.7).
- ``sheen fine``: the share of the forehead's highlight energy in detail finer than ~2 px: over the
  forehead box's brightest third of the specular light S blurred over 2 px, the mean absolute
  difference between S and its blur over the mean S. One smooth glaze is near 0; a sheen broken by
  the skin's relief into facets catching the light higher (main 67a54cb at 448 px: kwame 0.21).
- ``tone cv`` and ``hue sd``: the skin's own unevenness on the cheeks (larger boxes): the
  diffuse light D over D blurred by 8 px (the shading's slow change removed), its standard
  deviation (per cent); and the standard deviation of the diffuse light's hue,
  (R - G) / (R + G), over the same pixels, times 100 (blood and pigment vary the hue; a
  grey noise does not).

Eyes: the iris's pixels (found by rendering again with the iris in a loud colour, as
``scripts/eyes_mouth_figures.py`` does): mean HSV saturation and value; the sclera's
pixels likewise: mean RGB and its warmth (R - B, 0-255), and the upper band's luminance
(the sclera's top quarter by rows) against its whole (the lid's shade on the eyeball).

Usage::

    python3 scripts/skin_figures.py [CHARACTER ...]   (default: amara kwame ngozi kofi ava mei george)
"""
from __future__ import annotations

import argparse
import dataclasses

import numpy as np
from skimage.color import rgb2lab

from facsim import Face
from facsim.head.character import preset
from facsim.render.camera import project

SIZE = 512
LUMINANCE = np.array([0.2126, 0.7152, 0.0722])
SKIN_COLOURS = ("skin", "cheek", "eyelid", "lips")
SHOULDER = 0.55  # facsim/render/shaders/common.glsl tonemap()


def srgb_to_linear(c):
    c = np.asarray(c, float)
    return np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)


def linear_to_srgb(c):
    c = np.clip(np.asarray(c, float), 0, 1)
    return np.where(c <= 0.0031308, 12.92 * c, 1.055 * c ** (1 / 2.4) - 0.055)


def _tonemap(c):
    c = np.maximum(c, 0.0)
    c = c * (c + 0.012) / (c + 0.02)
    over = np.maximum(c - SHOULDER, 0.0) / (1.0 - SHOULDER)
    return np.minimum(c, SHOULDER) + (1.0 - SHOULDER) * (1.0 - np.exp2(-1.442695 * over))


_GRID = np.concatenate([np.linspace(0, 1, 20000) ** 2 * 8.0])
_CURVE = _tonemap(_GRID)


def radiance(image):
    """Linear radiance (times the exposure) of a display-sRGB uint8 image's RGB."""
    tonemapped = srgb_to_linear(image[..., :3].astype(float) / 255)
    return np.interp(tonemapped, _CURVE, _GRID)


def _render(face, appearance, deformation):
    camera = face.camera(size=(SIZE, SIZE))
    positions = np.asarray(deformation.positions, np.float32)
    image = face.renderer(size=SIZE, body="none").render(
        positions, appearance=appearance, camera=camera, wrinkle=deformation.wrinkle,
        crease_phase=deformation.crease_phase, occlusion=face.frame_occlusion(positions),
        lids=face.frame_lids(positions), proxies=face.proxy_draws(positions))
    return image[..., :3], camera


def _box(camera, points, r):
    """Boolean mask: squares of half-size ``r`` px around world ``points``."""
    mask = np.zeros((SIZE, SIZE), bool)
    for x, y in project(camera, np.asarray(points), SIZE)[0]:
        x, y = int(x), int(y)
        mask[max(y - r, 0):y + r + 1, max(x - r, 0):x + r + 1] = True
    return mask


def mid_scale_unevenness(image, mask, px_per_mm, fine=1.5, coarse=6.0):
    """(luminance, hue) unevenness in per cent between ``fine`` and ``coarse`` mm over ``mask``
    (see the module's ``mid tone`` and ``mid hue``); the background (near white) is left out of
    the blurs."""
    from scipy.ndimage import gaussian_filter

    linear = radiance(image)
    inside = (image[..., :3].min(-1) < 235).astype(float)

    def blur(mm):
        weight = np.maximum(gaussian_filter(inside, mm * px_per_mm), 1e-3)
        return np.stack([gaussian_filter(linear[..., c] * inside, mm * px_per_mm) / weight for c in range(3)], -1) + 1e-4
    f, c = blur(fine), blur(coarse)
    band = np.log(f @ LUMINANCE) - np.log(c @ LUMINANCE)
    hue = (f[..., 0] - f[..., 1]) / (f[..., 0] + f[..., 1]) - (c[..., 0] - c[..., 1]) / (c[..., 0] + c[..., 1])
    spread = lambda x: np.subtract(*np.percentile(x[mask], [75, 25])) / 1.349   # noqa: E731
    return 100 * spread(band), 100 * spread(hue)


def astronaut_figures():
    """``mid tone`` and ``mid hue`` on the cheeks of ``skimage.data.astronaut()`` (a studio
    portrait: pupils 44 px apart, ~63 mm)."""
    from skimage import data

    image = data.astronaut()
    cheeks = np.zeros(image.shape[:2], bool)
    cheeks[112:126, 192:208] = True
    cheeks[110:123, 242:258] = True
    return dict(zip(("mid tone", "mid hue"), mid_scale_unevenness(image, cheeks, 44 / 63)))


def _hsv(rgb):
    rgb = rgb / 255.0
    v = rgb.max(-1)
    s = np.where(v > 0, (v - rgb.min(-1)) / np.maximum(v, 1e-6), 0)
    return s, v


def figures(name, expression=""):
    face = Face(preset(name))
    try:
        from facsim.head.landmarks import landmarks

        marks = landmarks(face.head)
        deformation = face.deform(expression)
        p = np.asarray(deformation.positions, float)
        base = face.appearance
        image, camera = _render(face, base, deformation)
        darker = {k: tuple(linear_to_srgb(0.5 * srgb_to_linear(base.colors[k]))) for k in SKIN_COLOURS}
        half, _ = _render(face, dataclasses.replace(base, colors={**base.colors, **darker}), deformation)
        full_light, half_light = radiance(image), radiance(half)
        l1, l2 = full_light @ LUMINANCE, half_light @ LUMINANCE
        diffuse = np.clip(2 * (l1 - l2), 0, None)
        specular = np.clip(l1 - diffuse, 0, None)
        share = specular / np.maximum(l1, 1e-4)

        def pt(key):
            return p[marks[key]]
        regions = {
            "cheek": _box(camera, [pt("cheek_left") + [-0.08, 0.05, 0.1], pt("cheek_right") + [0.08, 0.05, 0.1]], 6),
            "forehead": _box(camera, [pt("glabella") + [0.0, 0.25, -0.03]], 8),
            "nose": _box(camera, [pt("nose_tip")], 4),
            "lower lip": _box(camera, [pt("lower_lip") + [0.0, 0.012, 0.0]], 4),
        }
        out = {k: float(np.sum(specular[m]) / np.maximum(np.sum(l1[m]), 1e-6)) for k, m in regions.items()}
        out["cheek S/D"] = float(np.sum(specular[regions["cheek"]]) / max(np.sum(diffuse[regions["cheek"]]), 1e-6))
        # The skin's unevenness: per-channel diffuse light, the slow shading divided out.
        from scipy.ndimage import gaussian_filter

        diffuse_rgb = np.clip(2 * (full_light - half_light), 1e-4, None)
        cheeks = _box(camera, [pt("cheek_left") + [-0.1, 0.02, 0.1], pt("cheek_right") + [0.1, 0.02, 0.1]], 14)
        d = diffuse_rgb @ LUMINANCE
        cheek_lab = np.median(rgb2lab(image[regions["cheek"]] / 255.0), axis=0)
        out["L*"], out["C*"] = float(cheek_lab[0]), float(np.hypot(cheek_lab[1], cheek_lab[2]))
        out["hue"] = float(np.degrees(np.arctan2(cheek_lab[2], cheek_lab[1])))
        a, b = project(camera, [pt("cheek_left"), pt("cheek_left") + [0.1, 0.0, 0.0]], SIZE)[0]
        px_per_mm = float(np.hypot(*(b - a))) / 10
        mid = _box(camera, [pt("cheek_left") + [-0.08, 0.02, 0.1], pt("cheek_right") + [0.08, 0.02, 0.1]],
                   int(8 * px_per_mm))
        out["mid tone"], out["mid hue"] = mid_scale_unevenness(image, mid, px_per_mm)
        out["fine tone"] = mid_scale_unevenness(image, mid, px_per_mm, fine=0.7, coarse=3.0)[0]
        out["tone cv"] = float(100 * np.std((d / np.maximum(gaussian_filter(d, 8), 1e-6))[cheeks]))
        r, g = diffuse_rgb[..., 0][cheeks], diffuse_rgb[..., 1][cheeks]
        out["hue sd"] = float(100 * np.std((r - g) / (r + g)))
        (x0, _), (x1, _) = project(camera, [pt("outer_brow_left"), pt("outer_brow_right")], SIZE)[0]
        (_, y0), = project(camera, [pt("outer_brow_left")], SIZE)[0]
        (_, y1), = project(camera, [pt("chin")], SIZE)[0]
        face_box = np.zeros((SIZE, SIZE), bool)
        face_box[int(y0):int(y1), int(min(x0, x1)):int(max(x0, x1))] = True
        # The skin's own pixels: those that darkened with the skin's colours.
        skin = face_box & (np.abs(image.astype(float) - half.astype(float)).sum(-1) > 6)
        out["hl area"] = float((share[skin] > 0.3).mean())
        forehead = regions["forehead"]
        ys, xs = np.nonzero(forehead)
        patch = specular[ys.min():ys.max() + 1, xs.min():xs.max() + 1]
        smooth = gaussian_filter(specular, 2.0)[ys.min():ys.max() + 1, xs.min():xs.max() + 1]
        brightest = smooth > np.percentile(smooth, 67)
        out["sheen fine"] = float(np.abs(patch - smooth)[brightest].sum() / max(patch[brightest].sum(), 1e-9))
        out["speckle"] = float(np.abs(np.diff(patch, axis=1)).mean() / max(patch.mean(), 1e-6))
        # The sheen's and the colour's pixel-scale grain (pores and fine lines, in aggregate):
        # the specular S on the forehead's and nose's boxes, the diffuse D on the cheeks', each
        # over itself blurred by 1.5 px; standard deviations in per cent.
        t_zone = regions["forehead"] | regions["nose"]
        out["sheen grain"] = float(100 * np.std((specular / np.maximum(gaussian_filter(specular, 1.5), 1e-6))[t_zone]))
        out["tone grain"] = float(100 * np.std((d / np.maximum(gaussian_filter(d, 1.5), 1e-6))[cheeks]))
        # As displayed: the mean step of the pixels' grey level (0-255) from each to its right-hand
        # neighbour over the forehead's box (skimage.data.astronaut()'s cheeks and forehead, a studio
        # portrait at ~1 px per mm: 3.4-4.5).
        grey = image.astype(float).mean(-1)[ys.min():ys.max() + 1, xs.min():xs.max() + 1]
        out["px step"] = float(np.abs(np.diff(grey, axis=1)).mean())

        # Eyes: recolour the iris / sclera and keep the changed pixels.
        def part(key, colour):
            marked, _ = _render(face, dataclasses.replace(base, colors={**base.colors, key: colour}), deformation)
            return np.abs(marked.astype(float) - image.astype(float)).sum(-1) > 60
        iris = part("iris", (1.0, 1.0, 1.0))
        sclera = part("sclera", (0.0, 0.0, 0.0)) & ~iris
        s, v = _hsv(image[iris].astype(float))
        out["iris sat"], out["iris val"] = float(s.mean()), float(v.mean())
        sc = image[sclera].astype(float)
        out["sclera L"] = float((sc @ LUMINANCE).mean())
        out["sclera R-B"] = float((sc[:, 0] - sc[:, 2]).mean())
        rows = np.nonzero(sclera)[0]
        top = sclera & (np.arange(SIZE)[:, None] < np.percentile(rows, 25))
        out["sclera top/all"] = float((image[top].astype(float) @ LUMINANCE).mean() / out["sclera L"])
        return out
    finally:
        face.close()


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("characters", nargs="*", default=["amara", "kwame", "ngozi", "kofi", "ava", "mei", "george"])
    parser.add_argument("--expression", default="")
    parser.add_argument("--astronaut", action="store_true", help="also the studio portrait's mid tone and hue")
    args = parser.parse_args(argv)
    if args.astronaut:
        print("astronaut " + "  ".join(f"{k} {v:.2f}" for k, v in astronaut_figures().items()))
    keys = None
    for name in args.characters:
        out = figures(name, args.expression)
        if keys is None:
            keys = list(out)
            print(f"{'':8s}" + "".join(f"{k:>15s}" for k in keys))
        print(f"{name:8s}" + "".join(f"{out[k]:15.3f}" for k in keys))


if __name__ == "__main__":
    main()
