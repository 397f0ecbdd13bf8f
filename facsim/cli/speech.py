"""The CLI's speech commands: ``facsim speak`` and ``facsim visemes``."""
from __future__ import annotations

from facsim.cli.options import TABLE_HELP, add_view_options, render_options


def add_commands(sub) -> None:
    p = sub.add_parser("speak", help="a talking face: text (or a recording) to a video with lip-synced sound")
    p.add_argument("text", nargs="?", help='what to say, e.g. "Pack my box with five dozen liquor jugs."')
    p.add_argument("-o", "--output", required=True,
                   help="talk.mp4 (AAC sound), talk.webm (Opus), or a folder for PNG frames (WAV beside it)")
    p.add_argument("--voice", help="flite voice slt (default), awb, rms, kal16, kal; or piper:MODEL if Piper is installed")
    p.add_argument("--audio", help="a WAV recording to lip-sync instead of text (needs --transcript)")
    p.add_argument("--transcript", help="the words spoken in --audio")
    p.add_argument("--emotion", help="an emotion shown while speaking (see `facsim emotions`)")
    p.add_argument("--intensity", default="100%", help="the emotion's intensity, e.g. 70%% or 0.7")
    p.add_argument("--table", help=TABLE_HELP)
    p.add_argument("--no-blinks", action="store_true", help="no spontaneous blinks")
    p.add_argument("--seed", type=int, default=0, help="seed for the blinks")
    p.add_argument("--fps", type=float, default=30.0)
    p.add_argument("--save-timeline", help="also write the timeline used (YAML or JSON)")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    add_view_options(p)
    p.set_defaults(handler=cmd_speak, antialias="fxaa")

    p = sub.add_parser("visemes", help="the viseme table: phones, FACS AUs and why")
    p.set_defaults(handler=cmd_visemes)


def cmd_speak(args) -> None:
    from facsim.cli.dynamics import _progress
    from facsim.pipeline import animate
    from facsim.timeline.speech import speech_timeline
    from facsim.timeline.io import save_timeline

    timeline = speech_timeline(args.text, audio=args.audio, transcript=args.transcript, voice=args.voice,
                               emotion=args.emotion, intensity=args.intensity, table=args.table,
                               blinks=not args.no_blinks, seed=args.seed, fps=args.fps,
                               intensities=args.intensities)
    if args.save_timeline:
        save_timeline(timeline, args.save_timeline)
    out = animate(timeline, args.output, character=args.character, engine=args.engine,
                  on_frame=_progress(args), **render_options(args))
    print(f"wrote {out}")


def cmd_visemes(args) -> None:
    from facsim.speech.visemes import describe_visemes

    print(describe_visemes())
