"""One closed loop of the thesis, run once on a given plant (``trms run``): the 1-DOF SAS/CSAS case tracking a
square wave (ch. 6/7), or the 2-DOF autopilot in one scenario (ch. 8), with the measures and the figure.
"""

from __future__ import annotations

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from trms.control.loop import Controller, closed_loop
from trms.control.lqg import LQGController, LQGDesign
from trms.control.metrics import StepMetrics, square_wave_metrics
from trms.control.plots import plot_closed_loop
from trms.errors import ConfigurationError, InputError, check_choice
from trms.experiments.ch8_designs import INVERSION, reference_prefilter
from trms.experiments.ch8_mimo_lqg import (
    CONTROLLERS,
    SCENARIOS,
    autopilot_controllers,
    measures,
    rest_levels,
    scenario_reference,
)
from trms.experiments.ch67_lqg import WIDE_BAND, judge, run_case
from trms.plant import Plant
from trms.record import Record
from trms.worlds import design_model, input_layer

__all__ = [
    "AUTOPILOT_CONTROLLERS",
    "CONTROL_HEADROOM",
    "pitch_loop",
    "autopilot_controller",
    "autopilot_loop",
    "plot_autopilot",
]

#: Room left above the controls in :func:`plot_autopilot`'s control panel, as a fraction of their range: the
#: actuator limits' line and the legend sit there, over no control.
CONTROL_HEADROOM = 0.6


def pitch_loop(
    plant: Plant, r: float, case: str, amplitude: float, period: float, duration: float, seed: int
) -> tuple[Record, list[StepMetrics], list[StepMetrics], str]:
    """The 1-DOF integral LQG (``Q = I``, ``R = r``) designed on eq. (3.11) tracking a square wave on ``plant``.

    Parameters
    ----------
    plant : Plant
        A 1-DOF plant (the twin or the linear model).
    r : float
        Control weight ``R``.
    case : str
        ``SAS`` or a CSAS prefilter (:data:`trms.experiments.ch67_lqg.ALL_CASES`).
    amplitude, period, duration : float
        Square wave amplitude (rad), period (s), run length (s).
    seed : int
        Seed of the plant's noise.

    Returns
    -------
    record : Record
    narrow, wide : list of StepMetrics
        Each step measured in the narrow and in the wide settling band.
    status : str
        :func:`trms.experiments.ch67_lqg.judge` of the run in the wide band (``"settled"``, ...).

    Examples
    --------
    >>> from trms.worlds import make_plant
    >>> rec, narrow, wide, status = pitch_loop(make_plant("linear", "1dof"), 125.0, "SAS", 0.2, 40.0, 40.0, 0)
    >>> len(rec), len(narrow) == len(wide), status
    (200, True, 'settled')
    """
    rec, steps = run_case(plant, r, case, amplitude, period, duration, seed, model=design_model("1dof"))
    wide = square_wave_metrics(rec, band=WIDE_BAND)
    return rec, steps, wide, judge(rec, wide)


#: Every 2-DOF controller ``trms run --config 2dof`` flies: the autopilot and its two SISO loops
#: (:mod:`~trms.experiments.ch8_mimo_lqg`), and the MIMO comparison's others
#: (:mod:`~trms.experiments.ch8_controllers_mimo`).
AUTOPILOT_CONTROLLERS = ("MIMO LQG", "two SISO loops", "MIMO MPC", "MIMO H-infinity", "MIMO PID")


def autopilot_controller(plant: Plant, controller: str, design: LQGDesign | None = None) -> Controller:
    """One 2-DOF controller of :data:`AUTOPILOT_CONTROLLERS` built for ``plant`` as chapter 8 flies it (its limits,
    behind the thrust-curve inversion on the twin); ``design``: an integral LQG to fly as the MIMO LQG instead of the
    autopilot's (e.g. :func:`trms.experiments.lqg_design.design_from_dict` of a ``trms design --config 2dof`` JSON).

    Raises
    ------
    InputError
        An unknown controller, or a design given for another controller.
    ConfigurationError
        A controller that needs a missing extra, or one not offered (its measured reason).

    Examples
    --------
    >>> from trms.worlds import make_plant
    >>> type(autopilot_controller(make_plant("twin", "2dof"), "MIMO LQG")).__name__
    'InvertedInputs'
    """
    from trms.experiments.ch8_controllers_mimo import controllers_for_mimo, design_controllers_mimo

    check_choice("controller", controller, AUTOPILOT_CONTROLLERS, error=InputError)
    if design is not None:
        if controller != "MIMO LQG":
            raise InputError(f"a design file sets the MIMO LQG's gains; it cannot fly {controller!r}")
        limits, wrap = input_layer(plant, INVERSION)
        return wrap(LQGController(design, limits))
    if controller in CONTROLLERS:
        return autopilot_controllers(design_model("2dof", plant.sample_time), plant)[controller]
    made, missing = controllers_for_mimo(design_controllers_mimo(plant.sample_time), plant)
    if controller in missing:
        raise ConfigurationError(f"{controller}: {missing[controller]}")
    return made[controller]


def autopilot_loop(
    plant: Plant, controller: str, scenario: str, seed: int, design: LQGDesign | None = None
) -> tuple[Record, int, dict[str, float]]:
    """A 2-DOF controller of :data:`AUTOPILOT_CONTROLLERS` (:func:`autopilot_controller`) in one of the ch. 8
    scenarios on ``plant``, through the reference prefilter, measured with the settling band of the loop's own
    wobble at rest (:func:`~trms.experiments.ch8_mimo_lqg.rest_levels`).

    Returns
    -------
    record : Record
    tracked : int
        The output the scenario's step drives (0 pitch, 1 yaw).
    measures : dict
        :func:`trms.experiments.ch8_mimo_lqg.measures` of the run.

    Raises
    ------
    InputError
        An unknown scenario or controller.

    Examples
    --------
    >>> from trms.experiments.ch8_mimo_lqg import meets_targets
    >>> from trms.worlds import make_plant
    >>> rec, tracked, m = autopilot_loop(make_plant("linear", "2dof"), "MIMO LQG", "yaw step", 0)
    >>> rec.output_names, tracked, meets_targets("yaw step", m)
    (('pitch', 'yaw'), 1, [])
    """
    if scenario not in SCENARIOS:
        raise InputError(f"unknown scenario {scenario!r}; allowed: {', '.join(repr(s) for s in SCENARIOS)}")
    rest = rest_levels(plant, autopilot_controller(plant, controller, design), scenario, seed)
    ctrl = autopilot_controller(plant, controller, design)
    ref = scenario_reference(scenario, plant.sample_time)
    rec = closed_loop(plant, ctrl, ref, reference_prefilter(plant.sample_time), seed=seed)
    tracked = SCENARIOS[scenario][0]
    return rec, tracked, measures(rec, tracked, rest)


def plot_autopilot(rec: Record, title: str, limits: tuple[np.ndarray, np.ndarray]) -> Figure:
    """A 2-DOF closed loop: one panel per output (pitch and yaw, rad), the controls with each input's own limits.

    Parameters
    ----------
    rec : Record
        From :func:`autopilot_loop` (``reference`` and ``control`` extras).
    title : str
    limits : (lower, upper)
        Each input's deviation limits (V), :func:`trms.control.loop.deviation_limits`.

    Returns
    -------
    matplotlib.figure.Figure

    Examples
    --------
    >>> from trms.control.loop import deviation_limits
    >>> from trms.worlds import make_plant
    >>> plant = make_plant("linear", "2dof")
    >>> fig = plot_autopilot(autopilot_loop(plant, "MIMO LQG", "yaw step", 0)[0], "t", deviation_limits(plant))
    >>> [a.get_ylabel() for a in fig.axes]
    ['pitch (rad)', 'yaw (rad)', 'control (V)']
    """
    n = len(rec.output_names)
    fig = Figure(figsize=(8.0, 2.4 * (n + 1) + 0.5), dpi=100)
    FigureCanvasAgg(fig)
    axes = fig.subplots(n + 1, 1, sharex=True)
    plot_closed_loop(rec, title, None, output=0, ax=(axes[0], axes[-1]))  # the first output and every control
    _, dy = rec.deviations()
    for i in range(1, n):
        axes[i].plot(rec.time, rec.extras["reference"][:, i], "k:", lw=1.0, label="command")
        axes[i].plot(rec.time, dy[:, i], "b", lw=1.2, label=f"{rec.output_names[i]} (deviation)")
        axes[i].legend(loc="upper right", fontsize=8)
        axes[i].grid(True, alpha=0.3)
    for i, name in enumerate(rec.output_names):
        axes[i].set_ylabel(f"{name} (rad)")
    ctrl = axes[-1]
    lo, hi = ctrl.get_ylim()
    text = []
    for j, name in enumerate(rec.input_names):
        pair = (float(limits[0][j]), float(limits[1][j]))
        inside = [v for v in pair if lo <= v <= hi]
        for v in inside:
            ctrl.axhline(v, color=ctrl.get_lines()[j].get_color(), ls="--", lw=0.8)
        text.append(f"{name} {pair[0]:+.3g} / {pair[1]:+.3g} V" + ("" if len(inside) == 2 else " (outside the view)"))
    # A band above the controls for the limits' line and the legend: neither hides a control (u2 ran under the
    # legend where it climbed late in the run).
    ctrl.set_ylim(lo, hi + CONTROL_HEADROOM * (hi - lo))
    ctrl.text(0.01, 0.95, "actuator limits: " + "; ".join(text), transform=ctrl.transAxes, fontsize=7, va="top")
    return fig
