"""A one-line progress bar on stderr, given to the pipeline as its ``on_frame`` callback."""
from __future__ import annotations

import sys
import time


class Progress:
    """A one-line progress bar on stderr (silent when ``enabled`` is False). Redrawn in
    place on a terminal; into a log file (not a terminal) it writes a line per tenth."""

    def __init__(self, total: int, label: str = "rendering", enabled: bool = True):
        self.total, self.label, self.enabled = total, label, enabled
        self.start = time.perf_counter()
        self.live = sys.stderr.isatty()
        self.step = max(1, -(-total // 10))

    def update(self, done: int) -> None:
        if not self.enabled or not (self.live or done % self.step == 0 or done >= self.total):
            return
        frac = done / max(self.total, 1)
        rate = done / max(time.perf_counter() - self.start, 1e-9)
        redraw = "\r" if self.live else ""  # back to the line's start on a terminal
        sys.stderr.write(f"{redraw}facsim: {self.label} [{'#' * int(30 * frac):<30}] {done}/{self.total} frames, {rate:5.1f} fps")
        if done >= self.total or not self.live:
            sys.stderr.write("\n")
        sys.stderr.flush()
