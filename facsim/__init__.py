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
    "parse": "facsim.notation",
    "format_expression": "facsim.notation",
    "Expression": "facsim.notation",
    "NotationError": "facsim.notation",
    "activations": "facsim.expression",
    "Activations": "facsim.expression",
    "emotion": "facsim.emotions",
    "Character": "facsim.character",
    "load_timeline": "facsim.timeline_io",
    "stimulus_timeline": "facsim.timeline",
    "animate": "facsim.video",
}

__all__ = sorted(_LAZY)


def __getattr__(name):
    if name in _LAZY:
        import importlib

        return getattr(importlib.import_module(_LAZY[name]), name)
    raise AttributeError(f"module 'facsim' has no attribute {name!r}")
