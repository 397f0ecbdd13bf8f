"""The validation report: Markdown and HTML with matplotlib plots, plus CSV tables."""
from __future__ import annotations

import csv
import html
import io
from pathlib import Path

import numpy as np

DISCLAIMER = (
    "This is facsim's closed loop: faces rendered by facsim's own engines, read back by facsim's own "
    "camera processor. It measures how faithfully an expression survives rendering and landmark analysis. "
    "It is **not a substitute for FACS-certified human raters** (HapFACS 3.0 was validated by three certified "
    "coders; their figures are shown beside ours for orientation only)."
)


def _write(path: Path, text: str) -> None:
    from facsim.atomic import atomic_write

    atomic_write(path, lambda tmp: tmp.write_text(text, encoding="utf-8"))


def _csv(rows: list[dict]) -> str:
    if not rows:
        return ""
    buf = io.StringIO()
    w = csv.DictWriter(buf, fieldnames=list(rows[0]))
    w.writeheader()
    for row in rows:
        w.writerow({k: (round(v, 4) if isinstance(v, float) else v) for k, v in row.items()})
    return buf.getvalue()


def _plot_f1(report, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    engines = list(report.per_au)
    codes = sorted({r["au"] for rows in report.per_au.values() for r in rows})
    fig, ax = plt.subplots(figsize=(max(6, 0.35 * len(codes) * len(engines)), 3.2))
    width = 0.8 / max(1, len(engines))
    for k, engine in enumerate(engines):
        f1 = {r["au"]: r["f1"] for r in report.per_au[engine]}
        ax.bar(np.arange(len(codes)) + k * width, [np.nan_to_num(f1.get(c, np.nan)) for c in codes], width,
               label=engine)
    ax.set_xticks(np.arange(len(codes)) + width * (len(engines) - 1) / 2, [str(c) for c in codes], fontsize=7)
    ax.set_ylim(0, 1)
    ax.set_ylabel("F1")
    ax.set_xlabel("AU")
    ax.legend(fontsize=7)
    ax.set_title("Per-AU F1 (closed loop)", fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def _plot_levels(report, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    engines = list(report.per_au)
    fig, axes = plt.subplots(1, len(engines), figsize=(3.4 * len(engines), 3.2), squeeze=False)
    for ax, engine in zip(axes[0], engines):
        pairs = [(v, r.read.get(code, 0.0)) for r in report.readings if r.engine == engine and r.case.kind == "single"
                 for code, v in r.truth.items()]
        if pairs:
            t, p = np.array(pairs).T
            ax.scatter(t + np.random.default_rng(0).normal(0, 0.01, len(t)), p, s=6, alpha=0.5)
        ax.plot([0, 1], [0, 1], color="grey", lw=0.8)
        ax.set_xlim(0, 1.05)
        ax.set_ylim(0, 1.05)
        ax.set_xlabel("rendered level")
        ax.set_ylabel("read level")
        ax.set_title(f"{engine}: single AUs", fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def _md_table(rows: list[dict], keys: list[str]) -> str:
    def cell(v):
        if isinstance(v, float):
            return "–" if np.isnan(v) else f"{v:.2f}"
        return "–" if v is None else str(v)

    lines = ["| " + " | ".join(keys) + " |", "|" + "---|" * len(keys)]
    lines += ["| " + " | ".join(cell(r.get(k)) for k in keys) + " |" for r in rows]
    return "\n".join(lines)


def write_report(report, out: Path, *, quick: bool, characters, views, size: int) -> Path:
    out = Path(out)
    _plot_f1(report, out / "f1_per_au.png")
    _plot_levels(report, out / "levels.png")
    _write(out / "cases.csv", readings_csv(report.readings))
    for engine in report.per_au:
        _write(out / f"per_au_{engine}.csv", _csv(report.per_au[engine]))
        _write(out / f"combinations_{engine}.csv", _csv(report.combinations[engine]))
    md = ["# facsim validate — closed-loop report", "", DISCLAIMER, "",
          f"Run: {'quick' if quick else 'full'}; characters: {', '.join(characters)}; views (yaw, pitch): "
          f"{', '.join(str(v) for v in views)}; {size}² renders; {len(report.readings)} renders analysed in "
          f"{report.seconds:.0f} s. Each case is read with the same character's neutral render (same view) as "
          "its baseline. Present = read level ≥ 0.15 (AUs) or ≥ 0.2 (head and eye codes).", "",
          "![F1 per AU](f1_per_au.png)", "", "![levels](levels.png)", ""]
    for engine, rows in report.per_au.items():
        md += [f"## Per AU — {engine} engine", "",
               _md_table(rows, ["au", "n_present", "precision", "recall", "f1", "r", "mae"]), ""]
    for engine, rows in report.combinations.items():
        md += [f"## The 54 HapFACS combinations — {engine} engine", "",
               "Accuracy, precision, recall and F1 as HapFACS 3.0's Table 4 defines them (over the scored AUs); "
               "`hapfacs_f1` is what the paper's certified coders scored on HapFACS's own renders.", "",
               _md_table(rows, ["combination", "accuracy", "precision", "recall", "f1", "hapfacs_f1", "read"]), ""]
    md += ["## What landmarks cannot show", "",
           "These codes are not read, or only weakly, from the 468 landmarks; the analysis reports them instead of "
           "guessing:", ""]
    md += [f"- AU{code}: {why}" for code, why in report.unobservable.items()]
    text = "\n".join(md) + "\n"
    _write(out / "report.md", text)
    _write(out / "report.html", _html(text))
    return out / "report.md"


def _html(markdown: str) -> str:
    """A small Markdown → HTML for this report's own constructs (headings, tables, images, lists)."""
    body, table = [], []

    def flush():
        if table:
            rows = [r for r in table if not set(r.replace("|", "").strip()) <= {"-"}]
            cells = [[html.escape(c.strip()) for c in r.strip().strip("|").split("|")] for r in rows]
            body.append("<table><tr>" + "".join(f"<th>{c}</th>" for c in cells[0]) + "</tr>"
                        + "".join("<tr>" + "".join(f"<td>{c}</td>" for c in row) + "</tr>" for row in cells[1:])
                        + "</table>")
            table.clear()

    for line in markdown.splitlines():
        if line.startswith("|"):
            table.append(line)
            continue
        flush()
        if line.startswith("## "):
            body.append(f"<h2>{html.escape(line[3:])}</h2>")
        elif line.startswith("# "):
            body.append(f"<h1>{html.escape(line[2:])}</h1>")
        elif line.startswith("!["):
            src = line[line.index("(") + 1: -1]
            body.append(f'<p><img src="{html.escape(src)}" alt=""></p>')
        elif line.startswith("- "):
            body.append(f"<li>{html.escape(line[2:])}</li>")
        elif line.strip():
            text = html.escape(line).replace("**", "")
            body.append(f"<p>{text}</p>")
    flush()
    style = ("body{font-family:sans-serif;max-width:1100px;margin:2em auto}table{border-collapse:collapse;"
             "font-size:12px}td,th{border:1px solid #ccc;padding:2px 6px}img{max-width:100%}")
    return f"<!doctype html><meta charset=utf-8><title>facsim validate</title><style>{style}</style>" + "".join(body)


def readings_csv(readings) -> str:
    buf = io.StringIO()
    w = csv.writer(buf)
    w.writerow(["engine", "character", "view", "case", "kind", "expression", "found", "read"])
    for r in readings:
        w.writerow([r.engine, r.character, r.view, r.case.name, r.case.kind, r.case.expression, int(r.found),
                    r.notation])
    return buf.getvalue()
