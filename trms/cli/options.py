"""Options and checks several ``trms`` commands share: the caps on durations and amplitudes, the plant options,
``--debug``, and the one-line summary of a record's ranges."""

from __future__ import annotations

import argparse
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from trms import reference
from trms.errors import InputError, check_in_range

if TYPE_CHECKING:
    from trms.plant import Plant
    from trms.record import Record

__all__ = [
    "MAX_DURATION",
    "MAX_AMPLITUDE_V",
    "MAX_AMPLITUDE_RAD",
    "DEMO_AMPLITUDE",
    "check_caps",
    "check_two_samples",
    "add_cap_options",
    "add_plant_options",
    "add_debug_option",
    "plant_of",
    "ranges",
    "say",
]

#: Longest run (s) a command accepts unless ``--max-duration`` raises it: one hour of rig time.
MAX_DURATION = 3600.0
#: Largest signal amplitude (V) around hover: twice the motor limit; anything wider only saturates.
MAX_AMPLITUDE_V = 2.0 * reference.VOLTAGE_LIMIT
#: Largest reference amplitude (rad) of ``trms run``: pitch's end stop (1.1 rad) in the shipped model.
MAX_AMPLITUDE_RAD = 1.1
#: PRBS amplitude (V) of ``trms demo``: a small excitation. The yaw axis (0.1 Hz, damping 0.04) is the one
#: it swings most: 2-DOF, 60 s, 2 Hz, seeds 0-9 reach at most 42 deg of yaw (0.2 V swung it to the +-172 deg stops).
DEMO_AMPLITUDE = 0.02


def check_caps(args: argparse.Namespace, amplitude_cap: float, unit: str) -> None:
    """Refuse a duration or amplitude beyond the stated caps (or the user's ``--max-*``)."""
    max_d = check_in_range("--max-duration", args.max_duration, 0.0, np.inf, unit=" s", low_open=True)
    max_a = (
        amplitude_cap
        if args.max_amplitude is None
        else check_in_range("--max-amplitude", args.max_amplitude, 0.0, np.inf, unit=unit)
    )
    try:
        check_in_range("--duration", args.duration, 0.0, max_d, unit=" s", low_open=True)
    except InputError as exc:
        raise InputError(f"{exc} (a longer run needs --max-duration)") from None
    try:
        check_in_range("--amplitude", args.amplitude, 0.0, max_a, unit=unit)
    except InputError as exc:
        raise InputError(f"{exc} (a larger amplitude needs --max-amplitude)") from None


def check_two_samples(args: argparse.Namespace, sample_time: float) -> None:
    """Refuse a ``--duration`` shorter than two samples (a run of one sample is a hold, not a response)."""
    try:
        check_in_range("--duration", args.duration, 2.0 * sample_time, float(args.max_duration), unit=" s")
    except InputError as exc:
        raise InputError(f"{exc} (a run needs at least two samples of {sample_time:g} s)") from None


def add_cap_options(p: argparse.ArgumentParser, unit: str, default: float) -> None:
    """``--max-duration`` and ``--max-amplitude`` (in ``unit``, default ``default``)."""
    p.add_argument(
        "--max-duration",
        type=float,
        default=MAX_DURATION,
        help=f"cap on --duration in s (default {MAX_DURATION:g}: one hour)",
    )
    p.add_argument(
        "--max-amplitude", type=float, default=None, help=f"cap on --amplitude in {unit} (default {default:g})"
    )


def add_plant_options(p: argparse.ArgumentParser, configs: Sequence[str] = ("1dof", "2dof", "yaw")) -> None:
    """``--plant``, ``--config``, ``--sample-time``, ``--seed``, ``--noise``."""
    p.add_argument(
        "--plant",
        default="twin",
        choices=["twin", "linear"],
        help="the MuJoCo twin or the linear model (eq. 3.11 for 1dof, the twin's linearisation otherwise)",
    )
    p.add_argument("--config", default="1dof", choices=list(configs), help="rig configuration (default 1dof)")
    p.add_argument("--sample-time", type=float, default=None, help="s (default: 0.2 for 1dof, 0.1 otherwise)")
    p.add_argument("--seed", type=int, default=0, help="seed of the signal, noise and gusts (default 0)")
    p.add_argument(
        "--noise", type=float, default=1e-3, help="measurement noise standard deviation in rad (default 1e-3)"
    )


def add_debug_option(p: argparse.ArgumentParser) -> None:
    """``--debug``: the traceback instead of the one-line message."""
    p.add_argument(
        "--debug",
        action="store_true",
        default=argparse.SUPPRESS,
        help="on failure, show the Python traceback instead of the one-line message",
    )


def plant_of(args: argparse.Namespace, **kwargs: Any) -> Plant:
    """The plant the plant options name (:func:`trms.worlds.make_plant`)."""
    from trms.worlds import make_plant

    return make_plant(
        args.plant,
        args.config,
        args.sample_time,
        seed=args.seed,
        noise_std=args.noise,
        gusts=getattr(args, "gusts", False),
        **kwargs,
    )


def ranges(rec: Record) -> str:
    """One line: each output's range (rad) and the number of saturated samples."""
    y = rec.outputs
    if len(rec) == 0:
        return "no samples"
    return (
        ", ".join(f"{n} in [{y[:, i].min():+.4f}, {y[:, i].max():+.4f}] rad" for i, n in enumerate(rec.output_names))
        + f"; saturated samples: {int(rec.extras['saturated'].any(axis=1).sum())}"
        + (
            f"; samples at an end stop: {int(rec.extras['at_stop'].any(axis=1).sum())}"
            if "at_stop" in rec.extras
            else ""
        )
    )


def say(line: str) -> None:
    """Print a line at once (a progress line, or one printed before a closed pipe could lose it)."""
    print(line, flush=True)
