"""The one place that wires character → engine → renderer → writer.

:func:`render_frame` turns one expression into an image; :func:`animate` turns
a timeline into a video file, stepping the engine frame by frame (an engine
with state applies only each frame's change).

Examples
--------
>>> from facsim.timeline.builders import stimulus_timeline    # doctest: +SKIP
>>> animate(stimulus_timeline("happiness"), "happy.mp4")       # doctest: +SKIP
PosixPath('happy.mp4')
"""
from __future__ import annotations

import os
import sys
import threading
from contextlib import contextmanager
from pathlib import Path
from typing import Callable, Iterator

import numpy as np

#: Frames below which deforming in a second process does not pay for starting it.
FORKED_MIN_FRAMES = 8
#: Frames the forked engine may run ahead of the drawing (a 512² frame's geometry is ~0.25 MB).
LOOKAHEAD = 64
#: Most bytes of finished frames kept to be written again later in the video (see :func:`frame_sources`).
KEPT_FRAMES_BYTES = 256 * 2**20


def render_frame(face, expression=None, **render_options) -> np.ndarray:
    """``face`` showing ``expression`` as an (H, W, 4) uint8 image (see :meth:`facsim.face.Face.render`)."""
    return face.render(expression, **render_options)


def animate(timeline, path, *, face=None, character=None, engine=None, fps: float | None = None, audio=None,
            on_frame: Callable[[int, int], None] | None = None, **render_options) -> Path:
    """Render ``timeline`` to a video file (or PNG sequence) at ``path``.

    Parameters
    ----------
    timeline : Timeline
    path : path
        ``.mp4``, ``.webm``, ``.gif``, or a folder for PNG frames (see :class:`~facsim.media.video.VideoWriter`).
    face : Face, optional
        The face to render; without one, a Face is made from ``character`` and
        ``engine``, which default to the timeline's settings, then "ava" and
        "registers". Giving ``face`` together with ``character`` or ``engine``
        is an error (they would be ignored).
    on_frame : callable(done, total), optional
        Called after each frame is written (progress bars, cancellation by raising).
    **render_options
        :meth:`Face.render` options (view, yaw, pitch, size, projection,
        background, antialias); video frames default to FXAA, which keeps up
        with real time where 4x MSAA does not.

    Returns
    -------
    Path of the finished file.

    Speed: a frame that shows what an earlier frame showed is that frame again, not drawn
    anew, where the engine keeps no state between frames (see :func:`frame_sources`: a
    stimulus video's apex holds one picture, and its offset replays its onset); the engine
    runs a few frames ahead in a forked child where that is safe (see :func:`deformations`),
    and the renderer keeps hair that holds still as pixels for the length of the video (see
    :meth:`Renderer.sequence <facsim.render.renderer.Renderer.sequence>`).
    ``benchmarks/bench_video.py`` measures the 3-s stimulus video end to end and per stage.

    A timeline with speech tracks gets their sound (unless ``audio`` is given):
    AAC in MP4, Opus in WebM, a WAV beside PNG frames (``frames/`` → ``frames.wav``);
    GIFs have no sound.
    """
    from facsim.face import Face
    from facsim.media.video import VideoWriter, check_output, video_format
    from facsim.timeline.sampling import sample_frames

    if face is not None and (character is not None or engine is not None):
        raise ValueError("give either face= or character=/engine=, not both (a Face already has its character and engine)")
    check_output(path, audio=audio)  # refuse a bad target before the face is built and frames rendered
    render_options.setdefault("antialias", "fxaa")
    own_face = face is None
    if own_face:
        face = Face(character or timeline.character or "ava", engine=engine or timeline.engine or "registers")
    fps = fps or timeline.fps
    frames = sample_frames(timeline, fps)
    width, height = _frame_size(face, render_options)
    sources = frame_sources(face, frames, frame_bytes=width * height * 4)
    speech = None if audio is not None else _speech_audio(timeline, fps)
    try:
        if speech is not None and video_format(path) in ("mp4", "webm"):
            audio = speech.name
        with VideoWriter(path, fps, audio=audio, cut_audio=speech is None) as writer, \
                deformations(face, [act for i, act in enumerate(frames) if sources[i] == i]) as stream, \
                face.renderer(**render_options).sequence():
            for i, image in enumerate(_frames_drawn(sources, stream, lambda d: face.render(deformation=d,
                                                                                            **render_options))):
                writer.append(image)
                if on_frame is not None:
                    on_frame(i + 1, len(frames))
        if speech is not None and writer.format == "png":     # PNG frames: the sound goes beside them
            import shutil

            from facsim.atomic import atomic_write

            atomic_write(writer.path.with_suffix(".wav"), lambda tmp: shutil.copyfile(speech.name, tmp))
        return writer.path
    finally:
        if own_face:
            face.close()
        if speech is not None:
            speech.close()


def frame_sources(face, frames, *, frame_bytes: int = 512 * 512 * 4, budget: int | None = None) -> list[int]:
    """For each frame of ``frames`` (Activations), the frame whose picture it shows: itself,
    or an earlier frame with the same activations whose image is kept to be written again.

    Only for an engine that keeps no state between frames (its class says ``stateless =
    True``, as the register engine's does): each of its frames depends on that frame's
    activations alone, so equal activations give the same deformation, bit for bit, and the
    same picture. A stateful engine (the muscle engine keeps relaxing a held expression) gets
    every frame drawn. Images are kept only while ``budget`` bytes (default
    :data:`KEPT_FRAMES_BYTES`) hold them, ``frame_bytes`` each; beyond it a frame is drawn again.

    Examples
    --------
    >>> from facsim.facs.activations import Activations
    >>> smile = Activations({(12, "left"): 0.5})
    >>> frame_sources(None, [Activations(), smile, smile, Activations()], budget=2**30)
    [0, 1, 1, 0]
    """
    if face is not None:
        from facsim.engines import ENGINES, engine_class

        name = getattr(face, "engine_name", None)
        if name not in ENGINES or not getattr(engine_class(name), "stateless", False):
            return list(range(len(frames)))
    budget = KEPT_FRAMES_BYTES if budget is None else budget
    keys = [tuple(act.levels.items()) for act in frames]
    last = {key: i for i, key in enumerate(keys)}
    held: dict = {}  # key -> the frame whose image is kept for it
    kept = 0
    sources = []
    for i, key in enumerate(keys):
        if key in held:
            sources.append(held[key])
            if last[key] == i:  # its last use: the image is dropped
                del held[key]
                kept -= frame_bytes
            continue
        sources.append(i)
        if last[key] > i and kept + frame_bytes <= budget:
            held[key] = i
            kept += frame_bytes
    return sources


def _frames_drawn(sources: list[int], deformations, draw) -> Iterator[np.ndarray]:
    """The video's images in order: ``draw(deformation)`` for each frame that is its own source
    (``deformations`` yields theirs in order), a kept image for the others (see :func:`frame_sources`)."""
    uses: dict[int, int] = {}
    for source in sources:
        uses[source] = uses.get(source, 0) + 1
    kept: dict[int, np.ndarray] = {}
    for i, source in enumerate(sources):
        if source == i:
            image = draw(next(deformations))
            if uses[i] > 1:
                kept[i] = image
        else:
            image = kept[source]
        uses[source] -= 1
        if not uses[source]:
            kept.pop(source, None)
        yield image


def _frame_size(face, render_options) -> tuple[int, int]:
    """(width, height) of the frames ``face.render(**render_options)`` draws."""
    from facsim.render.options import RenderOptions

    values = dict(render_options)
    options = values.pop("options", None) or RenderOptions()
    return (options.replace(**values) if values else options).size


@contextmanager
def deformations(face, frames) -> Iterator[Iterator]:
    """The face's engine stepped through ``frames`` (Activations): an iterator of Deformations.

    Deforming and drawing take turns in one process: on llvmpipe the GL threads wait while
    Python deforms the next frame, and Python waits while they draw. Where it is safe, the
    engine runs in a forked child instead, up to :data:`LOOKAHEAD` frames ahead of the
    drawing (the child is a copy of this process, so it starts at once and computes exactly
    what this process would; it deforms while this process starts its renderer, and while
    llvmpipe draws). It is safe on Linux before this process has made its GL context (EGL does
    not survive a fork) and with no other Python thread running; elsewhere, and with
    ``FACSIM_SERIAL_FRAMES=1`` in the environment, frames are deformed here as they are drawn.
    """
    forked = (len(frames) >= FORKED_MIN_FRAMES and sys.platform.startswith("linux")
              and os.environ.get("FACSIM_SERIAL_FRAMES", "") in ("", "0") and threading.active_count() == 1)
    if forked:
        from facsim.render.gl import context_exists

        forked = not context_exists()
    if not forked:
        engine = face.start_animation()
        yield (engine.step(act) for act in frames)
        return
    import multiprocessing

    ctx = multiprocessing.get_context("fork")
    queue = ctx.Queue(maxsize=LOOKAHEAD)
    child = ctx.Process(target=_deform_frames, args=(face, frames, queue, os.getpid()), daemon=True,
                        name="facsim-deform")
    try:  # a signal may arrive while the child starts: it is then cleaned up here too
        child.start()
        yield _received(queue, len(frames), child)
    finally:
        if child.pid is not None:
            if child.is_alive():  # stopped early (an error, a signal), or finishing: nothing to keep
                child.join(timeout=0.5)
                if child.is_alive():
                    child.kill()
            child.join()
        queue.close()
        queue.cancel_join_thread()


def _deform_frames(face, frames, queue, parent: int) -> None:
    """The forked child: put each frame's (positions, wrinkle, crease_phase), then None or an error.

    Signals get their default actions back: the parent's handlers (the CLI's, which report and
    clean up) are the parent's business, and Ctrl-C in a terminal reaches both processes.
    A child whose parent is gone exits instead of waiting on a full queue (it would keep the
    parent's stdout and stderr open, and whoever waits on them would wait for ever).
    """
    import queue as queues
    import signal

    for name in ("SIGINT", "SIGTERM", "SIGHUP"):
        if hasattr(signal, name):
            signal.signal(getattr(signal, name), signal.SIG_DFL)

    def put(item) -> None:
        while True:
            try:
                return queue.put(item, timeout=1.0)
            except queues.Full:
                if os.getppid() != parent:
                    os._exit(0)

    try:
        engine = face.start_animation()
        for act in frames:
            d = engine.step(act)
            put((d.positions, d.wrinkle, d.crease_phase))
        put(None)
    except BaseException as exc:  # noqa: BLE001 — handed to the parent, which raises it
        import pickle

        try:
            pickle.dumps(exc)
        except Exception:  # noqa: BLE001 — an exception that does not pickle: its type and message
            exc = RuntimeError(f"{type(exc).__name__}: {exc}")
        put(("error", exc))


def _received(queue, count: int, child) -> Iterator:
    import queue as queues

    from facsim.engines.base import Deformation

    def take():
        while True:
            try:
                return queue.get(timeout=1.0)
            except queues.Empty:
                if not child.is_alive():
                    raise RuntimeError(f"the deformation process stopped (exit code {child.exitcode})") from None

    for i in range(count + 1):
        item = take()
        if isinstance(item, tuple) and len(item) == 2 and item[0] == "error":
            raise item[1]
        if (item is None) != (i == count):
            raise RuntimeError(f"the deformation process sent {i} of {count} frames")
        if item is not None:
            positions, wrinkle, phase = item
            yield Deformation(positions, creases=None if wrinkle is None else (lambda w=wrinkle, p=phase: (w, p)))


def _speech_audio(timeline, fps):
    """A temporary WAV of the timeline's speech, as long as the video (``None`` without speech tracks)."""
    import tempfile

    from facsim.timeline.sampling import frame_count
    from facsim.timeline.speech import timeline_audio

    speech = timeline_audio(timeline, frame_count(timeline, fps) / fps)
    if speech is None:
        return None
    from scipy.io import wavfile

    from facsim.speech.audio import to_pcm16

    samples, rate = speech
    tmp = tempfile.NamedTemporaryFile(prefix="facsim-speech-", suffix=".wav")
    wavfile.write(tmp.name, rate, to_pcm16(samples))
    return tmp
