"""``facsim validate``: render known expressions, analyse the renders, score the camera processor per AU.

The closed loop: every case is a FACS expression with known levels, rendered
on a character from a view by one engine; the camera processor (landmarks →
fit) reads it back with the character's neutral render of the same view as
its baseline. Scores per AU: precision, recall, F1 (present = level ≥ the
analysis threshold), Pearson correlation and mean absolute error of the
levels; per combination, HapFACS 3.0's Table 4 measures. Cases come from
``facsim/data/validation_cases.yaml``.

This measures facsim against itself — how faithfully an expression made by an
engine survives rendering and landmark analysis. It is not a substitute for
FACS-certified human raters, and the report says so.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field
from functools import lru_cache
from importlib import resources
from pathlib import Path

import numpy as np
import yaml

RIGID_CODES = (51, 52, 53, 54, 55, 56, 61, 62, 63, 64)
EMOTIONS = ("happiness", "sadness", "surprise", "anger", "fear", "disgust", "contempt")


@lru_cache(maxsize=1)
def case_table() -> dict:
    return yaml.safe_load(resources.files("facsim").joinpath("data/validation_cases.yaml").read_text())


@dataclass(frozen=True)
class Case:
    """One stimulus: a name, its kind (single / combination / emotion) and its expression (FACS string)."""

    name: str
    kind: str
    expression: str


def build_cases(*, quick: bool) -> list[Case]:
    """Single AUs at each letter, the 54 combinations, the emotion presets at 50 and 100 %."""
    from facsim.analysis.fit import FITTED, NOT_FITTED_WHY
    from facsim.facs.emotions import emotion
    from facsim.facs.notation import format_expression
    from facsim.engines.registers import register_table

    table = case_table()
    rendered = sorted(set(register_table()["action_units"]) - {63, 64})
    letters = table["quick_single_intensities" if quick else "single_intensities"]
    cases = [Case(f"{code}{letter}", "single", f"{code}{letter}") for code in rendered
             if code in FITTED or code in NOT_FITTED_WHY for letter in letters]
    from facsim.facs.stimuli import hapfacs_stimuli

    level = table["combination_intensity"]
    for combination in hapfacs_stimuli()["combinations"]:
        expr = "+".join(f"{code}@{level}" for code in combination.split("+"))
        cases.append(Case(combination, "combination", expr))
    for name in EMOTIONS:
        for intensity in table["emotion_intensities"][-1:] if quick else table["emotion_intensities"]:
            expr = format_expression(emotion(name, intensity=intensity))
            cases.append(Case(f"{name} {int(round(intensity * 100))}%", "emotion", expr))
    return cases


@dataclass
class Reading:
    """One analysed render: truth and reading as code → level (max over sides)."""

    engine: str
    character: str
    view: str
    case: Case
    truth: dict
    read: dict
    notation: str
    found: bool


@dataclass
class Report:
    readings: list = field(default_factory=list)
    per_au: dict = field(default_factory=dict)            # engine → rows
    combinations: dict = field(default_factory=dict)      # engine → rows
    unobservable: dict = field(default_factory=dict)
    markdown_path: Path | None = None
    seconds: float = 0.0

    def summary_text(self) -> str:
        engines = list(self.per_au)
        codes = sorted({r["au"] for rows in self.per_au.values() for r in rows})
        head = "AU   " + "".join(f"| {e:^30} " for e in engines)
        sub = "     " + "".join("|  prec  rec   F1     r    MAE  " for _ in engines)
        lines = [head, sub]
        for code in codes:
            cells = []
            for e in engines:
                row = next((r for r in self.per_au[e] if r["au"] == code), None)
                cells.append("| " + ("  ".join(_fmt(row[k]) for k in ("precision", "recall", "f1", "r", "mae"))
                                     if row else " " * 30) + " ")
            lines.append(f"{code:<5}" + "".join(cells))
        for e in engines:
            rows = self.combinations[e]
            if rows:
                mean = {k: np.mean([r[k] for r in rows]) for k in ("accuracy", "precision", "recall", "f1")}
                lines.append(f"{e}: {len(rows)} combinations, mean accuracy {mean['accuracy']:.2f}, precision "
                             f"{mean['precision']:.2f}, recall {mean['recall']:.2f}, F1 {mean['f1']:.2f} "
                             "(HapFACS 3.0's coders: 0.98, 0.80, 0.81, 0.80)")
        return "\n".join(lines)


def _fmt(v) -> str:
    return "  -  " if v is None or (isinstance(v, float) and np.isnan(v)) else f"{v:5.2f}"


def _code_levels(levels: dict) -> dict:
    out = {}
    for (code, _side), v in levels.items():
        out[code] = max(out.get(code, 0.0), v)
    return out


def run_validation(*, engines=("registers", "muscle"), characters=None, quick: bool = False,
                   out: Path = Path("validation"), size: int = 320, progress: bool = True) -> Report:
    """Render, analyse and score (see the module docstring); writes the report into ``out``."""
    import sys

    from facsim.analysis.processor import PRESENT, PRESENT_RIGID, format_levels
    from facsim.analysis.fit import build_basis, fit_frame, fit_identity
    from facsim.analysis.landmarks import LandmarkDetector
    from facsim.engines.rigid import eye_levels, head_levels
    from facsim.facs.activations import activations
    from facsim.face import Face
    from facsim.head.character import resolve_character
    from facsim.facs.notation import parse

    t0 = time.perf_counter()
    table = case_table()
    characters = tuple(characters or table["quick_characters" if quick else "characters"])
    views = [tuple(v) for v in (table["views"][:1] if quick else table["views"])]
    cases = build_cases(quick=quick)
    model = build_basis()
    report = Report(unobservable=model.visibility())
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    total = len(engines) * len(characters) * len(views) * len(cases)
    done = 0
    with LandmarkDetector() as detector:
        for engine in engines:
            for character in characters:
                # symmetric: the loop scores AUs, not the character's natural asymmetry
                face = Face(resolve_character(character).with_(symmetric=True), engine=engine)
                for yaw, pitch in views:
                    view = f"yaw {yaw:+g}" + (f" pitch {pitch:+g}" if pitch else "")
                    neutral = detector.faces(face.render(None, yaw=yaw, pitch=pitch, size=size)[..., :3])
                    if not neutral:
                        raise RuntimeError(f"no face found on the neutral render of {character} ({view})")
                    identity = fit_identity(model, [neutral[0].points])
                    rest = fit_frame(model, neutral[0].points, neutral[0].irises, identity=identity)
                    for case in cases:
                        act = activations(parse(case.expression))
                        truth = {code: act.level(code) for code in act.codes}
                        image = face.render(act, yaw=yaw, pitch=pitch, size=size)[..., :3]
                        found = detector.faces(image)
                        if found:
                            fit = fit_frame(model, found[0].points, found[0].irises, identity=identity)
                            levels = model.side_levels(fit.levels)
                            rigid = head_levels(fit.rotvec - rest.rotvec)
                            eyes = fit.eyes - rest.eyes
                            rigid.update({k: v for k, v in eye_levels(eyes[1], eyes[0]).items() if k <= 64})
                            read = _code_levels(levels)
                            read.update(rigid)
                            notation = format_levels(levels, rigid)
                        else:
                            read, notation = {}, "no face found"
                        report.readings.append(Reading(engine, character, view, case, truth, read, notation,
                                                       bool(found)))
                        done += 1
                        if progress and done % 10 == 0:
                            sys.stderr.write(f"\rvalidate: {done}/{total} renders analysed")
                face.close()
    if progress:
        sys.stderr.write("\n")
    for engine in engines:
        readings = [r for r in report.readings if r.engine == engine]
        report.per_au[engine] = score_per_au(readings, model, PRESENT, PRESENT_RIGID)
        report.combinations[engine] = score_combinations([r for r in readings if r.case.kind == "combination"],
                                                         model, PRESENT, PRESENT_RIGID)
    report.seconds = time.perf_counter() - t0
    from .report import write_report

    report.markdown_path = write_report(report, out, quick=quick, characters=characters, views=views, size=size)
    return report


def scored_codes(model) -> list[int]:
    return sorted(set(model.codes) | set(RIGID_CODES))


def _present(code: int, level: float, threshold: float, rigid_threshold: float) -> bool:
    return level >= (rigid_threshold if code in RIGID_CODES else threshold)


def score_per_au(readings, model, threshold: float, rigid_threshold: float) -> list[dict]:
    """Precision, recall, F1, Pearson r and MAE of the level, per AU over all readings."""
    rows = []
    for code in scored_codes(model):
        truth = np.array([r.truth.get(code, 0.0) for r in readings])
        read = np.array([r.read.get(code, 0.0) for r in readings])
        if not (truth > 0).any():
            continue
        t = truth > 0
        p = np.array([_present(code, v, threshold, rigid_threshold) for v in read])
        tp, fp, fn = int((t & p).sum()), int((~t & p).sum()), int((t & ~p).sum())
        precision = tp / (tp + fp) if tp + fp else float("nan")
        recall = tp / (tp + fn) if tp + fn else float("nan")
        f1 = 2 * tp / (2 * tp + fp + fn) if tp + fp + fn else float("nan")
        r = float(np.corrcoef(truth, read)[0, 1]) if truth.std() > 0 and read.std() > 0 else float("nan")
        mae = float(np.abs(truth[t] - read[t]).mean())
        rows.append({"au": code, "n_present": int(t.sum()), "tp": tp, "fp": fp, "fn": fn, "precision": precision,
                     "recall": recall, "f1": f1, "r": r, "mae": mae})
    return rows


def score_combinations(readings, model, threshold: float, rigid_threshold: float) -> list[dict]:
    """HapFACS Table 4's measures per combination: accuracy, precision, recall, F1 over the scored AUs."""
    codes = scored_codes(model)
    groups: dict = {}
    for r in readings:
        groups.setdefault(r.case.name, []).append(r)
    paper = {row["aus"]: row for row in case_table()["coders"]}
    rows = []
    for name, group in groups.items():
        tp = fp = tn = fn = 0
        for r in group:
            for code in codes:
                t = r.truth.get(code, 0.0) > 0
                p = _present(code, r.read.get(code, 0.0), threshold, rigid_threshold)
                tp += t and p
                fp += (not t) and p
                tn += (not t) and (not p)
                fn += t and (not p)
        rows.append({
            "combination": name, "accuracy": (tp + tn) / max(1, tp + fp + tn + fn),
            "precision": tp / (tp + fp) if tp + fp else 0.0, "recall": tp / (tp + fn) if tp + fn else 0.0,
            "f1": 2 * tp / (2 * tp + fp + fn) if tp + fp + fn else 0.0,
            "read": "; ".join(sorted({r.notation for r in group}))[:120],
            "hapfacs_f1": paper.get(name, {}).get("f1"),
        })
    return rows
