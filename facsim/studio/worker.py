"""The studio's render worker: the one process that owns the OpenGL context.

Everything here runs inside a process started with ``spawn`` by
:class:`facsim.studio.jobs.RenderQueue`; HTTP handlers never call it directly.
The first render creates the GL context in this process (never before a fork:
a forked EGL context hangs). Faces are cached per (character, engine), so
moving a slider and pressing Render again costs one frame.

Each public function takes plain data (already validated by
:mod:`facsim.studio.requests`) and returns bytes or a file name. Jobs write
only inside the job folder they are given; thumbnails go to facsim's cache.
"""
from __future__ import annotations

import io
import json
from collections import OrderedDict
from pathlib import Path

#: Progress messages go to the server through this queue (set by :func:`init`).
_progress = None
#: (character json, engine) → Face; a few characters stay warm.
_faces: "OrderedDict[tuple[str, str], object]" = OrderedDict()
MAX_FACES = 4
#: A job folder holding this file is cancelled: the frame loop stops at the next frame.
CANCEL_FLAG = "cancel"


class Cancelled(Exception):
    """The user cancelled the job."""


def init(progress_queue) -> None:
    """Process initializer: remember where progress goes."""
    global _progress
    _progress = progress_queue


def face_for(character: dict | str, engine: str = "registers"):
    """A cached :class:`facsim.Face` for ``character`` (preset name or parameters)."""
    from facsim import Face

    key = (json.dumps(character, sort_keys=True), engine)
    if key in _faces:
        _faces.move_to_end(key)
        return _faces[key]
    face = Face(character, engine=engine)
    _faces[key] = face
    while len(_faces) > MAX_FACES:
        _faces.popitem(last=False)[1].close()
    return face


def png_bytes(image) -> bytes:
    """PNG bytes exactly as :func:`facsim.images.write_png` writes them (``facsim render``'s encoder)."""
    from PIL import Image

    buf = io.BytesIO()
    Image.fromarray(image, "RGBA" if image.shape[2] == 4 else "RGB").save(buf, format="PNG")
    return buf.getvalue()


def render_png(character, engine: str, expression: str, intensities: str, options: dict) -> bytes:
    """One still, as ``facsim render EXPRESSION --character … --engine … [view options]``."""
    from facsim import parse

    face = face_for(character, engine)
    return png_bytes(face.render(parse(expression, intensities=intensities), **_options(options)))


def _options(options: dict) -> dict:
    out = dict(options)
    if out.get("background") is not None:
        out["background"] = tuple(out["background"])
    out["size"] = tuple(out["size"])
    return out


def thumbnail(character, path: str, size: int = 128) -> str:
    """Render a neutral portrait of ``character`` to ``path`` (atomically) once; returns the path."""
    from facsim.atomic import atomic_write

    target = Path(path)
    if not target.exists():
        face = face_for(character)
        data = png_bytes(face.render(None, size=size, antialias=4))
        target.parent.mkdir(parents=True, exist_ok=True)
        atomic_write(target, lambda tmp: tmp.write_bytes(data))
    return str(target)


def glb_bytes(character) -> bytes:
    """The character as ``facsim export glb`` writes it (all AU morph targets, no animation)."""
    from facsim.exchange.gltf import glb_bytes as build

    return build(face_for(character), None, aus="all", interpolation="LINEAR", normals=True, fps=None)


# -------------------------------------------------------------------- jobs ---

def _report(job_id: str, done: int, total: int) -> None:
    if _progress is not None:
        _progress.put((job_id, done, total))


def _check_cancel(folder: Path) -> None:
    if (folder / CANCEL_FLAG).exists():
        raise Cancelled()


def run_job(job_id: str, folder: str, kind: str, spec: dict) -> str:
    """Run one export job; writes a single file in ``folder`` and returns its name.

    ``kind`` is ``png``, ``video`` (``spec["format"]`` mp4/webm/gif), ``glb``,
    ``arkit-csv``, ``facs`` or ``analyse`` (the camera processor on ``spec["upload"]``,
    a file in the job folder, into ``analysis.json``). Progress is reported per frame for videos,
    as one step otherwise. Raises :class:`Cancelled` when the folder is flagged.
    """
    folder = Path(folder)
    _check_cancel(folder)
    if kind == "analyse":
        return _analyse(job_id, folder, spec)
    if kind == "png":
        data = render_png(spec["character"], spec["engine"], spec["expression"], spec["intensities"],
                          spec["options"])
        return _write(folder, "face.png", data, job_id)
    timeline = _timeline(spec["timeline"])
    if kind == "video":
        return _video(job_id, folder, timeline, spec)
    if kind == "glb":
        from facsim.exchange.gltf import glb_bytes as build

        _report(job_id, 0, 1)
        data = build(face_for(spec["character"]), timeline, aus="all", interpolation="LINEAR", normals=True,
                     fps=None, body=spec["body"])
        return _write(folder, "face.glb", data, job_id)
    if kind == "arkit-csv":
        from facsim.exchange.arkit import dumps_arkit_csv

        return _write(folder, "arkit.csv", dumps_arkit_csv(timeline).encode(), job_id)
    if kind == "facs":
        from facsim.exchange import dumps_notation

        return _write(folder, "timeline.facs", dumps_notation(timeline).encode(), job_id)
    raise ValueError(f"unknown job kind {kind!r}")


def _timeline(document: dict):
    from facsim.studio.requests import timeline_from_document

    return timeline_from_document(document)


def _write(folder: Path, name: str, data: bytes, job_id: str) -> str:
    from facsim.atomic import atomic_write

    atomic_write(folder / name, lambda tmp: tmp.write_bytes(data))
    _report(job_id, 1, 1)
    return name


def _video(job_id: str, folder: Path, timeline, spec: dict) -> str:
    """``facsim animate`` into the job folder, reporting each frame; stops at the next frame when cancelled."""
    from facsim.pipeline import animate

    name = f"clip.{spec['format']}"
    _report(job_id, 0, 0)

    def on_frame(done: int, total: int) -> None:
        _report(job_id, done, total)
        _check_cancel(folder)

    animate(timeline, folder / name, face=face_for(spec["character"], spec["engine"]), on_frame=on_frame,
            **_options(spec["options"]))
    return name


def _analyse(job_id: str, folder: Path, spec: dict) -> str:
    """The camera processor on the uploaded file: ``analysis.json`` with the FACS string (an image)
    or the analysed timeline (a video), as ``facsim analyse`` finds them."""
    from facsim.analysis.processor import AnalysisError, analyse, iter_frames
    from facsim.studio.requests import MAX_ANALYSE_FRAMES
    from facsim.timeline.io import timeline_to_dict

    source = folder / spec["upload"]
    what = "the uploaded image" if spec["kind"] == "image" else "the uploaded video"
    try:
        _, fps, total = iter_frames(source)
        if total and total > MAX_ANALYSE_FRAMES:
            raise AnalysisError(f"{what} has {total} frames; the studio analyses up to {MAX_ANALYSE_FRAMES} "
                                f"(use `facsim analyse` for longer videos)")
        _report(job_id, 0, total or 0)

        def on_frame(done: int) -> None:
            _check_cancel(folder)
            if done > MAX_ANALYSE_FRAMES:
                raise AnalysisError(f"{what} is longer than {MAX_ANALYSE_FRAMES} frames")
            _report(job_id, done, max(total or 0, done))

        result = analyse(source, on_frame=on_frame)
    except AnalysisError as exc:
        # the message names the server's path; the user knows the file by what they uploaded
        message = str(exc)
        for name in (f"image {source}", f"video {source}", str(source), source.name):
            message = message.replace(name, what)
        raise AnalysisError(message) from None
    if not result.success:
        raise AnalysisError(f"no face found in {what}")
    found = sum(f.success for f in result.frames)
    out = {"kind": spec["kind"], "frames": len(result.frames), "found": found, "fps": result.fps,
           "expression": result.notation, "unobservable": {str(k): v for k, v in result.unobservable.items()}}
    if spec["kind"] == "video":
        out["timeline"] = timeline_to_dict(result.timeline())
    return _write(folder, "analysis.json", json.dumps(out).encode(), job_id)
