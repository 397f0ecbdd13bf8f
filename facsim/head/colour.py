"""Colour conversions: display sRGB ↔ linear light, and '#rrggbb' text.

Examples
--------
>>> hex_to_rgb("#ff8000")
(1.0, 0.5019607843137255, 0.0)
>>> round(float(linear_to_srgb(srgb_to_linear(0.5))), 6)
0.5
"""
from __future__ import annotations

import numpy as np


def srgb_to_linear(rgb) -> np.ndarray:
    """Display sRGB in [0, 1] → linear light (the exact IEC 61966-2-1 curve)."""
    rgb = np.asarray(rgb, float)
    return np.where(rgb <= 0.04045, rgb / 12.92, ((rgb + 0.055) / 1.055) ** 2.4)


def linear_to_srgb(rgb) -> np.ndarray:
    """Linear light → display sRGB in [0, 1] (clipped)."""
    rgb = np.clip(np.asarray(rgb, float), 0, 1)
    return np.where(rgb <= 0.0031308, rgb * 12.92, 1.055 * rgb ** (1 / 2.4) - 0.055)


def hex_to_rgb(text: str) -> tuple[float, float, float]:
    """'#rrggbb' → (r, g, b) in [0, 1]; a ValueError naming the expected form otherwise."""
    text = text.lstrip("#")
    if len(text) != 6 or any(c not in "0123456789abcdefABCDEF" for c in text):
        raise ValueError(f"colours are '#rrggbb' hex strings, got {'#' + text!r}")
    return tuple(int(text[i : i + 2], 16) / 255 for i in (0, 2, 4))
