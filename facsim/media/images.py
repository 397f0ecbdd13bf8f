"""Image files: write a rendered frame as PNG.

Examples
--------
>>> import tempfile, pathlib
>>> out = pathlib.Path(tempfile.mkdtemp()) / "dot.png"
>>> write_png(out, np.zeros((2, 3, 4), dtype=np.uint8)).name
'dot.png'
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from facsim.atomic import atomic_write


def write_png(path, image: np.ndarray) -> Path:
    """Write an (H, W, 3|4) uint8 image as PNG atomically (see :mod:`facsim.atomic`)."""
    from PIL import Image

    arr = np.asarray(image)
    if arr.dtype != np.uint8 or arr.ndim != 3 or arr.shape[2] not in (3, 4):
        raise ValueError(f"image must be (H, W, 3 or 4) uint8, got {arr.dtype} {arr.shape}")
    mode = "RGBA" if arr.shape[2] == 4 else "RGB"
    return atomic_write(path, lambda tmp: Image.fromarray(arr, mode).save(tmp, format="PNG"))
