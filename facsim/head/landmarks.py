"""Named facial landmarks as head-model vertex indices (data: ``data/landmarks.yaml``).

Examples
--------
>>> from facsim.face import load_head             # doctest: +SKIP
>>> marks = landmarks(load_head())                # doctest: +SKIP
>>> sorted(marks)[:3]                             # doctest: +SKIP
['cheek_left', 'cheek_right', 'chin']
"""
from __future__ import annotations

from functools import lru_cache
from importlib import resources

import numpy as np
import yaml


@lru_cache(maxsize=4)
def landmarks(head) -> dict[str, int]:
    """Landmark name → geometry vertex index; sided names end in ``_left``/``_right``."""
    table = yaml.safe_load(resources.files("facsim").joinpath("data/landmarks.yaml").read_text())
    skin = head.base_vertices[head.base_index[: head.skin_vertex_count]]

    def nearest(point) -> int:
        return int(np.argmin(((skin - np.asarray(point, float)) ** 2).sum(axis=1)))

    marks = {name: nearest(p) for name, p in table["midline"].items()}
    for name, p in table["sided"].items():
        left = nearest(p)
        marks[f"{name}_left"] = left
        marks[f"{name}_right"] = int(head.mirror[left])
    return marks
