"""trms: a MuJoCo digital twin of the Twin Rotor MIMO System, with identification and control toolkits.

Subpackages
-----------
trms.twin            the MuJoCo twin (needs mujoco): Twin plant, linearisation, render, control tasks
                     (Gymnasium: ``import trms.envs.gym``; dm_env suite: ``trms.envs.suite``)
trms.identification  signals, spectra, ARX/ARMAX by PEM, NARX-RBF, validation tests
trms.control         command shaping, integral LQG, closed loops, metrics
trms.experiments     the thesis's experiments as functions of a Plant

The package's names load on first use, so that ``import trms.cli`` (the ``trms`` command) starts at once and
catches a Ctrl-C while numpy and MuJoCo load.
"""

from __future__ import annotations

TYPE_CHECKING = False  # typing.TYPE_CHECKING without importing typing (type checkers take this name as true)
if TYPE_CHECKING:
    from trms.plant import LinearPlant, Plant, simulate
    from trms.record import OperatingPoint, Record

__all__ = ["LinearPlant", "OperatingPoint", "Plant", "Record", "simulate"]

#: The module each name of :data:`__all__` comes from.
_HOMES = {
    "LinearPlant": "trms.plant",
    "Plant": "trms.plant",
    "simulate": "trms.plant",
    "OperatingPoint": "trms.record",
    "Record": "trms.record",
}


def __getattr__(name: str) -> object:
    """A name of :data:`__all__` (or ``__version__``), imported on first use."""
    if name in _HOMES:
        import importlib

        value = getattr(importlib.import_module(_HOMES[name]), name)
    elif name == "__version__":
        from importlib.metadata import PackageNotFoundError, version

        try:
            value = version("trms")
        except PackageNotFoundError:  # a source tree that was never installed
            value = "0+unknown"
    else:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted({*globals(), *__all__, "__version__"})
