"""Images and video of faces → FACS: the camera processor's public entry point.

>>> from skimage import data                       # doctest: +SKIP
>>> analyse(data.astronaut()).notation             # doctest: +SKIP
'12C+...'

An :class:`Analysis` holds one :class:`FrameAnalysis` per frame (a single
image is one frame): AU levels per side (0–1, the engines' scale), head pose,
gaze, and whether a face was found. Frames without a face have
``success=False`` and no levels; nothing raises for a picture without a face.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

IMAGE_SUFFIXES = (".png", ".jpg", ".jpeg", ".bmp", ".tif", ".tiff", ".webp")
VIDEO_SUFFIXES = (".mp4", ".mov", ".avi", ".mkv", ".webm", ".m4v", ".gif")
#: A level at or above this is reported as present (FACS trace, A, is 0.15 on the HapFACS table).
PRESENT = 0.15
#: Head turns and eye turns under this level are not reported in the FACS string.
PRESENT_RIGID = 0.2
#: Frames of a video used as its neutral reference when none is given: the least active share.
NEUTRAL_SHARE = 0.1


class AnalysisError(ValueError):
    """The input cannot be analysed (unreadable file, unknown type); the message names it."""


@dataclass(frozen=True)
class FrameAnalysis:
    """One frame's result.

    Attributes
    ----------
    frame : int
        Frame number from 0 (the image's index in a folder).
    timestamp : float
        Seconds.
    success : bool
        A face was found and fitted.
    confidence : float
        Face Mesh's presence score (0 without a face).
    levels : dict
        (AU code, "left" | "right") → level 0–1 for every fitted AU; the
        character's own left and right.
    rotvec : (3,) degrees
        Head rotation (facsim's frame: +X the person's left, +Y up, +Z toward the camera).
    eyes : (2, 3) degrees
        Rotation vector of the right and left eye in the head.
    scale : float
        Pixels per decimetre of face at the head (for OpenFace's translation).
    centre : (2,) pixels
        Where the head's reference point is in the image.
    residual_px : float
        Weighted RMS landmark distance the fit leaves.
    landmarks : (468, 3) array or None
    source : str
        The image's file name, where there is one.
    """

    frame: int
    timestamp: float
    success: bool
    confidence: float = 0.0
    levels: dict = field(default_factory=dict)
    rotvec: np.ndarray = field(default_factory=lambda: np.zeros(3))
    eyes: np.ndarray = field(default_factory=lambda: np.zeros((2, 3)))
    scale: float = 0.0
    centre: np.ndarray = field(default_factory=lambda: np.zeros(2))
    residual_px: float = math.nan
    landmarks: np.ndarray | None = None
    source: str = ""

    def rigid_levels(self) -> dict[int, float]:
        """Levels of head codes 51–56 and eye codes 61–64 from pose and gaze."""
        from facsim.engines.rigid import eye_levels, head_levels

        if not self.success:
            return {}
        out = head_levels(self.rotvec)
        # 65/66 (eyes turned apart) need the eyes' vergence, which irises alone do not measure well
        out.update({k: v for k, v in eye_levels(self.eyes[1], self.eyes[0]).items() if k <= 64})
        return out

    def activations(self, *, rigid: bool = True):
        """The frame as facsim :class:`~facsim.facs.activations.Activations` (AUs, and head/eyes when ``rigid``)."""
        from facsim.facs.activations import Activations

        levels = {key: min(1.0, v) for key, v in self.levels.items() if v > 0}
        if rigid:
            for code, v in self.rigid_levels().items():
                if v > 0:
                    levels[(code, "left")] = levels[(code, "right")] = v
        return Activations(levels)

    def notation(self, *, threshold: float = PRESENT, rigid_threshold: float = PRESENT_RIGID) -> str:
        """A FACS string such as ``6C+12D+25B`` (``L12C`` where the sides differ); ``"0"`` for none."""
        return format_levels(self.levels, self.rigid_levels(), threshold=threshold, rigid_threshold=rigid_threshold)


@dataclass(frozen=True)
class Analysis:
    """The result of :func:`analyse`: frames, frame rate and what could not be seen.

    Attributes
    ----------
    frames : tuple of FrameAnalysis
    fps : float
        Frames per second (1 for images and folders).
    width, height : int
        Frame size in pixels.
    unobservable : dict
        AU code → why landmarks cannot tell it (reported rather than guessed).
    neutral : str
        Where the person's neutral reference came from ("none", "image", "video").
    identity : Identity or None
        The person's fitted resting face (``identity.sliders()``: facsim face-shape sliders).
    timings : dict
        Seconds spent in detection, landmarks and fit.
    """

    frames: tuple
    fps: float = 1.0
    width: int = 0
    height: int = 0
    unobservable: dict = field(default_factory=dict)
    neutral: str = "none"
    identity: object = None
    timings: dict = field(default_factory=dict)

    @property
    def notation(self) -> str:
        """The first frame's FACS string (the whole result for a single image)."""
        return self.frames[0].notation() if self.frames else "0"

    @property
    def success(self) -> bool:
        return any(f.success for f in self.frames)

    def timeline(self):
        """A facsim timeline passing through every frame's levels (failed frames hold the last good one)."""
        from facsim.timeline.builders import timeline_from_samples

        good = [f for f in self.frames if f.success]
        if not good:
            raise AnalysisError("no face was found in any frame, so there is no timeline to write")
        keys = sorted({k for f in good for k in f.levels} | {(c, s) for f in good for c in f.rigid_levels()
                                                             for s in ("left", "right")})
        rows, last = [], None
        for f in self.frames:
            last = f if f.success else last
            act = last.activations() if last is not None else None
            rows.append([act[k] if act is not None else 0.0 for k in keys])
        values = np.array(rows)
        times = np.arange(len(self.frames)) / self.fps
        curves = {}
        for i, (code, side) in enumerate(keys):
            if code >= 51:
                curves[(code, "both")] = values[:, i]
            else:
                curves[(code, side)] = values[:, i]
        curves = {k: np.round(v, 3) for k, v in curves.items() if np.any(v >= 0.02)}
        return timeline_from_samples(times, curves, fps=self.fps, description="facsim analyse")

    def save(self, path) -> Path:
        """Write ``.csv`` (OpenFace 2.0 layout), ``.yaml``/``.yml``/``.json`` (timeline) or ``.facs``."""
        path = Path(path)
        suffix = path.suffix.lower()
        if suffix == ".csv":
            from facsim.exchange.openface import write_openface_csv

            return write_openface_csv(self, path)
        if suffix in (".yaml", ".yml", ".json", ".facs"):
            from facsim.exchange import save_any_timeline

            return save_any_timeline(self.timeline(), path)
        raise AnalysisError(f"cannot write {path.name}: use .csv (OpenFace), .yaml/.json (timeline) or .facs")


def format_levels(levels: dict, rigid: dict, *, threshold: float = PRESENT, rigid_threshold: float = PRESENT_RIGID) -> str:
    """FACS notation for per-side AU levels and rigid-code levels."""
    from facsim.facs.catalogue import INTENSITY_TABLES, LETTERS

    values = [INTENSITY_TABLES["hapfacs"][letter] for letter in LETTERS]

    def letter(v: float) -> str:
        return LETTERS[int(np.argmin([abs(v - x) for x in values]))]

    parts = []
    for code in sorted({c for c, _ in levels}):
        left, right = levels.get((code, "left"), 0.0), levels.get((code, "right"), 0.0)
        if max(left, right) < threshold:
            continue
        if min(left, right) >= threshold and letter(left) == letter(right):
            parts.append(f"{code}{letter(max(left, right))}")
        elif min(left, right) >= threshold and abs(left - right) < 0.2:
            parts.append(f"{code}{letter((left + right) / 2)}")
        else:
            parts += [f"{s}{code}{letter(v)}" for s, v in (("L", left), ("R", right)) if v >= threshold]
    for code, v in sorted(rigid.items()):
        if v >= rigid_threshold:
            parts.append(f"{code}{letter(v)}")
    return "+".join(parts) or "0"


# ------------------------------------------------------------------ reading inputs


def _read_image(path: Path) -> np.ndarray:
    from PIL import Image, ImageOps

    from facsim.limits import check_image_size

    try:
        with Image.open(path) as im:
            check_image_size(*im.size, f"image {path.name}")  # before decoding: the header gives the size
            return np.asarray(ImageOps.exif_transpose(im).convert("RGB"))
    except ValueError as exc:
        raise AnalysisError(str(exc)) from None
    except Exception as exc:
        raise AnalysisError(f"cannot read image {path}: {exc}") from None


def input_kind(source) -> str:
    """``"array"``, ``"image"``, ``"folder"`` or ``"video"``; raises for anything else."""
    if isinstance(source, np.ndarray):
        return "array"
    path = Path(source)
    if path.is_dir():
        return "folder"
    if not path.exists():
        raise AnalysisError(f"no such file or folder: {path}")
    suffix = path.suffix.lower()
    if suffix in IMAGE_SUFFIXES:
        return "image"
    if suffix in VIDEO_SUFFIXES:
        return "video"
    raise AnalysisError(f"cannot analyse {path.name}: not an image ({', '.join(IMAGE_SUFFIXES)}) "
                        f"or a video ({', '.join(VIDEO_SUFFIXES)})")


def iter_frames(source):
    """(frames iterator of (name, RGB array), fps, count or None) for any input kind."""
    from facsim.limits import check_frames, check_image_size, limit, override_hint

    kind = input_kind(source)
    if kind == "array":
        array = np.asarray(source)
        if array.ndim >= 2:
            try:
                check_image_size(array.shape[1], array.shape[0], "the image array")
            except ValueError as exc:
                raise AnalysisError(str(exc)) from None
        return iter([("", array)]), 1.0, 1
    path = Path(source)
    if kind == "image":
        return iter([(path.name, _read_image(path))]), 1.0, 1
    if kind == "folder":
        files = sorted(p for p in path.iterdir() if p.suffix.lower() in IMAGE_SUFFIXES)
        if not files:
            raise AnalysisError(f"no images ({', '.join(IMAGE_SUFFIXES)}) in folder {path}")
        try:
            check_frames(len(files), f"folder {path}")
        except ValueError as exc:
            raise AnalysisError(str(exc)) from None
        return ((p.name, _read_image(p)) for p in files), 1.0, len(files)
    import imageio.v2 as imageio

    try:
        reader = imageio.get_reader(str(path), "ffmpeg")
        meta = reader.get_meta_data()
    except Exception as exc:
        raise AnalysisError(f"cannot read video {path}: {exc}") from None
    fps = float(meta.get("fps") or 30.0)
    duration = meta.get("duration")
    count = round(duration * fps) if duration and math.isfinite(duration * fps) else None
    try:
        if meta.get("size"):
            check_image_size(*meta["size"], f"a frame of video {path.name}")
        if count is not None:
            check_frames(count, f"video {path.name}")
    except ValueError as exc:
        reader.close()
        raise AnalysisError(str(exc)) from None

    def frames():
        try:
            for done, frame in enumerate(reader):
                if done >= limit("max_frames"):  # a container that understates its length
                    raise AnalysisError(f"video {path.name} has more than {limit('max_frames'):,} frames "
                                        f"{override_hint('max_frames')}")
                yield "", np.asarray(frame)[..., :3]
        finally:
            reader.close()
    return frames(), fps, count


# ------------------------------------------------------------------ smoothing


class OneEuro:
    """Casiez et al. 2012's 1€ filter on a vector: little lag on fast moves, little jitter at rest."""

    def __init__(self, fps: float, min_cutoff: float = 1.5, beta: float = 0.3, d_cutoff: float = 1.0):
        self.fps, self.min_cutoff, self.beta, self.d_cutoff = fps, min_cutoff, beta, d_cutoff
        self.x = self.dx = None

    def _alpha(self, cutoff):
        tau = 1.0 / (2 * math.pi * cutoff)
        return 1.0 / (1.0 + tau * self.fps)

    def __call__(self, x: np.ndarray) -> np.ndarray:
        if self.x is None:
            self.x, self.dx = x.copy(), np.zeros_like(x)
            return x
        dx = (x - self.x) * self.fps
        self.dx = self.dx + self._alpha(self.d_cutoff) * (dx - self.dx)
        cutoff = self.min_cutoff + self.beta * np.abs(self.dx)
        a = self._alpha(cutoff)
        self.x = self.x + a * (x - self.x)
        return self.x


# ------------------------------------------------------------------ the processor


def analyse(source, *, face: int = 0, neutral=None, baseline: bool = True, smooth: bool = True, threads: int = 1,
            landmarks: bool = False, on_frame=None) -> Analysis:
    """Analyse an image, a folder of images or a video.

    Parameters
    ----------
    source : path or (H, W, 3) array
        An image file, a folder of images (sorted by name, one frame each) or a video.
    face : int
        Which face when there are several: 0 = the largest, 1 = the next, ...
    neutral : path or array, optional
        An image of the same person at rest: their face shape is fitted on it
        so their resting face is not read as an expression. For a video without
        one, its least active frames serve (unless ``baseline`` is False).
    baseline : bool
        For a video without ``neutral``: take its least active frames as the
        person's rest. Turn off for a clip that never rests (it would read a
        held smile as neutral).
    smooth : bool
        Temporal smoothing of landmarks in video (1€ filter).
    threads : int
        Interpreter threads per model.
    landmarks : bool
        Keep each frame's 468 landmarks in the result.
    on_frame : callable, optional
        Called with the number of frames done (progress).
    """
    from scipy.spatial.transform import Rotation

    from .fit import build_basis, fit_frame, fit_identity
    from .landmarks import LandmarkDetector

    if face < 0:
        raise AnalysisError(f"face must be 0 (the largest) or more, got {face}")
    frames, fps, _ = iter_frames(source)
    kind = input_kind(source)
    model = build_basis()
    fit_seconds = 0.0
    observations = []  # (name, FaceLandmarks | None, (w, h))
    with LandmarkDetector(threads=threads) as detector:
        identity, neutral_from = None, "none"
        if neutral is not None:
            image = neutral if isinstance(neutral, np.ndarray) else _read_image(Path(neutral))
            found = detector.faces(image)
            if not found:
                raise AnalysisError(f"no face found in the neutral image {getattr(neutral, 'name', neutral)}")
            identity, neutral_from = fit_identity(model, [found[min(face, len(found) - 1)].points]), "image"
        tracked = None
        filt = OneEuro(fps) if (kind == "video" and smooth) else None
        for i, (name, image) in enumerate(frames):
            h, w = image.shape[:2]
            found = None
            if kind == "video" and tracked is not None:
                found = detector.landmarks(image, detector.track_roi(tracked))
            if found is None:
                faces = detector.faces(image)
                found = faces[face] if len(faces) > face else None
            tracked = found if kind == "video" else None
            if found is not None and filt is not None:
                scale = max(1.0, found.area ** 0.5)
                pts = filt(np.concatenate([found.points.ravel(), found.irises.ravel()]) / scale) * scale
                found = type(found)(pts[: 468 * 3].reshape(468, 3), pts[468 * 3:].reshape(2, 5, 2),
                                    found.roi, found.presence)
            elif found is None and filt is not None:
                filt.x = None  # a lost face restarts the filter
            observations.append((name, found, (w, h)))
            if on_frame is not None:
                on_frame(i + 1)
        timings = dict(detector.timings)
    if identity is None and kind == "video" and baseline:
        t0 = time.perf_counter()
        good = [o for o in observations if o[1] is not None]
        if len(good) >= 5:
            # rank at most 30 evenly spaced frames by how much they express (a quick fit each)
            ranked = range(0, len(good), -(-len(good) // 30))
            quick = [(np.abs(fit_frame(model, good[k][1].points, iterations=2).levels).sum(), k) for k in ranked]
            quick.sort()
            chosen = [good[k][1].points for _, k in quick[: max(1, int(len(quick) * NEUTRAL_SHARE))]]
            identity, neutral_from = fit_identity(model, chosen), "video"
        fit_seconds += time.perf_counter() - t0
    results = []
    for i, (name, found, (w, h)) in enumerate(observations):
        stamp = i / fps
        if found is None:
            results.append(FrameAnalysis(i, stamp, False, source=name))
            continue
        t0 = time.perf_counter()
        fit = fit_frame(model, found.points, found.irises, identity=identity)
        fit_seconds += time.perf_counter() - t0
        levels = {k: round(v, 4) for k, v in model.side_levels(fit.levels).items()}
        rot = Rotation.from_rotvec(np.radians(fit.rotvec)).as_matrix()
        centre = fit.scale * (rot @ model.neutral.mean(axis=0))[:2] + fit.translation[:2]
        results.append(FrameAnalysis(
            i, stamp, True, found.presence, levels, fit.rotvec, fit.eyes, fit.scale,
            np.array([centre[0], -centre[1]]), fit.residual_px, found.points if landmarks else None, name))
    timings["fit"] = fit_seconds
    width, height = observations[0][2] if observations else (0, 0)
    return Analysis(tuple(results), fps, width, height, model.visibility(), neutral_from, identity, timings)
