"""Step responses read as the thesis read them: dead time and time constant, crossings, the NRMSE fit.

The same functions read eq. (3.11)'s own step (:func:`system_step`) and the twin's mean step
(:func:`~trms.measurement.protocol.mean_step`).
"""

from __future__ import annotations

import numpy as np

from trms.identification.validation import fit_percent

__all__ = [
    "STEP_FIT_WINDOW",
    "tangent_figures",
    "system_step",
    "step_fit_percent",
    "step_figures",
    "crossing_figures",
]

#: The window of the step fit (s), from the step: eq. (3.11)'s first three periods of its 0.34 Hz mode and more.
STEP_FIT_WINDOW = 15.0


def tangent_figures(time: np.ndarray, response: np.ndarray, final_window: float = 10.0) -> tuple[float, float]:
    """Dead time and time constant (s) of a step response by the tangent (maximum-slope) construction.

    The tangent at the steepest point of the first rise crosses the start level at the dead time and the
    final value (the mean of the last ``final_window`` s) one time constant later. The same function reads
    eq. (3.11)'s step and the twin's mean step.

    Parameters
    ----------
    time : numpy.ndarray
        Sample times from the step (s).
    response : numpy.ndarray
        The response (any unit), starting from 0 at the step.
    final_window : float
        Length (s) of the end of the record that gives the final value.

    Returns
    -------
    (float, float)
        Dead time and time constant (s); NaN when the response has no final value of its own sign.

    Examples
    --------
    >>> t = np.arange(0.0, 60.0, 0.05)
    >>> y = np.where(t > 1.0, 1.0 - np.exp(-(t - 1.0) / 2.0), 0.0)  # a delay of 1 s and a lag of 2 s
    >>> [round(x, 1) for x in tangent_figures(t, y)]
    [1.0, 2.0]
    """
    t, y = np.asarray(time, float), np.asarray(response, float)
    final = float(np.mean(y[t >= t[-1] - final_window]))
    if final == 0 or not np.isfinite(final):
        return float("nan"), float("nan")
    slope = np.diff(y) / np.diff(t) * np.sign(final)
    # The first rise: up to the first crossing of the final value, or the whole record.
    first = int(np.argmax(np.sign(final) * y >= abs(final))) or y.size - 1
    i = int(np.argmax(slope[: max(first, 1)]))
    if slope[i] <= 0:
        return float("nan"), float("nan")
    t_mid, y_mid = 0.5 * (t[i] + t[i + 1]), 0.5 * (y[i] + y[i + 1]) * np.sign(final)
    return float(t_mid - y_mid / slope[i]), float(abs(final) / slope[i])


def system_step(system, duration: float) -> tuple[np.ndarray, np.ndarray]:
    """Time (s) and unit-step response of a discrete LTI model over ``duration`` s, at its own sample time.

    Examples
    --------
    >>> import control
    >>> t, y = system_step(control.tf([0.5], [1.0, -0.5], 0.2), 1.0)
    >>> t.round(3).tolist(), y.round(3).tolist()
    ([0.0, 0.2, 0.4, 0.6, 0.8], [0.0, 0.5, 0.75, 0.875, 0.938])
    """
    import control

    t = np.arange(int(round(duration / float(system.dt)))) * float(system.dt)
    if isinstance(system, control.TransferFunction):  # scipy's realisation, the same bits with or without slycot
        system = control.tf2ss(system, method="scipy")
    _, y = control.step_response(system, T=t)
    return t, np.ravel(y)


def step_fit_percent(
    time: np.ndarray, response: np.ndarray, reference: np.ndarray, window: float = STEP_FIT_WINDOW
) -> float:
    """NRMSE fit (%) of a step response to a reference one over the first ``window`` s:
    :func:`~trms.identification.validation.fit_percent` of the response against the reference, 100 for a perfect
    match.

    Examples
    --------
    >>> t = np.arange(0.0, 20.0, 0.2)
    >>> r = 1.0 - np.exp(-t)
    >>> step_fit_percent(t, r, r), round(step_fit_percent(t, 0.9 * r, r), 1)
    (100.0, 49.2)
    """
    keep = np.asarray(time) <= window
    return fit_percent(np.asarray(reference, float)[keep], np.asarray(response, float)[keep])


def step_figures(system) -> tuple[float, float]:
    """Delay (time to 5 % of the final value) and time constant (5 % to 63 %) of a discrete model's step (s): the
    crossing figures (:func:`crossing_figures`) of its 60 s step, the final value its DC gain.

    Parameters
    ----------
    system : control.LTI
        A discrete SISO model (sample time in s).

    Returns
    -------
    (float, float)
        Delay and time constant (s).

    Examples
    --------
    >>> import control
    >>> [round(x, 2) for x in step_figures(control.tf([0.5], [1.0, -0.5], 0.2))]
    [0.02, 0.28]
    """
    import control

    final = float(np.ravel(control.dcgain(system))[0])
    return crossing_figures(*system_step(system, 60.0), final=final)


def crossing_figures(time: np.ndarray, response: np.ndarray, final: float | None = None) -> tuple[float, float]:
    """Delay (time to 5 % of the final value) and time constant (5 % to 63 %) of a step response (s).

    Parameters
    ----------
    time, response : numpy.ndarray
        The step response from the step (s; any unit).
    final : float, optional
        Its final value; default: the mean of its last 10 s (as :func:`tangent_figures`).

    Examples
    --------
    >>> t = np.arange(0.0, 60.0, 0.05)
    >>> y = np.where(t > 1.0, 1.0 - np.exp(-(t - 1.0) / 2.0), 0.0)
    >>> [round(x, 2) for x in crossing_figures(t, y)]
    [1.1, 1.89]
    """
    t, y = np.asarray(time, float), np.asarray(response, float)
    final = float(np.mean(y[t >= t[-1] - 10.0])) if final is None else final
    if final == 0 or not np.isfinite(final):
        return float("nan"), float("nan")
    frac = y / final

    def crossing(level: float) -> float:
        i = int(np.argmax(frac >= level))
        if frac[i] < level:
            return float("nan")
        if i == 0:
            return 0.0
        return float(t[i - 1] + (level - frac[i - 1]) / (frac[i] - frac[i - 1]) * (t[i] - t[i - 1]))

    d = crossing(0.05)
    return d, crossing(0.63) - d
