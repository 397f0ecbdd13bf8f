"""The package's data tables (``facsim/data/``): one loader for all of them.

Every table is read once per process (cached) with libyaml's safe loader when
present. A table that is missing, unreadable or not of the expected shape
raises :class:`DataError` naming the file and the entry, e.g.
``registers.yaml, action_units: expected a mapping``.

Examples
--------
>>> sorted(load_yaml("rigid.yaml"))[:2]
['eye_rotations', 'head_motions']
>>> require(load_yaml("rigid.yaml"), "rigid.yaml", "neck_blend", dict)["full_above"]
0.4
"""
from __future__ import annotations

from functools import lru_cache
from importlib import resources


class DataError(ValueError):
    """A package data table is missing or malformed (a packaging or editing mistake)."""


def read_text(name: str) -> str:
    """The text of ``facsim/data/NAME``."""
    try:
        return resources.files("facsim").joinpath("data", name).read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise DataError(f"{name}: cannot be read ({exc})") from None


@lru_cache(maxsize=None)
def load_yaml(name: str):
    """``facsim/data/NAME`` parsed (cached; treat the result as read-only)."""
    import yaml

    try:
        return yaml.load(read_text(name), Loader=getattr(yaml, "CSafeLoader", yaml.SafeLoader))
    except yaml.YAMLError as exc:
        raise DataError(f"{name}: not valid YAML ({' '.join(str(exc).split())})") from None


def require(table, name: str, key: str, kind: type = dict):
    """``table[key]``, checked to be a ``kind``; a DataError naming ``name`` and ``key`` otherwise."""
    if not isinstance(table, dict) or key not in table:
        raise DataError(f"{name}: missing the entry {key!r}")
    value = table[key]
    if not isinstance(value, kind):
        raise DataError(f"{name}, {key}: expected a {kind.__name__}, got {type(value).__name__}")
    return value


@lru_cache(maxsize=None)
def load_arrays(name: str) -> dict:
    """``facsim/data/NAME`` (an ``.npz``) as a dict of read-only arrays (cached)."""
    import numpy as np

    try:
        with resources.files("facsim").joinpath("data", name).open("rb") as f, np.load(f, allow_pickle=False) as z:
            arrays = {k: z[k] for k in z.files}
    except (OSError, ValueError) as exc:
        raise DataError(f"{name}: cannot be read ({exc})") from None
    for array in arrays.values():
        array.setflags(write=False)
    return arrays
