"""Speaking characters: text or recorded speech → phones → visemes → AU curves, with audio.

Pipeline: :func:`synthesize` (flite, or Piper as a separate process) or
:func:`align_recording` (pocketsphinx) give an :class:`Utterance` (audio + phone
timings); :func:`speech_curves` turns its phones into AU curves through the viseme
table (``facsim/data/visemes.yaml``) with Cohen–Massaro coarticulation;
:func:`combine_curves` mixes them with an emotion's AUs; timelines carry them as
speech tracks, so videos, glTF and ARKit exports get them like any AU.
"""
from __future__ import annotations

_LAZY = {
    "Phone": "facsim.speech.utterance",
    "Utterance": "facsim.speech.utterance",
    "synthesize": "facsim.speech.synth",
    "voice_names": "facsim.speech.synth",
    "align_recording": "facsim.speech.align",
    "viseme_table": "facsim.speech.visemes",
    "speech_curves": "facsim.speech.coarticulation",
    "SpeechCurves": "facsim.speech.coarticulation",
    "combine_curves": "facsim.speech.combine",
    "mouth_shape": "facsim.speech.mouth",
    "MouthShape": "facsim.speech.mouth",
}

__all__ = sorted(_LAZY)


def __getattr__(name):
    if name in _LAZY:
        import importlib

        return getattr(importlib.import_module(_LAZY[name]), name)
    raise AttributeError(f"module 'facsim.speech' has no attribute {name!r}")
