"""Writing a calibration into rig files: a new MJCF (never by surprise onto the shipped or the start model), or the
shipped model on request, each with the values derived from the parameters and, for the shipped model, its README.

The twin's layer writes each part (:func:`trms.twin.model_files.write_model`,
:func:`trms.twin.model_files.write_readme`); this module knows which calibration stage sets which parameter
(:data:`SET_BY`), which the README states beside every value.
"""

from __future__ import annotations

import os
import shutil
from collections.abc import Mapping
from pathlib import Path

from trms.calibration.ambient import AMBIENT_PARAMETERS
from trms.calibration.coupling import DEFAULT_COUPLING
from trms.calibration.fit import DEFAULT_FIT
from trms.errors import InputError
from trms.twin.model import DEFAULT_MODEL_PATH
from trms.twin.model_files import README_PATH, model_readme, write_model, write_readme

__all__ = ["SET_BY", "check_destination", "write_new_model", "write_calibrated_model", "shipped_readme"]

#: What sets each calibrated parameter: the stage of ``trms calibrate`` that fits it.
SET_BY: dict[str, str] = {
    **{name: "`trms calibrate`, linear stage" for name in DEFAULT_FIT},
    **{name: "`trms calibrate`, ambient stage" for name in AMBIENT_PARAMETERS},
    **{name: "`trms calibrate`, coupling stage" for name in DEFAULT_COUPLING},
}


def check_destination(start_from: str | Path, mjcf: str | Path) -> Path:
    """The resolved path ``mjcf``, refused (one line) when it is the shipped model or ``start_from`` itself.

    Called before calibrating, so that a refused destination costs no run and leaves no report behind.

    Examples
    --------
    >>> check_destination(DEFAULT_MODEL_PATH, "/tmp/cal/trms.xml").name
    'trms.xml'
    >>> check_destination("/tmp/a.xml", DEFAULT_MODEL_PATH)
    Traceback (most recent call last):
    ...
    trms.errors.InputError: --mjcf ... is the shipped model; use --replace-shipped to replace it
    """
    dst = Path(mjcf).resolve()
    if dst == DEFAULT_MODEL_PATH.resolve():
        raise InputError(f"--mjcf {str(mjcf)!r} is the shipped model; use --replace-shipped to replace it")
    if dst == Path(start_from).resolve():
        raise InputError(f"--mjcf {str(mjcf)!r} is the model calibration starts from; write a new file")
    return dst


def write_new_model(values: dict[str, float], start_from: str | Path, mjcf: str | Path) -> Path:
    """Copy ``start_from`` to ``mjcf`` and write ``values`` into the copy (the one MJCF writer).

    Refuses to write onto the shipped model or onto ``start_from`` itself (:func:`check_destination`):
    replacing the shipped model is a separate, explicit step (:func:`write_calibrated_model`). The copy gets the
    values and the values derived from them (:func:`~trms.twin.model_files.write_model`).

    Parameters
    ----------
    values : dict
        Physical parameters by name (:mod:`trms.twin.parameters`), in their units.
    start_from, mjcf : path-like
        The model the values were calibrated from, and the new file.

    Returns
    -------
    Path
        The written MJCF (resolved).

    Examples
    --------
    >>> import tempfile
    >>> path = write_new_model({}, DEFAULT_MODEL_PATH, Path(tempfile.mkdtemp()) / "rig.xml")
    >>> path.read_bytes() == DEFAULT_MODEL_PATH.read_bytes()
    True
    """
    src, dst = Path(start_from).resolve(), check_destination(start_from, mjcf)
    dst.parent.mkdir(parents=True, exist_ok=True)
    tmp = dst.with_name(dst.name + ".copy")
    shutil.copyfile(src, tmp)
    try:
        write_model(tmp, values)
        tmp.replace(dst)
    finally:
        tmp.unlink(missing_ok=True)
    return dst


def shipped_readme(path: str | os.PathLike[str] = DEFAULT_MODEL_PATH) -> str:
    """The README of the rig file at ``path`` with the calibration's stages (:data:`SET_BY`).

    Examples
    --------
    >>> shipped_readme() == README_PATH.read_text()  # the shipped README is this text
    True
    """
    return model_readme(path, SET_BY)


def write_calibrated_model(path: str | os.PathLike[str], values: Mapping[str, float]) -> Path:
    """Write calibrated ``values`` into the rig file at ``path``, its derived values, and (shipped model) its README.

    Parameters
    ----------
    path : path-like
        The MJCF to change in place (each file is replaced atomically).
    values : mapping
        Parameter name -> value (units of :data:`~trms.twin.parameters.PARAMETERS`).

    Returns
    -------
    pathlib.Path
        ``path``.

    Examples
    --------
    >>> import shutil, tempfile
    >>> from trms.twin.parameters import read_parameters
    >>> from trms.twin import load_spec
    >>> rig = Path(tempfile.mkdtemp()) / "rig.xml"
    >>> _ = shutil.copy(DEFAULT_MODEL_PATH, rig)
    >>> _ = write_calibrated_model(rig, {"pitch_damping": 0.012})
    >>> read_parameters(load_spec(rig), ["pitch_damping"])
    {'pitch_damping': 0.012}
    """
    out = write_model(path, values)
    if Path(path).resolve() == DEFAULT_MODEL_PATH.resolve():
        write_readme(path, README_PATH, SET_BY)
    return out
