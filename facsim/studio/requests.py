"""Validation of what the page sends, with the parsers the CLI uses.

Every function takes JSON-decoded data and returns plain, checked data (or a
facsim object), or raises :class:`RequestError` naming the field and the
problem; the server turns that into a JSON error. Nothing here touches GL.

Examples
--------
>>> expression_text("r12c + 6b")
'6B+R12C'
>>> try:
...     expression_text("1+2+AU99")
... except RequestError as exc:
...     exc.field, exc.extra["position"]
('expression', 4)
>>> render_options({"size": 64, "background": "transparent"})["background"] is None
True
"""
from __future__ import annotations

import math
from dataclasses import asdict
from typing import Any, Mapping

from . import compat

#: Largest image side the studio renders (the CLI allows 8192; a browser tab has no use for it).
MAX_SIZE = 2048
#: Longest timeline the studio samples or renders, in frames.
MAX_FRAMES = 30 * 600
ANTIALIAS = (1, 2, 4, 8, "fxaa")
PROJECTIONS = ("perspective", "orthographic")
NAMED_COLORS = {"white": "#ffffff", "black": "#000000", "grey": "#808080", "gray": "#808080"}
VIDEO_FORMATS = ("mp4", "webm", "gif")
#: Points per track in the editor's drawing of its shape.
DRAW_SAMPLES = 241


class RequestError(ValueError):
    """Bad input from the page: ``field`` names what is wrong; ``extra`` adds detail (e.g. position)."""

    def __init__(self, message: str, *, field: str | None = None, status: int = 422, **extra: Any):
        super().__init__(message)
        self.field, self.status, self.extra = field, status, extra

    def to_json(self) -> dict:
        return {"error": str(self), "field": self.field, **self.extra}


def _mapping(body: Any, what: str = "request body") -> Mapping:
    if not isinstance(body, Mapping):
        raise RequestError(f"{what} must be a JSON object, got {type(body).__name__}", field=None)
    return body


def choice(value: Any, options, field: str):
    if value not in options:
        raise RequestError(f"{field} must be one of {', '.join(map(str, options))}, got {value!r}", field=field)
    return value


def number(value: Any, field: str, low: float, high: float) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise RequestError(f"{field} must be a number, got {value!r}", field=field)
    if not low <= value <= high:
        raise RequestError(f"{field} must be between {low:g} and {high:g}, got {value!r}", field=field)
    return float(value)


def engine(value: Any) -> str:
    """An engine name from :data:`facsim.engines.ENGINES` (default: facsim's default engine)."""
    return choice(value or compat.DEFAULT_ENGINE, tuple(compat.ENGINES), "engine")


def intensities_table(value: Any = "hapfacs") -> str:
    return choice(value or "hapfacs", tuple(compat.INTENSITY_TABLES), "intensities")


def expression_text(text: Any, intensities: str = "hapfacs") -> str:
    """The canonical FACS string of ``text``; a parse error carries ``position`` and ``token``."""
    if not isinstance(text, str):
        raise RequestError(f"expression must be a FACS string, got {type(text).__name__}", field="expression")
    if len(text) > 2000:
        raise RequestError("expression is longer than 2000 characters", field="expression")
    from facsim import parse

    try:
        return str(parse(text, intensities=intensities))
    except compat.NotationError as exc:
        raise RequestError(str(exc), field="expression", position=exc.position, token=exc.token) from None
    except ValueError as exc:
        raise RequestError(str(exc), field="expression") from None


def expression_units(text: str, intensities: str = "hapfacs") -> list[dict]:
    """Per (code, character side) levels of a FACS string: what the sliders show."""
    from facsim import activations, parse

    act = activations(parse(text, intensities=intensities))
    return [{"code": code, "side": side, "level": level} for (code, side), level in act]


def expression_from_levels(levels: Any, intensities: str = "hapfacs") -> str:
    """The canonical FACS string of slider levels ``{"12": {"left": 0.55, "right": 0.55}, "26": 1}``.

    Equal sides are written bilateral; a level equal to a letter of the table is written as the letter.
    """
    _mapping(levels, "levels")
    table = compat.INTENSITY_TABLES[intensities]
    units = []
    for key, value in levels.items():
        try:
            code = int(key)
            info = compat.catalogue()[code]
        except (ValueError, KeyError):
            raise RequestError(f"levels: unknown action unit {key!r}", field="levels") from None
        sides = value if isinstance(value, Mapping) else {"left": value, "right": value}
        left = number(sides.get("left", 0.0), f"levels[{key}].left", 0.0, 1.0)
        right = number(sides.get("right", 0.0), f"levels[{key}].right", 0.0, 1.0)
        if not info.unilateral and not math.isclose(left, right):
            raise RequestError(f"AU{code} ({info.name}) cannot differ between sides", field=f"levels[{key}]")
        pairs = [("both", left)] if math.isclose(left, right) else [("left", left), ("right", right)]
        for side, level in pairs:
            if level > 0:
                level = round(level, 3)
                letter = next((k for k, v in table.items() if math.isclose(v, level, abs_tol=5e-4)), None)
                if letter == "E":      # full intensity is written as the bare code
                    letter, level = None, 1.0
                units.append(compat.ActionUnit(code, table[letter] if letter else level, side, letter))
    return str(compat.Expression(tuple(units)))


# -------------------------------------------------------------- characters ---

def character_params(spec: Any) -> dict:
    """A character (preset name, ``random:SEED`` or parameters) as checked plain parameters."""
    if spec is None:
        spec = "ava"
    if not isinstance(spec, (str, Mapping)):
        raise RequestError(f"character must be a preset name or parameters, got {type(spec).__name__}",
                           field="character")
    if isinstance(spec, Mapping) and "face" in spec:
        face = spec["face"]
        if not isinstance(face, Mapping):
            raise RequestError("character.face must be a mapping of slider names to values", field="character.face")
        known = set(face_sliders())
        unknown = sorted(set(face) - known)
        if unknown:
            raise RequestError(f"unknown face-shape slider {unknown[0]!r}; names look like 'nose/nose-hump'",
                               field="character.face")
    try:
        character = compat.resolve_character(dict(spec) if isinstance(spec, Mapping) else spec)
    except (ValueError, TypeError) as exc:
        raise RequestError(str(exc), field="character") from None
    params = asdict(character)
    params["face"] = {k: float(v) for k, v in params["face"].items()}
    return params


_SLIDERS: list[str] = []


def face_sliders() -> list[str]:
    """The face-shape slider names the face data offers (``facsim characters --sliders``)."""
    if not _SLIDERS:
        _SLIDERS.extend(compat.slider_names(set(compat.load_face_data().target_names)))
    return _SLIDERS


def character_yaml(params: Mapping) -> str:
    """A character as YAML text, in the layout of ``facsim/data/characters.yaml`` entries."""
    import yaml

    out = {k: v for k, v in params.items() if v not in ("", {}, None)}
    return yaml.safe_dump(out, sort_keys=False, allow_unicode=True)


def character_from_yaml(text: Any) -> dict:
    import yaml

    if not isinstance(text, str):
        raise RequestError("text must be the YAML file's text", field="text")
    try:
        data = yaml.safe_load(text)
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f" at line {mark.line + 1}" if mark is not None else ""
        raise RequestError(f"malformed YAML{where}: {getattr(exc, 'problem', exc)}", field="text") from None
    if not isinstance(data, Mapping):
        raise RequestError("a character file holds a mapping of parameters (gender, age, ...)", field="text")
    return character_params(data)


# ----------------------------------------------------------------- renders ---

def _color(value: Any):
    if value is None or value == "transparent":
        return None
    if not isinstance(value, str):
        raise RequestError(f"background must be '#rrggbb', a colour name or 'transparent', got {value!r}",
                           field="background")
    try:
        return tuple(float(c) for c in compat.hex_to_rgb(NAMED_COLORS.get(value, value)))
    except ValueError as exc:
        raise RequestError(f"background: {exc} (or white, black, grey, transparent)", field="background") from None


def _size(value: Any) -> tuple[int, int]:
    if isinstance(value, (list, tuple)) and len(value) == 2:
        pair = value
    else:
        pair = (value, value)
    out = []
    for v in pair:
        if isinstance(v, bool) or not isinstance(v, int) or not 16 <= v <= MAX_SIZE:
            raise RequestError(f"size must be N or [W, H] pixels from 16 to {MAX_SIZE}, got {value!r}", field="size")
        out.append(v)
    return out[0], out[1]


def render_options(body: Any, *, video: bool = False) -> dict:
    """:meth:`facsim.Face.render` keyword arguments from the page's view options (the CLI's defaults)."""
    body = _mapping(body or {}, "options")
    view = choice(body.get("view", "front"), tuple(compat.VIEWS), "view")
    yaw = body.get("yaw")
    pitch = body.get("pitch")
    size = _size(body.get("size", 512))
    if video and (size[0] % 2 or size[1] % 2):
        raise RequestError(f"video frames need even sizes, got {size[0]}x{size[1]}", field="size")
    return {
        "view": view,
        "yaw": None if yaw is None else number(yaw, "yaw", -180, 180),
        "pitch": None if pitch is None else number(pitch, "pitch", -89, 89),
        "size": list(size),
        "projection": choice(body.get("projection", "perspective"), PROJECTIONS, "projection"),
        "background": None if (bg := _color(body.get("background", "white"))) is None else list(bg),
        "antialias": choice(body.get("antialias", "fxaa" if video else 4), ANTIALIAS, "antialias"),
        "body": body_style(body.get("body", compat.DEFAULT_BODY)),
    }


def body_style(value: Any) -> str:
    """What is under the head: a garment of ``facsim/data/body.yaml`` or ``none`` (``--body``)."""
    return choice(value, tuple(compat.body_styles()), "body")


# ---------------------------------------------------------------- timeline ---

def timeline_from_document(document: Any):
    """A :class:`~facsim.timeline.Timeline` from the page's document (facsim's timeline format)."""
    if not isinstance(document, Mapping):
        raise RequestError("timeline must be a JSON object in facsim's timeline format (`facsim schema`)",
                           field="timeline")
    tracks = document.get("tracks")
    for i, track in enumerate(tracks if isinstance(tracks, list) else ()):
        # a recording is a path on the server: the page may only send text to speak
        if isinstance(track, Mapping) and "audio" in track:
            raise RequestError("timeline: a speech clip in the studio says text ('say' with a 'voice'); "
                               "recordings ('audio') go through `facsim animate`", field="timeline",
                               location=["tracks", i, "audio"])
    try:
        timeline = compat.timeline_from_dict(document)
    except compat.TimelineError as exc:
        raise RequestError(f"timeline: {exc}", field="timeline", location=exc.path) from None
    except ValueError as exc:
        raise RequestError(f"timeline: {exc}", field="timeline") from None
    frames = timeline.length * timeline.fps
    if frames > MAX_FRAMES:
        raise RequestError(f"timeline: {frames:.0f} frames is more than the studio renders ({MAX_FRAMES}); "
                           f"use `facsim animate` for long videos", field="timeline")
    return timeline


def timeline_from_text(name: Any, text: Any) -> dict:
    """A timeline file's text (YAML, JSON or ``.facs``, by ``name``) as the canonical document."""
    import json

    import yaml

    if not isinstance(name, str) or not isinstance(text, str):
        raise RequestError("send the file's name and text", field="text")
    suffix = name.rsplit(".", 1)[-1].lower() if "." in name else ""
    try:
        if suffix == "facs":
            from facsim.exchange import loads_notation

            timeline = loads_notation(text)
        else:
            if suffix == "json":
                data = json.loads(text)
            elif suffix in ("yaml", "yml"):
                data = yaml.safe_load(text)
            else:
                raise RequestError(f"{name}: timelines are .yaml, .yml, .json or .facs files", field="name")
            timeline = timeline_from_document(data)
    except json.JSONDecodeError as exc:
        raise RequestError(f"{name}: malformed JSON at line {exc.lineno}: {exc.msg}", field="text") from None
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f" at line {mark.line + 1}" if mark is not None else ""
        raise RequestError(f"{name}: malformed YAML{where}", field="text") from None
    except RequestError as exc:
        raise RequestError(f"{name}: {exc}", field=exc.field, **exc.extra) from None
    except ValueError as exc:
        raise RequestError(f"{name}: {exc}", field="text") from None
    return compat.timeline_to_dict(timeline)


def timeline_text(document: Any, fmt: Any) -> str:
    """The document as a YAML or JSON file's text (after validation, as ``save_timeline`` writes it)."""
    import json

    import yaml

    fmt = choice(fmt, ("yaml", "json"), "format")
    data = compat.timeline_to_dict(timeline_from_document(document))
    if fmt == "yaml":
        return yaml.safe_dump(data, sort_keys=False, default_flow_style=None, allow_unicode=True, width=100)
    return json.dumps(data, indent=2, ensure_ascii=False) + "\n"


def timeline_preview(document: Any) -> dict:
    """Per-frame levels of every (AU, side) the timeline moves: what the 3-D view plays."""
    timeline = timeline_from_document(document)
    times = compat.frame_times(timeline, timeline.fps)
    curves = compat.activation_curves(timeline, times)
    out: dict[str, dict[str, list[float]]] = {}
    for (code, side), values in curves.items():
        out.setdefault(str(code), {})[side] = [round(float(v), 4) for v in values]
    # Each track's own level on a finer grid, for drawing its shape (easing included) in the editor.
    import numpy as np

    grid = np.linspace(0.0, timeline.length, DRAW_SAMPLES)
    shapes, speech = [], {}
    for i, track in enumerate(timeline.tracks):
        if isinstance(track, compat.Track):
            shapes.append([round(float(v), 4) for v in track.levels(grid)])
            continue
        # a speech clip: draw how much its mouth moves (the largest of its AU levels), and say where it ends
        moving = track.curves(grid).aus.values()
        level = np.max(np.stack(list(moving)), axis=0) if moving else np.zeros_like(grid)
        shapes.append([round(float(v), 4) for v in np.clip(level, 0.0, 1.0)])
        speech[str(i)] = {"start": round(track.start, 4), "end": round(track.end, 4), "label": track.label}
    return {"fps": timeline.fps, "length": timeline.length, "frames": len(times), "curves": out,
            "shapes": {"step": timeline.length / (DRAW_SAMPLES - 1), "levels": shapes}, "speech": speech}


def timeline_wav(document: Any) -> bytes | None:
    """The timeline's speech as 16-bit WAV bytes, as long as its video (what an MP4 export carries);
    None without speech. The page plays it along with the 3-D preview."""
    import io

    from scipy.io import wavfile

    from facsim.speech.audio import to_pcm16
    from facsim.timeline.sampling import frame_count
    from facsim.timeline.speech import timeline_audio

    timeline = timeline_from_document(document)
    audio = timeline_audio(timeline, frame_count(timeline, timeline.fps) / timeline.fps)
    if audio is None:
        return None
    buf = io.BytesIO()
    wavfile.write(buf, int(audio[1]), to_pcm16(audio[0]))
    return buf.getvalue()


#: Largest upload the "Analyse" button accepts (an image or a short video).
MAX_UPLOAD = 32 << 20
#: Longest video the studio analyses, in frames.
MAX_ANALYSE_FRAMES = 30 * 60
#: Leading bytes of each accepted file type → (kind, suffix the job folder stores it under).
SIGNATURES = (
    (b"\x89PNG\r\n\x1a\n", "image", ".png"), (b"\xff\xd8\xff", "image", ".jpg"), (b"BM", "image", ".bmp"),
    (b"II*\x00", "image", ".tif"), (b"MM\x00*", "image", ".tif"), (b"GIF87a", "video", ".gif"),
    (b"GIF89a", "video", ".gif"), (b"\x1aE\xdf\xa3", "video", ".webm"),
)


def upload_kind(data: bytes) -> tuple[str, str]:
    """``("image" | "video", suffix)`` of an uploaded file, by its content (never by the name the page sends).

    >>> upload_kind(b"\\x89PNG\\r\\n\\x1a\\n" + bytes(8))
    ('image', '.png')
    """
    if not data:
        raise RequestError("the upload is empty: send an image or a short video", field="file")
    if data[:4] == b"RIFF" and data[8:12] == b"WEBP":
        return "image", ".webp"
    if data[:4] == b"RIFF" and data[8:12] == b"AVI ":
        return "video", ".avi"
    if data[4:8] == b"ftyp":
        return "video", ".mov" if data[8:10] == b"qt" else ".mp4"
    for magic, kind, suffix in SIGNATURES:
        if data.startswith(magic):
            return kind, suffix
    raise RequestError("the upload is not an image (PNG, JPEG, BMP, TIFF, WebP) or a video (MP4, MOV, WebM, "
                       "MKV, AVI, GIF)", field="file", status=415)
