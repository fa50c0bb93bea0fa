"""A rig's compiled models and hover trim, built once per model, configuration and settings in a process.

Every :class:`~trms.twin.twin.Twin` needs its model compiled in its configuration (with the transport delay and
without it) and the hover trim solved on it: most of the cost of building a twin, and the same for every twin of
one parameter set (a verification builds about 190 twins of one model; a calibration candidate 6). :func:`built`
keys them by :func:`~trms.twin.parameters.model_key` (the MJCF text and every parameter's exact value) and the
settings that shape them, so a changed parameter, model or configuration is another key and never reads a stale
entry; each caller gets copies of its own.
"""

from __future__ import annotations

import collections
import copy
import threading

import mujoco

from trms.twin.model import Configuration, build_model, thrust_curves
from trms.twin.parameters import model_key
from trms.twin.state_sensors import with_state_sensors
from trms.twin.trim import Trim, solve_trim

__all__ = ["built", "cache_counts", "MAX_ENTRIES"]

#: Entries kept (the least recently used goes first): the parameter sets a process works on at a time.
MAX_ENTRIES = 64
_CACHE: collections.OrderedDict[tuple, tuple[mujoco.MjModel, mujoco.MjModel, Trim]] = collections.OrderedDict()
_LOCK = threading.Lock()
_COUNTS = {"hits": 0, "misses": 0}


def built(
    spec: mujoco.MjSpec,
    configuration: Configuration,
    voltage_limit: float,
    timestep: float,
    trim_rotors: tuple[int, ...],
    axes: tuple[str, ...],
) -> tuple[mujoco.MjModel, mujoco.MjModel, Trim]:
    """The model of ``spec`` in ``configuration`` with and without the transport delay, and its hover trim.

    The model with the delay carries sensors of its whole state (:func:`~trms.twin.state_sensors.add_state_sensors`),
    which the twin's rollouts record.

    Parameters
    ----------
    spec : mujoco.MjSpec
        The rig (not modified).
    configuration : Configuration
    voltage_limit : float
        Motor voltage limit (V).
    timestep : float
        Physics step (s).
    trim_rotors, axes : tuple
        What :func:`~trms.twin.trim.solve_trim` trims: the rotors it moves and the axes it holds level.

    Returns
    -------
    (mujoco.MjModel, mujoco.MjModel, Trim)
        Copies, the caller's own: the model with the delay, the one without, the trim.

    Examples
    --------
    >>> from trms.twin import load_spec
    >>> from trms.twin.model import CONFIGURATIONS
    >>> from trms.twin.parameters import with_parameters
    >>> args = (CONFIGURATIONS["1dof"], 10.0, 0.002, (0,), ("pitch", "yaw"))
    >>> a, _, _ = built(load_spec(), *args)
    >>> hits = cache_counts()["hits"]
    >>> b, _, _ = built(load_spec(), *args)
    >>> c, _, _ = built(with_parameters(load_spec(), {"main_motor_lag": 1.04774001}), *args)
    >>> cache_counts()["hits"] - hits, a is b
    (1, False)
    """
    key = (model_key(spec), configuration.name, float(voltage_limit), float(timestep), tuple(trim_rotors), tuple(axes))
    with _LOCK:
        entry = _CACHE.get(key)
        if entry is not None:
            _CACHE.move_to_end(key)
            _COUNTS["hits"] += 1
    if entry is None:
        # What a rollout records of each physics step (no physics changes).
        model = build_model(with_state_sensors(spec), configuration, voltage_limit, timestep=timestep)
        model_lin = build_model(spec, configuration, voltage_limit, delay=False, timestep=timestep)
        entry = (model, model_lin, solve_trim(model_lin, thrust_curves(spec), trim_rotors, axes, voltage_limit))
        with _LOCK:
            _COUNTS["misses"] += 1
            _CACHE[key] = entry
            while len(_CACHE) > MAX_ENTRIES:
                _CACHE.popitem(last=False)
    model, model_lin, trim = entry
    return copy.copy(model), copy.copy(model_lin), copy.deepcopy(trim)


def cache_counts() -> dict[str, int]:
    """How many :func:`built` calls this process answered from the cache (``hits``) and built (``misses``), and the
    entries held (``size``).

    Examples
    --------
    >>> sorted(cache_counts())
    ['hits', 'misses', 'size']
    """
    with _LOCK:
        return {**_COUNTS, "size": len(_CACHE)}
