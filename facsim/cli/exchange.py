"""The CLI's exchange commands: ``facsim export FORMAT ...`` and ``facsim import FORMAT ...``.

::

    facsim export glb -o face.glb --character ava [--timeline t.yaml] [--aus all|1,2,12] [--interpolation step]
    facsim export arkit-csv TIMELINE -o take.csv [--fps 60]
    facsim export notation TIMELINE -o clip.facs
    facsim export mesh "6+12" -o face.ply|face.obj --character ava [--engine auto|registers|muscle]
    facsim import openface perf.csv -o timeline.yaml|.json|.facs
    facsim import arkit-csv take.csv -o timeline.yaml
    facsim import notation clip.facs -o timeline.yaml

A TIMELINE argument is any file :func:`facsim.exchange.load_any_timeline`
reads (YAML, JSON, ``.facs``, ARKit or OpenFace CSV).
"""
from __future__ import annotations

import argparse

from facsim.cli.options import fps, number, output
from facsim.engines import ENGINES

CHARACTER_HELP = "preset name (see `facsim characters`) or random:SEED"


def _au_list(text: str):
    if text.strip().lower() == "all":
        return "all"
    try:
        if not text.isascii():     # int() would read '١٢' as 12
            raise ValueError(text)
        codes = [int(part) for part in text.replace("+", ",").split(",") if part.strip()]
    except ValueError:
        raise argparse.ArgumentTypeError(f"--aus takes 'all' or AU codes like 1,2,12, got {text!r}") from None
    if not codes:
        raise argparse.ArgumentTypeError("--aus needs at least one AU code (or 'all')")
    return codes


_TIMELINE_OUT = output(".yaml", ".yml", ".json", ".facs")


def add_commands(sub) -> None:
    """Add ``export`` and ``import`` to the ``facsim`` subcommands."""
    from facsim.cli.options import body_style
    from facsim.render.options import DEFAULT_BODY

    export = sub.add_parser("export", help="write a character or a timeline for other tools (glTF, ARKit CSV, "
                                           "notation, OBJ/PLY)")
    formats = export.add_subparsers(dest="format", required=True, metavar="FORMAT")

    p = formats.add_parser("glb", help="glTF 2.0 binary: head mesh, AU morph targets, head/eye joints, animation")
    p.add_argument("-o", "--output", required=True, type=output(".glb"), help="the .glb file to write")
    p.add_argument("--character", "-c", help=CHARACTER_HELP + " (default: the timeline's, else ava)")
    p.add_argument("--timeline", help="add this timeline (any readable file) as an animation")
    p.add_argument("--aus", type=_au_list, default="all", help="morph targets for 'all' AUs (default) or e.g. 1,2,12")
    p.add_argument("--interpolation", choices=("linear", "step"), default="linear", help="animation keys")
    p.add_argument("--fps", type=fps, help="animation frame rate (default: the timeline's)")
    p.add_argument("--no-normals", action="store_true", help="leave out normals and their morph deltas (smaller)")
    p.add_argument("--body", type=body_style, default=DEFAULT_BODY,
                   help=f"add the neck, shoulders and garment as mesh 'body' ({DEFAULT_BODY}, the default) "
                        "or none for the head alone")
    p.set_defaults(handler=cmd_export_glb)

    p = formats.add_parser("arkit-csv", help="ARKit-52 blendshape weights per frame, Live Link Face CSV layout")
    p.add_argument("timeline", help="timeline file (YAML, JSON, .facs, CSV)")
    p.add_argument("-o", "--output", required=True, type=output(".csv"), help="the .csv file to write")
    p.add_argument("--fps", type=fps, help="frames per second (default: the timeline's)")
    p.set_defaults(handler=cmd_export_arkit)

    p = formats.add_parser("notation", help="the timeline as compact, lossless .facs notation text")
    p.add_argument("timeline", help="timeline file (YAML, JSON, .facs, CSV)")
    p.add_argument("-o", "--output", required=True, type=output(".facs", allow_stdout=True),
                   help="the .facs file to write ('-' prints it)")
    p.set_defaults(handler=cmd_export_notation)

    p = formats.add_parser("mesh", help="one deformed frame as OBJ or PLY (with the muscle engine's wrinkle)")
    p.add_argument("expression", help='FACS string, e.g. "6+12", "R12A+L14", "neutral"')
    p.add_argument("-o", "--output", required=True, type=output(".obj", ".ply"), help="face.obj or face.ply")
    p.add_argument("--character", "-c", default="ava", help=CHARACTER_HELP)
    p.add_argument("--engine", choices=("auto", *ENGINES), default="auto",
                   help="auto (default): the muscle engine, whose skin compression the file carries as wrinkle")
    p.add_argument("--intensities", choices=("hapfacs", "facshuman"), default="hapfacs",
                   help="what the letters A-E mean")
    p.set_defaults(handler=cmd_export_mesh)

    imp = sub.add_parser("import", help="read another tool's file as a timeline (OpenFace, ARKit CSV, notation)")
    formats = imp.add_subparsers(dest="format", required=True, metavar="FORMAT")

    p = formats.add_parser("openface", help="an OpenFace 2.0 FeatureExtraction CSV (a recorded performance)")
    p.add_argument("input", help="the OpenFace .csv")
    p.add_argument("-o", "--output", required=True, type=_TIMELINE_OUT,
                   help="timeline to write: .yaml, .json or .facs")
    p.add_argument("--fps", type=fps, help="timeline frame rate (default: measured from the timestamps)")
    p.add_argument("--intensities", choices=("hapfacs", "facshuman"), default="hapfacs",
                   help="what OpenFace intensities 1-5 (A-E) mean")
    p.add_argument("--face-id", type=int, help="which face of a multi-face file (default: the lowest id)")
    p.add_argument("--min-confidence", type=number(0, 1), help="also hold frames less confident than this")
    p.set_defaults(handler=cmd_import_openface)

    p = formats.add_parser("arkit-csv", help="a Live Link Face (ARKit-52 blendshape) CSV")
    p.add_argument("input", help="the Live Link Face .csv")
    p.add_argument("-o", "--output", required=True, type=_TIMELINE_OUT,
                   help="timeline to write: .yaml, .json or .facs")
    p.add_argument("--fps", type=fps, help="the take's frame rate (default: from its Timecodes, else 60)")
    p.set_defaults(handler=cmd_import_arkit)

    p = formats.add_parser("notation", help="a .facs notation file")
    p.add_argument("input", help="the .facs file")
    p.add_argument("-o", "--output", required=True, type=_TIMELINE_OUT,
                   help="timeline to write: .yaml, .json or .facs")
    p.set_defaults(handler=cmd_import_notation)


# ------------------------------------------------------------------ export ---

def cmd_export_glb(args) -> None:
    from facsim.exchange import export_glb, load_any_timeline
    from facsim.face import Face

    timeline = load_any_timeline(args.timeline) if args.timeline else None
    character = args.character or (timeline.character if timeline is not None else None) or "ava"
    with Face(character) as face:
        out = export_glb(face, args.output, timeline, aus=args.aus, interpolation=args.interpolation,
                         normals=not args.no_normals, fps=args.fps, body=args.body)
    print(f"wrote {out}")


def cmd_export_arkit(args) -> None:
    from facsim.exchange import load_any_timeline, write_arkit_csv

    print(f"wrote {write_arkit_csv(load_any_timeline(args.timeline), args.output, fps=args.fps)}")


def cmd_export_notation(args) -> None:
    from facsim.exchange import dumps_notation, load_any_timeline, write_notation

    timeline = load_any_timeline(args.timeline)
    if args.output == "-":
        print(dumps_notation(timeline), end="")
        return
    print(f"wrote {write_notation(timeline, args.output)}")


def cmd_export_mesh(args) -> None:
    from facsim.exchange import write_mesh
    from facsim.face import Face
    from facsim.facs.notation import parse

    expression = parse(args.expression, intensities=args.intensities)
    with Face(args.character, engine="muscle" if args.engine == "auto" else args.engine) as face:
        out = write_mesh(face, expression, args.output)
    print(f"wrote {out}")


# ------------------------------------------------------------------ import ---

def _save(timeline, output) -> None:
    from facsim.exchange import save_any_timeline

    print(f"wrote {save_any_timeline(timeline, output)}")


def cmd_import_openface(args) -> None:
    from facsim.exchange import read_openface_csv

    _save(read_openface_csv(args.input, intensities=args.intensities, face_id=args.face_id,
                            min_confidence=args.min_confidence, fps=args.fps), args.output)


def cmd_import_arkit(args) -> None:
    from facsim.exchange import read_arkit_csv

    _save(read_arkit_csv(args.input, fps=args.fps), args.output)


def cmd_import_notation(args) -> None:
    from facsim.exchange import read_notation

    _save(read_notation(args.input), args.output)
