"""How much a hairstyle's inside varies in brightness: strand and clump detail against a flat, painted mass.

Renders a character's neutral face twice on a transparent background (with its hair and with
``--hair none``) and takes as the hair the pixels the hair changes (any channel by more than
0.15), fully covered in both, eroded by 2 pixels so outlines and cast-shadow edges do not
count. On their luminance (Rec. 709 weights on the sRGB values) it prints

- ``fine``: the standard deviation of the luminance minus its Gaussian blur (sigma 2 px), over
  the mean luminance: detail one to a few pixels across (strands, clumps, broken highlights);
  a flat, clay-like mass gives a figure near 0;
- ``mass``: the standard deviation of the blurred luminance over its mean: the volume's shading
  and large locks;
- ``pixels``: how many pixels were measured;
- ``ends``: below the jaw (the image's lowest 3/8), of the pixels where the hair covers the
  background at all (alpha over 0.08 with hair, under 0.01 without), the share it covers only
  partly (alpha under 0.92): long hair ending in a translucent film (pale smears and streaks
  against a light background) gives a high figure, strands ending solid a low one;
- ``streaks``: how far the hair's detail runs in streaks one way (strands) rather than in
  blotches (clumps, mottled stone): the coherence (lambda1 - lambda2) / (lambda1 + lambda2) of the
  luminance's structure tensor (Sobel gradients, Gaussian sigma 2 px), averaged over the hair
  pixels weighted by the gradient energy; 0 for blotches that vary alike every way, 1 for
  parallel streaks;
- ``hairline``: in the middle fifth of the columns, the mean luminance of the hair 2-9 px
  above the forehead's hairline (the lowest pixel above 35 % of the height darker than 0.6 of
  the forehead there; for hair darker than the skin) over the hair's mean luminance: hair drawn
  in the shade of the cards' edge, a dark brim along the forehead, gives a low figure;
- ``crown``: on the crown (hair pixels from the top of the image to 4 % of its height below the
  top of the skin, in the middle 40 % of its width), the standard deviation of the luminance's
  band-pass down the columns (Gaussian 1.5 px minus 6 px) over the mean: rows of cards drawn
  as horizontal bands across the crown (long01) give a high figure;
- ``flow``: on the crown (hair pixels above 4 % of the height below the top of the skin), how far
  the hair's detail runs down its flow from the crown (out from a point 5 % of the height above
  the hair's top, over the middle of its columns), as a combed head of hair's strands, locks
  and partings do: the luminance's structure tensor (Sobel gradients, Gaussian sigma 2 px)
  gives each pixel its streaks' direction; the figure is the mean of cos(2 x their angle to
  the flow) weighted by the tensor's anisotropic energy: 1 for streaks all along the flow, 0
  for no preferred direction, -1 across it. Cards drawn as blocks and rows of wood grain across
  the flow give a low figure.

    PYTHONPATH=. python3 benchmarks/bench_hair_texture.py [--character liam] [--view front] [--size 512]
"""
from __future__ import annotations

import argparse
import sys

import numpy as np


def hair_mask(with_hair: np.ndarray, without_hair: np.ndarray, *, change: float = 0.15, erode: int = 2) -> np.ndarray:
    """(H, W) bool: pixels of two (H, W, 4) uint8 RGBA renders that the hair changes, fully covered
    in both, eroded by ``erode`` pixels."""
    from scipy.ndimage import binary_erosion

    a, b = with_hair.astype(np.float32) / 255.0, without_hair.astype(np.float32) / 255.0
    changed = np.abs(a[..., :3] - b[..., :3]).max(axis=-1) > change
    covered = (a[..., 3] > 0.99) & ((b[..., 3] > 0.99) | (b[..., 3] < 0.01))
    return binary_erosion(changed & covered, iterations=erode)


def luminance_variation(image: np.ndarray, mask: np.ndarray, *, sigma: float = 2.0) -> tuple[float, float]:
    """(fine, mass): the relative standard deviations of the luminance's detail finer than
    ``sigma`` pixels and of its blurred part, over the pixels in ``mask``."""
    from scipy.ndimage import gaussian_filter

    rgb = image[..., :3].astype(np.float32) / 255.0
    lum = rgb @ np.array([0.2126, 0.7152, 0.0722], np.float32)
    # Blur inside the mask only (normalised convolution), so the skin and background around
    # the hair do not leak into its blurred brightness.
    weight = gaussian_filter(mask.astype(np.float32), sigma)
    blurred = gaussian_filter(lum * mask, sigma) / np.maximum(weight, 1e-6)
    mean = float(lum[mask].mean())
    return float((lum - blurred)[mask].std() / mean), float(blurred[mask].std() / mean)


def streak_coherence(image: np.ndarray, mask: np.ndarray, *, sigma: float = 2.0) -> float:
    """The ``streaks`` figure (module docstring) of an (H, W, 4) uint8 render over ``mask``."""
    from scipy.ndimage import gaussian_filter, sobel

    lum = image[..., :3].astype(np.float32) @ np.array([0.2126, 0.7152, 0.0722], np.float32)
    gx, gy = sobel(lum, axis=1), sobel(lum, axis=0)
    jxx, jyy, jxy = (gaussian_filter(g, sigma) for g in (gx * gx, gy * gy, gx * gy))
    energy = jxx + jyy
    coherence = np.sqrt((jxx - jyy) ** 2 + 4.0 * jxy ** 2) / np.maximum(energy, 1e-6)
    weight = energy[mask]
    return float((coherence[mask] * weight).sum() / max(float(weight.sum()), 1e-6))


def hairline_band(image: np.ndarray, mask: np.ndarray, *, rows: tuple[int, int] = (2, 9)) -> tuple[float, int]:
    """(figure, columns): the ``hairline`` figure (module docstring) of an (H, W, 4) uint8 render
    with its hair ``mask`` (:func:`hair_mask`), and over how many columns it was taken."""
    lum = image[..., :3].astype(np.float32) @ np.array([0.2126, 0.7152, 0.0722], np.float32) / 255.0
    h, w = lum.shape
    forehead = int(0.35 * h)
    band = []
    for x in range(int(0.4 * w), int(0.6 * w)):
        dark = np.nonzero(lum[:forehead, x] < 0.6 * lum[forehead, x])[0]
        if len(dark) and dark.max() > rows[1]:
            edge = dark.max()
            band.append(lum[edge - rows[1]:edge - rows[0] + 1, x])
    if not band or not mask.any():
        return 0.0, 0
    return float(np.mean(band) / lum[mask].mean()), len(band)


def partial_cover_below_jaw(with_hair: np.ndarray, without_hair: np.ndarray) -> tuple[float, int]:
    """(share, pixels): of the pixels in the lowest 3/8 of two (H, W, 4) uint8 RGBA renders on a
    transparent background where the hair covers the background (see the module docstring),
    the share it covers only partly, and how many there are."""
    below = slice(int(0.625 * with_hair.shape[0]), None)
    cover = with_hair[below, :, 3].astype(np.float32) / 255.0
    touched = (without_hair[below, :, 3] < 3) & (cover > 0.08)
    partial = touched & (cover < 0.92)
    return float(partial.sum() / max(touched.sum(), 1)), int(touched.sum())


def crown_banding(image: np.ndarray, mask: np.ndarray, without_hair: np.ndarray) -> tuple[float, int]:
    """(banding, pixels): the ``crown`` figure (module docstring) of an (H, W, 4) uint8 render
    with hair, its hair ``mask`` (:func:`hair_mask`) and the render without hair."""
    from scipy.ndimage import gaussian_filter1d

    h, w = mask.shape
    skin_rows = np.nonzero((without_hair[..., 3] > 250).any(axis=1))[0]
    crown = mask.copy()
    crown[(skin_rows.min() if len(skin_rows) else h) + int(0.04 * h):] = False
    crown[:, : int(0.3 * w)] = False
    crown[:, int(0.7 * w):] = False
    lum = image[..., :3].astype(np.float32) @ np.array([0.2126, 0.7152, 0.0722], np.float32)
    band = gaussian_filter1d(lum, 1.5, axis=0) - gaussian_filter1d(lum, 6.0, axis=0)
    return (float(band[crown].std() / lum[crown].mean()) if crown.any() else 0.0), int(crown.sum())


def flow_alignment(image: np.ndarray, mask: np.ndarray, without_hair: np.ndarray, *,
                   sigma: float = 2.0) -> tuple[float, int]:
    """(alignment, pixels): the ``flow`` figure (module docstring) of an (H, W, 4) uint8 render
    with hair, its hair ``mask`` (:func:`hair_mask`) and the render without hair."""
    from scipy.ndimage import gaussian_filter, sobel

    h, w = mask.shape
    rows, columns = np.nonzero(mask.any(axis=1))[0], np.nonzero(mask.any(axis=0))[0]
    skin_rows = np.nonzero((without_hair[..., 3] > 250).any(axis=1))[0]
    if not len(rows) or not len(skin_rows):
        return 0.0, 0
    crown = mask.copy()
    crown[skin_rows.min() + int(0.04 * h):] = False
    lum = image[..., :3].astype(np.float32) @ np.array([0.2126, 0.7152, 0.0722], np.float32)
    gx, gy = sobel(lum, axis=1), sobel(lum, axis=0)
    jxx, jyy, jxy = (gaussian_filter(g, sigma) for g in (gx * gx, gy * gy, gx * gy))
    y, x = np.mgrid[0:h, 0:w].astype(np.float64)
    fx, fy = x - 0.5 * (columns.min() + columns.max()), y - (rows.min() - 0.05 * h)
    f2 = fx * fx + fy * fy + 1e-9
    # (double angles: the gradient's (jxx - jyy, 2 jxy), the flow's (fx² - fy², 2 fx fy) / |f|²;
    # streaks run across their gradient, hence the minus sign)
    gradient_c, gradient_s = jxx - jyy, 2.0 * jxy
    along = -(gradient_c * (fx * fx - fy * fy) + gradient_s * 2.0 * fx * fy) / f2
    anisotropy = np.sqrt(gradient_c ** 2 + gradient_s ** 2)
    if not crown.any():
        return 0.0, 0
    return float(along[crown].sum() / max(float(anisotropy[crown].sum()), 1e-9)), int(crown.sum())


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--character", default="liam")
    parser.add_argument("--view", default="front")
    parser.add_argument("--size", type=int, default=512)
    args = parser.parse_args(argv)

    from facsim.face import Face
    from facsim.head.character import resolve_character

    character = resolve_character(args.character)
    images = [Face(c).render(None, size=args.size, view=args.view, background=None)
              for c in (character, character.with_(hair="none"))]
    mask = hair_mask(*images)
    fine, mass = luminance_variation(images[0], mask)
    print(f"{args.character} {args.view}: fine {fine:.3f}, mass {mass:.3f} over {int(mask.sum())} hair pixels "
          f"({args.size}²)")
    print(f"streaks: {streak_coherence(images[0], mask):.3f} coherence of the hair's detail")
    band, columns = hairline_band(images[0], mask)
    print(f"hairline: {band:.3f} the hair just above the forehead's hairline over the hair's mean, {columns} columns")
    banding, pixels = crown_banding(images[0], mask, images[1])
    print(f"crown: {banding:.3f} band-pass down the columns over {pixels} crown pixels")
    alignment, pixels = flow_alignment(images[0], mask, images[1])
    print(f"flow: {alignment:.3f} the crown's detail along the hair's flow, over {pixels} crown pixels")
    share, pixels = partial_cover_below_jaw(*images)
    print(f"ends: {share:.3f} of {pixels} hair pixels over the background below the jaw only partly covered")
    return 0


if __name__ == "__main__":
    sys.exit(main())
