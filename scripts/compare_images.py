"""Compare two golden-output folders: identical bytes, or the largest per-pixel
difference for images that differ (``python scripts/compare_images.py A B``)."""
import hashlib
import sys
from pathlib import Path

import numpy as np
from PIL import Image

a, b = (Path(p) for p in sys.argv[1:3])
worst = 0
for fa in sorted(p for p in a.rglob("*") if p.is_file()):
    fb = b / fa.relative_to(a)
    if not fb.exists():
        print(f"missing {fb}")
        worst = 999
        continue
    if hashlib.sha256(fa.read_bytes()).digest() == hashlib.sha256(fb.read_bytes()).digest():
        print(f"identical  {fa.relative_to(a)}")
        continue
    if fa.suffix == ".png":
        d = np.abs(np.asarray(Image.open(fa), np.int16) - np.asarray(Image.open(fb), np.int16)).max()
        worst = max(worst, int(d))
        print(f"differs    {fa.relative_to(a)}: max {d}/255 per pixel")
    else:
        worst = 999
        print(f"DIFFERS    {fa.relative_to(a)}")
print(f"worst difference: {worst}/255" if worst < 999 else "non-image files differ")
sys.exit(0 if worst <= 1 else 1)
