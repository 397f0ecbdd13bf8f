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

from pathlib import Path
from typing import Callable

import numpy as np


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
    speech = None if audio is not None else _speech_audio(timeline, fps)
    try:
        if speech is not None and video_format(path) in ("mp4", "webm"):
            audio = speech.name
        with VideoWriter(path, fps, audio=audio, cut_audio=speech is None) as writer:
            engine = face.start_animation()
            for i, act in enumerate(frames):
                writer.append(face.render(deformation=engine.step(act), **render_options))
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
