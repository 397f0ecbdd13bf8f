"""``facsim render``: one FACS expression, emotion or timeline frame to a PNG."""
from __future__ import annotations

from facsim.cli.options import TABLE_HELP, add_view_options, character_of, number, output, render_options


def add_commands(sub) -> None:
    p = sub.add_parser("render", help="render a FACS expression (or an emotion) to a PNG")
    p.add_argument("expression", nargs="?", default=None, help='FACS string, e.g. "1+2+5B+26", "R12A+L14", "neutral"')
    p.add_argument("-o", "--output", required=True, type=output(".png"), help="PNG file to write")
    p.add_argument("--emotion", help="an emotion preset instead of an expression (see `facsim emotions`)")
    p.add_argument("--table", default="facsim", help=TABLE_HELP)
    p.add_argument("--intensity", default="100%", help="global intensity for --emotion, e.g. 50%% or 0.5")
    p.add_argument("--timeline", help="render one frame of a timeline file (YAML or JSON) ...")
    p.add_argument("--time", type=number(0, unit="seconds"), help="... at this time in seconds")
    add_view_options(p)
    p.set_defaults(handler=cmd_render)


def cmd_render(args) -> None:
    from facsim.cli import CliError
    from facsim.face import Face

    if args.timeline:
        from facsim.cli.dynamics import timeline_activations

        if args.time is None:
            raise CliError("--timeline needs --time SECONDS")
        if args.expression or args.emotion:
            raise CliError("give an expression, --emotion or --timeline, not several")
        expression = timeline_activations(args.timeline, args.time)
    elif args.emotion:
        if args.expression:
            raise CliError("give either an expression or --emotion, not both")
        from facsim.facs.emotions import emotion

        expression = emotion(args.emotion, table=args.table, intensity=args.intensity, intensities=args.intensities)
    else:
        if args.time is not None:
            raise CliError("--time needs --timeline FILE")
        from facsim.facs.notation import parse

        expression = parse(args.expression or "neutral", intensities=args.intensities)
    from facsim.atomic import check_target

    check_target(args.output)  # before the face is built: a refusal should not wait for it
    with Face(character_of(args), engine=args.engine) as face:
        face.save(args.output, expression, **render_options(args))
    print(f"wrote {args.output}")
