"""Score facsim's emotions the way a photo-trained panel does: render the blind-review set, rate it, tabulate.

    python scripts/panel/score.py --engine registers,muscle --characters ava,liam,amara,kwame,mei,george
    python scripts/panel/score.py --photos          # sanity check on real photographs only

For each engine: every character × emotion × intensity (default the six basic
emotions at 100 % and 50 %) plus each character's neutral face is rendered
front-on with facsim's own API, rated by each photo-trained rater of the panel
(:mod:`rater`: FER2013 mini-Xception; :mod:`faceapi`: face-api.js's
FaceExpressionNet) and summarised per rater: recognition per emotion and
intensity, the confusion table, the mean probability of the intended label,
and recognition averaged over a grid of 12 crops (a single crop's verdicts move
by several points when the box moves by a few pixels; the grid figure is the
steadier one to compare changes with). ``--out DIR`` keeps the renders and
writes ``results.json`` (every reading). Same inputs → same figures.
"""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from rater import CROP_GRID, FER_LABEL, LABELS, RATERS, Panel, RaterError

BASIC = ("happiness", "sadness", "surprise", "anger", "fear", "disgust")
BLIND_REVIEW_PRESETS = ("ava", "liam", "amara", "kwame", "mei", "george")
#: The issue's goals for the panel: emotions at 100 % and at 50 %.
GOALS = {1.0: 0.85, 0.5: 0.75}


class UsageError(ValueError):
    """Bad command-line input; main() prints it on one line and exits 2."""


# ------------------------------------------------------------------ the set

def stimulus_items(characters, emotions, intensities):
    """The stimuli as plain dicts (character, emotion, intensity), neutral once per character."""
    items = []
    for character in characters:
        for name in emotions:
            for level in intensities:
                items.append({"character": character, "emotion": name, "intensity": level})
        items.append({"character": character, "emotion": "neutral", "intensity": 0.0})
    return items


def render_and_rate(engine: str, items, panel: Panel, *, size: int, out: Path | None = None, log=None):
    """Render each item with ``engine`` and rate it; one row per item and rater, ``reading`` None: no face."""
    import facsim
    from facsim.facs.emotions import emotion

    rows, faces = [], {}
    try:
        for n, item in enumerate(items, 1):
            character = item["character"]
            if character not in faces:
                for old in faces.values():
                    old.close()
                faces = {character: facsim.Face(character, engine=engine)}
            expression = None if item["emotion"] == "neutral" else emotion(item["emotion"], intensity=item["intensity"])
            try:
                image = faces[character].render(expression, size=size)
            except ValueError as exc:   # e.g. a solver that diverged: record it, go on with the rest of the set
                rows.extend({**item, "engine": engine, "rater": rater.name, "reading": None, "error": str(exc)}
                            for rater in panel.raters)
                if log:
                    log(f"\n{engine} {character} {item['emotion']} {item['intensity']:.0%}: render failed: {exc}\n")
                continue
            if out is not None:
                from facsim.media.images import write_png

                write_png(out / f"{engine}_{character}_{item['emotion']}_{round(item['intensity'] * 100)}.png", image)
            readings = panel.rate(image, grid=True)
            for rater in panel.raters:
                reading = None if readings is None else readings[rater.name]
                rows.append({**item, "engine": engine, "rater": rater.name,
                             "reading": None if reading is None else {
                                 "label": reading.label, "scores": reading.scores, "box": list(reading.box),
                                 "grid_labels": list(reading.grid_labels)}})
            if log:
                log(f"\r{engine}: {n}/{len(items)} rated")
    finally:
        for face in faces.values():
            face.close()
    if log:
        log("\n")
    return rows


# ------------------------------------------------------------------ figures

def summarise(rows) -> dict:
    """Recognition per (emotion, intensity), per intensity overall, confusion counts, mean target probability.

    ``overall_grid`` and each cell's ``grid``: the share of crop-grid variants that name the target.

    An emotion without a FER2013 label (contempt, embarrassment, pride) appears in the confusion table only.
    A stimulus where no face was found, or whose render failed (``error``), counts as not recognised.
    """
    cells, confusion, overall = {}, {}, {}
    for row in rows:
        reading = row["reading"]
        said = reading["label"] if reading else ("render failed" if row.get("error") else "no face")
        key = (row["emotion"], row["intensity"])
        confusion.setdefault(key, {}).setdefault(said, 0)
        confusion[key][said] += 1
        target = FER_LABEL.get(row["emotion"])
        if target is None:
            continue
        hit = said == target
        prob = reading["scores"][target] if reading else 0.0
        grid = reading.get("grid_labels") if reading else None
        grid_hit = sum(label == target for label in grid) / len(grid) if grid else float(hit)
        cell = cells.setdefault(key, {"n": 0, "hits": 0, "prob": 0.0, "grid": 0.0})
        cell["n"] += 1
        cell["hits"] += hit
        cell["prob"] += prob
        cell["grid"] += grid_hit
        if row["emotion"] != "neutral":
            tally = overall.setdefault(row["intensity"], [0, 0, 0.0])
            tally[0] += hit
            tally[1] += 1
            tally[2] += grid_hit
    for cell in cells.values():
        cell["rate"] = cell["hits"] / cell["n"]
        cell["prob"] /= cell["n"]
        cell["grid"] /= cell["n"]
    return {"cells": cells, "confusion": confusion,
            "overall": {level: hits / n for level, (hits, n, _) in overall.items()},
            "overall_grid": {level: grid / n for level, (_, n, grid) in overall.items()},
            "no_face": sum(1 for r in rows if r["reading"] is None and not r.get("error")),
            "failed": sum(1 for r in rows if r.get("error")), "n": len(rows)}


def format_report(engine: str, rater_title: str, summary: dict, emotions, intensities) -> str:
    lines = [f"== {engine} engine, rater {rater_title}: {summary['n']} images, no face in {summary['no_face']}"
             + (f", RENDER FAILED for {summary['failed']}" if summary["failed"] else "")]
    for level in intensities:
        if level in summary["overall"]:
            goal = GOALS.get(level)
            lines.append(f"emotions at {level:.0%}: {summary['overall'][level]:.1%} recognised"
                         + (f" (goal {goal:.0%})" if goal else "")
                         + f"; over {len(CROP_GRID)} crops {summary['overall_grid'][level]:.1%}")
    neutral = summary["cells"].get(("neutral", 0.0))
    if neutral:
        lines.append(f"neutral: {neutral['rate']:.1%} read as neutral; over {len(CROP_GRID)} crops "
                     f"{neutral['grid']:.1%}")
    lines.append("")
    header = f"{'emotion':<14}" + "".join(f"{f'{lv:.0%}':>16}" for lv in intensities)
    lines.append(header + "   (hits/n, rate, mean p(target) — one crop, as the panel)")
    for name in [*emotions, "neutral"]:
        # neutral has one cell (intensity 0), shown in the first column
        levels = intensities[:1] if name == "neutral" else intensities
        row = f"{name:<14}"
        for level in levels:
            cell = summary["cells"].get((name, 0.0 if name == "neutral" else level))
            if cell:
                row += f"{cell['hits']:>5}/{cell['n']:<2} {cell['rate']:>4.0%} {cell['prob']:.2f}"
            else:
                row += f"{'(no label)':>16}"
        lines.append(row)
    lines.append("")
    columns = [*LABELS, "no face"] + (["render failed"] if summary["failed"] else [])
    lines.append("confusion (rows: stimulus; columns: the rater's label)")
    lines.append(f"{'':<20}" + "".join(f"{'failed' if c == 'render failed' else c:>9}" for c in columns))
    for (name, level), said in sorted(summary["confusion"].items(),
                                      key=lambda kv: ([*emotions, "neutral"].index(kv[0][0]), -kv[0][1])):
        label = f"{name} {level:.0%}" if name != "neutral" else "neutral"
        lines.append(f"{label:<20}" + "".join(f"{said.get(c, 0) or '.':>9}" for c in columns))
    return "\n".join(lines)


def contact_sheet(rows, out: Path, engine: str, *, tile: int = 160) -> Path:
    """``out/sheet_ENGINE.png``: one row per character, one column per stimulus, each rater's label under it.

    A label in green names the intended emotion; red does not (grey: the emotion has no label to match).
    """
    from PIL import Image, ImageDraw

    stimuli, characters, labels = [], [], {}
    for row in rows:
        if row["engine"] != engine:
            continue
        key = (row["emotion"], row["intensity"])
        if key not in stimuli:
            stimuli.append(key)
        if row["character"] not in characters:
            characters.append(row["character"])
        labels.setdefault((row["character"], key), []).append(row)
    band = 14 * (1 + max((len(v) for v in labels.values()), default=1))
    sheet = Image.new("RGB", (tile * len(stimuli), (tile + band) * len(characters)), "white")
    draw = ImageDraw.Draw(sheet)
    for r, character in enumerate(characters):
        for c, (name, level) in enumerate(stimuli):
            x, y = c * tile, r * (tile + band)
            path = out / f"{engine}_{character}_{name}_{round(level * 100)}.png"
            if path.exists():
                sheet.paste(Image.open(path).convert("RGB").resize((tile, tile), Image.BILINEAR), (x, y))
            draw.text((x + 3, y + tile + 1), f"{character} {name} {level:.0%}" if name != "neutral"
                      else f"{character} neutral", fill=(0, 0, 0))
            target = FER_LABEL.get(name)
            for k, row in enumerate(labels.get((character, (name, level)), [])):
                reading = row["reading"]
                said = f"{reading['label']} {reading['scores'][reading['label']]:.2f}" if reading else "-"
                colour = (120, 120, 120) if target is None else (0, 130, 0) if reading and \
                    reading["label"] == target else (200, 0, 0)
                draw.text((x + 3, y + tile + 15 + 14 * k), f"{row['rater']}: {said}", fill=colour)
    path = out / f"sheet_{engine}.png"
    from facsim.atomic import atomic_write

    atomic_write(path, lambda tmp: sheet.save(tmp, format="PNG"))
    return path


# ------------------------------------------------------------------ photos

def photo_check(panel: Panel) -> tuple[str, bool]:
    """Real photographs shipped with scikit-image: the smiling astronaut must read happy; LFW faces tallied."""
    import numpy as np
    from skimage import data

    lines, ok = [], True
    astronaut, camera = panel.rate(data.astronaut()), panel.rate(data.camera())
    faces = (np.stack([data.lfw_subset()[:100]] * 3, axis=-1) * 255).round().astype(np.uint8)
    for rater in panel.raters:
        reading = astronaut and astronaut[rater.name]
        happy = reading is not None and reading.label == "happy"
        ok &= happy
        lines.append(f"[{rater.name}] astronaut (Eileen Collins, smiling): "
                     + (f"{reading.label} {reading.confidence:.2f}" if reading else "no face")
                     + ("" if happy else "  <-- FAILED: expected happy"))
        reading = camera and camera[rater.name]
        lines.append(f"[{rater.name}] cameraman (profile, no expression expected): "
                     + (f"{reading.label} {reading.confidence:.2f}" if reading else "no face"))
        # scikit-image's LFW subset: 100 real faces already cropped to 25² (too small to detect): rate the crops.
        tally = {}
        for face in faces:
            label = rater.rate_square(face)
            tally[label] = tally.get(label, 0) + 1
        lines.append(f"[{rater.name}] LFW subset (100 news photos, 25² crops): "
                     + ", ".join(f"{k} {v}" for k, v in sorted(tally.items(), key=lambda kv: -kv[1])))
    return "\n".join(lines), ok


# ------------------------------------------------------------------ CLI

def parse_args(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--engine", default="registers", help="registers, muscle or both, comma-separated")
    p.add_argument("--characters", default=",".join(BLIND_REVIEW_PRESETS), help="comma-separated presets")
    p.add_argument("--emotions", default="basic",
                   help="'basic' (6), 'all' (9; contempt, embarrassment, pride have no FER label) or a list")
    p.add_argument("--intensities", default="1,0.5", help="comma-separated, each in (0, 1]")
    p.add_argument("--size", type=int, default=512, help="render size in pixels (default 512)")
    p.add_argument("--out", type=Path, help="keep renders and write results.json here")
    p.add_argument("--photos", action="store_true", help="only the sanity check on real photographs")
    p.add_argument("--raters", default=",".join(RATERS), help=f"comma-separated, from {', '.join(RATERS)}")
    p.add_argument("--threads", type=int, default=1)
    return p.parse_args(argv)


def check_args(args):
    """Validated (engines, characters, emotions, intensities); raises UsageError naming the bad value."""
    from facsim.engines import ENGINES
    from facsim.facs.emotions import emotion

    engines = [e.strip() for e in args.engine.split(",") if e.strip()]
    for e in engines:
        if e not in ENGINES:
            raise UsageError(f"--engine: unknown engine {e!r}; choose from {', '.join(ENGINES)}")
    characters = [c.strip() for c in args.characters.split(",") if c.strip()]
    if not characters:
        raise UsageError("--characters: give at least one preset")
    from facsim.head.character import CharacterError, resolve_character

    for c in characters:   # fail on a bad preset before any rendering
        try:
            resolve_character(c)
        except CharacterError as exc:
            raise UsageError(f"--characters: {exc}") from None
    if args.emotions == "basic":
        emotions = list(BASIC)
    elif args.emotions == "all":
        emotions = [*BASIC, "contempt", "embarrassment", "pride"]
    else:
        emotions = [e.strip() for e in args.emotions.split(",") if e.strip()]
    for name in emotions:
        if name == "neutral":
            raise UsageError("--emotions: neutral is always included; list the others")
        try:
            emotion(name)
        except ValueError as exc:
            raise UsageError(f"--emotions: {exc}") from None
    try:
        intensities = [float(v) for v in args.intensities.split(",")]
    except ValueError:
        raise UsageError(f"--intensities: {args.intensities!r} is not a comma-separated list of numbers") from None
    if not intensities or any(not 0 < v <= 1 for v in intensities):
        raise UsageError(f"--intensities: each must lie in (0, 1], got {args.intensities}")
    if not 64 <= args.size <= 4096:
        raise UsageError(f"--size: {args.size} is outside 64..4096")
    raters = [r.strip() for r in args.raters.split(",") if r.strip()]
    for r in raters:
        if r not in RATERS:
            raise UsageError(f"--raters: unknown rater {r!r}; choose from {', '.join(RATERS)}")
    if not raters:
        raise UsageError("--raters: give at least one")
    return engines, characters, emotions, intensities, raters


def main(argv=None) -> int:
    args = parse_args(argv)
    try:
        engines, characters, emotions, intensities, raters = check_args(args)
        panel = Panel(raters, threads=args.threads)
    except (UsageError, RaterError) as exc:
        print(f"score.py: {exc}", file=sys.stderr)
        return 2
    with panel:
        text, ok = photo_check(panel)
        print("Sanity check on real photographs\n" + text + "\n")
        if args.photos:
            return 0 if ok else 1
        results = []
        if args.out:
            args.out.mkdir(parents=True, exist_ok=True)
        items = stimulus_items(characters, emotions, intensities)
        for engine in engines:
            rows = render_and_rate(engine, items, panel, size=args.size, out=args.out,
                                   log=(lambda s: (sys.stderr.write(s), sys.stderr.flush()))
                                   if sys.stderr.isatty() else None)
            results.extend(rows)
            for rater in panel.raters:
                mine = [row for row in rows if row["rater"] == rater.name]
                print(format_report(engine, rater.title, summarise(mine), emotions, intensities) + "\n")
            if args.out:
                print(f"contact sheet: {contact_sheet(rows, args.out, engine)}\n")
    if args.out:
        from facsim.atomic import atomic_write

        atomic_write(args.out / "results.json", lambda tmp: tmp.write_text(json.dumps(results, indent=1)))
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
