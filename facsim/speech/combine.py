"""Speech with emotion: how speech AUs and other tracks' AUs share the face.

The rule (``speech_owns`` in ``facsim/data/visemes.yaml``): while speaking,
speech owns the AUs that set the lips' aperture and shape and the jaw (8, 10,
16-19, 22-28); other tracks' values of those AUs fade out in proportion to
``speaking`` (1 while talking, 0 at rest), so an emotion's own mouth returns in
pauses. Every other AU (lip corners 12-15 and 20, cheeks 6, nose 9/11, the
whole upper face, head and eyes) adds as tracks always do, clamped to 1: an
emotion keeps its smile, cheeks and brows while the mouth talks.

Examples
--------
>>> import numpy as np
>>> other = {(12, "left"): np.array([0.7, 0.7]), (25, "left"): np.array([0.7, 0.7])}
>>> speech = {(25, "left"): np.array([0.0, 0.2])}
>>> out = combine_curves(other, speech, np.array([0.0, 1.0]))
>>> out[(12, "left")].tolist(), out[(25, "left")].tolist()
([0.7, 0.7], [0.7, 0.2])
"""
from __future__ import annotations

from typing import Mapping

import numpy as np

from .visemes import viseme_table

Key = tuple[int, str]


def combine_curves(other: Mapping[Key, np.ndarray], speech: Mapping[Key, np.ndarray],
                   speaking: np.ndarray) -> dict[Key, np.ndarray]:
    """Other tracks' curves and speech curves (``(code, side)`` → levels), combined by the rule above."""
    owns = viseme_table().speech_owns
    out: dict[Key, np.ndarray] = {}
    for key, values in other.items():
        out[key] = values * (1.0 - speaking) if key[0] in owns else values.copy()
    for key, values in speech.items():
        out[key] = out[key] + values if key in out else values.copy()
    return {key: np.clip(values, 0.0, 1.0) for key, values in sorted(out.items())}
