"""Exchange: facsim data to and from other tools' files, one module per format.

=================  ==========================================  =============================
module             format                                      API
=================  ==========================================  =============================
``gltf``           glTF 2.0 binary (``.glb``): head mesh, AU   :func:`export_glb`
                   morph targets, head/eye joints, animation
``arkit``          ARKit-52 blendshape weights per frame,      :func:`write_arkit_csv`,
                   Live Link Face CSV layout                   :func:`read_arkit_csv`
``openface``       OpenFace 2.0 FeatureExtraction CSV          :func:`read_openface_csv`
``notation_file``  ``.facs``: the notation as a compact,       :func:`dumps_notation`,
                   lossless timeline text                      :func:`loads_notation`
``meshfile``       OBJ / PLY of one deformed frame             :func:`write_mesh`
=================  ==========================================  =============================

Every reader returns a :class:`~facsim.timeline.Timeline`, every writer
replaces its file atomically (:mod:`facsim.atomic`: a temporary file
beside it, then moved into place). Format modules are imported only when their function is
first used, so ``import facsim.exchange`` stays cheap and the core never
imports them. Errors in input files are :class:`ExchangeError` (a
``ValueError``): one line naming the file, the line (and column where it
helps) and what is wrong.

This module also holds what the formats share: reading and writing files, CSV helpers.
Rigid motions (head 51–58, eyes 61–66) as rotation vectors and back are
:mod:`facsim.engines.rigid`'s.
"""
from __future__ import annotations

from importlib import import_module
from pathlib import Path

import numpy as np

#: Public function → the format module that defines it (imported on first use).
_LAZY = {
    "export_glb": "gltf",
    "write_arkit_csv": "arkit", "read_arkit_csv": "arkit", "arkit_weights": "arkit",
    "read_openface_csv": "openface",
    "dumps_notation": "notation_file", "loads_notation": "notation_file",
    "read_notation": "notation_file", "write_notation": "notation_file", "NotationFileError": "notation_file",
    "write_mesh": "meshfile",
}

#: Suffixes :func:`load_any_timeline` reads, and how.
TIMELINE_SUFFIXES = (".yaml", ".yml", ".json", ".facs", ".csv")


def __getattr__(name: str):
    if name in _LAZY:
        value = getattr(import_module(f"{__name__}.{_LAZY[name]}"), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


class ExchangeError(ValueError):
    """An input file that cannot be read, in one line: ``file:line:column: problem``.

    Attributes
    ----------
    problem : str
        What is wrong.
    file : str or None
    line, column : int or None
        1-based, where known.
    """

    def __init__(self, problem: str, *, file=None, line: int | None = None, column: int | None = None):
        self.problem, self.file, self.line, self.column = problem, None if file is None else str(file), line, column
        if self.file is not None:
            where = self.file + "".join(f":{n}" for n in (line, column) if n is not None)
        elif line is not None:
            where = f"line {line}" + ("" if column is None else f", column {column}")
        else:
            where = ""
        from facsim.limits import clip

        # One bounded line: a hostile file must not make a megabyte-long message.
        super().__init__(clip(f"{where}: {problem}" if where else str(problem)))

    def in_file(self, file) -> "ExchangeError":
        """The same error, naming the file it came from."""
        return type(self)(self.problem, file=file, line=self.line, column=self.column)


# ------------------------------------------------------------------ files ---

def write_file(path, data: bytes | str) -> Path:
    """Write ``data`` (bytes, or text as UTF-8) to ``path`` atomically (:mod:`facsim.atomic`); returns the path."""
    from facsim.atomic import atomic_write

    path = Path(path)
    if not path.parent.is_dir():
        raise FileNotFoundError(f"cannot write {path}: folder {path.parent} does not exist")
    payload = data.encode("utf-8") if isinstance(data, str) else bytes(data)
    return atomic_write(path, lambda tmp: tmp.write_bytes(payload))


def samples_timeline(path, times, curves, **settings):
    """:func:`~facsim.timeline.builders.timeline_from_samples`, its TimelineError (a frame rate out of range,
    too many frames) turned into an :class:`ExchangeError` naming ``path``: importers raise one error type."""
    from facsim.timeline.builders import timeline_from_samples
    from facsim.timeline.model import TimelineError

    try:
        return timeline_from_samples(times, curves, **settings)
    except TimelineError as exc:
        raise ExchangeError(str(exc), file=path) from None


def check_input_size(path) -> None:
    """An :class:`ExchangeError` if the file at ``path`` is over the input size limit (:mod:`facsim.limits`)."""
    from facsim.limits import check_file_size

    check_file_size(path, lambda problem: ExchangeError(problem, file=path))


def _csv_kind(path: Path) -> str:
    with open(path, encoding="utf-8-sig", errors="replace") as handle:
        header = handle.readline()
    names = {name.strip() for name in header.split(",")}
    if "BlendShapeCount" in names:
        return "arkit"
    if {"success", "timestamp"} <= names or any(name.startswith("AU") and name.endswith("_r") for name in names):
        return "openface"
    raise ExchangeError("not a CSV facsim can read: the header has neither Live Link Face's 'BlendShapeCount' "
                        "nor OpenFace's 'timestamp', 'success' and AU columns", file=path, line=1)


def load_any_timeline(path):
    """A :class:`~facsim.timeline.Timeline` from any file facsim reads, by suffix.

    ``.yaml``/``.yml``/``.json`` (facsim's timeline format), ``.facs``
    (:mod:`~facsim.exchange.notation_file`), ``.csv`` (an ARKit/Live Link
    Face or OpenFace 2.0 CSV, told apart by its header).
    """
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in TIMELINE_SUFFIXES:
        raise ExchangeError(f"unsupported timeline file type {suffix or '(none)'!r}; use "
                            f"{', '.join(TIMELINE_SUFFIXES)}", file=path)
    if not path.is_file():
        raise FileNotFoundError(f"no such file: {path}")
    if suffix == ".facs":
        return __getattr__("read_notation")(path)
    if suffix == ".csv":
        return (__getattr__("read_arkit_csv") if _csv_kind(path) == "arkit" else __getattr__("read_openface_csv"))(path)
    from facsim.timeline.io import load_timeline

    return load_timeline(path)


def save_any_timeline(timeline, path) -> Path:
    """Write ``timeline`` as ``.facs`` notation or YAML/JSON (by suffix), atomically."""
    path = Path(path)
    if path.suffix.lower() == ".facs":
        return __getattr__("write_notation")(timeline, path)
    from facsim.timeline.io import save_timeline

    return save_timeline(timeline, path)


# -------------------------------------------------------------- CSV ---

def read_csv_rows(path) -> tuple[list[str], list[tuple[int, list[str]]]]:
    """A CSV file's header (names stripped) and its data rows as (line number, cells).

    Blank lines are skipped; every row must have as many cells as the header.
    """
    import csv
    import io

    path = Path(path)
    check_input_size(path)
    try:
        text = path.read_text(encoding="utf-8-sig")
    except UnicodeDecodeError as exc:
        raise ExchangeError(f"not UTF-8 text ({exc.reason} at byte {exc.start})", file=path) from None
    reader = csv.reader(io.StringIO(text))
    rows = [(reader.line_num, cells) for cells in reader if any(c.strip() for c in cells)]
    if not rows:
        raise ExchangeError("empty file; expected a CSV header", file=path, line=1)
    header = [name.strip() for name in rows[0][1]]
    for line, cells in rows[1:]:
        if len(cells) != len(header):
            problem = "truncated row: " if len(cells) < len(header) else "row too long: "
            raise ExchangeError(f"{problem}{len(cells)} cells, the header has {len(header)}", file=path, line=line)
    if len(rows) == 1:
        raise ExchangeError("no frames: the file has a header but no rows", file=path, line=1)
    return header, rows[1:]


def csv_number(cells: list[str], i: int, header: list[str], line: int, path) -> float:
    """Cell ``i`` of a row as a finite float, else an ExchangeError naming the line and column."""
    text = cells[i].strip()
    try:
        value = float(text)
    except ValueError:
        value = float("nan")
    if not np.isfinite(value):
        raise ExchangeError(f"column {header[i]}: {text!r} is not a number", file=path, line=line)
    return value


def require_columns(header: list[str], required, path, what: str) -> dict[str, int]:
    """Index of each name in ``header`` (any case); an ExchangeError listing the missing ``required`` ones."""
    lookup = {name.lower(): i for i, name in enumerate(header)}
    missing = [name for name in required if name.lower() not in lookup]
    if missing:
        shown = ", ".join(missing[:6]) + (f" and {len(missing) - 6} more" if len(missing) > 6 else "")
        raise ExchangeError(f"not {what}: missing column{'s' * (len(missing) > 1)} {shown}", file=path, line=1)
    return lookup


__all__ = [
    "ExchangeError", "TIMELINE_SUFFIXES", "check_input_size", "csv_number", "samples_timeline",
    "load_any_timeline", "read_csv_rows", "require_columns", "save_any_timeline",
    "write_file", *sorted(_LAZY),
]
