"""OpenFace 2.0 FeatureExtraction CSV → timeline: a recorded performance, replayed on any character.

Columns used (names are matched after stripping the spaces OpenFace puts
after each comma, in any case): ``timestamp`` and ``success`` (required),
``face_id``, ``confidence``, ``gaze_angle_x``, ``gaze_angle_y``,
``pose_Rx``, ``pose_Ry``, ``pose_Rz`` (optional), and the AU intensity
columns ``AU01_r`` … ``AU45_r`` (at least one). Presence columns (``AUxx_c``)
are not used: AU28 has only presence and is left out.

Conversions
    * Intensity 0–5 → level: 0 → 0, 1 → A, 2 → B, 3 → C, 4 → D, 5 → E of
      the intensity table (HapFACS: 0.15, 0.30, 0.55, 0.85, 1.0), linear in
      between, clipped to 0..5.
    * Head pose: ``pose_R*`` are radians, R = Rx·Ry·Rz in the camera frame
      (x right in the image, y down, z away from the camera). facsim's head
      frame (+X the character's left, +Y up, +Z toward the camera) is that
      frame turned 180° about x, so the head's rotation vector is
      (rx, −ry, −rz) of the camera one; its share along each head-turn axis
      over the register engine's full angle gives 51–56
      (:func:`facsim.engines.rigid.head_levels`).
    * Gaze: ``gaze_angle_x/y`` are radians in the camera frame (x > 0: the
      person looks to the image's right, their own left; y > 0: down).
      The gaze is turned into the head's frame (so a turned head looking
      at the camera has its eyes turned back), then its yaw and pitch give
      61–64 with the engine's eye angles (:func:`facsim.engines.rigid.eye_levels`).
    * Frames with ``success`` 0 (and, with ``min_confidence``, less confident
      ones) hold the last good frame's values (neutral before the first).
    * Times are ``timestamp`` minus the first one. The frame rate is
      1 / median frame interval, snapped to a common rate within 1 %; when
      every timestamp is within a quarter frame of ``i / fps`` the times
      become exactly ``i / fps``, so the timeline's frames sample the
      recorded ones.

Each AU becomes a track of linear segments from frame to frame
(:func:`facsim.timeline.builders.timeline_from_samples`).
"""
from __future__ import annotations

import math

import re
from pathlib import Path

import numpy as np

from facsim.engines.rigid import eye_levels, head_levels
from facsim.exchange import ExchangeError, csv_number, read_csv_rows, require_columns, samples_timeline

#: Frame rates the measured one is snapped to (within 1 %).
COMMON_FPS = (15, 24, 25, 30, 48, 50, 60, 90, 100, 120)
_AU_COLUMN = re.compile(r"^AU(\d{1,4})_r$", re.IGNORECASE | re.ASCII)
_POSE = ("pose_Rx", "pose_Ry", "pose_Rz")
_GAZE = ("gaze_angle_x", "gaze_angle_y")


def intensity_levels(values, table: str = "hapfacs") -> np.ndarray:
    """OpenFace intensities (0–5) as levels: 0, A … E of ``table`` at 0, 1 … 5, linear between.

    Examples
    --------
    >>> intensity_levels([0, 1, 3, 4.5, 7]).tolist()
    [0.0, 0.15, 0.55, 0.925, 1.0]
    """
    from facsim.facs.catalogue import INTENSITY_TABLES, LETTERS

    knots = [0.0] + [INTENSITY_TABLES[table][letter] for letter in LETTERS]
    return np.interp(np.clip(np.asarray(values, float), 0.0, 5.0), np.arange(6.0), knots)


def head_rotvec_degrees(pose: np.ndarray) -> np.ndarray:
    """Head rotation vectors (n, 3) in degrees, facsim's head frame, from OpenFace ``pose_R*`` (n, 3) radians."""
    from scipy.spatial.transform import Rotation

    camera = Rotation.from_euler("XYZ", np.atleast_2d(pose)).as_rotvec()
    return np.degrees(camera * np.array([1.0, -1.0, -1.0]))


def eye_rotvec_degrees(gaze: np.ndarray, head_degrees: np.ndarray) -> np.ndarray:
    """Eye-in-head rotation vectors (n, 3) in degrees from OpenFace ``gaze_angle_x/y`` (n, 2) radians."""
    from scipy.spatial.transform import Rotation

    gaze = np.atleast_2d(gaze)
    forward = np.stack([np.tan(gaze[:, 0]), -np.tan(gaze[:, 1]), np.ones(len(gaze))], axis=1)  # head frame axes
    in_head = Rotation.from_rotvec(np.radians(head_degrees)).inv().apply(forward)
    yaw = np.degrees(np.arctan2(in_head[:, 0], in_head[:, 2]))
    pitch = np.degrees(np.arctan2(-in_head[:, 1], np.hypot(in_head[:, 0], in_head[:, 2])))
    return np.stack([pitch, yaw, np.zeros(len(gaze))], axis=1)


def _frame_rate(times: np.ndarray, path) -> float:
    if len(times) < 2:
        return 30.0
    from facsim.limits import MIN_FPS, limit

    step = float(np.median(np.diff(times)))
    rate = 1.0 / step if step > 0 else math.inf
    if not MIN_FPS <= rate <= limit("max_fps"):    # odd timestamps: say so rather than divide by ~0
        raise ExchangeError(f"timestamps {step:g} s apart (median) make {rate:g} frames per second; expected "
                            f"{MIN_FPS:g} to {limit('max_fps'):,} (give the frame rate: --fps)", file=path)
    near = min(COMMON_FPS, key=lambda r: abs(r - rate))
    return float(near) if abs(near - rate) <= 0.01 * rate else round(rate, 3)


def _hold_bad_frames(values: np.ndarray, good: np.ndarray) -> np.ndarray:
    """Each bad row replaced by the last good row before it (zeros before the first)."""
    index = np.where(good, np.arange(len(good)), -1)
    last = np.maximum.accumulate(index)
    padded = np.vstack([np.zeros((1, values.shape[1])), values])
    return padded[last + 1]


def read_openface_csv(path, *, intensities: str = "hapfacs", face_id: int | None = None,
                      min_confidence: float | None = None, fps: float | None = None):
    """A timeline from an OpenFace 2.0 FeatureExtraction CSV (see the module docstring).

    Parameters
    ----------
    path : path
    intensities : str
        Letter table for intensities 1–5 (``"hapfacs"`` or ``"facshuman"``).
    face_id : int, optional
        Which face of a multi-face file (default: the lowest id).
    min_confidence : float, optional
        Also hold frames whose ``confidence`` is below this.
    fps : float, optional
        The timeline's frame rate; default: measured from the timestamps.

    Raises
    ------
    ExchangeError
        Missing columns, a truncated row, a cell that is not a number,
        timestamps that go backwards; naming the file and line.
    """
    path = Path(path)
    header, data = read_csv_rows(path)
    lookup = require_columns(header, ["timestamp", "success"], path, "an OpenFace CSV")
    au_at = {int(m.group(1)): i for i, name in enumerate(header) if (m := _AU_COLUMN.match(name))}
    if not au_at:
        raise ExchangeError("not an OpenFace CSV: no AU intensity columns (AU01_r ...)", file=path, line=1)
    wanted = ["timestamp", "success", "face_id", "confidence", *_POSE, *_GAZE]
    optional = {name: lookup.get(name.lower()) for name in wanted}
    numbers = np.array([[csv_number(cells, i, header, line, path) if i is not None else 0.0
                         for i in [*optional.values(), *au_at.values()]] for line, cells in data])
    column = {name: numbers[:, k] for k, name in enumerate(optional)}
    if optional["face_id"] is not None:
        chosen = column["face_id"].min() if face_id is None else face_id
        keep = column["face_id"] == chosen
        if not keep.any():
            raise ExchangeError(f"no rows with face_id {face_id}", file=path)
        numbers, data = numbers[keep], [row for row, k in zip(data, keep) if k]
        column = {name: numbers[:, k] for k, name in enumerate(optional)}
    for name in (*_POSE, *_GAZE):     # radians; beyond a full turn is no head pose or gaze (and overflows)
        if optional[name] is not None and np.any(np.abs(column[name]) > 2 * math.pi):
            row = int(np.flatnonzero(np.abs(column[name]) > 2 * math.pi)[0])
            raise ExchangeError(f"column {name}: {column[name][row]:g} radians is more than a full turn",
                                file=path, line=data[row][0])
    stamps = column["timestamp"]
    backwards = np.flatnonzero(np.diff(stamps) <= 0)
    if backwards.size:
        raise ExchangeError(f"timestamp {stamps[backwards[0] + 1]:g} does not come after the previous row's "
                            f"({stamps[backwards[0]]:g})", file=path, line=data[backwards[0] + 1][0])
    good = column["success"] > 0
    if min_confidence is not None and optional["confidence"] is not None:
        good &= column["confidence"] >= min_confidence
    values = _hold_bad_frames(numbers[:, len(optional):], good)
    pose = _hold_bad_frames(np.stack([column[n] for n in _POSE], 1), good)
    gaze = _hold_bad_frames(np.stack([column[n] for n in _GAZE], 1), good)

    times = stamps - stamps[0]
    rate = float(fps) if fps else _frame_rate(times, path)
    index = np.round(times * rate)
    if np.all(np.abs(times * rate - index) <= 0.25) and np.all(np.diff(index) > 0):
        times = index / rate
    curves = {(code, "both"): intensity_levels(values[:, k], intensities) for k, code in enumerate(au_at)}
    head = head_rotvec_degrees(pose)
    if any(optional[n] is not None for n in _POSE):
        for code in head_levels(np.zeros(3)):
            curves[(code, "both")] = np.array([head_levels(v)[code] for v in head])
    if any(optional[n] is not None for n in _GAZE):
        eyes = eye_rotvec_degrees(gaze, head)
        levels = [eye_levels(v, v) for v in eyes]
        for code in (61, 62, 63, 64):
            curves[(code, "both")] = np.array([lv[code] for lv in levels])
    curves = {key: v for key, v in curves.items() if np.any(v > 0)}
    return samples_timeline(path, times, curves, fps=rate, intensities=intensities,
                                 description=f"OpenFace performance {path.name}")


# ------------------------------------------------------------------ writing

#: OpenFace 2.0's AU columns: intensities (``AUxx_r``, 0–5) and presences (``AUxx_c``, 0/1), in its order.
#: The reader above matches any ``AUxx_r``; the writer writes exactly these, so tools that expect
#: OpenFace's layout find every column where they look for it.
AU_INTENSITY_CODES = (1, 2, 4, 5, 6, 7, 9, 10, 12, 14, 15, 17, 20, 23, 25, 26, 45)
AU_PRESENCE_CODES = (1, 2, 4, 5, 6, 7, 9, 10, 12, 14, 15, 17, 20, 23, 25, 26, 28, 45)
#: Leading columns (OpenFace 2.0 FeatureExtraction, without its landmark and shape blocks).
FRAME_COLUMNS = ("frame", "face_id", "timestamp", "confidence", "success", "gaze_angle_x", "gaze_angle_y",
                 "pose_Tx", "pose_Ty", "pose_Tz", "pose_Rx", "pose_Ry", "pose_Rz")


def openface_columns() -> list[str]:
    """The header :func:`write_openface_csv` writes."""
    return [*FRAME_COLUMNS, *(f"AU{c:02d}_r" for c in AU_INTENSITY_CODES),
            *(f"AU{c:02d}_c" for c in AU_PRESENCE_CODES)]


def level_intensities(levels, table: str = "hapfacs") -> np.ndarray:
    """Levels 0–1 → OpenFace intensities 0–5, the inverse of :func:`intensity_levels`.

    Examples
    --------
    >>> level_intensities([0.0, 0.15, 0.55, 0.925, 1.0]).tolist()
    [0.0, 1.0, 3.0, 4.5, 5.0]
    """
    from facsim.facs.catalogue import INTENSITY_TABLES, LETTERS

    knots = [0.0] + [INTENSITY_TABLES[table][letter] for letter in LETTERS]
    return np.interp(np.clip(np.asarray(levels, float), 0.0, 1.0), knots, np.arange(6.0))


def camera_pose(head_rotvec_deg) -> np.ndarray:
    """OpenFace ``pose_Rx/Ry/Rz`` (radians) from a head rotation vector in degrees; inverse of :func:`head_rotvec_degrees`."""
    from scipy.spatial.transform import Rotation

    camera = np.radians(np.atleast_2d(head_rotvec_deg)) * np.array([1.0, -1.0, -1.0])
    return Rotation.from_rotvec(camera).as_euler("XYZ")


def camera_gaze(eyes_deg, head_rotvec_deg) -> np.ndarray:
    """OpenFace ``gaze_angle_x/y`` (radians) from eye-in-head rotation vectors (2, 3) and the head's; inverse of
    :func:`eye_rotvec_degrees` for the eyes' mean direction."""
    from scipy.spatial.transform import Rotation

    in_head = Rotation.from_rotvec(np.radians(np.mean(eyes_deg, axis=0))).apply([0.0, 0.0, 1.0])
    world = Rotation.from_rotvec(np.radians(head_rotvec_deg)).apply(in_head)
    return np.array([np.arctan2(world[0], world[2]), np.arctan2(-world[1], world[2])])


def write_openface_csv(analysis, path, *, presence: float = 0.15, face_id: int = 0):
    """Write a :class:`facsim.analysis.Analysis` in OpenFace 2.0's CSV layout (atomically).

    Intensities are the larger side's level on 0–5 (:func:`level_intensities`);
    ``AUxx_c`` is 1 from ``presence`` up. Translation is in millimetres for a
    pinhole camera whose focal length is the frame width (OpenFace's own
    default when no intrinsics are given is similar), from the fitted face scale.
    Rows without a face have ``success`` 0 and zeros elsewhere, as OpenFace writes them.
    """
    from facsim.exchange import write_file

    lines = [", ".join(openface_columns())]
    focal = float(analysis.width or 640)
    for f in analysis.frames:
        row = [f.frame + 1, face_id, round(f.timestamp, 3), round(f.confidence, 2), int(f.success)]
        if f.success:
            level = {c: max(f.levels.get((c, "left"), 0.0), f.levels.get((c, "right"), 0.0)) for c, _ in f.levels}
            gaze = camera_gaze(f.eyes, f.rotvec)
            depth = focal / max(f.scale, 1e-6) * 100.0  # mm: scale is pixels per decimetre
            tx = (f.centre[0] - analysis.width / 2) / focal * depth
            ty = (f.centre[1] - analysis.height / 2) / focal * depth
            pose = camera_pose(f.rotvec)[0]
            row += [*np.round(gaze, 3), round(tx, 1), round(ty, 1), round(depth, 1), *np.round(pose, 3)]
            row += [round(float(level_intensities(level.get(c, 0.0))), 2) for c in AU_INTENSITY_CODES]
            row += [int(level.get(c, 0.0) >= presence) for c in AU_PRESENCE_CODES]
        else:
            row += [0] * (len(FRAME_COLUMNS) - 5 + len(AU_INTENSITY_CODES) + len(AU_PRESENCE_CODES))
        lines.append(", ".join(str(v) for v in row))
    return write_file(Path(path), "\n".join(lines) + "\n")
