"""The few facsim internals the studio uses beyond the public API, in one place.

Module paths follow the package layout (``facsim.timeline.sampling``,
``facsim.media.video``, ...); each name falls back to its older module so
the studio works on either side of the layout change.
"""
from __future__ import annotations

from importlib import import_module
from pathlib import Path


def _first(name: str, *modules: str):
    import facsim

    home = Path(facsim.__file__).resolve().parent
    for module in modules:
        try:
            found = import_module(module)
            # An editable install elsewhere can shadow missing submodules: use only facsim's own files.
            if home not in Path(found.__file__).resolve().parents:
                continue
            return getattr(found, name)
        except (ImportError, AttributeError):
            continue
    raise ImportError(f"facsim.studio: cannot find {name} in {', '.join(modules)}")


def __getattr__(name: str):
    where = _WHERE.get(name)
    if where is None:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = _first(name, *where)
    globals()[name] = value
    return value


_WHERE = {
    "VideoWriter": ("facsim.media.video", "facsim.video"),
    "video_format": ("facsim.media.video", "facsim.video"),
    "sample_frames": ("facsim.timeline.sampling", "facsim.timeline"),
    "frame_times": ("facsim.timeline.sampling", "facsim.timeline"),
    "activation_curves": ("facsim.timeline.sampling", "facsim.timeline"),
    "TimelineError": ("facsim.timeline.model", "facsim.timeline"),
    "timeline_from_dict": ("facsim.timeline.io", "facsim.timeline_io"),
    "timeline_to_dict": ("facsim.timeline.io", "facsim.timeline_io"),
    "timeline_schema": ("facsim.timeline.io", "facsim.timeline_io"),
    "stimulus_timeline": ("facsim.timeline.builders", "facsim.timeline"),
    "catalogue": ("facsim.facs.catalogue", "facsim.catalogue"),
    "INTENSITY_TABLES": ("facsim.facs.catalogue", "facsim.catalogue"),
    "letter_of": ("facsim.facs.catalogue", "facsim.catalogue"),
    "ActionUnit": ("facsim.facs.notation", "facsim.notation"),
    "Expression": ("facsim.facs.notation", "facsim.notation"),
    "NotationError": ("facsim.facs.notation", "facsim.notation"),
    "parse_intensity": ("facsim.facs.notation", "facsim.notation"),
    "emotion": ("facsim.facs.emotions", "facsim.emotions"),
    "blend": ("facsim.facs.emotions", "facsim.emotions"),
    "emotion_names": ("facsim.facs.emotions", "facsim.emotions"),
    "preset_tables": ("facsim.facs.emotions", "facsim.emotions"),
    "Character": ("facsim.head.character", "facsim.character"),
    "CharacterError": ("facsim.head.character", "facsim.character"),
    "preset_names": ("facsim.head.character", "facsim.character"),
    "preset": ("facsim.head.character", "facsim.character"),
    "resolve_character": ("facsim.head.character", "facsim.character"),
    "slider_names": ("facsim.head.character", "facsim.character"),
    "ETHNICITIES": ("facsim.head.character", "facsim.character"),
    "load_face_data": ("facsim.head.assets", "facsim.assets"),
    "cache_dir": ("facsim.head.assets", "facsim.assets"),
    "EASINGS": ("facsim.timeline.easing", "facsim.easing"),
    "VIEWS": ("facsim.render.camera", "facsim.camera"),
    "hex_to_rgb": ("facsim.head.appearance", "facsim.appearance"),
    "register_table": ("facsim.engines.registers", "facsim.registers"),
    "simulated_codes": ("facsim.engines.registers", "facsim.registers"),
}
