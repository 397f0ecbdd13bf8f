"""Shuffle sets together into numbered contact sheets (6 a sheet).

Usage: ``make_sheets.py ROOT [SET ...]`` (default sets: before after), each a folder of ROOT from render_set.py.
"""
import json, random, sys
from pathlib import Path
from PIL import Image, ImageDraw, ImageFont

root = Path(sys.argv[1])  # holds before/ and after/ from render_set.py
items = []
for phase in sys.argv[2:] or ("before", "after"):
    for it in json.loads((root / phase / "key.json").read_text()):
        items.append({**it, "phase": phase, "path": str(root / phase / it["file"])})
random.Random(2026).shuffle(items)
sheets = root / "sheets"; sheets.mkdir(exist_ok=True)
font = ImageFont.load_default(size=28) if hasattr(ImageFont, "load_default") else None
key = []
for s in range(0, len(items), 6):
    sheet = Image.new("RGB", (3 * 320, 2 * 320 + 2 * 36), "white")
    d = ImageDraw.Draw(sheet)
    for k, it in enumerate(items[s:s + 6]):
        n = s + k + 1
        im = Image.open(it["path"]).convert("RGBA")
        if im.size != (320, 320):  # renders of any size fill the cell whole (pasted as-is, 448² lost the mouth)
            im = im.resize((320, 320), Image.LANCZOS)
        bg = Image.new("RGBA", im.size, "white"); bg.alpha_composite(im)
        x, y = (k % 3) * 320, (k // 3) * (320 + 36)
        sheet.paste(bg.convert("RGB"), (x, y + 36))
        d.text((x + 8, y + 2), f"#{n}", fill="black", font=font)
        key.append({"id": n, **{k2: v for k2, v in it.items() if k2 != "path"}})
    sheet.save(sheets / f"sheet_{s // 6 + 1:02d}.png")
(root / "private_key.json").write_text(json.dumps(key, indent=1))
print(len(items), "images on", (len(items) + 5) // 6, "sheets")
