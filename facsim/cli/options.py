"""Options shared by every command that renders: types that check values where they are parsed.

Every value is checked by its argparse ``type`` as the command line is read, so a
bad one ends in argparse's one-line usage error (exit 2) naming the option:
numbers must be finite and in range, output names must end in a suffix the
command writes (``render -o x.jpg`` would otherwise get PNG bytes under a
JPEG name).
"""
from __future__ import annotations

import argparse
import math

#: ``--table``'s help, wherever an emotion preset is named (the tables are facsim/data/emotions.yaml's).
TABLE_HELP = "emotion preset table: facsim (the default: HapFACS Table 5, anger and surprise from EMFACS), hapfacs or emfacs"


def number(low: float | None = None, high: float | None = None, *, unit: str = "",
           low_open: bool = False, high_open: bool = False):
    """An argparse type: a finite float in ``[low, high]`` (``low_open``/``high_open`` leave an end out).

    Examples
    --------
    >>> number(0, 10)("2.5")
    2.5
    >>> number(0, 10)("inf")
    Traceback (most recent call last):
    ...
    argparse.ArgumentTypeError: expected a finite number, got 'inf'
    """
    def parse(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            value = math.nan
        if not math.isfinite(value):
            raise argparse.ArgumentTypeError(f"expected a finite number{' of ' + unit if unit else ''}, got {text!r}")
        too_low = low is not None and (value <= low if low_open else value < low)
        too_high = high is not None and (value >= high if high_open else value > high)
        if too_low or too_high:
            lo = "" if low is None else f"{'>' if low_open else '>='} {low:g}"
            hi = "" if high is None else f"{'<' if high_open else '<='} {high:g}"
            raise argparse.ArgumentTypeError(f"must be {' and '.join(p for p in (lo, hi) if p)}"
                                             f"{' ' + unit if unit else ''}, got {text!r}")
        return value
    return parse


def integer(low: int, high: int | None = None):
    """An argparse type: an ASCII integer in ``[low, high]``.

    Examples
    --------
    >>> integer(1, 64)("4")
    4
    >>> integer(1, 64)("0")
    Traceback (most recent call last):
    ...
    argparse.ArgumentTypeError: must be an integer from 1 to 64, got '0'
    """
    def parse(text: str) -> int:
        span = f"from {low} to {high}" if high is not None else f">= {low}"
        try:
            if not text.strip().lstrip("+-").isascii():   # int() would read '٤' as 4
                raise ValueError(text)
            value = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"must be an integer {span}, got {text!r}") from None
        if value < low or (high is not None and value > high):
            raise argparse.ArgumentTypeError(f"must be an integer {span}, got {text!r}")
        return value
    return parse


def fps(text: str) -> float:
    """An argparse type for frame rates: finite, within :func:`facsim.limits.check_fps`'s range."""
    from facsim.limits import check_fps

    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected frames per second, got {text!r}") from None
    try:
        return check_fps(value, "the frame rate")
    except ValueError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


def output(*suffixes: str, allow_stdout: bool = False):
    """An argparse type: an output path whose suffix is one of ``suffixes`` (any case).

    Examples
    --------
    >>> output(".png")("face.PNG")
    'face.PNG'
    >>> output(".png")("face.jpg")
    Traceback (most recent call last):
    ...
    argparse.ArgumentTypeError: 'face.jpg' must end in .png (the format this command writes)
    """
    def parse(text: str) -> str:
        from pathlib import Path

        if allow_stdout and text == "-":
            return text
        if not text.strip():
            raise argparse.ArgumentTypeError("expected a file name, got ''")
        if Path(text).suffix.lower() not in suffixes:
            raise argparse.ArgumentTypeError(f"{text!r} must end in {' or '.join(suffixes)} "
                                             "(the format this command writes)")
        return text
    return parse


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
    from facsim.render.options import parse_antialias

    try:
        if not text.isascii():       # int() and str.isdigit() would take '٤' for 4
            raise ValueError(f"antialias must be MSAA samples (1, 2, 4...), fxaa or ssaa2..ssaa4, got {text!r}")
        value = int(text) if text.strip().isdigit() else text
        parse_antialias(value)       # the renderer's own check, here where the option is read
    except ValueError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None
    return value


def _size(text: str):
    from facsim.render.options import size_pair

    try:
        if "x" in text.lower():
            w, h = (int(v) for v in text.lower().split("x"))
            size = (w, h)
        else:
            size = (int(text), int(text))
    except ValueError:
        raise argparse.ArgumentTypeError(f"size must be N or WxH in pixels, got {text!r}") from None
    try:
        return size_pair(size)     # the renderer's own range check, here where the option is read
    except ValueError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


def add_view_options(p: argparse.ArgumentParser) -> None:
    """Options shared by every command that renders."""
    from facsim.engines import DEFAULT_ENGINE, ENGINES
    from facsim.render.options import DEFAULT_BODY, VIEWS

    p.add_argument("--character", "-c", default="ava", help="preset name (see `facsim characters`) or random:SEED")
    p.add_argument("--hair", help="hair style (bob01, bob02, short01-04, long01, ponytail01, braid01, afro01, crop) "
                                  "or none; default: the character's own")
    p.add_argument("--engine", choices=tuple(ENGINES), default=DEFAULT_ENGINE, help="how AUs move the face")
    p.add_argument("--view", choices=sorted(VIEWS), default="front")
    p.add_argument("--yaw", type=number(-360, 360, unit="degrees"), help="camera yaw in degrees (positive: toward the character's left)")
    p.add_argument("--pitch", type=number(-90, 90, unit="degrees", low_open=True, high_open=True), help="camera pitch in degrees (positive: from above)")
    p.add_argument("--size", type=_size, default=(512, 512), help="N or WxH pixels (default 512)")
    p.add_argument("--projection", choices=("perspective", "orthographic"), default="perspective")
    p.add_argument("--background", type=_color, default=(1.0, 1.0, 1.0), help="#rrggbb, a colour name or transparent")
    p.add_argument("--antialias", type=_antialias, default=4,
                   help="MSAA samples (1 = off, 4 = default) or fxaa (fast post-process smoothing)")
    p.add_argument("--intensities", choices=("hapfacs", "facshuman"), default="hapfacs",
                   help="what the letters A-E mean (HapFACS: 15/30/55/85/100 %%)")
    p.add_argument("--body", type=body_style, default=DEFAULT_BODY,
                   help=f"neck and shoulders in a garment under the head ({DEFAULT_BODY}, the default; "
                        "facsim/data/body.yaml) or none for the head alone")


def body_style(text: str) -> str:
    """An argparse type: a garment of ``facsim/data/body.yaml`` or ``none`` (the table is read
    only when ``--body`` is given, so ``--help`` stays light)."""
    from facsim.head.body import body_styles

    if text not in body_styles():
        raise argparse.ArgumentTypeError(f"choose from {', '.join(body_styles())}, got {text!r}")
    return text


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
                background=args.background, antialias=args.antialias, body=args.body)


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
