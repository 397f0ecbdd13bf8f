"""facsim: FACS notation → expression → activations → deformation → frames.

>>> import facsim
>>> facsim.parse("1+2+5B+26").codes == {1, 2, 5, 26}
True
"""
from __future__ import annotations

__version__ = "0.1.0"

#: Public names, imported on first use so ``import facsim`` stays light (no GL, no data).
_LAZY = {
    "Face": "facsim.face",
    "parse": "facsim.facs.notation",
    "format_expression": "facsim.facs.notation",
    "Expression": "facsim.facs.notation",
    "NotationError": "facsim.facs.notation",
    "activations": "facsim.facs.activations",
    "Activations": "facsim.facs.activations",
    "emotion": "facsim.facs.emotions",
    "Character": "facsim.head.character",
    "load_timeline": "facsim.timeline.io",
    "stimulus_timeline": "facsim.timeline.builders",
    "animate": "facsim.pipeline",
    "analyse": "facsim.analysis.processor",
    "Analysis": "facsim.analysis.processor",
}

__all__ = sorted(_LAZY)


def __getattr__(name):
    if name in _LAZY:
        import importlib

        return getattr(importlib.import_module(_LAZY[name]), name)
    raise AttributeError(f"module 'facsim' has no attribute {name!r}")
