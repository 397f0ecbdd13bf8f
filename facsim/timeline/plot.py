"""Plot a timeline: one line per AU (and side) over time, for checking stimuli.

matplotlib is imported only when :func:`plot_timeline` runs, with the
non-interactive Agg backend, so importing facsim never needs a display.

Examples
--------
>>> from facsim.timeline.builders import stimulus_timeline
>>> plot_timeline(stimulus_timeline("happiness"), "happiness.png")   # doctest: +SKIP
PosixPath('happiness.png')
"""
from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from facsim.facs.catalogue import INTENSITY_TABLES, catalogue
from facsim.atomic import atomic_write
from facsim.timeline.model import Timeline
from facsim.timeline.sampling import frame_times, intensity_curves

#: File types :func:`plot_timeline` writes, by suffix.
PLOT_FORMATS = {".png": "png", ".svg": "svg"}
#: Line style per side: both sides alike, the character's left, right.
_SIDE_STYLES = {"": "-", "(L)": "--", "(R)": "-."}


def _legend_label(label: str) -> str:
    """``"AU12 (L)"`` → ``"AU12 Lip Corner Puller (L)"``."""
    code, _, side = label.partition(" ")
    name = catalogue()[int(code[2:])].name
    return f"{code} {name}" + (f" {side}" if side else "")


def _identical_groups(curves: dict[str, np.ndarray]) -> list[list[str]]:
    """Labels grouped by identical curves, so that one line (and one legend entry)
    stands for all AUs that move exactly alike instead of hiding each other."""
    groups: list[list[str]] = []
    for label, values in curves.items():
        for group in groups:
            if np.array_equal(curves[group[0]], values):
                group.append(label)
                break
        else:
            groups.append([label])
    return groups


def plot_timeline(timeline: Timeline, path: str | os.PathLike, *, fps: float | None = None,
                  title: str | None = None, intensities: str | None = None) -> Path:
    """Draw every AU's intensity over time and write it as PNG or SVG.

    Curves are sampled at the video's frame times (what the frames will
    show), so ``fps`` changes the sampling as it would change the video.
    AUs whose curves are identical share one line and one legend entry (so
    none hides behind another); the character's left side is dashed, the
    right dash-dotted. Dotted horizontal lines mark the intensity letters A-E.

    Parameters
    ----------
    timeline : Timeline
    path : str or PathLike
        Ends in ``.png`` or ``.svg``; written atomically (temporary file in the
        same folder, then renamed).
    fps : float, optional
        Sampling rate; default ``timeline.fps``.
    title : str, optional
        Default: the timeline's ``description``, else a summary.
    intensities : str, optional
        Intensity table for the A-E guide lines; default the timeline's.

    Returns
    -------
    Path
        ``path``.

    Raises
    ------
    ValueError
        For a suffix other than ``.png`` or ``.svg``.
    """
    path = Path(path)
    fmt = PLOT_FORMATS.get(path.suffix.lower())
    if fmt is None:
        raise ValueError(f"plot path must end in {' or '.join(PLOT_FORMATS)}, got {str(path)!r}")
    table = INTENSITY_TABLES[intensities or timeline.intensities]

    import matplotlib                     # lazily: only plotting needs it
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    times = frame_times(timeline, fps)
    if times.size == 0:                   # a clip shorter than half a frame: show t = 0
        times = np.zeros(1)
    curves = intensity_curves(timeline, times)
    # Draw to the video's end: the last frame's value carries to `length`.
    x = np.append(times, timeline.length)

    fig = Figure(figsize=(10, 5.2), dpi=120, layout="constrained")
    FigureCanvasAgg(fig)                  # Agg, without touching pyplot's global backend
    ax = fig.add_subplot()
    for letter, level in table.items():
        ax.axhline(level, color="0.75", linewidth=0.8, linestyle=":", zorder=0)
        ax.annotate(letter, xy=(1.0, level), xycoords=("axes fraction", "data"), xytext=(4, 0),
                    textcoords="offset points", va="center", fontsize=9, color="0.4")
    groups = _identical_groups(curves)
    colours = matplotlib.colormaps["tab10" if len(groups) <= 10 else "tab20"]
    for i, labels in enumerate(groups):
        values = curves[labels[0]]
        sides = {label.partition(" ")[2] for label in labels}
        ax.plot(x, np.append(values, values[-1]), color=colours(i % colours.N),
                linestyle=_SIDE_STYLES.get(sides.pop(), "-") if len(sides) == 1 else "-",
                linewidth=1.8, label="\n".join(_legend_label(label) for label in labels))
    ax.set_xlim(0.0, timeline.length)
    ax.set_ylim(-0.02, 1.05)
    ax.set_xlabel("time (s)")
    ax.set_ylabel("intensity")
    fps_used = timeline.fps if fps is None else fps
    summary = f"{len(timeline.tracks)} track{'s' * (len(timeline.tracks) != 1)}, " \
              f"{timeline.length:g} s at {fps_used:g} fps ({times.size} frames)"
    ax.set_title(title or timeline.description or "Timeline", loc="left", fontsize=11)
    ax.text(1.0, 1.01, summary, transform=ax.transAxes, ha="right", va="bottom", fontsize=8, color="0.35")
    ax.grid(axis="x", color="0.9")
    if curves:
        sided = any(label.endswith(("(L)", "(R)")) for label in curves)
        ax.legend(loc="upper left", bbox_to_anchor=(1.03, 1.0), fontsize=8, frameon=False,
                  title="L/R = character's left/right" if sided else None, title_fontsize=7)
    else:
        ax.text(0.5, 0.5, "no action units", transform=ax.transAxes, ha="center", color="0.5")
    return atomic_write(path, lambda tmp: fig.savefig(tmp, format=fmt))
