"""The project's exceptions and the argument checks that raise them.

Every error message names the offending value and what is allowed, so a user can
fix the call without reading the source. All exceptions derive from the built-in
``ValueError`` (bad input) or ``RuntimeError`` (a computation that failed), so
callers that only know the standard library can still catch them.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import SupportsFloat, SupportsIndex, TypeVar

import numpy as np

__all__ = [
    "TrmsError",
    "InputError",
    "ConfigurationError",
    "ModelFileError",
    "SimulationError",
    "DivergenceError",
    "EstimationError",
    "DesignError",
    "as_finite_array",
    "check_in_range",
    "check_int",
    "check_choice",
    "check_seed",
    "short_repr",
]

_T = TypeVar("_T")


def short_repr(value: object, limit: int = 80) -> str:
    """A value for a one-line message: its ``repr`` on one line, cut to ``limit`` characters.

    Examples
    --------
    >>> short_repr("strong")
    "'strong'"
    >>> short_repr(list(range(100)), 20)
    '[0, 1, 2, 3, 4, 5...'
    """
    text = " ".join(repr(value).split())
    return text if len(text) <= limit else text[: limit - 3] + "..."


class TrmsError(Exception):
    """Base class of every error raised by :mod:`trms`."""


class InputError(TrmsError, ValueError):
    """A value passed in is malformed: NaN/inf, wrong shape, out of range."""


class ConfigurationError(TrmsError, ValueError):
    """An unknown configuration, an invalid sample time or option."""


class ModelFileError(TrmsError, ValueError):
    """An MJCF file is missing, malformed, or lacks a required element."""


class SimulationError(TrmsError, RuntimeError):
    """The physics engine reported a problem (any MuJoCo warning) during a simulation."""


class DivergenceError(SimulationError):
    """A simulation produced a non-finite or runaway state."""


class EstimationError(TrmsError, RuntimeError):
    """An estimator could not produce a trustworthy model (e.g. no convergence)."""


class DesignError(TrmsError, ValueError):
    """A controller or filter cannot be designed from the given data."""


def as_finite_array(
    name: str,
    value: object,
    shape: Sequence[int | None] | None = None,
    *,
    dtype: type = float,
) -> np.ndarray:
    """Convert ``value`` to a finite numpy array, checking its shape.

    Parameters
    ----------
    name : str
        Name of the argument, used in the error message.
    value : array_like
        The value to check.
    shape : sequence of int or None, optional
        Expected shape; ``None`` entries accept any length on that axis.
    dtype : type
        Target dtype (default float).

    Returns
    -------
    numpy.ndarray
        A new array (never a view of ``value``).

    Raises
    ------
    InputError
        If the value is not real and numeric (complex numbers, booleans, strings, ragged nesting and
        numbers beyond the float range are refused), not finite, or has the wrong shape.

    Examples
    --------
    >>> as_finite_array("u", [1, 2.5], (2,))
    array([1. , 2.5])
    """
    reason = None
    try:
        kind = np.asarray(value).dtype.kind
        if kind == "c" and not np.issubdtype(np.dtype(dtype), np.complexfloating):
            reason = "complex values are not allowed (the imaginary part would be lost)"
        elif kind == "b" and np.dtype(dtype).kind != "b":
            reason = "booleans are not allowed (write the values as numbers, e.g. 0.0 and 1.0)"
        elif kind in "USV":
            reason = "text values are not allowed"
        else:
            arr: np.ndarray = np.array(value, dtype=dtype, copy=True)
    except OverflowError:
        reason = "a number beyond the float range (about 1.8e308)"
    except (TypeError, ValueError) as exc:
        ragged = "inhomogeneous" in str(exc) or "sequence" in str(exc)
        reason = "ragged nesting (rows of different lengths)" if ragged else "a value that is not a number"
    if reason is not None:
        flat = " ".join(repr(value).split())  # one line, whatever numpy's repr wraps
        text = flat if len(flat) <= 80 else flat[:77] + "..."
        raise InputError(f"{name} must be real numbers (float64), got {text}: {reason}")
    if shape is not None:
        ok = arr.ndim == len(shape) and all(want is None or want == got for want, got in zip(shape, arr.shape))
        if not ok:
            parts = ["any" if s is None else str(s) for s in shape]
            want_txt = "(" + ", ".join(parts) + ("," if len(parts) == 1 else "") + ")"
            raise InputError(f"{name} must have shape {want_txt}, got shape {arr.shape}")
    if not np.all(np.isfinite(arr)):
        bad = np.argwhere(~np.isfinite(arr))
        first = tuple(int(i) for i in bad[0]) if arr.ndim else ()
        raise InputError(f"{name} must be finite; found {arr[first] if arr.ndim else arr} at index {first}")
    return arr


def check_in_range(
    name: str,
    value: object,
    low: float,
    high: float,
    *,
    unit: str = "",
    low_open: bool = False,
    error: type[TrmsError] = InputError,
) -> float:
    """Return ``float(value)`` if ``low <= value <= high``, else raise ``error``.

    Parameters
    ----------
    name : str
        Argument name for the message.
    value : object
        Value to check: a real number (anything ``float`` converts except complex numbers, text and booleans;
        NaN is refused).
    low, high : float
        Allowed closed interval (``low`` is excluded when ``low_open``).
    unit : str
        Unit appended to the numbers in the message.
    low_open : bool
        Exclude the lower bound.
    error : type
        Exception class to raise.
    """
    if isinstance(value, (complex, np.complexfloating, str, bytes, bool, np.bool_)):
        raise error(f"{name} must be a real number in [{low}{unit}, {high}{unit}], got {value!r}")
    try:
        if not isinstance(value, (SupportsFloat, SupportsIndex)):
            raise TypeError(f"{type(value).__name__} is not a number")
        v = float(value)
    except (TypeError, ValueError, OverflowError) as exc:
        flat = " ".join(repr(value).split())  # one line, whatever numpy's repr wraps
        text = flat if len(flat) <= 80 else flat[:77] + "..."
        raise error(f"{name} must be a real number in [{low}{unit}, {high}{unit}], got {text}") from exc
    below = v <= low if low_open else v < low
    if not np.isfinite(v) or below or v > high:
        lb = "(" if low_open else "["
        raise error(f"{name} = {value!r}{unit} is outside the allowed range {lb}{low}{unit}, {high}{unit}]")
    return v


def check_int(name: str, value: object, low: int, unit: str = "", high: float = np.inf) -> int:
    """Return ``value`` as an int if it is an integer in ``[low, high]``, else raise InputError.

    A float such as ``2.5`` or ``2.0`` is refused, never truncated.

    Examples
    --------
    >>> check_int("order", 3, 1)
    3
    >>> check_int("order", 2.0, 1)
    Traceback (most recent call last):
    ...
    trms.errors.InputError: order must be an int, got 2.0
    """
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        raise InputError(f"{name} must be an int, got {value!r}")
    return int(check_in_range(name, value, low, high, unit=unit))


def check_choice(name: str, value: object, allowed: Sequence[_T], *, error: type[TrmsError] = ConfigurationError) -> _T:
    """Return the entry of ``allowed`` equal to ``value``, else raise ``error`` listing them."""
    for choice in allowed:
        if choice is value or choice == value:
            return choice
    raise error(f"unknown {name} {value!r}; allowed: {', '.join(repr(a) for a in allowed)}")


def check_seed(name: str, value: object, *, allow_none: bool = True) -> int | None:
    """Return ``value`` as a Python int if it is a non-negative integer (numpy integers too).

    Parameters
    ----------
    name : str
        Argument name for the message.
    value : int or None
        The seed; ``None`` is allowed only with ``allow_none``.
    allow_none : bool
        Accept ``None`` (fresh entropy, not reproducible).

    Raises
    ------
    InputError
        Booleans, floats (even ``2.0``), negative or non-integer values.

    Examples
    --------
    >>> check_seed("seed", np.int64(3))
    3
    """
    if value is None and allow_none:
        return None
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, np.integer)) or value < 0:
        allowed = "a non-negative integer" + (" or None" if allow_none else "")
        flat = " ".join(repr(value).split())  # one line, whatever numpy's repr wraps
        text = flat if len(flat) <= 80 else flat[:77] + "..."
        raise InputError(f"{name} must be {allowed}, got {text}")
    return int(value)
