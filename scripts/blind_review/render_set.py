"""Render the blind-review set: 6 presets x 6 basic emotions x {100 %, 50 %} + neutral per preset (78 images)."""
import json, sys
from pathlib import Path
import facsim
from facsim.facs.emotions import emotion

out = Path(sys.argv[1]); out.mkdir(parents=True, exist_ok=True)
presets = ["ava", "liam", "amara", "kwame", "mei", "george"]
emotions = ["happiness", "sadness", "surprise", "anger", "fear", "disgust"]
items = []
for c in presets:
    face = facsim.Face(c)
    for e in emotions:
        for level in (1.0, 0.5):
            name = f"{c}_{e}_{int(level*100)}"
            face.save(out / f"{name}.png", emotion(e, intensity=level), size=320)
            items.append({"file": f"{name}.png", "character": c, "emotion": e, "intensity": level})
    face.save(out / f"{c}_neutral_0.png", None, size=320)
    items.append({"file": f"{c}_neutral_0.png", "character": c, "emotion": "neutral", "intensity": 0})
    face.close()
(out / "key.json").write_text(json.dumps(items, indent=1))
print(len(items))
