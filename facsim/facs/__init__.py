"""FACS itself, as data: the Action Unit catalogue, notation, activations and emotion presets.

Pure Python over the tables in ``facsim/data/`` (no GL, no scipy): a FACS string
is parsed into an :class:`~facsim.facs.notation.Expression`, which becomes the
per-side :class:`~facsim.facs.activations.Activations` the engines consume.
"""
