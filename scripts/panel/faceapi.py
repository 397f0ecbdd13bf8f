"""A second photo-trained rater: face-api.js's FaceExpressionNet, run in numpy.

The weights (``face_expression_model.bin``, 330 kB, uint8-quantised, with its
``-weights_manifest.json``) ship inside the npm tarball ``@vladmandic/face-api``
1.7.15 (MIT, Vladimir Mandic; the network and weights are Vincent Mühler's
face-api.js, MIT, "trained on a variety of images from publicly available
datasets as well as images scraped from the web"). facsim runs no JavaScript:
the tarball is fetched once at that version, checked against the registry's
sha512 ``dist.integrity``, and the two model files are copied into
``<cache>/face-api-1.7.15/``. ``$FACSIM_FACEAPI_TARBALL`` points at a local copy.

The network is small enough for numpy (~0.1 GFLOP): four dense blocks of
depthwise-separable 3×3 convolutions (112² RGB → 7² × 256), a 7² average pool,
one fully connected layer, softmax. :func:`forward` follows face-api.js's
``FaceFeatureExtractor.forwardInput`` / ``FaceExpressionNet.forwardInput`` op by op
(TensorFlow "same" padding; tfjs 1.x ``resizeBilinear`` without half-pixel
centres); it was checked against face-api.js 0.22.2 on tfjs-core 1.7.0 (see README).

Labels: neutral, happy, sad, angry, fearful, disgusted, surprised.
"""
from __future__ import annotations

import io
import json
import os
import tarfile
import urllib.request
from pathlib import Path

import numpy as np
from rater import (  # the sibling module in scripts/panel
    CROP_GRID,
    RaterError,
    Reading,
    haar_like_box,
)

from facsim.atomic import atomic_write
from facsim.wheel import sri_digest

VERSION = "1.7.15"
TARBALL = f"https://registry.npmjs.org/@vladmandic/face-api/-/face-api-{VERSION}.tgz"
#: ``npm view @vladmandic/face-api@1.7.15 dist.integrity``.
INTEGRITY = "sha512-WDMmK3CfNLo8jylWqMoQgf4nIst3M0fzx1dnac96wv/dvMTN4DxC/Pq1DGtduDk1lktCamQ3MIDXFnvrdHTXDw=="
MEMBERS = ("package/model/face_expression_model-weights_manifest.json", "package/model/face_expression_model.bin")
CACHE_FOLDER = f"face-api-{VERSION}"
ENV = "FACSIM_FACEAPI_TARBALL"
LABELS = ("neutral", "happy", "sad", "angry", "fearful", "disgusted", "surprised")
#: face-api.js labels → the FER2013 names the panel reports in.
AS_FER = {"neutral": "neutral", "happy": "happy", "sad": "sad", "angry": "angry", "fearful": "fear",
          "disgusted": "disgust", "surprised": "surprise"}
INPUT_SIZE = 112
MEAN_RGB = np.array([122.782, 117.001, 104.298], np.float32)


class FaceApiError(RaterError):
    """The model could not be fetched, checked or read; the message says how to fix it."""


def model_dir() -> Path:
    from facsim.head.assets import cache_dir

    return cache_dir() / CACHE_FOLDER


def install_model(*, tarball=None) -> Path:
    """Fetch and check the npm tarball, then write the manifest and weights into the cache."""
    source = tarball or os.environ.get(ENV)
    if source:
        data = Path(source).read_bytes()
    else:
        try:
            with urllib.request.urlopen(TARBALL, timeout=120) as response:
                data = response.read()
        except OSError as exc:
            raise FaceApiError(f"could not download {TARBALL} ({exc}); on an offline machine fetch it elsewhere "
                               f"(`npm pack @vladmandic/face-api@{VERSION}`) and set {ENV}=/path/to/it") from None
    algorithm = INTEGRITY.partition("-")[0]
    if sri_digest(data, algorithm) != INTEGRITY:
        raise FaceApiError(f"face-api-{VERSION}.tgz failed its {algorithm} check; the file is corrupt or not "
                           f"@vladmandic/face-api {VERSION} — download it again")
    folder = model_dir()
    folder.mkdir(parents=True, exist_ok=True)
    with tarfile.open(fileobj=io.BytesIO(data), mode="r:gz") as archive:
        for member in MEMBERS:
            blob = archive.extractfile(member).read()
            atomic_write(folder / Path(member).name, lambda tmp, blob=blob: tmp.write_bytes(blob))
    return folder


def load_weights(*, fetch: bool = True) -> dict[str, np.ndarray]:
    """The named float32 weights, dequantised as tfjs's ``io.decodeWeights`` does (q · scale + min)."""
    folder = model_dir()
    manifest_path = folder / Path(MEMBERS[0]).name
    if not manifest_path.exists():
        if not fetch:
            raise FaceApiError(f"{manifest_path} is missing; run `python scripts/panel/faceapi.py` to fetch it")
        install_model()
    groups = json.loads(manifest_path.read_text())
    weights = {}
    for group in groups:
        blob = b"".join((folder / path).read_bytes() for path in group["paths"])
        offset = 0
        for spec in group["weights"]:
            count = int(np.prod(spec["shape"])) if spec["shape"] else 1
            quant = spec.get("quantization")
            if quant:
                dtype = np.dtype(quant["dtype"])
                raw = np.frombuffer(blob, dtype, count, offset)
                values = raw.astype(np.float32) * np.float32(quant["scale"]) + np.float32(quant["min"])
            else:
                dtype = np.dtype(spec["dtype"])
                values = np.frombuffer(blob, dtype, count, offset).astype(np.float32)
            offset += count * dtype.itemsize
            weights[spec["name"]] = values.reshape(spec["shape"])
    if offset != len(blob):
        raise FaceApiError(f"{folder}: the weights file has {len(blob)} bytes, the manifest describes {offset}")
    return weights


# ------------------------------------------------------------------ the network in numpy (NHWC batches)

def _same_pad(x: np.ndarray, stride: int) -> np.ndarray:
    """TensorFlow "same" padding of (N, H, W, C) for a 3×3 kernel: the odd pixel goes after."""
    pads = [(0, 0)]
    for n in x.shape[1:3]:
        out = -(-n // stride)
        total = max((out - 1) * stride + 3 - n, 0)
        pads.append((total // 2, total - total // 2))
    return np.pad(x, (*pads, (0, 0)))


def _taps(x: np.ndarray, stride: int):
    """The nine (i, j, shifted input) taps of a 3×3 "same" convolution at ``stride``, each (N, H', W', C)."""
    p = _same_pad(x, stride)
    h, w = -(-x.shape[1] // stride), -(-x.shape[2] // stride)
    for i in range(3):
        for j in range(3):
            yield i, j, p[:, i: i + (h - 1) * stride + 1: stride, j: j + (w - 1) * stride + 1: stride]


def conv3x3(x: np.ndarray, filters: np.ndarray, stride: int) -> np.ndarray:
    """``tf.conv2d(x, filters [3, 3, Cin, Cout], stride, 'same')``."""
    return sum(tap @ filters[i, j] for i, j, tap in _taps(x, stride))


def separable_conv(x: np.ndarray, depthwise: np.ndarray, pointwise: np.ndarray, bias: np.ndarray,
                   stride: int) -> np.ndarray:
    """``tf.separableConv2d(x, depthwise [3,3,C,1], pointwise [1,1,C,O], stride, 'same') + bias``."""
    depth = sum(tap * depthwise[i, j, :, 0] for i, j, tap in _taps(x, stride))
    return depth @ pointwise[0, 0] + bias


def dense_block(x: np.ndarray, w: dict, name: str, *, first: bool) -> np.ndarray:
    """face-api.js ``denseBlock4``: each conv sees the sum of all earlier outputs of the block."""
    relu = lambda v: np.maximum(v, 0)
    if first:
        out1 = relu(conv3x3(x, w[f"{name}/conv0/filters"], 2) + w[f"{name}/conv0/bias"])
    else:
        out1 = relu(separable_conv(x, *(w[f"{name}/conv0/{k}"] for k in ("depthwise_filter", "pointwise_filter",
                                                                          "bias")), 2))
    conv = lambda v, i: separable_conv(v, w[f"{name}/conv{i}/depthwise_filter"],
                                       w[f"{name}/conv{i}/pointwise_filter"], w[f"{name}/conv{i}/bias"], 1)
    out2 = conv(out1, 1)
    out3 = conv(relu(out1 + out2), 2)
    out4 = conv(relu(out1 + out2 + out3), 3)
    return relu(out1 + out2 + out3 + out4)


def forward(images: np.ndarray, w: dict) -> np.ndarray:
    """(N, 112, 112, 3) or (112, 112, 3) RGB in 0–255 → (N, 7) or (7,) probabilities (order of :data:`LABELS`)."""
    x = np.asarray(images, np.float32)
    single = x.ndim == 3
    x = (x[None] if single else x) - MEAN_RGB
    x = x / np.float32(255.0)
    for i in range(4):
        x = dense_block(x, w, f"dense{i}", first=i == 0)
    features = x.mean(axis=(1, 2))                       # avgPool 7×7 'valid' on a 7×7 map
    logits = features @ w["fc/weights"] + w["fc/bias"]
    e = np.exp(logits - logits.max(axis=1, keepdims=True))
    probs = e / e.sum(axis=1, keepdims=True)
    return probs[0] if single else probs


def resize_tfjs(rgb: np.ndarray, size: int) -> np.ndarray:
    """tfjs 1.x ``image.resizeBilinear(x, [size, size])`` (no corner alignment, no half-pixel centres)."""
    h, w = rgb.shape[:2]

    def axis(n_in):
        x = np.arange(size) * (n_in / size)
        i0 = np.minimum(np.floor(x).astype(int), n_in - 1)
        i1 = np.minimum(i0 + 1, n_in - 1)
        return i0, i1, (x - i0).astype(np.float32)

    y0, y1, fy = axis(h)
    x0, x1, fx = axis(w)
    img = rgb.astype(np.float32)
    top = img[y0][:, x0] * (1 - fx)[:, None] + img[y0][:, x1] * fx[:, None]
    bottom = img[y1][:, x0] * (1 - fx)[:, None] + img[y1][:, x1] * fx[:, None]
    return top * (1 - fy)[:, None, None] + bottom * fy[:, None, None]


def face_input(rgb: np.ndarray, box) -> np.ndarray:
    """face-api.js's face crop: the box clipped to the image, padded square (centred, black), resized to 112²."""
    x0, y0, x1, y1 = (int(np.round(v)) for v in box)
    h, w = rgb.shape[:2]
    x0, y0, x1, y1 = max(0, x0), max(0, y0), min(w, x1), min(h, y1)
    if x1 <= x0 or y1 <= y0:
        raise ValueError(f"face box {box} lies outside the {w}x{h} image")
    crop = rgb[y0:y1, x0:x1, :3]
    ch, cw = crop.shape[:2]
    side = max(ch, cw)
    pad_y, pad_x = side - ch, side - cw
    crop = np.pad(crop, ((pad_y // 2, pad_y - pad_y // 2), (pad_x // 2, pad_x - pad_x // 2), (0, 0)))
    return resize_tfjs(crop, INPUT_SIZE)


class FaceApiRater:
    """face-api.js FaceExpressionNet on a face box; scores under FER2013's label names."""

    name = "faceapi"
    title = "face-api.js FaceExpressionNet (npm @vladmandic/face-api 1.7.15)"

    def __init__(self, *, fetch: bool = True):
        self._weights = load_weights(fetch=fetch)

    def close(self) -> None:
        self._weights = None

    def rate_face(self, rgb: np.ndarray, box, *, grid: bool = False) -> Reading:
        """The reading of the face in BlazeFace ``box`` (the box squared; ``grid`` adds the variants' labels)."""
        boxes = [haar_like_box(box, shift=(0.0, 0.0))]
        if grid:
            boxes += [haar_like_box(box, shift=shift, scale=scale) for shift, scale in CROP_GRID]
        corners = [(x, y, x + w, y + h) for x, y, w, h in boxes]
        probs = forward(np.stack([face_input(rgb, c) for c in corners]), self._weights)
        names = [AS_FER[label] for label in LABELS]
        return Reading(dict(zip(names, (float(p) for p in probs[0]))), corners[0],
                       tuple(names[int(np.argmax(p))] for p in probs[1:]))


    def rate_square(self, rgb: np.ndarray) -> str:
        """The label of an already cropped square face image ((S, S, 3) uint8)."""
        probs = forward(resize_tfjs(rgb, INPUT_SIZE), self._weights)
        return AS_FER[LABELS[int(np.argmax(probs))]]


def main() -> None:
    """``python scripts/panel/faceapi.py [TARBALL]``: fetch the tarball and extract the model."""
    import sys

    try:
        folder = install_model(tarball=sys.argv[1] if len(sys.argv) > 1 else None)
    except FaceApiError as exc:
        sys.exit(f"facsim panel: {exc}")
    print(f"face-api.js expression model in {folder}")


if __name__ == "__main__":
    main()
