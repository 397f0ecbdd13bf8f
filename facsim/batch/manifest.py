"""The output folder's records: the journal of finished files, the run state, the manifest.

Layout of an output folder ``DIR``::

    DIR/<files of the set>
    DIR/manifest.csv, manifest.json     the set, sorted by file (written last, atomically)
    DIR/key.csv                         blind naming only: what each file shows
    DIR/.facsim-batch/state.json        the spec hash the folder belongs to
    DIR/.facsim-batch/journal.jsonl     one line per finished file (key, file, checksum, bytes)

The journal is append-only: a line is written only after
its file was moved into place, so a kill at any moment leaves at worst a
file without a line (made again, the same bytes) or a torn last line (ignored
and cut off). On resume a file counts as done only if its checksum matches
its line. When the set is complete the journal is rewritten in key order, so
a resumed set and an uninterrupted one are the same bytes throughout.
"""
from __future__ import annotations

import csv
import hashlib
import io
import json
import os
from pathlib import Path
from typing import Iterable, Mapping

from facsim.atomic import atomic_write

from .items import Item

STATE_DIR = ".facsim-batch"
JOURNAL = "journal.jsonl"
STATE = "state.json"
MANIFEST_CSV = "manifest.csv"
MANIFEST_JSON = "manifest.json"

#: Manifest columns, in order (PsychoPy and jsPsych read the CSV as a conditions file). PsychoPy's
#: Builder makes each column a Python variable, so no name shadows a builtin (list, format, bytes).
COLUMNS = ("file", "kind", "block", "list_no", "character", "label", "facs", "aus", "emotion", "table", "side",
           "intensity", "peak", "engine", "view", "width", "height", "duration", "fps", "onset", "apex", "offset",
           "file_format", "checksum", "file_bytes")
#: What a blind manifest may show: nothing about the expression or the character.
BLIND_COLUMNS = ("file", "kind", "width", "height", "duration", "fps", "file_format", "checksum", "file_bytes")


def sha256_file(path: os.PathLike) -> str:
    digest = hashlib.sha256()
    with open(path, "rb") as fh:
        for chunk in iter(lambda: fh.read(1 << 20), b""):
            digest.update(chunk)
    return digest.hexdigest()


class Journal:
    """Append-only record of finished files: ``{key: {"file", "checksum", "bytes"}}``."""

    def __init__(self, folder: Path):
        self.path = Path(folder) / STATE_DIR / JOURNAL
        self.entries: dict[str, dict] = {}
        self._fh = None

    def load(self) -> dict[str, dict]:
        """Read the journal, ignoring a torn last line (and cutting it off, so appends start clean)."""
        self.entries = {}
        if not self.path.exists():
            return self.entries
        data = self.path.read_bytes()
        complete = data[: data.rfind(b"\n") + 1]
        for line in complete.splitlines():
            try:
                entry = json.loads(line)
                self.entries[entry["key"]] = entry
            except (ValueError, KeyError, TypeError):
                continue  # a line damaged some other way: its file is simply made again
        if len(complete) != len(data):
            with open(self.path, "r+b") as fh:
                fh.truncate(len(complete))
        return self.entries

    def append(self, key: str, file: str, checksum: str, size: int) -> None:
        entry = {"key": key, "file": file, "checksum": checksum, "bytes": size}
        if self._fh is None:
            self.path.parent.mkdir(parents=True, exist_ok=True)
            self._fh = open(self.path, "ab")
        # One write(2) per line: once it returns, a killed process cannot lose the line. No fsync: the
        # journal is a hint, checked against each file's checksum on resume, so even a line that outlived
        # its file in a power cut only means the file is made again.
        self._fh.write((json.dumps(entry, sort_keys=True) + "\n").encode())
        self._fh.flush()
        self.entries[key] = entry

    def rewrite_sorted(self) -> None:
        """The whole journal again, in key order (atomically)."""
        self.close()
        text = "".join(json.dumps(self.entries[k], sort_keys=True) + "\n" for k in sorted(self.entries))
        self.path.parent.mkdir(parents=True, exist_ok=True)
        atomic_write(self.path, lambda tmp: tmp.write_text(text, encoding="utf-8"))

    def reset(self) -> None:
        self.close()
        self.path.unlink(missing_ok=True)
        self.entries = {}

    def close(self) -> None:
        if self._fh is not None:
            self._fh.close()
            self._fh = None


def read_state(folder: Path) -> dict | None:
    try:
        return json.loads((Path(folder) / STATE_DIR / STATE).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None


def write_state(folder: Path, state: Mapping) -> None:
    path = Path(folder) / STATE_DIR / STATE
    path.parent.mkdir(parents=True, exist_ok=True)
    atomic_write(path, lambda tmp: tmp.write_text(json.dumps(state, indent=2, sort_keys=True) + "\n"))


def _number(value: float) -> str:
    return f"{value:.6g}"


def row(item: Item, entry: Mapping) -> dict[str, str]:
    """One manifest row (all text) for a finished item."""
    stim = item.stimulus
    timed = item.kind != "still"
    return {
        "file": item.file, "kind": item.kind, "block": item.block, "list_no": str(item.list or ""),
        "character": item.character, "label": stim.label, "facs": stim.facs,
        "aus": " ".join(str(code) for code in item.aus), "emotion": stim.emotion or "", "table": stim.table or "",
        "side": stim.side if stim.kind == "au" else "", "intensity": _number(item.intensity),
        "peak": _number(item.peak), "engine": item.engine, "view": item.view, "width": str(item.width),
        "height": str(item.height), "duration": _number(item.duration) if timed else "",
        "fps": _number(item.fps) if timed else "", "onset": _number(item.onset) if timed and item.onset else "",
        "apex": _number(item.apex) if timed and item.apex else "",
        "offset": _number(item.offset) if timed and item.offset else "", "file_format": item.format,
        "checksum": entry["checksum"], "file_bytes": str(entry["bytes"]),
    }


def _csv_text(rows: Iterable[Mapping[str, str]], columns: tuple[str, ...]) -> str:
    buf = io.StringIO()
    writer = csv.DictWriter(buf, fieldnames=columns, extrasaction="ignore", lineterminator="\n")
    writer.writeheader()
    writer.writerows(rows)
    return buf.getvalue()


def write_manifest(folder: Path, items: Iterable[Item], entries: Mapping[str, Mapping], *, spec: Mapping,
                   spec_hash: str, naming: str, key_file: str, version: str) -> list[Path]:
    """Write manifest.csv and manifest.json (and the key for blind naming), sorted by file, atomically."""
    folder = Path(folder)
    rows = sorted((row(item, entries[item.key]) for item in items), key=lambda r: r["file"])
    blind = naming == "blind"
    columns = BLIND_COLUMNS if blind else COLUMNS
    shown = [{c: r[c] for c in columns} for r in rows]
    written = []
    if blind:
        written.append(atomic_write(folder / key_file,
                                    lambda tmp: tmp.write_text(_csv_text(rows, COLUMNS), encoding="utf-8")))
    document = {"facsim_version": version, "spec_hash": spec_hash, "naming": naming,
                "key_file": key_file if blind else None, "items": len(rows), "columns": list(columns),
                "spec": spec, "rows": shown}
    written.append(atomic_write(folder / MANIFEST_JSON, lambda tmp: tmp.write_text(
        json.dumps(document, indent=1, ensure_ascii=False) + "\n", encoding="utf-8")))
    written.append(atomic_write(folder / MANIFEST_CSV,
                                lambda tmp: tmp.write_text(_csv_text(shown, columns), encoding="utf-8")))
    return written


__all__ = ["BLIND_COLUMNS", "COLUMNS", "Journal", "read_state", "row", "sha256_file", "write_manifest",
           "write_state"]
