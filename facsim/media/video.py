"""Frames → files: MP4 (H.264, yuv420p), WebM (VP9), GIF and PNG sequences.

:class:`VideoWriter` is a resource (``with`` / ``close()``) that writes to a
temporary file beside the target and moves it into place only when every frame
was written, so an interrupted render never leaves a half-written video.

Wiring a timeline, a face and a writer together is :func:`facsim.pipeline.animate`'s job.

Examples
--------
>>> import numpy as np
>>> with VideoWriter("clip.mp4", fps=30) as writer:          # doctest: +SKIP
...     writer.append(np.zeros((64, 64, 3), np.uint8))
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from facsim.atomic import commit, discard, temp_beside

FORMATS = {".mp4": "mp4", ".m4v": "mp4", ".webm": "webm", ".gif": "gif"}


def video_format(path) -> str:
    """'mp4', 'webm', 'gif' or 'png' (a directory, or a name with '%d' or ending in .png)."""
    path = Path(path)
    if path.suffix.lower() in FORMATS:
        return FORMATS[path.suffix.lower()]
    if path.suffix.lower() == ".png" or path.suffix == "":
        return "png"
    raise ValueError(f"unknown video format {path.suffix!r} for {str(path)!r}; use .mp4, .webm, .gif, .png or a folder name")


class VideoWriter:
    """Append RGBA or RGB uint8 frames; ``close()`` finalises the file atomically.

    Parameters
    ----------
    path : path
        ``.mp4``, ``.webm``, ``.gif``; a folder (or ``name.png``) for a PNG sequence
        ``frame_00000.png`` …
    fps : float
    audio : path, optional
        An audio file muxed into MP4 (AAC) or WebM (Opus).
    quality : int
        ffmpeg quality 0–10 (imageio-ffmpeg's scale; 8 is visually lossless for faces).
    cut_audio : bool
        End the file with the shorter stream (ffmpeg ``-shortest``, for audio longer than
        the video). False for audio made to the video's length: ``-shortest`` ends on whole
        audio codec frames and can drop the last video frame.
    """

    def __init__(self, path, fps: float = 30.0, *, audio=None, quality: int = 8, cut_audio: bool = True):
        self.path = Path(path)
        self.format = video_format(self.path)
        self.fps = float(fps)
        if not self.fps > 0:
            raise ValueError(f"fps must be > 0, got {fps}")
        if audio is not None and not Path(audio).is_file():
            raise FileNotFoundError(f"audio file {audio} does not exist")
        if audio is not None and self.format not in ("mp4", "webm"):
            raise ValueError(f"an audio track can only be muxed into .mp4 or .webm, not {self.format}")
        self.audio = None if audio is None else str(audio)
        self.cut_audio = cut_audio
        self.quality = quality
        self.frames_written = 0
        self._encoder = None
        self._gif_frames: list = []
        if self.format == "png" and self.path.suffix:  # "frames.png" names the folder "frames"
            self.path = self.path.with_suffix("")
        if not self.path.parent.is_dir():
            raise FileNotFoundError(f"folder {self.path.parent} does not exist")
        self._tmp = temp_beside(self.path, directory=self.format == "png")
        self._closed = False

    def append(self, frame: np.ndarray) -> None:
        """Add one (H, W, 3|4) uint8 frame (alpha is composited over white for video codecs)."""
        frame = np.asarray(frame)
        if frame.dtype != np.uint8 or frame.ndim != 3 or frame.shape[2] not in (3, 4):
            raise ValueError(f"frames must be (H, W, 3|4) uint8 arrays, got {frame.dtype} {frame.shape}")
        if self.format == "png":
            from facsim.media.images import write_png

            write_png(self._tmp / f"frame_{self.frames_written:05d}.png", frame)
        elif self.format == "gif":
            self._gif_frames.append(_rgb(frame))
        else:
            if self._encoder is None:
                self._encoder = self._start(frame.shape[1], frame.shape[0])
            self._encoder.send(_opaque_rgba(frame))
        self.frames_written += 1

    def _start(self, width: int, height: int):
        import imageio_ffmpeg

        if width % 2 or height % 2:
            raise ValueError(f"H.264/VP9 with yuv420p need even frame sizes, got {width}x{height}")
        codec, extra = ("libx264", ["-preset", "veryfast", "-movflags", "+faststart"]) if self.format == "mp4" else ("libvpx-vp9", ["-row-mt", "1", "-deadline", "realtime", "-cpu-used", "8"])
        audio_codec = None if self.audio is None else ("aac" if self.format == "mp4" else "libopus")
        encoder = imageio_ffmpeg.write_frames(
            str(self._tmp), (width, height), fps=self.fps, codec=codec, pix_fmt_in="rgba", pix_fmt_out="yuv420p",
            quality=self.quality, macro_block_size=1, output_params=extra + (["-shortest"] if self.audio and self.cut_audio else []),
            audio_path=self.audio, audio_codec=audio_codec, ffmpeg_log_level="error",
        )
        encoder.send(None)  # start the generator
        return encoder

    def close(self) -> Path:
        """Finish the file and move it into place; returns the final path."""
        if self._closed:
            return self.path
        self._closed = True
        try:
            if self.frames_written == 0:
                raise ValueError("no frames were written")
            if self.format == "gif":
                from PIL import Image

                images = [Image.fromarray(f) for f in self._gif_frames]
                # GIF delays are whole centiseconds: spread the rounding so the clip keeps its length.
                ends = np.round(np.arange(1, len(images) + 1) * 100.0 / self.fps) * 10
                durations = np.diff(np.concatenate([[0], ends])).astype(int).tolist()
                images[0].save(self._tmp, format="GIF", save_all=True, append_images=images[1:],
                               duration=durations, loop=0, optimize=False)
            elif self._encoder is not None:
                self._encoder.close()
            return commit(self._tmp, self.path)
        except BaseException:
            self.abort()
            raise

    def abort(self) -> None:
        """Drop everything written so far."""
        self._closed = True
        if self._encoder is not None:
            try:
                self._encoder.close()
            except Exception:
                pass
        discard(self._tmp)

    def __enter__(self):
        return self

    def __exit__(self, exc_type, *exc):
        if exc_type is None:
            self.close()
        else:
            self.abort()


def _opaque_rgba(frame: np.ndarray) -> np.ndarray:
    """The frame as contiguous opaque RGBA: what the encoders read (ffmpeg drops the alpha
    itself, cheaper than copying the colour channels out of a renderer's RGBA frame)."""
    if frame.shape[2] == 4 and frame[..., 3].min() == 255:
        return np.ascontiguousarray(frame)
    out = np.empty(frame.shape[:2] + (4,), np.uint8)
    out[..., :3] = _rgb(frame)
    out[..., 3] = 255
    return out


def _rgb(frame: np.ndarray) -> np.ndarray:
    if frame.shape[2] == 3:
        return frame
    if frame[..., 3].min() == 255:  # opaque background: nothing to composite
        return frame[..., :3]
    alpha = frame[..., 3:4].astype(np.float32) / 255
    return (frame[..., :3] * alpha + 255 * (1 - alpha) + 0.5).astype(np.uint8)
