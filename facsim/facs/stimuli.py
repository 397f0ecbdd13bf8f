"""Published stimulus designs as data: HapFACS 3.0's validation AUs and combinations.

The batch renderer (``aus: hapfacs``, ``combinations: hapfacs``) and ``facsim validate``
read the same table, ``facsim/data/hapfacs_stimuli.yaml``.
"""
from __future__ import annotations

from facsim._data import load_yaml, require

HAPFACS_TABLE = "hapfacs_stimuli.yaml"


def hapfacs_stimuli() -> dict:
    """HapFACS 3.0's validation stimuli (``facsim/data/hapfacs_stimuli.yaml``):
    ``{"single_aus": [49 codes], "combinations": [54 FACS strings]}``.

    Examples
    --------
    >>> t = hapfacs_stimuli()
    >>> len(t["single_aus"]), t["combinations"][:3]
    (49, ['1+2', '1+4', '1+2+4'])
    """
    data = load_yaml(HAPFACS_TABLE)
    codes = [code for group in require(data, HAPFACS_TABLE, "single_aus").values() for code in group]
    return {"single_aus": codes, "combinations": list(require(data, HAPFACS_TABLE, "combinations", list))}
