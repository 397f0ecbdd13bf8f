"""How to render a face: one frozen, validated :class:`RenderOptions` wherever options travel.

Examples
--------
>>> RenderOptions(size=256, view="three-quarter-left").size
(256, 256)
>>> RenderOptions(antialias="fxaa").renderer_settings()
{'antialias': 1, 'aa_method': 'fxaa', 'shadows': True}
>>> RenderOptions(yaw=float("inf"))
Traceback (most recent call last):
...
ValueError: yaw must be a finite number of degrees, got inf
"""
from __future__ import annotations

import math
from dataclasses import asdict, dataclass

#: Named views: (yaw, pitch) in degrees; "...-left" shows the character's left side.
VIEWS: dict[str, tuple[float, float]] = {
    "front": (0.0, 0.0),
    "three-quarter-left": (45.0, 0.0),
    "three-quarter-right": (-45.0, 0.0),
    "profile-left": (90.0, 0.0),
    "profile-right": (-90.0, 0.0),
}

PROJECTIONS = ("perspective", "orthographic")

#: What is under the head unless asked otherwise: a garment of ``facsim/data/body.yaml``.
DEFAULT_BODY = "crewneck"

#: Image sides facsim renders (pixels): below, faces are unreadable; above, llvmpipe runs out of memory.
SIZE_RANGE = (16, 8192)
#: MSAA samples accepted (llvmpipe's maximum is 4; a GPU's driver caps higher counts).
MAX_SAMPLES = 16


def size_pair(size) -> tuple[int, int]:
    """``N`` or ``(width, height)`` → ``(width, height)``, each side within :data:`SIZE_RANGE`."""
    if isinstance(size, bool):
        raise ValueError(f"size must be a number of pixels or (width, height), got {size!r}")
    if isinstance(size, (int, float)) and float(size).is_integer():
        width = height = int(size)
    else:
        try:
            width, height = size
            if isinstance(width, bool) or isinstance(height, bool) or not all(
                    isinstance(v, (int, float)) and float(v).is_integer() for v in (width, height)):
                raise TypeError
            width, height = int(width), int(height)
        except (TypeError, ValueError):
            raise ValueError(f"size must be a number of pixels or (width, height), got {size!r}") from None
    low, high = SIZE_RANGE
    if not (low <= width <= high and low <= height <= high):
        raise ValueError(f"image size must be between {low} and {high} pixels per side, got {width}x{height}")
    return width, height


def parse_antialias(antialias) -> tuple[int, str]:
    """User-facing anti-aliasing → the renderer's ``(antialias, aa_method)``.

    ``antialias`` is MSAA samples (1 = off, 4 = llvmpipe's best), ``"fxaa"``
    (post-process edge smoothing, about the cost of no AA) or ``"ssaaN"``
    (N×N supersampling, N = 2..4).
    """
    if isinstance(antialias, str):
        text = antialias.strip().lower()
        if text == "fxaa":
            return 1, "fxaa"
        if text.startswith("ssaa") and text[4:].isdigit() and 1 <= int(text[4:]) <= 4:
            return int(text[4:]), "ssaa"
        if text.isdigit():
            antialias = int(text)
    if isinstance(antialias, bool) or not isinstance(antialias, int) or not 1 <= antialias <= MAX_SAMPLES:
        raise ValueError(f"antialias must be MSAA samples 1..{MAX_SAMPLES} (4 = default), 'fxaa' or 'ssaa2'..'ssaa4', "
                         f"got {antialias!r}")
    return antialias, "msaa"


def _angle(value, name: str):
    if value is None:
        return None
    try:
        value = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a number of degrees, got {value!r}") from None
    if not math.isfinite(value):
        raise ValueError(f"{name} must be a finite number of degrees, got {value!r}")
    return value


def _background(value):
    if value is None:
        return None
    try:
        rgb = tuple(float(v) for v in value)
    except (TypeError, ValueError):
        raise ValueError(f"background must be (r, g, b) in 0..1 or None (transparent), got {value!r}") from None
    if len(rgb) != 3 or not all(0.0 <= v <= 1.0 for v in rgb):
        raise ValueError(f"background must be (r, g, b) in 0..1 or None (transparent), got {value!r}")
    return rgb


@dataclass(frozen=True)
class RenderOptions:
    """Everything about a picture that is not the face: view, camera, size, background, anti-aliasing.

    Parameters
    ----------
    view : str
        A named view (:data:`~facsim.render.camera.VIEWS`): front, three-quarter-left/right, profile-left/right.
    yaw, pitch : float, optional
        Camera angles in degrees, overriding the view's (yaw > 0 looks from the character's left).
    size : int or (width, height)
        Pixels, 16..8192 per side.
    projection : {"perspective", "orthographic"}
    background : (r, g, b) in 0..1, or None
        None renders a transparent background.
    antialias : int or str
        MSAA samples, ``"fxaa"`` or ``"ssaaN"`` (see :func:`parse_antialias`).
    body : str
        What is under the head: a garment of ``facsim/data/body.yaml`` over hm08's neck and
        shoulders (``"crewneck"``), or ``"none"`` for the head alone (see :mod:`facsim.head.body`).
    shadows : bool
        The key light's soft cast shadows (nose, brows, hair, chin); False leaves only the
        baked ambient occlusion (see :class:`~facsim.render.renderer.Renderer`).
    """

    view: str = "front"
    yaw: float | None = None
    pitch: float | None = None
    size: tuple[int, int] = (512, 512)
    projection: str = "perspective"
    background: tuple[float, float, float] | None = (1.0, 1.0, 1.0)
    antialias: int | str = 4
    body: str = DEFAULT_BODY
    shadows: bool = True

    def __post_init__(self):
        if self.view not in VIEWS:
            raise ValueError(f"view must be one of {', '.join(VIEWS)}, got {self.view!r}")
        if self.projection not in PROJECTIONS:
            raise ValueError(f"projection must be one of {', '.join(PROJECTIONS)}, got {self.projection!r}")
        set_ = object.__setattr__
        set_(self, "yaw", _angle(self.yaw, "yaw"))
        set_(self, "pitch", _angle(self.pitch, "pitch"))
        if self.pitch is not None and abs(self.pitch) >= 90:
            raise ValueError(f"pitch must be between -90 and 90 degrees (exclusive), got {self.pitch:g}")
        set_(self, "size", size_pair(self.size))
        set_(self, "background", _background(self.background))
        from facsim.head.body import check_body_style

        check_body_style(self.body)
        if not isinstance(self.shadows, bool):
            raise ValueError(f"shadows must be True or False, got {self.shadows!r}")
        samples, method = parse_antialias(self.antialias)
        set_(self, "antialias", "fxaa" if method == "fxaa" else f"ssaa{samples}" if method == "ssaa" else samples)

    def renderer_settings(self) -> dict:
        """The :class:`~facsim.render.renderer.Renderer` keyword arguments for the anti-aliasing and shadows."""
        samples, method = parse_antialias(self.antialias)
        return {"antialias": samples, "aa_method": method, "shadows": self.shadows}

    def replace(self, **changes) -> "RenderOptions":
        """A copy with ``changes`` (validated again)."""
        return RenderOptions(**{**asdict(self), **changes})
