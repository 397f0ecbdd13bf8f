"""The camera processor: images and video of real faces → FACS (Platt & Badler's first module).

Pipeline: :mod:`.models` (Face Mesh v1 files from a pinned wheel) → :mod:`.landmarks`
(BlazeFace → eye-aligned crop → 468 points + irises) → :mod:`.fit` (pose, gaze and AU
intensities against facsim's own AU basis, :mod:`.calibrate`, through the surface
binding of :mod:`.correspondence`) → :mod:`.processor` (the :class:`Analysis` result, files).
"""
from __future__ import annotations

__all__ = ["analyse", "Analysis", "FrameAnalysis", "AnalysisError"]


def __getattr__(name):
    if name in __all__:
        from . import processor as module

        return getattr(module, name)
    raise AttributeError(f"module 'facsim.analysis' has no attribute {name!r}")
