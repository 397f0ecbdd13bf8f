"""Stimulus sets: one spec → a labelled, counterbalanced set of stills, videos and glb files.

The pipeline: a YAML spec (:mod:`facsim.batch.spec`, checked against
``facsim/data/stimulus_set.schema.json``) → a deterministic list of items
(:mod:`facsim.batch.items`, a pure function) → files rendered in a process
pool or on Dask (:mod:`facsim.batch.work`, :mod:`facsim.batch.run`) → the
journal and the manifest (:mod:`facsim.batch.manifest`).

Examples
--------
>>> from facsim.batch import load_spec, expand, run_batch      # doctest: +SKIP
>>> spec = load_spec("examples/quick_set.yaml")                # doctest: +SKIP
>>> run_batch(spec, "set/", workers=2)                          # doctest: +SKIP
"""
from __future__ import annotations

_LAZY = {
    "load_spec": "facsim.batch.spec", "spec_from_dict": "facsim.batch.spec", "SpecError": "facsim.batch.spec",
    "StimulusSet": "facsim.batch.spec", "expand": "facsim.batch.items", "Item": "facsim.batch.items",
    "run_batch": "facsim.batch.run", "BatchError": "facsim.batch.run", "BatchResult": "facsim.batch.run",
}

__all__ = sorted(_LAZY)


def __getattr__(name):
    if name in _LAZY:
        import importlib

        return getattr(importlib.import_module(_LAZY[name]), name)
    raise AttributeError(f"module 'facsim.batch' has no attribute {name!r}")
