"""Easing curves: how a timeline segment moves from its start to its end level.

Each easing maps progress ``u`` in [0, 1] (the fraction of the segment's time
that has passed) to the fraction of the way from the start level to the end
level, with ``f(0) = 0`` and ``f(1) = 1``, never decreasing in between. The
functions take and return numpy arrays (scalars work too); input outside
[0, 1] is clipped.

HapFACS 3.0 only changed intensities linearly; the others give the eased
onsets and offsets that real facial actions show.

======================  ==========================================  ========
name                    curve                                       f(0.5)
======================  ==========================================  ========
``linear``              ``u``                                       0.5
``ease-in``             ``u**2`` (slow start)                       0.25
``ease-out``            ``1 - (1 - u)**2`` (slow end)               0.75
``smoothstep``          ``3u**2 - 2u**3`` (slow start and end)      0.5
``sigmoid``             logistic, steepness 10, rescaled to [0, 1]  0.5
======================  ==========================================  ========

Examples
--------
>>> import numpy as np
>>> u = np.array([0.0, 0.5, 1.0])
>>> EASINGS["ease-in"](u)
array([0.  , 0.25, 1.  ])
>>> float(ease("smoothstep", 0.25))
0.15625
>>> sorted(EASINGS)
['ease-in', 'ease-out', 'linear', 'sigmoid', 'smoothstep']
"""
from __future__ import annotations

from types import MappingProxyType
from typing import Callable, Mapping

import numpy as np

#: Steepness of :func:`sigmoid` (the logistic's slope parameter over [0, 1]).
SIGMOID_STEEPNESS = 10.0


def _progress(u) -> np.ndarray:
    return np.clip(np.asarray(u, dtype=float), 0.0, 1.0)


def linear(u) -> np.ndarray:
    """Constant speed: ``f(u) = u`` (HapFACS's only curve).

    >>> linear([0.0, 0.25, 2.0])
    array([0.  , 0.25, 1.  ])
    """
    return _progress(u)


def ease_in(u) -> np.ndarray:
    """Quadratic, slow start and fast end: ``f(u) = u**2``.

    >>> ease_in([0.0, 0.5, 1.0])
    array([0.  , 0.25, 1.  ])
    """
    u = _progress(u)
    return u * u


def ease_out(u) -> np.ndarray:
    """Quadratic, fast start and slow end: ``f(u) = 1 - (1 - u)**2``.

    >>> ease_out([0.0, 0.5, 1.0])
    array([0.  , 0.75, 1.  ])
    """
    v = 1.0 - _progress(u)
    return 1.0 - v * v


def smoothstep(u) -> np.ndarray:
    """Cubic Hermite, slow start and end: ``f(u) = 3u**2 - 2u**3``.

    >>> smoothstep([0.0, 0.5, 1.0])
    array([0. , 0.5, 1. ])
    """
    u = _progress(u)
    return u * u * (3.0 - 2.0 * u)


def sigmoid(u) -> np.ndarray:
    """Logistic S-curve of steepness :data:`SIGMOID_STEEPNESS`, rescaled so that
    ``f(0) = 0`` and ``f(1) = 1`` exactly; flatter ends than :func:`smoothstep`.

    >>> np.round(sigmoid([0.0, 0.5, 1.0]), 12)
    array([0. , 0.5, 1. ])
    """
    u = _progress(u)
    k = SIGMOID_STEEPNESS
    logistic = 1.0 / (1.0 + np.exp(-k * (u - 0.5)))
    low = 1.0 / (1.0 + np.exp(k / 2.0))
    return np.clip((logistic - low) / (1.0 - 2.0 * low), 0.0, 1.0)


#: Easing name (as written in timeline files) → function.
EASINGS: Mapping[str, Callable[[np.ndarray], np.ndarray]] = MappingProxyType({
    "linear": linear,
    "ease-in": ease_in,
    "ease-out": ease_out,
    "smoothstep": smoothstep,
    "sigmoid": sigmoid,
})


def get_easing(name: str) -> Callable[[np.ndarray], np.ndarray]:
    """The easing function called ``name``.

    Raises
    ------
    ValueError
        If there is no such easing; the message lists the known names.

    Examples
    --------
    >>> get_easing("linear") is linear
    True
    >>> get_easing("bounce")
    Traceback (most recent call last):
    ...
    ValueError: unknown easing 'bounce'; choose one of linear, ease-in, ease-out, smoothstep, sigmoid
    """
    try:
        return EASINGS[name]
    except (KeyError, TypeError):
        raise ValueError(f"unknown easing {name!r}; choose one of {', '.join(EASINGS)}") from None


def ease(name: str, u) -> np.ndarray:
    """Apply the easing called ``name`` to progress ``u`` (see :func:`get_easing`)."""
    return get_easing(name)(u)
