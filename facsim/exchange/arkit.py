"""ARKit-52 blendshape weights per frame, in Live Link Face's CSV layout, to and from timelines.

AUs → ARKit
    The register engine's own ``faceunits/<ARKit name>`` registers
    (``facsim/data/registers.yaml``) are the mapping: a frame's activations
    go through :func:`facsim.registers.register_weights` (HapFACS Eq. 1, with
    the engine's concave intensity response) and
    each Face Units register is an ARKit shape. A shape without a side
    (``jawOpen``) takes the mean of its two halves. Sideways gaze
    (``eyeLookIn/Out``), which no register drives, comes from the eyes' yaw,
    and the nine angle columns from the engine's head (51–56) and eye (61–66)
    rotations. What facsim adds to the registers is data in
    ``facsim/data/arkit52.yaml``.

ARKit → AUs
    Per frame, the AU levels whose ARKit weights best match the frame's:
    ``scipy.optimize.lsq_linear`` over the same map (one column per AU, or per
    AU and side where the AU can act on one side and its shapes have sides),
    bounded to 0..1 (non-negative least squares with a ceiling; the shares
    become intensities through the inverse of the engine's response), plus a small
    ridge (:data:`RIDGE`) so that where several AU mixes give the same shapes
    (AU25 is AU26 at 0.13 plus AU16 at 0.32) the answer is unique: the
    smallest levels; levels under :data:`LEVEL_FLOOR` are dropped. AUs whose
    columns duplicate a kept AU's are left out (listed in ``arkit52.yaml``).
    The inverse recovers levels exactly where no two active AUs share a shape;
    where they do, Eq. 1's clamp is not undone. Head angles give 51–56 (each
    code's share of the rotation along its axis over its full angle; 57/58,
    moving the head forward and back, have no ARKit column); eye
    angles, when the file has any, give 61–66, else 61–64 come from the
    eyeLook shapes. The levels become a timeline of linear segments from
    frame to frame (:func:`facsim.timeline.builders.timeline_from_samples`).

CSV layout
    ``Timecode, BlendShapeCount``, the 52 shapes in Live Link Face order
    (``EyeBlinkLeft … TongueOut``), then ``HeadYaw, HeadPitch, HeadRoll,
    LeftEyeYaw, LeftEyePitch, LeftEyeRoll, RightEyeYaw, RightEyePitch,
    RightEyeRoll`` (:func:`csv_columns`). Timecode ``HH:MM:SS:FF.fff``; angles
    are rotation-vector components in degrees / 180 (signs in
    ``arkit52.yaml``). A reader matches columns by name (any case), ignores
    extra ones and treats missing angle columns as 0.
"""
from __future__ import annotations

import csv
import io
import math
import re
from functools import lru_cache
from importlib import resources
from pathlib import Path

import numpy as np

from facsim.engines.rigid import eye_levels, eye_motion, head_levels, head_motion, rigid_table
from facsim.exchange import (ExchangeError, csv_number, read_csv_rows, require_columns, samples_timeline,
                             write_file)

REGISTER_PREFIX = "faceunits/"
#: Frame rates a Live Link Face take's frame numbers are snapped up to.
COMMON_FPS = (24, 25, 30, 48, 50, 60, 100, 120)
#: Weight of the ridge term that makes the ARKit -> AU inverse unique where
#: several AU mixes give the same shapes (it prefers the smallest levels).
RIDGE = 0.01
#: Recovered levels below this are set to 0 (least-squares crumbs, not actions).
LEVEL_FLOOR = 0.005
# ASCII digits, bounded lengths: '٠١' is no frame number, and 400 nines would be an infinite one.
_TIMECODE = re.compile(r"^\s*([0-9]{1,4}):([0-9]{1,2}):([0-9]{1,2})[:;.]([0-9]{1,4}(?:\.[0-9]{0,9})?)\s*$", re.ASCII)


@lru_cache(maxsize=1)
def arkit_table() -> dict:
    """The parsed ``facsim/data/arkit52.yaml``."""
    import yaml

    return yaml.safe_load(resources.files("facsim").joinpath("data/arkit52.yaml").read_text(encoding="utf-8"))


def csv_columns() -> list[str]:
    """The Live Link Face CSV header, 63 names."""
    return list(arkit_table()["live_link_face"]["columns"])


def shape_names() -> tuple[str, ...]:
    """ARKit's 52 blendshape names (camelCase, ``eyeBlinkLeft``), in CSV column order."""
    columns = csv_columns()
    return tuple(c[0].lower() + c[1:] for c in columns[2:54])


def angle_names() -> tuple[str, ...]:
    """The nine angle columns (``HeadYaw`` … ``RightEyeRoll``)."""
    return tuple(csv_columns()[54:])


# --------------------------------------------------------- AUs -> ARKit ---

def arkit_weights(act) -> dict[str, float]:
    """The 52 ARKit weights (0..1, by camelCase name) of one frame's :class:`~facsim.expression.Activations`."""
    from facsim.engines.registers import register_weights

    table = arkit_table()
    weights = dict.fromkeys(shape_names(), 0.0)
    for col, weight in register_weights(act).items():
        if col.target.startswith(REGISTER_PREFIX):
            name = col.target[len(REGISTER_PREFIX):]
            weights[name] += weight if col.sided else weight / 2      # unsided: mean of the halves
    gaze = table["gaze"]
    for side, rotvec in eye_motion(act.level).items():
        yaw = math.degrees(rotvec[1]) / gaze["full_degrees"]
        if yaw:
            name = gaze["positive_yaw" if yaw > 0 else "negative_yaw"][side]
            weights[name] += abs(yaw)
    return {name: min(1.0, max(0.0, value)) for name, value in weights.items()}


def arkit_angles(act) -> dict[str, float]:
    """The nine angle columns of one frame: rotation-vector components in degrees / 180."""
    table = arkit_table()
    scale = table["live_link_face"]["angle_scale_degrees"]
    head, _ = head_motion(act.level)
    eyes = eye_motion(act.level)
    out = {}
    for group, rotvec in (("head", head), ("left_eye", eyes["left"]), ("right_eye", eyes["right"])):
        for name, axis in table["angles"][group].items():
            out[name] = float(np.degrees(rotvec) @ np.asarray(axis, float)) / scale
    return out


def _timecode(index: int, fps: float) -> str:
    if float(fps).is_integer():
        seconds, frame = divmod(index, int(fps))
    else:
        t = index / fps
        seconds = int(t)
        frame = round((t - seconds) * fps, 3)
    hours, rest = divmod(int(seconds), 3600)
    minutes, secs = divmod(rest, 60)
    return f"{hours:02d}:{minutes:02d}:{secs:02d}:{frame:06.3f}"


def _number(value: float) -> str:
    text = f"{value:.6f}".rstrip("0").rstrip(".")
    return "0" if text in ("", "-0") else text


def dumps_arkit_csv(timeline, *, fps: float | None = None) -> str:
    """The timeline's frames as Live Link Face CSV text (header :func:`csv_columns`)."""
    from facsim.timeline.sampling import sample_frames

    fps = fps or timeline.fps
    names, angles = shape_names(), angle_names()
    count = arkit_table()["live_link_face"]["blendshape_count"]
    out = io.StringIO()
    writer = csv.writer(out, lineterminator="\n")
    writer.writerow(csv_columns())
    for index, act in enumerate(sample_frames(timeline, fps)):
        weights, rotations = arkit_weights(act), arkit_angles(act)
        writer.writerow([_timecode(index, fps), count] + [_number(weights[n]) for n in names]
                        + [_number(rotations[n]) for n in angles])
    return out.getvalue()


def write_arkit_csv(timeline, path, *, fps: float | None = None) -> Path:
    """Write the timeline's frames (at ``fps``, default the timeline's) as a Live Link Face CSV, atomically."""
    return write_file(path, dumps_arkit_csv(timeline, fps=fps))


# --------------------------------------------------------- ARKit -> AUs ---

@lru_cache(maxsize=1)
def inverse_map() -> tuple[tuple[tuple[int, str], ...], np.ndarray]:
    """The unknowns of the ARKit → AU inverse and their columns.

    Returns
    -------
    unknowns : tuple of (code, side)
        side "both", or "left"/"right" where the AU can act on one side and
        its two sides move different shapes.
    matrix : (52, len(unknowns)) array
        ARKit weights of each unknown at level 1.
    """
    from facsim.facs.catalogue import info
    from facsim.facs.activations import Activations
    from facsim.engines.registers import register_table

    table = register_table()
    excluded = set(arkit_table()["inverse"]["excluded"])
    codes = {code for code, spec in table["action_units"].items()
             if any(r["target"].startswith(REGISTER_PREFIX) for r in spec.get("registers", []))}
    codes |= {code for code, spec in rigid_table()["eye_rotations"].items() if spec["left"] or spec["right"]}
    names = shape_names()
    unknowns, columns = [], []
    for code in sorted(codes - excluded):
        vector = lambda levels: np.array([arkit_weights(Activations(levels))[n] for n in names])  # noqa: E731
        left, right = vector({(code, "left"): 1.0}), vector({(code, "right"): 1.0})
        if info(code).unilateral and not np.allclose(left, right):
            unknowns += [(code, "left"), (code, "right")]
            columns += [left, right]
        else:
            unknowns.append((code, "both"))
            columns.append(vector({(code, "left"): 1.0, (code, "right"): 1.0}))
    return tuple(unknowns), np.stack(columns, axis=1)


def au_levels(weights: np.ndarray) -> np.ndarray:
    """AU levels (frames, unknowns) whose ARKit weights best match ``weights`` (frames, 52), each in 0..1."""
    from scipy.optimize import lsq_linear

    unknowns, matrix = inverse_map()
    weights = np.atleast_2d(np.asarray(weights, float))
    ridged = np.vstack([matrix, RIDGE * np.eye(len(unknowns))])
    padding = np.zeros(len(unknowns))
    out = np.zeros((len(weights), len(unknowns)))
    for i, row in enumerate(weights):
        if row.any():
            out[i] = lsq_linear(ridged, np.concatenate([row, padding]), bounds=(0.0, 1.0), method="bvls").x
    # The solve gives each AU's share of its shapes; register-driven AUs reach that share at
    # a lower intensity (the engine's concave response), sideways gaze (61/62) linearly.
    from facsim.engines.registers import register_table, response_inverse

    morphs = register_table()["action_units"]
    for j, (code, _) in enumerate(unknowns):
        if code in morphs:
            out[:, j] = [response_inverse(u, code) for u in np.clip(out[:, j], 0.0, 1.0)]
    out[out < LEVEL_FLOOR] = 0.0
    return np.clip(out, 0.0, 1.0)


def _parse_timecode(text: str, line: int, file) -> tuple[int, float]:
    """(whole seconds, frame number with its fraction) of a Timecode cell."""
    found = _TIMECODE.match(text)
    if not found:
        raise ExchangeError(f"Timecode {text.strip()!r} is not HH:MM:SS:FF.fff", file=file, line=line)
    hours, minutes, seconds, frame = found.groups()
    return (int(hours) * 3600 + int(minutes) * 60 + int(seconds)), float(frame)


def _fps_from_frames(seconds: list[int], frames: list[float]) -> float | None:
    """The take's frame rate, from the largest frame number when the take crosses a second."""
    if len(set(seconds)) < 2:
        return None
    top = int(max(frames)) + 1
    return float(next((rate for rate in COMMON_FPS if rate >= top), top))


def read_arkit_csv(path, *, fps: float | None = None):
    """A timeline from a Live Link Face (ARKit-52) CSV; see the module docstring for the inverse.

    Parameters
    ----------
    path : path
    fps : float, optional
        The take's frame rate; default: from the Timecode frame numbers
        (snapped up to a common rate), or 60 (Live Link Face's default) for a
        take shorter than a second.

    Raises
    ------
    ExchangeError
        Missing columns, a truncated row, a cell that is not a number, a bad
        Timecode, or no frames; naming the file and line.
    """
    path = Path(path)
    header, data = read_csv_rows(path)
    lookup = require_columns(header, ["Timecode", *csv_columns()[2:54]], path, "a Live Link Face CSV")
    shape_at = [lookup[name.lower()] for name in csv_columns()[2:54]]
    angle_at = [lookup.get(name.lower()) for name in angle_names()]
    seconds, frames = [], []
    weights = np.zeros((len(data), len(shape_at)))
    angles = np.zeros((len(data), len(angle_at)))
    for k, (line, cells) in enumerate(data):
        sec, frame = _parse_timecode(cells[lookup["timecode"]], line, path)
        seconds.append(sec)
        frames.append(frame)
        weights[k] = [csv_number(cells, i, header, line, path) for i in shape_at]
        angles[k] = [0.0 if i is None else csv_number(cells, i, header, line, path) for i in angle_at]
        if np.any(np.abs(angles[k]) > 1.0 + 1e-6):   # -1..1 is -180..180 degrees; more would overflow into NaN
            column = next(n for n, v in zip(angle_names(), angles[k]) if abs(v) > 1.0 + 1e-6)
            raise ExchangeError(f"column {column}: {angles[k][angle_names().index(column)]:g} is outside -1..1 "
                                "(Live Link Face angles are degrees / 180)", file=path, line=line)
    fps = float(fps) if fps else (_fps_from_frames(seconds, frames) or arkit_table()["live_link_face"]["default_fps"])
    index = np.array(seconds, float) * fps + np.array(frames)
    snapped = np.round(index)
    index = np.where(np.abs(index - snapped) < 1e-6, snapped, index)
    times = (index - index[0]) / fps
    bad = np.flatnonzero(np.diff(times) <= 0)
    if bad.size:
        raise ExchangeError(f"Timecode {data[bad[0] + 1][1][lookup['timecode']].strip()!r} does not come after "
                            "the previous row's", file=path, line=data[bad[0] + 1][0])
    curves = _curves(np.clip(weights, 0.0, 1.0), angles)
    return samples_timeline(path, times, curves, fps=fps, description=f"ARKit blendshapes from {path.name}")


def _curves(weights: np.ndarray, angles: np.ndarray) -> dict:
    unknowns, _ = inverse_map()
    levels = au_levels(weights)
    curves = {key: levels[:, j] for j, key in enumerate(unknowns)}
    table = arkit_table()
    scale = table["live_link_face"]["angle_scale_degrees"]
    names = angle_names()

    def rotvecs(group):
        axes = table["angles"][group]
        return sum(np.outer(angles[:, names.index(n)] * scale, np.asarray(a, float)) for n, a in axes.items())

    head, left, right = rotvecs("head"), rotvecs("left_eye"), rotvecs("right_eye")
    heads = [head_levels(v) for v in head]
    for code in heads[0]:
        curves[(code, "both")] = np.array([h[code] for h in heads])
    if np.any(left) or np.any(right):
        eyes = [eye_levels(a, b) for a, b in zip(left, right)]
        for code in eyes[0]:
            curves[(code, "both")] = np.array([e[code] for e in eyes])
    return {key: values for key, values in curves.items() if np.any(values > 0)}
