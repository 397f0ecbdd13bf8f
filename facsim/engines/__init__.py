"""Deformation engines: Activations in, a :class:`~facsim.engines.base.Deformation` out.

``ENGINES`` is the one table of engines: adding an engine is one module that
implements :class:`~facsim.engines.base.Engine` and one row here. Modules are
imported on first use, so naming the engines costs nothing.

- ``registers``: HapFACS-style morph-target registers combined by Eq. 1.
- ``muscle``: Platt & Badler's tension net moved by muscles.

Both use :mod:`facsim.engines.rigid` for the head (51–58) and eyes (61–66).

Examples
--------
>>> sorted(ENGINES)
['muscle', 'registers']
>>> 12 in simulated_codes("muscle")
True
"""
from __future__ import annotations

from importlib import import_module

#: name → (module, engine class). The first is the default.
ENGINES = {
    "registers": ("facsim.engines.registers", "RegisterEngine"),
    "muscle": ("facsim.engines.muscle", "MuscleEngine"),
}
DEFAULT_ENGINE = "registers"


def _module(name: str):
    if name not in ENGINES:
        raise ValueError(f"unknown engine {name!r}; choose from {', '.join(ENGINES)}")
    return import_module(ENGINES[name][0])


def engine_class(name: str):
    """The engine class called ``name`` (its module is imported now)."""
    return getattr(_module(name), ENGINES[name][1])


def simulated_codes(name: str) -> set[int]:
    """The AU codes engine ``name`` simulates."""
    return _module(name).simulated_codes()


def coverage(name: str) -> dict[int, str]:
    """For each AU code engine ``name`` does not simulate, the reason."""
    return _module(name).coverage()
