"""Limits of a loop's signals as ``(lower, upper)`` arrays of deviations: a user's pair checked and broadcast, and the
end stops of a plant's angle outputs.
"""

from __future__ import annotations

import numpy as np

from trms.control._checks import real_array
from trms.errors import InputError
from trms.plant import Plant
from trms.rigdata import end_stops

__all__ = ["limit_pair", "output_stop_limits"]


def limit_pair(name: str, value: tuple[object, object] | None, size: int) -> tuple[np.ndarray, np.ndarray]:
    """``(lower, upper)`` limits, each a scalar or ``(size,)`` (``+-inf`` allowed), as two ``(size,)`` arrays;
    ``+-inf`` for ``None``.

    Raises
    ------
    InputError
        Not a pair, a side of the wrong size, NaN or text.

    Examples
    --------
    >>> [v.tolist() for v in limit_pair("input_limits", (-1.0, [2.0, 3.0]), 2)]
    [[-1.0, -1.0], [2.0, 3.0]]
    >>> limit_pair("input_limits", (-1.0, [2.0, 3.0, 4.0]), 2)
    Traceback (most recent call last):
    ...
    trms.errors.InputError: input_limits upper must be a scalar or have shape (2,), got shape (3,)
    """
    if value is None:
        return np.full(size, -np.inf), np.full(size, np.inf)
    if not isinstance(value, (tuple, list)) or len(value) != 2:
        raise InputError(f"{name} must be a pair (lower, upper), got {value!r}")
    sides = []
    for side, v in zip(("lower", "upper"), value):
        arr = real_array(f"{name} {side}", v, infinite=True)
        if arr.size not in (1, size) or arr.ndim > 1:
            raise InputError(f"{name} {side} must be a scalar or have shape ({size},), got shape {arr.shape}")
        sides.append(np.broadcast_to(arr.ravel(), (size,)).astype(float))
    return sides[0], sides[1]


def output_stop_limits(plant: Plant) -> tuple[np.ndarray, np.ndarray]:
    """The end stops of a plant's angle outputs as deviations from its trim (rad); ``+-inf`` for other outputs.

    The stops are the joint ranges of the twin's model (:func:`trms.rigdata.end_stops`), by output name.

    Examples
    --------
    >>> from trms.worlds import make_plant
    >>> lo, hi = output_stop_limits(make_plant("linear", "1dof"))
    >>> float(lo[0]), float(hi[0])
    (-1.1, 1.1)
    """
    stops = end_stops()
    op = plant.operating_point
    names = op.output_names
    hi = np.array([stops.get(n, np.inf) for n in names])
    return op.output_deviation(-hi), op.output_deviation(hi)
