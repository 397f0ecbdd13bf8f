"""Limits on untrusted input: how big a file, how deep, how many tracks and frames facsim accepts.

Inputs come from people and from other programs; a few hundred hostile bytes
must not be able to take the machine's memory or hours of its time. Each limit
is generous for real stimuli and can be raised through an environment
variable, named in the error a user sees when they reach it::

    FACSIM_MAX_INPUT_BYTES   size of an input file (timeline, CSV, .facs)   default 16 MiB
    FACSIM_MAX_DEPTH         nesting of lists/mappings in a timeline file    default 32
    FACSIM_MAX_TRACKS        tracks in one timeline                          default 10,000
    FACSIM_MAX_VALUES        values (numbers, strings, lists...) in one file default 500,000
    FACSIM_MAX_FRAMES        frames in one video (duration x fps)            default 1,000,000 (9.3 h at 30 fps)
    FACSIM_MAX_FPS           frame rate                                      default 1,000
    FACSIM_MAX_NOTATION      characters of one FACS string                   default 10,000
    FACSIM_MAX_IMAGE_PIXELS  pixels of an image or video frame to analyse    default 50,000,000 (50 MP)
    FACSIM_MAX_ITEMS         output files one batch spec expands to          default 100,000

YAML aliases (``*name``) are refused outright: timeline files never need them,
and nested aliases are how a 450-byte file expands to gigabytes.

Examples
--------
>>> limit("max_tracks")
10000
>>> short("x" * 1000, 20)
"'xxxxxxx … xxxxxxx'"
"""
from __future__ import annotations

import math
import os
import reprlib

#: name -> (environment variable, default)
LIMITS = {
    "max_input_bytes": ("FACSIM_MAX_INPUT_BYTES", 16 * 1024 * 1024),
    "max_depth": ("FACSIM_MAX_DEPTH", 32),
    "max_tracks": ("FACSIM_MAX_TRACKS", 10_000),
    "max_values": ("FACSIM_MAX_VALUES", 500_000),
    "max_frames": ("FACSIM_MAX_FRAMES", 1_000_000),
    "max_fps": ("FACSIM_MAX_FPS", 1000),
    "max_notation": ("FACSIM_MAX_NOTATION", 10_000),
    "max_image_pixels": ("FACSIM_MAX_IMAGE_PIXELS", 50_000_000),
    "max_items": ("FACSIM_MAX_ITEMS", 100_000),
}
#: The slowest frame rate a video may have (one frame every 100 s).
MIN_FPS = 0.01
#: Longest message an error carries; longer problems are cut in the middle.
MAX_MESSAGE = 400


def limit(name: str) -> int:
    """The limit ``name`` (see :data:`LIMITS`): the environment variable if set to a positive integer, else the default."""
    variable, default = LIMITS[name]
    text = os.environ.get(variable, "").strip()
    if text:
        try:
            value = int(text)
        except ValueError:
            value = 0
        if value > 0:
            return value
    return default


def override_hint(name: str) -> str:
    """``"(set FACSIM_MAX_... to raise it)"`` for error messages."""
    return f"(limit {limit(name):,}; set {LIMITS[name][0]} to raise it)"


def short(value, width: int = 60) -> str:
    """``repr(value)`` cut to about ``width`` characters (the middle elided), on one line.

    Cheap for huge values: big containers are shortened before they are turned into text.
    """
    if isinstance(value, str):
        text = repr(value if len(value) <= 2 * width else value[:width] + value[-width:])
    else:
        r = reprlib.Repr()
        r.maxstring, r.maxother, r.maxlist, r.maxdict, r.maxlevel = width, width, 6, 4, 3
        text = r.repr(value)
    return clip(text, width)


def clip(text: str, width: int = MAX_MESSAGE) -> str:
    """``text`` on one line and at most ``width`` characters, the middle elided with ``…``."""
    if len(text) > 4 * width:
        text = text[:2 * width] + text[-2 * width:]
    text = " ".join(text.split())
    if len(text) <= width:
        return text
    keep = max(width - 3, 2) // 2
    return f"{text[:keep]} … {text[-keep:]}"


def check_fps(value, name: str = "fps") -> float:
    """A frame rate in ``[MIN_FPS, max_fps]`` as float, else ``ValueError`` naming ``name``."""
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise ValueError(f"{name} must be a finite number of frames per second, got {short(value)}")
    if not MIN_FPS <= value <= limit("max_fps"):
        raise ValueError(f"{name} must be between {MIN_FPS:g} and {limit('max_fps'):,} frames per second, "
                         f"got {value:g} {override_hint('max_fps')}")
    return float(value)


def check_frames(frames: float, what: str) -> None:
    """``ValueError`` if ``frames`` (a count) is over the frame limit; ``what`` says where it came from."""
    if not frames <= limit("max_frames"):
        raise ValueError(f"{what} makes {frames:,.0f} frames, too many for one video {override_hint('max_frames')}")


def check_image_size(width: int, height: int, what: str) -> None:
    """``ValueError`` if an image of ``width`` × ``height`` pixels is over the pixel limit
    (checked before it is decoded); ``what`` names the image."""
    if width * height > limit("max_image_pixels"):
        raise ValueError(f"{what} is {width:,}x{height:,} pixels, too big to analyse "
                         f"{override_hint('max_image_pixels')}")


def check_file_size(path, problem=ValueError) -> None:
    """Raise ``problem(message)`` if the file at ``path`` is bigger than the input limit."""
    size = os.path.getsize(path)
    if size > limit("max_input_bytes"):
        raise problem(f"file is {size:,} bytes, too big for an input file {override_hint('max_input_bytes')}; "
                      "long recordings are smaller as .facs")


__all__ = ["LIMITS", "MAX_MESSAGE", "MIN_FPS", "check_file_size", "check_fps", "check_frames", "check_image_size", "clip", "limit",
           "override_hint", "short"]
