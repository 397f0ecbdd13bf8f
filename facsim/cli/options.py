"""Options shared by every command that renders: types that check values where they are parsed."""
from __future__ import annotations

import argparse


def _color(text: str):
    """'#rrggbb', 'white', 'black', 'grey' or 'transparent' → RGB tuple or None."""
    named = {"white": "#ffffff", "black": "#000000", "grey": "#808080", "gray": "#808080"}
    if text == "transparent":
        return None
    from facsim.head.colour import hex_to_rgb

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
    from facsim.engines import DEFAULT_ENGINE, ENGINES
    from facsim.render.options import VIEWS

    p.add_argument("--character", "-c", default="ava", help="preset name (see `facsim characters`) or random:SEED")
    p.add_argument("--hair", help="hair style (bob01, bob02, short01-04, long01, ponytail01, braid01, afro01) "
                                  "or none; default: the character's own")
    p.add_argument("--engine", choices=tuple(ENGINES), default=DEFAULT_ENGINE, help="how AUs move the face")
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


def character_of(args, fallback=None):
    """The character the view options name (``--character``, else ``fallback``), with ``--hair`` applied."""
    name = args.character or fallback
    if getattr(args, "hair", None) is None:
        return name
    from facsim.head.character import resolve_character

    return resolve_character(name).with_(hair=args.hair)


def render_options(args) -> dict:
    """The Face.render keyword arguments from the shared view options."""
    return dict(view=args.view, yaw=args.yaw, pitch=args.pitch, size=args.size, projection=args.projection,
                background=args.background, antialias=args.antialias)


def add_overwrite_option(parser: argparse.ArgumentParser) -> None:
    """``--overwrite`` on every (sub)command that writes ``-o/--output`` (see :func:`facsim.atomic.check_target`)."""
    actions = parser._actions
    if any(a.dest == "output" for a in actions) and not any(a.dest == "overwrite" for a in actions):
        parser.add_argument("--overwrite", action="store_true",
                            help="replace an existing folder of facsim's frames, or a file of another kind "
                                 "(never a folder holding other files)")
    for action in actions:
        if isinstance(action, argparse._SubParsersAction):
            for sub in set(action.choices.values()):
                add_overwrite_option(sub)
