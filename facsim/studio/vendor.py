"""three.js for the studio page: fetched once from the npm registry into the cache.

The studio's 3-D view runs three.js (MIT) in the browser. It is not committed to
facsim and needs no npm: on first use (or ``bash install.sh``) the published
tarball of one pinned version is downloaded with :mod:`urllib`, its sha512 is
checked against the registry's published ``dist.integrity``, and only the
files the page loads (``build/`` and ``examples/jsm/``) are unpacked into
``<cache>/three-<version>/``.

Examples
--------
>>> THREE_VERSION
'0.187.0'
>>> safe_vendor_path(Path("/x"), "../etc/passwd") is None
True
"""
from __future__ import annotations

import io
import os
import shutil
import tarfile
import tempfile
import urllib.request
from pathlib import Path

from facsim.wheel import sri_digest

THREE_VERSION = "0.187.0"
THREE_TARBALL = f"https://registry.npmjs.org/three/-/three-{THREE_VERSION}.tgz"
#: ``npm view three@0.187.0 dist.integrity``: the registry's published checksum of the tarball.
THREE_INTEGRITY = "sha512-Qiu7R+Cmh8CstZsY1uJOSWnVlfo7ZtNLV7mF8Jltk3LB3AtDu9cRZlcnRKkAk8Y4z6KKw35z7Y7Urd7jWY8etA=="
#: Tarball folders the page needs (everything else, docs and sources, is skipped).
_KEEP = ("package/build/", "package/examples/jsm/", "package/LICENSE")
#: Written last, so a folder without it is an interrupted unpack.
_DONE = ".complete"


class VendorError(RuntimeError):
    """three.js could not be fetched or failed its checksum."""


def _cache_dir() -> Path:
    from facsim.head.assets import cache_dir

    return cache_dir()


def three_dir() -> Path:
    """Where the unpacked three.js lives (it may not be there yet: see :func:`ensure_three`)."""
    return _cache_dir() / f"three-{THREE_VERSION}"


def check_integrity(data: bytes, integrity: str = THREE_INTEGRITY) -> None:
    """Raise :class:`VendorError` unless ``data`` has the npm ``integrity`` (``sha512-<base64>``)."""
    algorithm, _, expected = integrity.partition("-")
    digest = sri_digest(data, algorithm).partition("-")[2]
    if digest != expected:
        raise VendorError(f"three-{THREE_VERSION}.tgz failed its {algorithm} check (got {digest[:16]}…, "
                          f"expected {expected[:16]}…); the download is corrupt or was replaced")


def ensure_three(*, tarball: str | os.PathLike | None = None) -> Path:
    """The unpacked three.js folder, downloading and checking it first if needed.

    ``tarball`` (or ``FACSIM_THREE_TARBALL``) uses a local copy of the ``.tgz``
    instead of the registry (offline machines); it must pass the same check.
    """
    target = three_dir()
    if (target / _DONE).exists():
        return target
    source = tarball or os.environ.get("FACSIM_THREE_TARBALL")
    if source:
        data = Path(source).read_bytes()
    else:
        try:
            with urllib.request.urlopen(THREE_TARBALL, timeout=120) as response:
                data = response.read()
        except OSError as exc:
            raise VendorError(f"could not download three.js from {THREE_TARBALL}: {exc} "
                              f"(offline? set FACSIM_THREE_TARBALL to a local three-{THREE_VERSION}.tgz)") from None
    check_integrity(data)
    target.parent.mkdir(parents=True, exist_ok=True)
    staging = Path(tempfile.mkdtemp(prefix=".three-", dir=target.parent))
    try:
        with tarfile.open(fileobj=io.BytesIO(data), mode="r:gz") as archive:
            members = [m for m in archive.getmembers()
                       if m.isfile() and m.name.startswith(_KEEP) and ".." not in m.name.split("/")]
            archive.extractall(staging, members=members, filter="data")
        (staging / "package" / _DONE).write_text(THREE_INTEGRITY + "\n")
        if target.exists():      # an interrupted earlier unpack
            shutil.rmtree(target)
        os.replace(staging / "package", target)
    finally:
        shutil.rmtree(staging, ignore_errors=True)
    return target


#: URL prefix → folder inside the unpacked package, for the page's import map.
VENDOR_ROOTS = {"build": "build", "addons": "examples/jsm"}


def safe_vendor_path(root: Path, relative: str) -> Path | None:
    """``root / relative`` if it is a ``.js`` file inside ``root``, else None (never a path outside it)."""
    if not relative or relative.startswith("/") or "\\" in relative or ".." in relative.split("/"):
        return None
    path = (root / relative).resolve()
    try:
        path.relative_to(root.resolve())
    except ValueError:
        return None
    return path if path.suffix == ".js" and path.is_file() else None


if __name__ == "__main__":  # ``python -m facsim.studio.vendor``: used by install.sh
    print(f"three.js {THREE_VERSION}: {ensure_three()}")
