"""Atomic file output: write beside the target, then move into place.

Every file facsim writes goes through here, so an interrupted or failed write
never leaves a half-written file (the old one, if any, stays intact), and
facsim never replaces what it did not make (:func:`check_target`):

- a folder of PNG frames replaces only an empty folder, or (with
  ``overwrite``) a folder holding nothing but facsim's ``frame_NNNNN.png``;
- the current folder (or one above it) and a file where a folder belongs (or
  the other way round) are always refused;
- a file replaces an existing file only if that one is of the same kind (its
  first bytes match the suffix), unless ``overwrite`` says so.

Temporaries are named ``.NAME.PID.XXXX.partSUFFIX``; one whose process is gone
(a run killed with SIGKILL) is removed by the next write to the same target.

Examples
--------
>>> import tempfile, pathlib
>>> out = pathlib.Path(tempfile.mkdtemp()) / "note.txt"
>>> atomic_write(out, lambda tmp: tmp.write_text("hello")).read_text()
'hello'
"""
from __future__ import annotations

import contextlib
import contextvars
import glob
import os
import re
import shutil
import tempfile
from pathlib import Path
from typing import Callable

#: What facsim itself puts in a folder of frames (and may therefore replace).
FRAME_NAME = re.compile(r"frame_\d+\.png")

_overwrite = contextvars.ContextVar("facsim_overwrite", default=False)


class OutputError(ValueError):
    """An output target facsim refuses to replace (one line naming the path and why)."""


@contextlib.contextmanager
def overwriting(allowed: bool = True):
    """Within the block, writes may replace facsim's own outputs and files of another kind
    (the CLI's ``--overwrite``)."""
    token = _overwrite.set(bool(allowed))
    try:
        yield
    finally:
        _overwrite.reset(token)


def check_target(path, *, directory: bool = False, overwrite: bool | None = None) -> None:
    """Raise :class:`OutputError` unless writing a file (or a folder) at ``path`` is safe."""
    path = Path(path)
    overwrite = _overwrite.get() if overwrite is None else overwrite
    resolved = path.resolve()
    try:
        cwd = Path.cwd().resolve()
    except FileNotFoundError:  # the current folder was removed: nothing of it to protect
        cwd = Path("/nonexistent")
    if resolved == cwd or resolved in cwd.parents or resolved == Path.home().resolve():
        raise OutputError(f"refusing to write over {str(path)!r}: it is the current folder, one above it or "
                          "the home folder; name a new file or folder")
    if not os.path.lexists(path):
        return
    if path.is_symlink():
        if directory or not overwrite:
            raise OutputError(f"{path} is a symbolic link; facsim does not replace it"
                              + ("" if directory else " (use --overwrite to replace the link itself)"))
        return
    if path.is_dir():
        if not directory:
            raise OutputError(f"{path} is a folder; name a file to write")
        entries = sorted(p.name for p in path.iterdir())
        foreign = [name for name in entries if not FRAME_NAME.fullmatch(name)]
        if foreign:
            shown = ", ".join(foreign[:3]) + (f" and {len(foreign) - 3} more" if len(foreign) > 3 else "")
            raise OutputError(f"{path} is a folder holding files facsim did not write ({shown}); "
                              "facsim never replaces it: name a new folder for the frames")
        if entries and not overwrite:
            raise OutputError(f"{path} already holds {len(entries)} frames; use --overwrite to replace them")
        return
    if directory:
        raise OutputError(f"{path} is a file, not a folder of frames; name a new folder")
    if not path.is_file():
        raise OutputError(f"{path} is not a regular file; facsim does not replace it")
    if not overwrite and not _same_kind(path):
        raise OutputError(f"{path} exists and is not a {path.suffix or 'suffix-less'} file facsim would write; "
                          "use --overwrite to replace it")


def temp_beside(path, *, directory: bool = False, overwrite: bool | None = None) -> Path:
    """A new temporary file (or folder) in ``path``'s folder, to be :func:`commit`-ted.

    Checks the target first (:func:`check_target`) and removes temporaries that
    killed runs left for the same target.
    """
    path = Path(path)
    check_target(path, directory=directory, overwrite=overwrite)
    remove_stale(path)
    prefix, suffix = f".{path.name}.{os.getpid()}.", ".part" + ("" if directory else path.suffix)
    if directory:
        return Path(tempfile.mkdtemp(dir=path.parent, prefix=prefix, suffix=suffix))
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=prefix, suffix=suffix)
    os.close(fd)
    return Path(tmp)


def remove_stale(path) -> list[Path]:
    """Remove temporaries for ``path`` whose process no longer runs; returns them."""
    path = Path(path)
    removed = []
    pattern = re.compile(re.escape(f".{path.name}.") + r"(\d+)\.[^/]*\.part" + re.escape(path.suffix))
    for found in glob.glob(glob.escape(str(path.parent / f".{path.name}.")) + "*.part*"):
        match = pattern.fullmatch(Path(found).name)
        if match and not _alive(int(match.group(1))):
            discard(found)
            removed.append(Path(found))
    return removed


def commit(tmp, path, *, overwrite: bool | None = None) -> Path:
    """Move a finished temporary file or folder onto ``path`` (replacing it, if :func:`check_target`
    allows), with normal permissions."""
    path, tmp = Path(path), Path(tmp)
    check_target(path, directory=tmp.is_dir(), overwrite=overwrite)  # again: it may have appeared meanwhile
    if tmp.is_dir():
        if path.is_dir():
            shutil.rmtree(path)   # empty, or only facsim's frames (check_target)
        os.chmod(tmp, 0o777 & ~_umask())
    else:
        os.chmod(tmp, (path.stat().st_mode & 0o777) if path.exists() else 0o666 & ~_umask())  # mkstemp gives 0o600
    os.replace(tmp, path)
    return path


def discard(tmp) -> None:
    """Remove a temporary file or folder that will not be committed."""
    tmp = Path(tmp)
    if tmp.is_dir() and not tmp.is_symlink():
        shutil.rmtree(tmp, ignore_errors=True)
    else:
        tmp.unlink(missing_ok=True)


def atomic_write(path, write: Callable[[Path], object], *, overwrite: bool | None = None) -> Path:
    """Call ``write(tmp)`` on a temporary file beside ``path``, then move it into place."""
    tmp = temp_beside(path, overwrite=overwrite)
    try:
        write(tmp)
        return commit(tmp, path, overwrite=overwrite)
    except BaseException:
        discard(tmp)
        raise


# First bytes of the binary formats facsim writes; text formats must read as UTF-8 text.
_MAGIC = {".png": (b"\x89PNG\r\n\x1a\n",), ".gif": (b"GIF87a", b"GIF89a"), ".webm": (b"\x1a\x45\xdf\xa3",),
          ".glb": (b"glTF",), ".wav": (b"RIFF",), ".npy": (b"\x93NUMPY",), ".ply": (b"ply",),
          ".jpg": (b"\xff\xd8\xff",), ".jpeg": (b"\xff\xd8\xff",)}
_TEXT = {".yaml", ".yml", ".json", ".csv", ".facs", ".obj", ".svg", ".txt"}


def _same_kind(path: Path) -> bool:
    """Whether an existing file looks like what facsim writes under its suffix (empty files do)."""
    suffix = path.suffix.lower()
    with open(path, "rb") as fh:
        head = fh.read(8192)
    if not head:
        return True
    if suffix in _MAGIC:
        return head.startswith(_MAGIC[suffix])
    if suffix in (".mp4", ".m4v"):
        return head[4:8] == b"ftyp"
    if suffix in _TEXT:
        if b"\0" in head:
            return False
        try:
            head.decode("utf-8")
        except UnicodeDecodeError as exc:
            return exc.start >= len(head) - 3  # a character cut at the end of the sample
    return True


def _alive(pid: int) -> bool:
    if pid == os.getpid():
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask
