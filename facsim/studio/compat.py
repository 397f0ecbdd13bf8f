"""The facsim internals the studio uses beyond the public API, in one table.

Names are imported on first use (so importing the studio stays light), each
from the module that defines it (``facsim.timeline.sampling``, ...).
"""
from __future__ import annotations

from importlib import import_module


def __getattr__(name: str):
    where = _WHERE.get(name)
    if where is None:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(import_module(where), name)
    globals()[name] = value
    return value


_WHERE = {
    "frame_times": "facsim.timeline.sampling",
    "activation_curves": "facsim.timeline.sampling",
    "TimelineError": "facsim.timeline.model",
    "Track": "facsim.timeline.model",
    "voice_names": "facsim.speech.synth",
    "timeline_from_dict": "facsim.timeline.io",
    "timeline_to_dict": "facsim.timeline.io",
    "timeline_schema": "facsim.timeline.io",
    "stimulus_timeline": "facsim.timeline.builders",
    "catalogue": "facsim.facs.catalogue",
    "INTENSITY_TABLES": "facsim.facs.catalogue",
    "letter_of": "facsim.facs.catalogue",
    "ActionUnit": "facsim.facs.notation",
    "Expression": "facsim.facs.notation",
    "NotationError": "facsim.facs.notation",
    "parse_intensity": "facsim.facs.notation",
    "emotion": "facsim.facs.emotions",
    "blend": "facsim.facs.emotions",
    "emotion_names": "facsim.facs.emotions",
    "preset_tables": "facsim.facs.emotions",
    "DEFAULT_TABLE": "facsim.facs.emotions",
    "Character": "facsim.head.character",
    "CharacterError": "facsim.head.character",
    "preset_names": "facsim.head.character",
    "preset": "facsim.head.character",
    "resolve_character": "facsim.head.character",
    "slider_names": "facsim.head.character",
    "ETHNICITIES": "facsim.head.character",
    "load_face_data": "facsim.head.assets",
    "cache_dir": "facsim.head.assets",
    "ENGINES": "facsim.engines",
    "DEFAULT_ENGINE": "facsim.engines",
    "EASINGS": "facsim.timeline.easing",
    "VIEWS": "facsim.render.camera",
    "DEFAULT_BODY": "facsim.render.options",
    "body_styles": "facsim.head.body",
    "hex_to_rgb": "facsim.head.colour",
    "rigid_table": "facsim.engines.rigid",
    "register_table": "facsim.engines.registers",
    "simulated_codes": "facsim.engines.registers",
}
