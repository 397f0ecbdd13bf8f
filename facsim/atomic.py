"""Atomic file output: write beside the target, then move into place.

Every file facsim writes goes through here, so an interrupted or failed write
never leaves a half-written file (the old one, if any, stays intact).

Examples
--------
>>> import tempfile, pathlib
>>> out = pathlib.Path(tempfile.mkdtemp()) / "note.txt"
>>> atomic_write(out, lambda tmp: tmp.write_text("hello")).read_text()
'hello'
"""
from __future__ import annotations

import os
import shutil
import tempfile
from pathlib import Path
from typing import Callable


def temp_beside(path, *, directory: bool = False) -> Path:
    """A new temporary file (or folder) in ``path``'s folder, to be :func:`commit`-ted."""
    path = Path(path)
    if directory:
        return Path(tempfile.mkdtemp(dir=path.parent, prefix=f".{path.name}."))
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".part" + path.suffix)
    os.close(fd)
    return Path(tmp)


def commit(tmp, path) -> Path:
    """Move a finished temporary file or folder onto ``path`` (replacing it), with normal permissions."""
    path, tmp = Path(path), Path(tmp)
    if tmp.is_dir():
        if path.exists():
            shutil.rmtree(path) if path.is_dir() else path.unlink()
        os.chmod(tmp, 0o777 & ~_umask())
    else:
        os.chmod(tmp, (path.stat().st_mode & 0o777) if path.exists() else 0o666 & ~_umask())  # mkstemp gives 0o600
    os.replace(tmp, path)
    return path


def discard(tmp) -> None:
    """Remove a temporary file or folder that will not be committed."""
    tmp = Path(tmp)
    if tmp.is_dir():
        shutil.rmtree(tmp, ignore_errors=True)
    else:
        tmp.unlink(missing_ok=True)


def atomic_write(path, write: Callable[[Path], object]) -> Path:
    """Call ``write(tmp)`` on a temporary file beside ``path``, then move it into place."""
    tmp = temp_beside(path)
    try:
        write(tmp)
        return commit(tmp, path)
    except BaseException:
        discard(tmp)
        raise


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask
