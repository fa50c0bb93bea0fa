"""Argument checks shared by the control toolkit, on top of :mod:`trms.errors`.

:func:`trms.errors.as_finite_array` refuses text, complex numbers, ragged nesting and NaN/inf; the
designers here also refuse ``None`` and booleans (``R=True`` is a slip, not a weight of 1), may
allow infinite entries (unlimited actuators), and take index lists that must be integers.
"""

from __future__ import annotations

from collections.abc import Sequence

import control
import numpy as np

from trms.errors import InputError, as_finite_array, short_repr

__all__ = ["real_array", "real_vector", "index_tuple", "positive_count", "finite_system", "is_discrete_dt"]


def real_array(
    name: str, value: object, shape: Sequence[int | None] | None = None, *, infinite: bool = False
) -> np.ndarray:
    """``value`` as a float array of real numbers, refusing ``None``, booleans, text, complex and NaN.

    Parameters
    ----------
    name : str
        Argument name for the message.
    value : array_like
        The value to check.
    shape : sequence of int or None, optional
        Expected shape (``None`` entries accept any length).
    infinite : bool
        Accept ``+-inf`` entries (NaN is always refused).

    Returns
    -------
    numpy.ndarray
        A new float array.

    Raises
    ------
    InputError
        One line naming the value and what is allowed.

    Examples
    --------
    >>> real_array("R", 75)
    array(75.)
    >>> real_array("R", True)
    Traceback (most recent call last):
    ...
    trms.errors.InputError: R must be real numbers (float64), got True: booleans are not numbers here
    """
    kind: str = ""  # ragged when it stays empty: as_finite_array names it
    try:
        kind = np.asarray(value).dtype.kind
    except (TypeError, ValueError):
        pass
    if value is None or kind == "b":
        what = "None is not a number" if value is None else "booleans are not numbers here"
        raise InputError(f"{name} must be real numbers (float64), got {short_repr(value)}: {what}")
    if not infinite or kind in "USVc" or kind == "":
        return as_finite_array(name, value, shape)
    try:
        arr = np.array(value, dtype=float)
    except (TypeError, ValueError, OverflowError):
        return as_finite_array(name, value, shape)  # raises its one-line reason
    if np.isnan(arr).any():
        first = tuple(int(i) for i in np.argwhere(np.isnan(arr))[0])
        raise InputError(f"{name} must be numbers or +-inf, not NaN; found nan at index {first}")
    as_finite_array(name, np.where(np.isinf(arr), 0.0, arr), shape)  # the shape
    return arr


def real_vector(name: str, value: object, size: int) -> np.ndarray:
    """``value`` (a number, a list, a column...) as ``size`` real, finite numbers, flattened; else one line.

    Examples
    --------
    >>> real_vector("reference", [[0.1]], 1)
    array([0.1])
    >>> real_vector("reference", "a", 1)
    Traceback (most recent call last):
    ...
    trms.errors.InputError: reference must be real numbers (float64), got 'a': text values are not allowed
    """
    arr = real_array(name, value).ravel()
    if arr.size != size:
        raise InputError(f"{name} must be {size} number{'s' if size != 1 else ''}, got {arr.size}")
    return arr


def index_tuple(name: str, value: object, size: int, what: str = "indices") -> tuple[int, ...]:
    """Distinct integer indices into ``range(size)``, from a sequence (not text, not booleans, not floats).

    Parameters
    ----------
    name : str
        Argument name for the message.
    value : sequence of int
        The indices.
    size : int
        Number of items indexed.
    what : str
        What the indices point at, for the message (e.g. ``"state indices"``).

    Returns
    -------
    tuple of int

    Raises
    ------
    InputError
        Not a non-empty sequence of distinct integers in ``[0, size - 1]``.

    Examples
    --------
    >>> index_tuple("keep", [1, 0], 3)
    (1, 0)
    """
    allowed = f"{name} must be a non-empty sequence of integers, distinct {what} in [0, {size - 1}]"
    if isinstance(value, (str, bytes)) or not isinstance(value, (Sequence, np.ndarray)):
        raise InputError(f"{allowed}, got {short_repr(value)}")
    items = list(np.ravel(np.asarray(value, dtype=object))) if isinstance(value, np.ndarray) else list(value)
    ok = all(isinstance(i, (int, np.integer)) and not isinstance(i, (bool, np.bool_)) for i in items)
    if not items or not ok or len(set(items)) != len(items) or any(not 0 <= i < size for i in items):
        raise InputError(f"{allowed}, got {short_repr(value)}")
    return tuple(int(i) for i in items)


def positive_count(name: str, value: object) -> int:
    """``value`` as a Python int ``>= 1`` (numpy integers too; booleans, floats and text refused).

    Examples
    --------
    >>> positive_count("n_inputs", np.int64(2))
    2
    """
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, np.integer)) or value < 1:
        raise InputError(f"{name} must be an integer >= 1, got {short_repr(value)}")
    return int(value)


def finite_system(
    system: control.StateSpace | control.TransferFunction, name: str = "system"
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The matrices ``A, B, C, D`` of a state space, each checked finite (NaN/inf named ``name.A`` etc.).

    A transfer function's coefficients are checked before it is realised (named ``name.num``/``name.den``):
    a realisation of NaN coefficients can fail to return at all; an improper one (more zeros than poles) has none.

    Examples
    --------
    >>> A, B, C, D = finite_system(control.ss([[0.5]], [[1.0]], [[1.0]], [[0.0]], 0.1))
    >>> A.tolist()
    [[0.5]]
    """
    if isinstance(system, control.TransferFunction):
        for label in ("num", "den"):
            coeffs = [np.ravel(np.asarray(c, float)) for row in getattr(system, label) for c in row]
            as_finite_array(f"{name}.{label}", np.concatenate(coeffs) if coeffs else np.zeros(0))
        for i, (nums, dens) in enumerate(zip(system.num, system.den)):
            for j, (num, den) in enumerate(zip(nums, dens)):
                zeros, poles = (len(np.trim_zeros(np.ravel(np.asarray(c, float)), "f")) - 1 for c in (num, den))
                if zeros > poles:
                    where = f"[{i}, {j}] " if system.noutputs * system.ninputs > 1 else ""
                    raise InputError(
                        f"{name} {where}is improper: a numerator of degree {zeros} over a denominator of degree "
                        f"{poles}; allowed: proper systems (no more zeros than poles), which have a state space"
                    )
        system = control.tf2ss(system, method="scipy")  # the same realisation with or without slycot
    A, B, C, D = (as_finite_array(f"{name}.{label}", np.asarray(getattr(system, label), float)) for label in "ABCD")
    return A, B, C, D


def is_discrete_dt(dt: object) -> bool:
    """True when ``dt`` is a sample time of a discrete system: a finite number > 0 (not ``True``/``None``).

    Examples
    --------
    >>> is_discrete_dt(0.2), is_discrete_dt(True), is_discrete_dt(float("nan"))
    (True, False, False)
    """
    if dt is None or isinstance(dt, (bool, np.bool_)) or not isinstance(dt, (int, float, np.number)):
        return False
    return bool(np.isfinite(dt) and dt > 0)
