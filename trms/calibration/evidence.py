"""What the calibration measures on a model, computed once per model and code: a content-addressed store.

The verification of a model at the unseen seeds (:func:`~trms.calibration.verify.verify`), its large-signal
checks (:func:`~trms.calibration.large_signal.large_signal_checks`), its static pitch curve
(:func:`~trms.calibration.static_pitch.static_pitch_curves`) and the side-peak evidence
(:func:`~trms.calibration.elastic_modes.side_peak_evidence`) depend only on the model and on the code that
measures them, and cost about a minute. :func:`measured`, :func:`measured_large_signal` and
:func:`measured_static_pitch` key them by a :func:`fingerprint` of
both -- the model's MJCF, every source file of the packages that simulate and measure (``trms/twin``,
``trms/identification`` and the package's top-level modules but the report and the command line) and the
versions of the libraries they call -- and reads them from the first store that holds that key: the one shipped
beside the model (``trms/models/evidence.json``, for the shipped model) or the user's cache folder
(``$XDG_CACHE_HOME/trms`` or ``~/.cache/trms``). Anything else is computed and written to the user's cache. A
changed model, a changed line of code or another library version is another key: a stale result is never read.
``python -m trms.calibration.evidence`` refreshes the shipped store after the shipped model or the code
changes (``trms calibrate --replace-shipped`` does it too); a test checks that it is current and equal to a
fresh verification.
"""

from __future__ import annotations

import hashlib
import json
import os
import sys
from pathlib import Path
from typing import Any

import mujoco

from trms.calibration.large_signal import LargeSignalCheck, large_signal_checks
from trms.calibration.static_pitch import StaticPitch, static_pitch_curves
from trms.calibration.verify import Verification
from trms.files import atomic_write
from trms.twin.model import DEFAULT_MODEL_PATH
from trms.twin.parameters import model_key

__all__ = [
    "SHIPPED_PATH",
    "fingerprint",
    "user_cache",
    "measured",
    "measured_large_signal",
    "measured_static_pitch",
    "refresh_shipped",
]

#: The shipped model's measurements, beside it.
SHIPPED_PATH = DEFAULT_MODEL_PATH.with_name("evidence.json")
_PACKAGE = Path(__file__).resolve().parents[1]
#: Top-level modules whose code does not change a measurement (presentation and the command line).
_NOT_MEASURING = ("report.py", "cli.py")


def _sources() -> list[Path]:
    top = [p for p in sorted(_PACKAGE.glob("*.py")) if p.name not in _NOT_MEASURING]
    folders = ("twin", "identification", "calibration", "batch")
    return top + [p for folder in folders for p in sorted((_PACKAGE / folder).rglob("*.py"))]


def fingerprint(spec: mujoco.MjSpec) -> str:
    """The key of a model's measurements: SHA-256 of its MJCF, of the measuring code and of the library versions.

    Examples
    --------
    >>> from trms.twin import load_spec
    >>> from trms.twin.parameters import with_parameters
    >>> a, b = fingerprint(load_spec()), fingerprint(with_parameters(load_spec(), {"pitch_damping": 0.02}))
    >>> len(a), a == fingerprint(load_spec()), a == b
    (64, True, False)

    A model apart only beyond the 6 significant digits MuJoCo writes its MJCF with is another key too:

    >>> a == fingerprint(with_parameters(load_spec(), {"main_motor_lag": 1.04774001}))
    False
    """
    import control
    import numpy
    import scipy

    h = hashlib.sha256()
    h.update(model_key(spec).encode())  # the text and the parameters' exact values: its 6 digits are not enough
    for path in _sources():
        h.update(path.relative_to(_PACKAGE).as_posix().encode())
        h.update(path.read_bytes())
    for lib in (mujoco, numpy, scipy, control):
        h.update(f"{lib.__name__} {lib.__version__}".encode())
    return h.hexdigest()


def user_cache() -> Path:
    """The user's cache folder for measurements (``$XDG_CACHE_HOME/trms``, else ``~/.cache/trms``).

    Returns
    -------
    pathlib.Path
        The folder (not created here).

    Examples
    --------
    >>> import os
    >>> old = os.environ.get("XDG_CACHE_HOME")
    >>> os.environ["XDG_CACHE_HOME"] = "/var/cache/example"
    >>> user_cache().as_posix()
    '/var/cache/example/trms'
    >>> _ = os.environ.pop("XDG_CACHE_HOME") if old is None else os.environ.update(XDG_CACHE_HOME=old)
    """
    base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(base) / "trms"


def _compute(spec: mujoco.MjSpec, side_peaks: bool) -> dict[str, Any]:
    from trms.calibration.elastic_modes import side_peak_evidence
    from trms.calibration.targets import Targets
    from trms.calibration.verify import verify

    out: dict[str, Any] = {
        "verification": verify(spec, Targets.thesis()).to_dict(),
        "large_signal": [c.to_dict() for c in large_signal_checks(spec)],
        "static_pitch": static_pitch_curves(spec).to_dict(),
    }
    if side_peaks:
        out["side_peaks"] = side_peak_evidence(spec)
    return out


def _read(path: Path, key: str) -> dict[str, Any] | None:
    try:
        data = json.loads(path.read_text())
    except (OSError, ValueError):
        return None
    return data if isinstance(data, dict) and data.get("fingerprint") == key else None


def measured(spec: mujoco.MjSpec, side_peaks: bool = True) -> tuple[Verification, dict | None]:
    """The thesis targets' verification of ``spec`` and, with ``side_peaks``, its side-peak evidence, from the
    first store that holds them under ``spec``'s :func:`fingerprint`, else computed and stored in the user's cache
    (a cache that cannot be written is skipped).

    Parameters
    ----------
    spec : mujoco.MjSpec
        The model.
    side_peaks : bool
        Whether the side-peak evidence is wanted too.

    Returns
    -------
    (Verification, dict or None)
        The verification at the unseen seeds, and the side-peak evidence (None without ``side_peaks``).

    Examples
    --------
    A store in the user's cache under the model's fingerprint is read, not recomputed:

    >>> import json, os, tempfile
    >>> from trms.calibration.checks import Check
    >>> from trms.twin import load_spec
    >>> spec = load_spec()
    >>> spec.modelname = "evidence example"  # a model of its own: its own fingerprint
    >>> old = os.environ.get("XDG_CACHE_HOME")
    >>> os.environ["XDG_CACHE_HOME"] = tempfile.mkdtemp()
    >>> stored = Verification([Check("peak", 0.34, 0.34, "+-0.03 Hz", True, "Hz", seed=101)], seeds=(101,))
    >>> store = user_cache() / f"evidence-{fingerprint(spec)[:32]}.json"
    >>> store.parent.mkdir(parents=True)
    >>> _ = store.write_text(json.dumps({"fingerprint": fingerprint(spec), "verification": stored.to_dict()}))
    >>> ver, side = measured(spec, side_peaks=False)
    >>> ver.seeds, ver.all_met, side
    ((101,), True, None)
    >>> _ = os.environ.pop("XDG_CACHE_HOME") if old is None else os.environ.update(XDG_CACHE_HOME=old)
    """
    key = fingerprint(spec)
    data = _stored(key, "side_peaks" if side_peaks else "verification")
    if data is None:
        data = {"fingerprint": key, **_compute(spec, side_peaks)}
        try:
            mine = _cache_path(key)
            mine.parent.mkdir(parents=True, exist_ok=True)
            atomic_write(mine, lambda fh: fh.write(json.dumps(data)), binary=False)
        except OSError:
            pass
    return Verification.from_dict(data["verification"]), data.get("side_peaks")


def measured_large_signal(spec: mujoco.MjSpec) -> list[LargeSignalCheck]:
    """The large-signal checks of ``spec`` from the first store that holds them under its :func:`fingerprint`
    (written with its verification by :func:`measured`), else measured now (about a second; nothing is stored).

    Parameters
    ----------
    spec : mujoco.MjSpec
        The model.

    Returns
    -------
    list of LargeSignalCheck
        As :func:`~trms.calibration.large_signal.large_signal_checks` gives them.

    Examples
    --------
    >>> from trms.twin import load_spec
    >>> checks = measured_large_signal(load_spec())  # the shipped model: read from the shipped store
    >>> len(checks), checks[0].name, checks[0].unit
    (8, 'time to pass +1 rad at +10 V', 's')
    """
    data = _stored(fingerprint(spec), "large_signal")
    if data is None:
        return large_signal_checks(spec)
    return [LargeSignalCheck.from_dict(c) for c in data["large_signal"]]


def measured_static_pitch(spec: mujoco.MjSpec) -> StaticPitch:
    """The static pitch curve of ``spec`` beside the published model's from the first store that holds it under
    its :func:`fingerprint` (written with its verification by :func:`measured`), else measured now (a few seconds;
    nothing is stored).

    Parameters
    ----------
    spec : mujoco.MjSpec
        The model.

    Returns
    -------
    StaticPitch
        As :func:`~trms.calibration.static_pitch.static_pitch_curves` gives it at its default offsets.

    Examples
    --------
    >>> from trms.twin import load_spec
    >>> curves = measured_static_pitch(load_spec())  # the shipped model: read from the shipped store
    >>> float(curves.offsets[0]), float(curves.offsets[-1]), curves.stops
    (-1.0, 1.0, (-1.1, 1.1))
    """
    data = _stored(fingerprint(spec), "static_pitch")
    if data is None:
        return static_pitch_curves(spec)
    return StaticPitch.from_dict(data["static_pitch"])


def _cache_path(key: str) -> Path:
    return user_cache() / f"evidence-{key[:32]}.json"


def _stored(key: str, field: str) -> dict[str, Any] | None:
    """The first store (shipped, then the user's cache) whose record has ``key`` and holds ``field``."""
    for path in (SHIPPED_PATH, _cache_path(key)):
        data = _read(path, key)
        if data is not None and field in data:
            return data
    return None


def refresh_shipped(path: str | os.PathLike[str] = DEFAULT_MODEL_PATH) -> Path:
    """Measure the model at ``path`` (the shipped one by default) and write its store beside it.

    The verification at every unseen seed and the side-peak evidence: about a minute.

    Parameters
    ----------
    path : path-like
        An MJCF file; the store is written beside it as ``evidence.json``.

    Returns
    -------
    pathlib.Path
        The store written.

    Examples
    --------
    >>> import shutil, tempfile
    >>> from pathlib import Path
    >>> model = Path(tempfile.mkdtemp()) / "trms.xml"
    >>> _ = shutil.copy(DEFAULT_MODEL_PATH, model)
    >>> refresh_shipped(model).name  # doctest: +SKIP
    'evidence.json'
    """
    from trms.twin.model import load_spec

    spec = load_spec(path)
    data = {"fingerprint": fingerprint(spec), **_compute(spec, side_peaks=True)}
    target = Path(path).with_name(SHIPPED_PATH.name)
    return atomic_write(target, lambda fh: fh.write(json.dumps(data)), binary=False)


if __name__ == "__main__":  # python -m trms.calibration.evidence
    print(f"wrote {refresh_shipped()}", file=sys.stdout)
