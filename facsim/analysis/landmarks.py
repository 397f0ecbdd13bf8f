"""Faces and their 468 Face Mesh landmarks plus irises, from an RGB image.

The MediaPipe Face Mesh v1 pipeline, run with ai-edge-litert:

1. BlazeFace (short range and full range, merged) on the whole frame, letterboxed to its square input; anchors decoded, weighted
   non-maximum suppression.
2. Each face's region of interest: its box made square on the long side,
   scaled 1.5×, rotated so the eye keypoints lie level (the "eye-aligned" crop),
   warped to 192² for Face Mesh → 468 points (x, y in image pixels, z in the
   same scale, smaller = nearer the camera).
3. Each eye's region from its corners (scaled 2.3×, rotated level), 64², the
   right one mirrored as the model expects → 5 iris points per eye.

For video, :class:`LandmarkDetector` can track: the next frame's region comes
from the last landmarks (as MediaPipe does), so detection runs only when the
face is lost.

Image coordinates: x right, y down, pixel centres at i + 0.5.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

#: BlazeFace SSD anchors: (input size, strides, anchors per cell) for each detector.
DETECTORS = {
    "face_detection_short_range.tflite": (128, (8, 16, 16, 16)),
    "face_detection_full_range.tflite": (192, (4,)),
}
MIN_DETECTION_SCORE = 0.5
NMS_IOU = 0.3
MESH_SIZE = 192
MESH_ROI_SCALE = 1.5
MIN_PRESENCE = 0.5
IRIS_SIZE = 64
IRIS_ROI_SCALE = 2.3
#: Face Mesh indices of each eye's corners (outer, inner) for the iris crop and the tracking rotation.
#: "left"/"right" are the person's own sides: their left eye is on the image's right.
EYE_CORNERS = {"right": (33, 133), "left": (362, 263)}
TRACK_ROTATION = (33, 263)


@dataclass(frozen=True)
class Detection:
    """One BlazeFace detection in image pixels: box (x0, y0, x1, y1), six keypoints (6, 2), score."""

    box: np.ndarray
    keypoints: np.ndarray
    score: float

    @property
    def area(self) -> float:
        return float((self.box[2] - self.box[0]) * (self.box[3] - self.box[1]))


@dataclass(frozen=True)
class Roi:
    """A rotated square crop: centre (x, y) in pixels, side, rotation in radians (x axis = (cos, sin))."""

    cx: float
    cy: float
    size: float
    rotation: float

    def to_image(self, points: np.ndarray, tensor_size: int) -> np.ndarray:
        """Tensor pixel coordinates (n, 2 or 3) → image pixels (z scaled like x)."""
        c, s = math.cos(self.rotation), math.sin(self.rotation)
        scale = self.size / tensor_size
        local = (points[:, :2] - tensor_size / 2) * scale
        out = np.empty((len(points), points.shape[1]), np.float64)
        out[:, 0] = self.cx + c * local[:, 0] - s * local[:, 1]
        out[:, 1] = self.cy + s * local[:, 0] + c * local[:, 1]
        if points.shape[1] > 2:
            out[:, 2] = points[:, 2] * scale
        return out


@dataclass(frozen=True)
class FaceLandmarks:
    """One face's landmarks in image pixels.

    Attributes
    ----------
    points : (468, 3) float
        Face Mesh v1 landmarks: x, y in pixels, z relative depth in the same scale.
    irises : (2, 5, 2) float
        Iris centre and four rim points, person's right eye then left eye.
    roi : Roi
        The crop the points came from (the tracker's next crop starts from it).
    presence : float
        Face Mesh's face-presence score (0–1).
    """

    points: np.ndarray
    irises: np.ndarray
    roi: Roi
    presence: float

    @property
    def box(self) -> tuple[float, float, float, float]:
        lo, hi = self.points[:, :2].min(axis=0), self.points[:, :2].max(axis=0)
        return float(lo[0]), float(lo[1]), float(hi[0]), float(hi[1])

    @property
    def area(self) -> float:
        x0, y0, x1, y1 = self.box
        return (x1 - x0) * (y1 - y0)


def ssd_anchors(size: int, strides) -> np.ndarray:
    """Anchor centres (n, 2) in [0, 1] as MediaPipe's SsdAnchorsCalculator makes them for BlazeFace."""
    anchors = []
    i = 0
    while i < len(strides):
        j, repeats = i, 0
        while j < len(strides) and strides[j] == strides[i]:
            repeats += 2 if len(strides) > 1 else 1  # two aspect ratios per layer (interpolated scale) or one
            j += 1
        cells = size // strides[i]
        grid = (np.arange(cells) + 0.5) / cells
        yy, xx = np.meshgrid(grid, grid, indexing="ij")
        centres = np.stack([xx.ravel(), yy.ravel()], axis=1)
        anchors.append(np.repeat(centres, repeats, axis=0))
        i = j
    return np.concatenate(anchors).astype(np.float32)


def weighted_nms(boxes: np.ndarray, scores: np.ndarray, keypoints: np.ndarray, iou: float):
    """MediaPipe's weighted non-maximum suppression: overlapping boxes are averaged by score."""
    order = np.argsort(-scores)
    kept = []
    while order.size:
        top = order[0]
        x0 = np.maximum(boxes[top, 0], boxes[order, 0])
        y0 = np.maximum(boxes[top, 1], boxes[order, 1])
        x1 = np.minimum(boxes[top, 2], boxes[order, 2])
        y1 = np.minimum(boxes[top, 3], boxes[order, 3])
        inter = np.clip(x1 - x0, 0, None) * np.clip(y1 - y0, 0, None)
        area = (boxes[:, 2] - boxes[:, 0]) * (boxes[:, 3] - boxes[:, 1])
        union = area[top] + area[order] - inter
        overlap = order[inter / np.maximum(union, 1e-12) > iou]
        w = scores[overlap][:, None]
        box = (boxes[overlap] * w).sum(0) / w.sum()
        kps = (keypoints[overlap] * w[:, :, None]).sum(0) / w.sum()
        kept.append((box, kps, float(scores[top])))
        order = order[~np.isin(order, overlap)]
    return kept


def _affine_crop(image, roi: Roi, size: int, *, flip: bool = False) -> np.ndarray:
    """Warp the rotated square ``roi`` of a PIL image to (size, size, 3) float32 in [0, 1]."""
    from PIL import Image

    c, s = math.cos(roi.rotation), math.sin(roi.rotation)
    k = roi.size / size
    sx = -k if flip else k
    # output (u, v) → input: centre + R @ ((u - size/2) * sx, (v - size/2) * k)
    a, b = c * sx, -s * k
    d, e = s * sx, c * k
    cx = roi.cx - (a + b) * size / 2
    cy = roi.cy - (d + e) * size / 2
    crop = image.transform((size, size), Image.AFFINE, (a, b, cx, d, e, cy), resample=Image.BILINEAR)
    return np.asarray(crop, np.float32) * (1.0 / 255.0)


def _roi_from_points(points: np.ndarray, start: np.ndarray, end: np.ndarray, scale: float) -> Roi:
    lo, hi = points.min(axis=0), points.max(axis=0)
    centre = (lo + hi) / 2
    rotation = -math.atan2(start[1] - end[1], end[0] - start[0])
    rotation -= 2 * math.pi * math.floor((rotation + math.pi) / (2 * math.pi))
    return Roi(float(centre[0]), float(centre[1]), float(max(hi - lo)) * scale, rotation)


class LandmarkDetector:
    """Faces → landmarks. A native resource: use ``with`` or call :meth:`close`.

    Parameters
    ----------
    threads : int
        Interpreter threads per model.
    irises : bool
        Also run the iris model (gaze needs it).
    """

    def __init__(self, *, threads: int = 1, irises: bool = True):
        from .models import interpreter

        self._detectors = {}
        for name, (size, strides) in DETECTORS.items():
            interp = interpreter(name, threads=threads)
            outs = sorted(interp.get_output_details(), key=lambda d: d["shape"][-1])
            self._detectors[name] = (interp, size, ssd_anchors(size, strides),
                                     interp.get_input_details()[0]["index"], outs[1]["index"], outs[0]["index"])
        self._mesh = interpreter("face_landmark.tflite", threads=threads)
        mesh_out = sorted(self._mesh.get_output_details(), key=lambda d: -int(np.prod(d["shape"])))
        self._mesh_io = (self._mesh.get_input_details()[0]["index"], mesh_out[0]["index"], mesh_out[1]["index"])
        self._iris = interpreter("iris_landmark.tflite", threads=threads) if irises else None
        if self._iris is not None:
            iris_out = {d["name"]: d["index"] for d in self._iris.get_output_details()}
            self._iris_io = (self._iris.get_input_details()[0]["index"], iris_out["output_iris"])
        self.timings = {"detection": 0.0, "landmarks": 0.0}

    def close(self) -> None:
        self._detectors.clear()
        self._mesh = self._iris = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    # ---------------------------------------------------------- detection

    def detect(self, image) -> list[Detection]:
        """Faces in ``image`` (PIL RGB or (H, W, 3) uint8), largest first."""
        import time

        image = _pil(image)
        t0 = time.perf_counter()
        # Both detectors: short range finds near faces, full range the small ones far away.
        found = []
        for name in DETECTORS:
            for det in self._detect_with(name, image):
                if all(_iou(det.box, other.box) < NMS_IOU for other in found):
                    found.append(det)
        self.timings["detection"] += time.perf_counter() - t0
        return sorted(found, key=lambda d: -d.area)

    def _detect_with(self, name: str, image) -> list[Detection]:
        interp, size, anchors, inp, box_out, score_out = self._detectors[name]
        w, h = image.size
        side = max(w, h)
        letterbox = Roi(w / 2, h / 2, side, 0.0)
        tensor = _affine_crop(image, letterbox, size) * 2.0 - 1.0
        interp.set_tensor(inp, tensor[None])
        interp.invoke()
        raw = interp.get_tensor(box_out)[0].reshape(len(anchors), -1, 2) / size
        scores = 1.0 / (1.0 + np.exp(-np.clip(interp.get_tensor(score_out)[0, :, 0], -80, 80)))
        keep = scores > MIN_DETECTION_SCORE
        if not keep.any():
            return []
        raw, scores, anch = raw[keep], scores[keep], anchors[keep]
        centre, extent = raw[:, 0] + anch, raw[:, 1]
        boxes = np.concatenate([centre - extent / 2, centre + extent / 2], axis=1)
        kps = raw[:, 2:] + anch[:, None, :]
        valid = (extent > 0).all(axis=1)
        out = []
        for box, kp, score in weighted_nms(boxes[valid], scores[valid], kps[valid], NMS_IOU):
            to_px = lambda p: (p - 0.5) * side + np.array([w / 2, h / 2])  # noqa: E731 — letterbox → pixels
            out.append(Detection(to_px(box.reshape(2, 2)).ravel(), to_px(kp), score))
        return out

    # ---------------------------------------------------------- landmarks

    def roi_from_detection(self, det: Detection) -> Roi:
        box = det.box.reshape(2, 2)
        return _roi_from_points(box, det.keypoints[0], det.keypoints[1], MESH_ROI_SCALE)

    def landmarks(self, image, roi: Roi) -> FaceLandmarks | None:
        """The face in ``roi``; None when Face Mesh says there is no face there."""
        import time

        image = _pil(image)
        t0 = time.perf_counter()
        inp, out_points, out_presence = self._mesh_io
        self._mesh.set_tensor(inp, _affine_crop(image, roi, MESH_SIZE)[None])
        self._mesh.invoke()
        presence = float(1.0 / (1.0 + math.exp(-float(np.clip(self._mesh.get_tensor(out_presence).ravel()[0], -80, 80)))))
        if presence < MIN_PRESENCE:
            self.timings["landmarks"] += time.perf_counter() - t0
            return None
        raw = self._mesh.get_tensor(out_points).reshape(-1, 3)[:468]
        points = roi.to_image(raw, MESH_SIZE)
        irises = self._irises(image, points) if self._iris is not None else np.full((2, 5, 2), np.nan)
        self.timings["landmarks"] += time.perf_counter() - t0
        return FaceLandmarks(points, irises, roi, presence)

    def _irises(self, image, points: np.ndarray) -> np.ndarray:
        inp, out = self._iris_io
        result = np.empty((2, 5, 2))
        for k, (side, (i, j)) in enumerate(EYE_CORNERS.items()):
            corners = points[[i, j], :2]
            roi = _roi_from_points(corners, corners[0], corners[1], IRIS_ROI_SCALE)
            flip = side == "left"  # the model was trained on one eye; the other is mirrored
            self._iris.set_tensor(inp, _affine_crop(image, roi, IRIS_SIZE, flip=flip)[None])
            self._iris.invoke()
            raw = self._iris.get_tensor(out).reshape(5, 3)
            if flip:
                raw[:, 0] = IRIS_SIZE - raw[:, 0]
            result[k] = roi.to_image(raw, IRIS_SIZE)[:, :2]
        return result

    def track_roi(self, face: FaceLandmarks) -> Roi:
        """The crop for the next video frame, from this frame's landmarks."""
        pts = face.points[:, :2]
        return _roi_from_points(pts, pts[TRACK_ROTATION[0]], pts[TRACK_ROTATION[1]], MESH_ROI_SCALE)

    def faces(self, image) -> list[FaceLandmarks]:
        """Every face found in ``image``, largest first."""
        image = _pil(image)
        found = []
        for det in self.detect(image):
            face = self.landmarks(image, self.roi_from_detection(det))
            if face is not None:
                found.append(face)
        return sorted(found, key=lambda f: -f.area)


def _iou(a: np.ndarray, b: np.ndarray) -> float:
    w = max(0.0, min(a[2], b[2]) - max(a[0], b[0]))
    h = max(0.0, min(a[3], b[3]) - max(a[1], b[1]))
    union = (a[2] - a[0]) * (a[3] - a[1]) + (b[2] - b[0]) * (b[3] - b[1]) - w * h
    return w * h / union if union > 0 else 0.0


def _pil(image):
    from PIL import Image

    if isinstance(image, Image.Image):
        return image if image.mode == "RGB" else image.convert("RGB")
    array = np.asarray(image)
    if array.ndim == 2:
        array = np.stack([array] * 3, axis=-1)
    if array.ndim != 3 or array.shape[2] not in (3, 4):
        raise ValueError(f"image must be (H, W, 3) RGB or (H, W, 4) RGBA, got shape {array.shape}")
    if array.dtype != np.uint8:
        array = np.clip(np.asarray(array, float) * (255.0 if array.max() <= 1.0 else 1.0), 0, 255).astype(np.uint8)
    return Image.fromarray(np.ascontiguousarray(array[..., :3]))
