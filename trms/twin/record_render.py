"""Rendering a saved Record of the twin: its configuration (given or recorded) checked against the record, then
the frames drawn with the model of that configuration (:func:`trms.twin.render.render_record`)."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from trms.errors import ConfigurationError, InputError
from trms.record import Record
from trms.twin import Twin, render

__all__ = ["render_saved_record"]


def render_saved_record(
    record: Record,
    path: str | os.PathLike[str],
    config: str | None = None,
    *,
    label: str = "record",
    camera: str = "oblique",
    every: int = 2,
    width: int = 320,
    height: int = 240,
) -> tuple[Path, str]:
    """Render ``record`` to ``path`` (``.png`` last frame, ``.gif`` or ``.mp4``) with the twin of its configuration.

    Parameters
    ----------
    record : Record
        A twin Record (its ``qpos`` channel), at least one sample, a sample time > 0.
    path : path-like
        The file to write.
    config : str, optional
        ``1dof``, ``2dof`` or ``yaw``; default: the record's ``config`` metadata. Refused when it differs from it.
    label : str
        The record's name in messages (its file).
    camera, every, width, height
        As in :func:`trms.twin.render.render_record`.

    Returns
    -------
    path : Path
        The written file.
    config : str
        The configuration rendered.

    Raises
    ------
    InputError
        No configuration known, no samples, joint positions that are not the configuration's or not finite.
    ConfigurationError
        ``config`` is not the recorded one.

    Examples
    --------
    >>> import numpy as np
    >>> rec = Record(np.zeros(0), np.zeros((0, 1)), np.zeros((0, 1)), ("u1",), ("pitch",))
    >>> render_saved_record(rec, "r.png", "1dof", label="empty.npz")
    Traceback (most recent call last):
    ...
    trms.errors.InputError: record 'empty.npz' holds 0 samples; allowed: at least 1 to render
    """
    recorded = record.metadata.get("config")
    chosen = config or recorded
    if chosen is None:
        raise InputError(f"record {label!r} does not say its configuration; pass --config")
    if recorded is not None and chosen != recorded:
        raise ConfigurationError(
            f"--config {chosen} does not match record {label!r}, recorded in "
            f"configuration {recorded!r}: pass the --config it was recorded with ({recorded}) or leave it out"
        )
    if len(record) == 0:
        raise InputError(f"record {label!r} holds 0 samples; allowed: at least 1 to render")
    record.sample_time  # noqa: B018 -- refuses a record whose sample time is not > 0 before anything is drawn
    model = Twin(chosen, 0.1).model
    if "qpos" in record.extras and record.extras["qpos"].shape[1] != model.nq:
        raise InputError(
            f"record {label!r} has {record.extras['qpos'].shape[1]} joint positions per sample; the "
            f"{chosen} twin has {model.nq}: pass the --config it was recorded with"
        )
    if "qpos" in record.extras:
        bad = np.flatnonzero(~np.isfinite(np.asarray(record.extras["qpos"], float)).all(axis=1))
        if bad.size:
            raise InputError(
                f"record {label!r} has joint positions that are not finite in {bad.size} sample(s), first at "
                f"sample {int(bad[0])} (t = {record.time[bad[0]]:g} s); allowed: finite positions (NaN draws nothing)"
            )
    out = render.render_record(model, record, path, camera=camera, every=every, width=width, height=height)
    return out, chosen
