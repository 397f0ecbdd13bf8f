"""The CLI's time-based commands: ``facsim animate``, ``facsim emotion``, ``facsim plot``."""
from __future__ import annotations

from facsim.cli.options import TABLE_HELP, add_view_options, character_of, fps, number, output, render_options


def add_commands(sub) -> None:
    p = sub.add_parser("animate", help="render a timeline (YAML/JSON) to MP4, WebM, GIF or PNG frames")
    p.add_argument("timeline", help="timeline file (see examples/ and `facsim schema`)")
    p.add_argument("-o", "--output", required=True, help="out.mp4, out.webm, out.gif, or a folder for PNG frames")
    p.add_argument("--fps", type=fps, help="frames per second (default: the timeline's)")
    p.add_argument("--audio", help="an audio file to mux into the MP4/WebM")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    add_view_options(p)
    p.set_defaults(handler=cmd_animate, character=None, engine=None, antialias="fxaa")

    p = sub.add_parser("emotion", help="a HapFACS-style emotion (or FACS) stimulus video: onset, apex, offset")
    p.add_argument("name", help='an emotion (see `facsim emotions`) or a FACS string such as "1+2+5B+26"')
    p.add_argument("-o", "--output", required=True)
    p.add_argument("--intensity", default="100%", help="peak intensity, e.g. 50%% (HapFACS used 50 and 100)")
    p.add_argument("--table", help=TABLE_HELP)
    p.add_argument("--onset", type=number(0, 3600, unit="seconds"), default=1.0, help="seconds (default 1)")
    p.add_argument("--apex", type=number(0, 3600, unit="seconds"), default=1.0, help="seconds (default 1)")
    p.add_argument("--offset", type=number(0, 3600, unit="seconds"), default=1.0, help="seconds (default 1)")
    p.add_argument("--easing", default="linear", help="linear, ease-in, ease-out, smoothstep, sigmoid")
    p.add_argument("--fps", type=fps, default=30.0)
    p.add_argument("--blinks", action="store_true", help="add seeded spontaneous blinks")
    p.add_argument("--seed", type=int, default=0, help="seed for --blinks")
    p.add_argument("--audio", help="an audio file to mux into the MP4/WebM")
    p.add_argument("--save-timeline", type=output(".yaml", ".yml", ".json"), help="also write the timeline used (YAML or JSON)")
    p.add_argument("--quiet", action="store_true")
    add_view_options(p)
    p.set_defaults(handler=cmd_emotion, antialias="fxaa")

    p = sub.add_parser("plot", help="plot a timeline's AU intensities over time (PNG or SVG)")
    p.add_argument("timeline")
    p.add_argument("-o", "--output", required=True, type=output(".png", ".svg"), help="plot.png or plot.svg")
    p.set_defaults(handler=cmd_plot)

    p = sub.add_parser("schema", help="print the timeline JSON Schema")
    p.set_defaults(handler=cmd_schema)


def timeline_activations(path, time: float):
    """The activations of timeline ``path`` at ``time`` seconds."""
    from facsim.exchange import load_any_timeline as load_timeline
    from facsim.timeline.sampling import sample

    timeline = load_timeline(path)
    if not 0 <= time <= timeline.length:
        raise ValueError(f"--time {time} is outside the timeline (0 to {timeline.length:g} s)")
    return sample(timeline, time)


def cmd_animate(args) -> None:
    from facsim.exchange import load_any_timeline as load_timeline
    from facsim.pipeline import animate

    timeline = load_timeline(args.timeline)
    character = character_of(args, timeline.character) if args.hair else args.character
    out = animate(timeline, args.output, character=character, engine=args.engine, fps=args.fps,
                  audio=args.audio, on_frame=_progress(args), **render_options(args))
    print(f"wrote {out}")


def cmd_emotion(args) -> None:
    from facsim.timeline.model import Blinks
    from facsim.timeline.builders import stimulus_timeline
    from facsim.timeline.io import save_timeline
    from facsim.pipeline import animate

    timeline = stimulus_timeline(
        args.name, args.onset, args.apex, args.offset, args.fps, intensity=args.intensity, easing=args.easing,
        table=args.table, intensities=args.intensities, blinks=Blinks(seed=args.seed) if args.blinks else None,
    )
    if args.save_timeline:
        save_timeline(timeline, args.save_timeline)
    out = animate(timeline, args.output, character=character_of(args), engine=args.engine, audio=args.audio,
                  on_frame=_progress(args), **render_options(args))
    print(f"wrote {out}")


def cmd_plot(args) -> None:
    from facsim.exchange import load_any_timeline as load_timeline
    from facsim.timeline.plot import plot_timeline

    plot_timeline(load_timeline(args.timeline), args.output)
    print(f"wrote {args.output}")


def cmd_schema(args) -> None:
    import json

    from facsim.timeline.io import timeline_schema

    print(json.dumps(timeline_schema(), indent=2))


def _progress(args):
    """The progress bar's callback, or None with --quiet."""
    if args.quiet:
        return None
    from facsim.cli.progress import Progress

    bar = None

    def update(done: int, total: int) -> None:
        nonlocal bar
        bar = bar or Progress(total)
        bar.update(done)
    return update
