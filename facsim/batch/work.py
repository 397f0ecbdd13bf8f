"""One item → the bytes of its file, in whatever process runs it.

:func:`render_item` is the task the process pool and Dask workers run. It
keeps one :class:`facsim.Face` (and so one renderer and GL context) per
character and engine per process, so a worker pays for a head once, and
returns the finished file's bytes; the parent alone writes files and the
journal (one writer: nothing written twice, nothing half-written). The
bytes depend only on the item, so a retried or repeated task gives the same
file.

Worker processes must be started with ``spawn`` or ``forkserver``: an EGL
context inherited through ``fork`` hangs the child (checked on Mesa
llvmpipe). :func:`set_render_threads` sets ``LP_NUM_THREADS`` (llvmpipe's
threads per context) before the first context exists.
"""
from __future__ import annotations

import os
import shutil
import tempfile
from collections import OrderedDict
from pathlib import Path

from .items import Item

#: Faces kept per process; items arrive grouped by character, so a few suffice.
FACE_CACHE_SIZE = 4

_faces: "OrderedDict[tuple[str, str], object]" = OrderedDict()
_scratch: Path | None = None


def set_render_threads(threads: int | None) -> None:
    """Give llvmpipe ``threads`` per context (only before this process has made a context)."""
    if threads is not None and not _faces:
        os.environ["LP_NUM_THREADS"] = str(max(1, int(threads)))


def init_worker(threads: int | None) -> None:
    """Process-pool initializer: renderer threads, Ctrl-C left to the parent, and exit with the parent."""
    import signal

    set_render_threads(threads)
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # the parent handles Ctrl-C and stops the pool
    _exit_with_parent()


def _exit_with_parent(interval: float = 0.5) -> None:
    """Stop this process when its parent is gone (killed with SIGKILL, it cannot stop its pool): an
    orphaned worker would otherwise sit on its queue, or keep rendering items nobody will write."""
    import threading
    import time

    parent = os.getppid()

    def watch():
        while os.getppid() == parent:
            time.sleep(interval)
        os._exit(1)

    threading.Thread(target=watch, name="facsim-exit-with-parent", daemon=True).start()


def face_for(character: str, engine: str):
    """This process's Face for ``character`` and ``engine`` (made once, least recently used dropped)."""
    from facsim import Face

    key = (character, engine)
    if key in _faces:
        _faces.move_to_end(key)
        return _faces[key]
    while len(_faces) >= FACE_CACHE_SIZE:
        _, old = _faces.popitem(last=False)
        old.close()
    face = _faces[key] = Face(character, engine=engine)
    return face


def _scratch_dir() -> Path:
    global _scratch
    if _scratch is None or not _scratch.is_dir():
        _scratch = Path(tempfile.mkdtemp(prefix="facsim-batch-"))
        import atexit

        atexit.register(shutil.rmtree, _scratch, True)
    return _scratch


def item_timeline(item: Item, *, level: float | None = None):
    """The item's timeline: its own (timelines), else a HapFACS envelope to ``item.peak``
    (``level`` given: a constant hold at that level, for stills)."""
    import json

    from facsim.timeline.builders import stimulus_timeline
    from facsim.timeline.model import Hold, Timeline, Track
    from facsim.timeline.io import timeline_from_dict

    stim = item.stimulus
    if stim.kind == "timeline":
        return timeline_from_dict(json.loads(stim.timeline))
    if level is not None:
        source = {"emotion": stim.emotion, "table": stim.table} if stim.kind == "emotion" else {"facs": stim.facs}
        return Timeline((Track(timing=Hold(0.0, 1.0, level), **source),), intensities=item.intensities)
    what = stim.emotion if stim.kind == "emotion" else stim.facs
    return stimulus_timeline(what, item.onset, item.apex, item.offset, item.fps, intensity=item.peak,
                             easing=item.easing, table=stim.table, intensities=item.intensities)


def render_item(item: Item, threads: int | None = None) -> bytes:
    """Make ``item``'s file and return its bytes (PNG, MP4/WebM/GIF or GLB).

    ``threads`` sets ``LP_NUM_THREADS`` if this process has no context yet
    (Dask workers, which run no initializer).
    """
    set_render_threads(threads if "LP_NUM_THREADS" not in os.environ else None)
    face = face_for(item.character, item.engine)
    options = dict(view=item.view, size=(item.width, item.height), body=item.body)
    if item.kind == "still":
        from facsim.timeline.sampling import sample

        activations = sample(item_timeline(item, level=item.intensity), 0.5)
        image = face.render(activations, background=item.background, antialias=item.antialias, **options)
        return _png_bytes(image)
    if item.kind == "glb":
        from facsim.exchange.gltf import glb_bytes
        from facsim.engines.registers import register_table

        # Morph targets for the item's own AUs keep the file small (2.8 MB with all 68); head and eye
        # positions (51-58, 61-66) are joint rotations, animated whatever the targets.
        morphs = sorted(set(item.aus) & set(register_table()["action_units"]))
        return glb_bytes(face, item_timeline(item), aus=morphs or "all", fps=item.fps, body=item.body)
    from facsim.pipeline import animate

    path = _scratch_dir() / f"{os.getpid()}-item.{item.format}"
    try:
        animate(item_timeline(item), path, face=face, fps=item.fps,
                background=item.background, **options)
        return path.read_bytes()
    finally:
        path.unlink(missing_ok=True)


def _png_bytes(image) -> bytes:
    import io

    from PIL import Image

    buf = io.BytesIO()
    Image.fromarray(image, "RGBA" if image.shape[2] == 4 else "RGB").save(buf, format="PNG")
    return buf.getvalue()


__all__ = ["face_for", "init_worker", "item_timeline", "render_item", "set_render_threads"]
