"""Render the blind-review set: 6 presets x 6 basic emotions x {100 %, 50 %} + neutral per preset (78 images).

Example: ``python scripts/blind_review/render_set.py /work/blind/after --engine muscle --size 320``
"""
import argparse
import json
from pathlib import Path

import facsim
from facsim.facs.emotions import emotion

PRESETS = ["ava", "liam", "amara", "kwame", "mei", "george"]
EMOTIONS = ["happiness", "sadness", "surprise", "anger", "fear", "disgust"]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out", type=Path)
    parser.add_argument("--engine", default="registers", choices=["registers", "muscle"])
    parser.add_argument("--size", type=int, default=320)
    args = parser.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    items = []
    for character in PRESETS:
        face = facsim.Face(character, engine=args.engine)
        for name, level in [(e, lv) for e in EMOTIONS for lv in (1.0, 0.5)] + [("neutral", 0)]:
            file = f"{character}_{name}_{int(level * 100)}.png"
            expression = None if name == "neutral" else emotion(name, intensity=level)
            face.save(args.out / file, expression, size=args.size)
            items.append({"file": file, "character": character, "emotion": name, "intensity": level,
                          "engine": args.engine})
        face.close()
    (args.out / "key.json").write_text(json.dumps(items, indent=1))
    print(len(items))


if __name__ == "__main__":
    main()
