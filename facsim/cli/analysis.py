"""CLI commands of the camera processor: ``analyse``, ``retarget``, ``validate``.

``add_commands(sub)`` adds them to the ``facsim`` parser; handlers raise
ValueError-type errors (:class:`~facsim.analysis.processor.AnalysisError`) for one-line exit-2 messages.
"""
from __future__ import annotations

import sys
from pathlib import Path

from facsim.cli.options import integer


def add_commands(sub, add_view_options=None) -> None:
    p = sub.add_parser("analyse", aliases=["analyze"], help="images or video of a real face -> FACS (camera processor)")
    p.add_argument("input", help="an image, a folder of images, or a video")
    p.add_argument("-o", "--output", help="write .csv (OpenFace 2.0 layout), .yaml/.json (timeline) or .facs")
    p.add_argument("--face", type=integer(0, 99), default=0, help="which face when there are several: 0 = largest (default)")
    p.add_argument("--neutral", help="an image of the same person at rest (their baseline)")
    p.add_argument("--no-smooth", action="store_true", help="no temporal smoothing of video landmarks")
    p.add_argument("--no-baseline", action="store_true",
                   help="video without --neutral: do not take its least active frames as the person's rest")
    p.add_argument("--threads", type=integer(1, 256), default=1, help="interpreter threads per model (default 1)")
    p.add_argument("--explain", action="store_true", help="also list the AUs landmarks cannot show, and why")
    p.set_defaults(handler=cmd_analyse)

    p = sub.add_parser("retarget", help="re-enact a face video on a facsim character (audio kept)")
    p.add_argument("input", help="a video of a face")
    p.add_argument("-o", "--output", required=True, help="the character video (.mp4, .webm, .gif)")
    p.add_argument("--character", "-c", default="ava", help="preset name or random:SEED")
    p.add_argument("--engine", choices=("registers", "muscle"), default="registers")
    p.add_argument("--size", type=integer(16, 8192), default=384, help="output frame size in pixels (square, default 384)")
    p.add_argument("--face", type=integer(0, 99), default=0, help="which face when there are several")
    p.add_argument("--neutral", help="an image of the performer at rest")
    p.add_argument("--no-baseline", action="store_true",
                   help="without --neutral: do not take the video's least active frames as the performer's rest")
    p.set_defaults(handler=cmd_retarget)

    p = sub.add_parser("validate", help="closed loop: render known expressions, analyse them, score per AU")
    p.add_argument("--engine", choices=("registers", "muscle", "both"), default="both")
    p.add_argument("--characters",
                   help="comma-separated presets, or all (default: ava, kwame, mei, george; --quick: ava)")
    p.add_argument("--quick", action="store_true", help="a small set: front view, one character, fewer cases")
    p.add_argument("-o", "--output", default="validation", help="report folder (default ./validation)")
    p.add_argument("--size", type=integer(16, 8192), default=320, help="render size in pixels (default 320)")
    p.set_defaults(handler=cmd_validate)


def _limit_threads() -> None:
    """One BLAS thread: the fit's small solves are many times slower when threads fight for 2 cores."""
    try:
        from threadpoolctl import threadpool_limits

        threadpool_limits(1)
    except ImportError:
        pass


def cmd_analyse(args) -> int:
    from facsim.analysis.processor import AnalysisError, analyse, input_kind

    _limit_threads()
    kind = input_kind(args.input)
    if args.threads < 1:
        raise AnalysisError(f"--threads must be 1 or more, got {args.threads}")
    if args.output and Path(args.output).suffix.lower() not in (".csv", ".yaml", ".yml", ".json", ".facs"):
        raise AnalysisError(f"cannot write {args.output}: use .csv (OpenFace), .yaml/.json (timeline) or .facs")
    progress = _progress_printer() if kind == "video" else None
    result = analyse(args.input, face=args.face, neutral=args.neutral, baseline=not args.no_baseline,
                     smooth=not args.no_smooth, threads=args.threads, on_frame=progress)
    if progress:
        sys.stderr.write("\n")
    if args.output:
        path = result.save(args.output)
        found = sum(f.success for f in result.frames)
        print(f"wrote {path} ({len(result.frames)} frames, a face in {found})")
    elif len(result.frames) == 1:
        frame = result.frames[0]
        print(frame.notation() if frame.success else "no face found")
    else:
        for frame in result.frames:
            label = frame.source or f"{frame.timestamp:8.3f}s"
            print(f"{label}\t{frame.notation() if frame.success else 'no face found'}")
    if args.explain:
        for code, why in result.unobservable.items():
            print(f"  AU{code}: {why}", file=sys.stderr)
    return 0


def _progress_printer():
    def show(done: int) -> None:
        if done % 10 == 0:
            sys.stderr.write(f"\ranalysing: {done} frames")
            sys.stderr.flush()
    return show


def has_audio(path) -> bool:
    """Whether a media file has an audio stream (ffmpeg's own report)."""
    import subprocess

    import imageio_ffmpeg

    proc = subprocess.run([imageio_ffmpeg.get_ffmpeg_exe(), "-hide_banner", "-i", str(path)],
                          capture_output=True, text=True)
    return "Audio:" in proc.stderr


def padded_audio(video, out: Path) -> Path:
    """The video's sound as WAV with a second of silence after it.

    The writer cuts the result to the shorter stream; re-encoded sound can come out a
    few milliseconds short of the picture, which would drop the last frame.
    """
    import subprocess

    import imageio_ffmpeg

    proc = subprocess.run([imageio_ffmpeg.get_ffmpeg_exe(), "-hide_banner", "-loglevel", "error", "-y", "-i",
                           str(video), "-vn", "-af", "apad=pad_dur=1", str(out)], capture_output=True, text=True)
    if proc.returncode:
        raise ValueError(f"cannot read the sound of {video}: {proc.stderr.strip().splitlines()[-1:]}")
    return out


def cmd_retarget(args) -> int:
    from facsim.pipeline import animate

    from facsim.analysis.processor import AnalysisError, analyse, input_kind

    _limit_threads()
    if input_kind(args.input) != "video":
        raise AnalysisError(f"retarget needs a video, got {args.input}")
    progress = _progress_printer()
    result = analyse(args.input, face=args.face, neutral=args.neutral, baseline=not args.no_baseline,
                     on_frame=progress)
    sys.stderr.write("\n")
    timeline = result.timeline()
    import tempfile

    with tempfile.TemporaryDirectory() as tmp:
        audio = padded_audio(args.input, Path(tmp) / "audio.wav") if has_audio(args.input) else None
        path = animate(timeline, args.output, character=args.character, engine=args.engine, fps=result.fps,
                       audio=audio, size=args.size)
    found = sum(f.success for f in result.frames)
    print(f"wrote {path} ({len(result.frames)} frames at {result.fps:g} fps, a face in {found}"
          f"{', audio kept' if audio else ''})")
    return 0


def cmd_validate(args) -> int:
    from facsim.validate.run import run_validation

    _limit_threads()
    engines = ("registers", "muscle") if args.engine == "both" else (args.engine,)
    characters = tuple(c.strip() for c in args.characters.split(",")) if args.characters else None
    if characters == ("all",):
        from facsim.head.character import preset_names

        characters = tuple(preset_names())
    elif characters:
        from facsim.head.character import resolve_character

        for name in characters:
            resolve_character(name)  # an unknown name fails here, before any rendering
    report = run_validation(engines=engines, characters=characters, quick=args.quick, out=Path(args.output),
                            size=args.size)
    print(report.summary_text())
    print(f"report: {report.markdown_path}")
    return 0
