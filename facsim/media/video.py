"""Frames → files: MP4 (H.264, yuv420p), WebM (VP9), GIF and PNG sequences.

:class:`VideoWriter` is a resource (``with`` / ``close()``) that writes to a
temporary file beside the target and moves it into place only when every frame
was written and the file holds them all, so an interrupted or failed render
never leaves a half-written video, and never reports one as written.

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

from facsim.atomic import check_target, commit, discard, temp_beside

FORMATS = {".mp4": "mp4", ".m4v": "mp4", ".webm": "webm", ".gif": "gif"}


def video_format(path) -> str:
    """'mp4', 'webm', 'gif' or 'png' (a directory, or a name with '%d' or ending in .png)."""
    path = Path(path)
    if path.suffix.lower() in FORMATS:
        return FORMATS[path.suffix.lower()]
    if path.suffix.lower() == ".png" or path.suffix == "":
        return "png"
    raise ValueError(f"unknown video format {path.suffix!r} for {str(path)!r}; use .mp4, .webm, .gif, .png or a folder name")


def check_output(path, *, audio=None, overwrite: bool | None = None) -> Path:
    """Refuse, before any frame is rendered, an output :class:`VideoWriter` would refuse at its
    start (format, folder, a target facsim must not replace, audio ffmpeg cannot read); returns
    the path the video will have."""
    path = Path(path)
    fmt = video_format(path)
    if fmt == "png" and path.suffix:
        path = path.with_suffix("")
    if not path.parent.is_dir():
        raise FileNotFoundError(f"folder {path.parent} does not exist")
    check_target(path, directory=fmt == "png", overwrite=overwrite)
    if audio is not None and Path(audio).is_file() and fmt in ("mp4", "webm"):
        _check_audio(audio)
    return path


class VideoError(RuntimeError):
    """ffmpeg failed, or the finished file does not hold every frame (one line: the file and ffmpeg's reason)."""


class VideoWriter:
    """Append RGBA or RGB uint8 frames; ``close()`` finalises the file atomically.

    MP4, WebM and GIF frames stream into one ffmpeg process (memory flat in the
    video's length); ``close()`` checks ffmpeg's exit status and counts the
    frames in the finished file before moving it into place. Identical frames
    give byte-identical files in every format.

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
    overwrite : bool, optional
        May replace a folder of facsim's own frames or a file of another kind
        (see :func:`facsim.atomic.check_target`); default: the CLI's ``--overwrite``.
    """

    def __init__(self, path, fps: float = 30.0, *, audio=None, quality: int = 8, cut_audio: bool = True,
                 overwrite: bool | None = None):
        self.path = Path(path)
        self.format = video_format(self.path)
        self.fps = float(fps)
        if not self.fps > 0 or not np.isfinite(self.fps):
            raise ValueError(f"fps must be > 0, got {fps}")
        if audio is not None and not Path(audio).is_file():
            raise FileNotFoundError(f"audio file {audio} does not exist")
        if audio is not None and self.format not in ("mp4", "webm"):
            raise ValueError(f"an audio track can only be muxed into .mp4 or .webm, not {self.format}")
        if audio is not None:
            _check_audio(audio)
        self.audio = None if audio is None else str(audio)
        self.cut_audio = cut_audio
        self.quality = quality
        self.overwrite = overwrite
        self.frames_written = 0
        self._encoder = None     # the ffmpeg process
        self._log = None         # its stderr
        if self.format == "png" and self.path.suffix:  # "frames.png" names the folder "frames"
            self.path = self.path.with_suffix("")
        if not self.path.parent.is_dir():
            raise FileNotFoundError(f"folder {self.path.parent} does not exist")
        self._tmp = temp_beside(self.path, directory=self.format == "png", overwrite=overwrite)
        self._closed = False

    def append(self, frame: np.ndarray) -> None:
        """Add one (H, W, 3|4) uint8 frame (alpha is composited over white for video codecs)."""
        frame = np.asarray(frame)
        if frame.dtype != np.uint8 or frame.ndim != 3 or frame.shape[2] not in (3, 4):
            raise ValueError(f"frames must be (H, W, 3|4) uint8 arrays, got {frame.dtype} {frame.shape}")
        if self.format == "png":
            from facsim.media.images import write_png

            write_png(self._tmp / f"frame_{self.frames_written:05d}.png", frame)
        else:
            if self._encoder is None:
                self._size = (frame.shape[1], frame.shape[0])
                self._encoder = self._start(*self._size)
            elif (frame.shape[1], frame.shape[0]) != self._size:
                raise ValueError(f"frame {self.frames_written} is {frame.shape[1]}x{frame.shape[0]}, "
                                 f"the video {self._size[0]}x{self._size[1]}")
            try:
                self._encoder.stdin.write(memoryview(_opaque_rgba(frame)).cast("B"))
            except (BrokenPipeError, OSError):   # ffmpeg stopped: say why
                raise self._failure() from None
        self.frames_written += 1

    def _start(self, width: int, height: int):
        import subprocess
        import tempfile
        from fractions import Fraction

        import imageio_ffmpeg

        if self.format != "gif" and (width % 2 or height % 2):
            raise ValueError(f"H.264/VP9 with yuv420p need even frame sizes, got {width}x{height}")
        loss = 1 - self.quality / 10.0   # imageio-ffmpeg's quality scale, so files match earlier versions
        cmd = [imageio_ffmpeg.get_ffmpeg_exe(), "-y", "-v", "error", "-f", "rawvideo", "-vcodec", "rawvideo",
               "-s", f"{width}x{height}", "-pix_fmt", "rgba", "-r", str(Fraction(self.fps).limit_denominator()),
               "-i", "-"]
        if self.audio is not None:
            cmd += ["-i", self.audio, "-map", "0:v:0", "-map", "1:a:0",
                    "-acodec", "aac" if self.format == "mp4" else "libopus"]
            cmd += ["-shortest"] if self.cut_audio else []
        else:
            cmd += ["-an"]
        if self.format == "mp4":
            cmd += ["-vcodec", "libx264", "-pix_fmt", "yuv420p", "-crf", str(int(loss * 51)),
                    "-preset", "veryfast", "-movflags", "+faststart"]
        elif self.format == "webm":
            # bitexact + no metadata: the muxer writes no random segment UID, date or encoder
            # version, so identical frames give identical files.
            cmd += ["-vcodec", "libvpx-vp9", "-pix_fmt", "yuv420p", "-qscale:v", str(int(loss * 30) + 1),
                    "-row-mt", "1", "-deadline", "realtime", "-cpu-used", "8",
                    "-fflags", "+bitexact", "-flags:v", "+bitexact", "-flags:a", "+bitexact", "-map_metadata", "-1"]
        else:
            # A palette per frame, made and used as the frame passes: nothing is kept for the whole clip.
            cmd += ["-lavfi", "split[a][b];[a]palettegen=stats_mode=single[p];[b][p]paletteuse=new=1",
                    "-loop", "0"]
        cmd += ["-f", self.format, str(self._tmp)]
        self._log = tempfile.TemporaryFile()
        # A session of its own: Ctrl-C in a terminal stops facsim, which then stops ffmpeg and
        # removes the temporary file, rather than ffmpeg dying first with a broken pipe.
        encoder = subprocess.Popen(cmd, stdin=subprocess.PIPE, stdout=subprocess.DEVNULL, stderr=self._log,
                                   start_new_session=True)
        _widen_pipe(encoder.stdin, width * height * 4)
        return encoder

    def _failure(self) -> Exception:
        """The error to raise when ffmpeg failed: its exit status and the last line it wrote."""
        try:
            self._encoder.stdin.close()
        except OSError:
            pass
        status = self._encoder.wait()
        self._log.seek(0)
        lines = [line.strip() for line in self._log.read().decode("utf-8", "replace").splitlines() if line.strip()]
        if status == 0:  # it ended the file on its own: -shortest with shorter audio
            if self.audio and self.cut_audio:   # a user error (exit 2 in the CLI), not a failure of ffmpeg's
                return ValueError(f"could not write {self.path}: the audio {self.audio} is shorter than the "
                                  f"video (it ends at frame {self.frames_written})")
            return VideoError(f"could not write {self.path}: ffmpeg stopped taking frames at frame {self.frames_written}")
        reason = lines[-1] if lines else f"exit status {status}"
        return VideoError(f"could not write {self.path}: ffmpeg failed ({reason[:300]})")

    def close(self) -> Path:
        """Finish the file, check it holds every frame, and move it into place; returns the final path."""
        if self._closed:
            return self.path
        self._closed = True
        try:
            if self.frames_written == 0:
                raise ValueError("no frames were written")
            if self._encoder is not None:
                try:
                    self._encoder.stdin.close()
                except OSError:
                    pass
                if self._encoder.wait() != 0:
                    raise self._failure()
                found = count_frames(self._tmp)
                # -shortest ends on whole audio codec frames: it may drop the last video frame.
                least = self.frames_written - (1 if self.audio and self.cut_audio else 0)
                if not least <= found <= self.frames_written:
                    hint = " (is the audio shorter than the video?)" if self.audio and found < least else ""
                    raise VideoError(f"could not write {self.path}: it holds {found} of "
                                     f"{self.frames_written} frames{hint}")
            return commit(self._tmp, self.path, overwrite=self.overwrite)
        except BaseException:
            self.abort()
            raise

    def abort(self) -> None:
        """Drop everything written so far (stops ffmpeg, removes the temporary file)."""
        self._closed = True
        if self._encoder is not None:
            if self._encoder.poll() is None:
                self._encoder.kill()
            try:
                self._encoder.stdin.close()
            except OSError:
                pass
            self._encoder.wait()
        if self._log is not None:
            self._log.close()
        discard(self._tmp)

    def __enter__(self):
        return self

    def __exit__(self, exc_type, *exc):
        if exc_type is None:
            self.close()
        else:
            self.abort()


def _widen_pipe(pipe, frame_bytes: int) -> None:
    """Let the pipe to ffmpeg hold a whole frame (Linux; 64 KiB by default), so handing a frame
    over returns at once and the next frame is drawn while ffmpeg encodes this one."""
    try:
        import fcntl

        with open("/proc/sys/fs/pipe-max-size") as f:
            limit = int(f.read())
        fcntl.fcntl(pipe.fileno(), 1031, min(frame_bytes, limit))  # F_SETPIPE_SZ
    except (ImportError, OSError, ValueError):  # not Linux, or not allowed: the default pipe works
        pass


def count_frames(path) -> int:
    """Video frames in an MP4, WebM or GIF file (its packets, read without decoding)."""
    import re
    import subprocess

    import imageio_ffmpeg

    run = subprocess.run([imageio_ffmpeg.get_ffmpeg_exe(), "-nostdin", "-v", "error", "-nostats", "-i", str(path),
                          "-map", "0:v:0", "-c", "copy", "-f", "null", "-progress", "pipe:1", "-"],
                         capture_output=True, text=True)
    counts = re.findall(r"^frame=(\d+)", run.stdout, re.M)
    if run.returncode != 0 or not counts:
        return 0
    return int(counts[-1])


def _check_audio(audio) -> None:
    """Refuse a file ffmpeg cannot read as sound, before any frame is rendered."""
    import subprocess

    import imageio_ffmpeg

    run = subprocess.run([imageio_ffmpeg.get_ffmpeg_exe(), "-nostdin", "-v", "error", "-i", str(audio),
                          "-map", "0:a:0", "-c", "copy", "-f", "null", "-"], capture_output=True, text=True)
    if run.returncode != 0:
        lines = [line.strip() for line in run.stderr.splitlines() if line.strip()]
        reason = lines[-1] if lines else f"ffmpeg exit status {run.returncode}"
        raise ValueError(f"audio file {audio} is not sound ffmpeg can read: {reason[:200]}")


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
