"""The ch. 8 controllers over the twin's parameter spread: Monte Carlo success and robust stability.

Every controller of :mod:`trms.experiments.ch8_designs`, designed once on eq. (3.11) and built as the comparison
flies it (prefilter, thrust-curve inversion), flies the comparison's square wave on the same ``n`` sampled twins as
the LQG study of :mod:`trms.experiments.robustness` (its :func:`~trms.experiments.robustness.sample_parameters`: the
same parameters, noise and gust seeds), all ``n`` of one controller closed in one batch
(:func:`trms.batch.batch_closed_loop`). A sample succeeds as in that study: no divergence, no stops, the last step
settled within the wide 5 % band
(:func:`~trms.experiments.robustness.measure`).

Robust stability: the sampled twins' linearisations ``G_i`` (delay and bending included) against eq. (3.11),
``G0``, give the multiplicative input uncertainty ``l_I(w) = max_i |(G_i - G0) / G0|`` at ``z = exp(j w Ts)``
(:func:`input_uncertainty`); a first-order weight ``W_I`` lies above it (:func:`fit_weight`,
:func:`~trms.experiments.ch8_designs.input_uncertainty_weight`), and a linear loop is robustly stable for
every plant of that set when ``max_w |W_I(j w) T(e^{j w Ts})| < 1``, ``T = L / (1 + L)``,
``L = K_y G0`` (SISO: no structured singular value needed; :func:`robust_stability`).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import control
import numpy as np

from trms.batch import batch_closed_loop
from trms.control.loop import Controller
from trms.errors import ConfigurationError, InputError, check_choice, check_in_range
from trms.experiments.ch8_controllers import square_reference
from trms.experiments.ch8_designs import (
    CONTROLLERS,
    SPREAD_WEIGHT,
    controllers_for,
    designs_at,
    feedback_compensator,
    input_uncertainty_weight,
    reference_prefilter,
)
from trms.experiments.robustness import LOOPS, SPREAD, measure, sample_parameters
from trms.present.sections import finite_or
from trms.present.tables import ComparisonTable
from trms.worlds import design_model, make_plant

__all__ = [
    "ControllerSpread",
    "Robustness",
    "cancelling_certificate",
    "controller_robustness",
    "fit_weight",
    "input_uncertainty",
    "robust_stability",
    "robust_verdict",
    "table_robustness",
]

#: The study's 1-DOF loop, whose measure (pitch, wide band) every controller's run is judged by.
_LOOP_1DOF = next(name for name, config in LOOPS.items() if config == "1dof")
#: Frequency grid of the uncertainty (rad/s): 0.01 rad/s to Nyquist.
_POINTS = 2000


@dataclass(frozen=True)
class ControllerSpread:
    """One controller on the sampled twins.

    Attributes
    ----------
    controller : str
    statuses : tuple of str
        Per sample: ``"settled"``, ``"not settled"``, ``"hit the stops"`` or ``"diverged"``.
    overshoot, settling : tuple of float
        Per sample: worst overshoot (%) and worst 5 % settling time (s).
    peak : float or None
        ``max |W_I T|`` on eq. (3.11) (None: no linear compensator, MPC).
    lowest_command : tuple of float
        Per sample: the lowest main-rotor command of the run (absolute V; below 0 V the rotor reverses, where its
        thrust, proportional to ``w |w|``, has almost no gain: what no linearisation at hover shows). NaN where
        the run diverged.
    status : str
        ``"flown"``, or why not (a missing extra).
    """

    controller: str
    statuses: tuple[str, ...]
    overshoot: tuple[float, ...]
    settling: tuple[float, ...]
    peak: float | None
    lowest_command: tuple[float, ...] = ()
    status: str = "flown"

    @property
    def successes(self) -> int:
        """Samples that settled."""
        return sum(s == "settled" for s in self.statuses)


@dataclass(frozen=True)
class Robustness:
    """Every controller over the spread: per controller its samples; the weight and the study's settings.

    ``coverage`` is ``max_w l_I(w) / |W_I(j w)|`` over this study's own samples (:func:`input_uncertainty`): at most
    1 when the stated weight lies above their uncertainty (NaN: not measured).
    """

    controllers: tuple[ControllerSpread, ...]
    weight: dict[str, float]
    n_samples: int
    seed: int
    spread: float
    sample_time: float
    coverage: float = float("nan")
    cancelling: tuple[float, float] = (float("nan"), float("nan"))


def cancelling_certificate(sample_time: float = 0.2) -> tuple[float, float]:
    """The spread design without its input-disturbance channel (python-control's ``mixsyn`` with ``W3 = W_I``):
    its ``max |W_I T|`` and its closed-loop damping of the pitch mode on eq. (3.11), ``(peak, damping)`` (NaN
    without slycot). The design that holds the certificate cancels the mode; the note of :func:`table_robustness`
    sets it beside the designs that damp it.

    Examples
    --------
    >>> peak, damping = cancelling_certificate()
    >>> bool(peak < 1.0), bool(damping < 0.06)
    (True, True)
    """
    from trms.control.damping import mode_damping
    from trms.control.hinf import HinfController, design_mixsyn, pitch_weights

    model = design_model("1dof", sample_time)
    weight = input_uncertainty_weight(**SPREAD_WEIGHT)
    try:
        design = design_mixsyn(model, *pitch_weights(), weight)
    except ConfigurationError:
        return float("nan"), float("nan")
    peak = robust_stability({"cancelling": HinfController(design)}, weight, sample_time)["cancelling"]
    assert peak is not None
    return float(peak), float(mode_damping(model, design.discrete_controller).closed.damping)


def input_uncertainty(
    n_samples: int, seed: int = 0, spread: float = SPREAD, sample_time: float = 0.2
) -> tuple[np.ndarray, np.ndarray]:
    """``l_I(w) = max_i |(G_i - G0) / G0|`` of the linearised sampled twins against eq. (3.11) (module docstring).

    Returns
    -------
    frequencies : numpy.ndarray
        rad/s, 0.01 to the Nyquist frequency, log-spaced.
    bound : numpy.ndarray
        ``l_I`` at each frequency (-).

    Examples
    --------
    >>> w, l_i = input_uncertainty(2)
    >>> bool(w[-1] == np.pi / 0.2), bool(0.0 < l_i[0] < 0.3 < l_i.max())
    (True, True)
    """
    n = int(check_in_range("n_samples", n_samples, 1, 100_000))
    ts = float(check_choice("sample_time", float(sample_time), (0.2, 0.1), error=InputError))
    g0 = design_model("1dof", ts)
    w = np.logspace(-2.0, np.log10(np.pi / ts), _POINTS)
    z = np.exp(1j * w * ts)
    nominal = g0(z)
    bound = np.zeros(w.size)
    for i in range(n):
        params, _ = sample_parameters(seed, i, spread)
        g = make_plant("twin", "1dof", ts, parameters=params).linearise().discrete
        bound = np.maximum(bound, np.abs((g(z) - nominal) / nominal))
    return w, bound


def fit_weight(frequencies: np.ndarray, bound: np.ndarray, margin: float = 0.05) -> dict[str, float]:
    """The first-order weight above ``bound``: ``r0 = bound[0]``, ``r_inf = (1 + margin) max(bound)``, and the
    smallest ``tau`` (s) with ``|W_I(j w)| >= bound`` at every frequency (``|W_I|`` grows with ``tau``; bisection).

    Examples
    --------
    A bound drawn by a weight of ``tau = 2 s`` is fitted back (``r_inf`` 5 % above its largest value):

    >>> w = np.logspace(-2, 1, 200)
    >>> bound = np.abs(input_uncertainty_weight(0.1, 2.0, 1.05)(1j * w))
    >>> fit = fit_weight(w, bound)
    >>> round(fit["tau"], 1), bool(np.all(np.abs(input_uncertainty_weight(**fit)(1j * w)) >= bound))
    (2.0, True)
    """
    w = np.asarray(frequencies, float)
    b = np.asarray(bound, float)
    margin = check_in_range("margin", margin, 0.0, 10.0, low_open=True)
    r0, r_inf = float(b[0]), float((1.0 + margin) * b.max())
    if not 0.0 < r0 < r_inf:
        raise InputError(f"bound must start positive and below its largest value, got {r0!r} and {float(b.max())!r}")
    lo, hi = 0.0, 1.0
    while not np.all(np.abs(input_uncertainty_weight(r0, hi, r_inf)(1j * w)) >= b):
        lo, hi = hi, 2.0 * hi
    for _ in range(50):
        mid = 0.5 * (lo + hi)
        covered = np.all(np.abs(input_uncertainty_weight(r0, mid, r_inf)(1j * w)) >= b)
        lo, hi = (lo, mid) if covered else (mid, hi)
    return {"r0": r0, "tau": hi, "r_inf": r_inf}


def robust_stability(
    controllers: Mapping[str, Controller], weight: control.TransferFunction, sample_time: float = 0.2
) -> dict[str, float | None]:
    """``max_w |W_I(j w) T(e^{j w Ts})|`` of each controller's loop on eq. (3.11) (None without a linear
    compensator); below 1: stable for every plant within the weight.

    Examples
    --------
    >>> from trms.control.pid import PIDController, PIDGains
    >>> peaks = robust_stability({"P": PIDController(PIDGains(0.5, 0.0, 0.0), 0.2)}, control.tf([0.1], [1.0]))
    >>> 0.0 < peaks["P"] < 1.0
    True
    """
    ts = float(check_choice("sample_time", float(sample_time), (0.2, 0.1), error=InputError))
    g0 = design_model("1dof", ts)
    w = np.logspace(-2.0, np.log10(np.pi / ts), _POINTS)
    z = np.exp(1j * w * ts)
    wi = np.abs(weight(1j * w))
    out: dict[str, float | None] = {}
    for name, c in controllers.items():
        k = feedback_compensator(c)
        if k is None:
            out[name] = None
            continue
        loop = k(z) * g0(z)
        out[name] = float(np.max(wi * np.abs(loop / (1.0 + loop))))
    return out


def controller_robustness(
    n_samples: int,
    seed: int = 0,
    spread: float = SPREAD,
    sample_time: float = 0.2,
    controllers: Sequence[str] = CONTROLLERS,
) -> Robustness:
    """Every controller on the same ``n_samples`` sampled twins (gusts on), one batch per controller.

    Parameters
    ----------
    n_samples : int
        Samples of :func:`~trms.experiments.robustness.sample_parameters` (the LQG study's draws).
    seed : int
        Seed of the study.
    spread : float
        Relative half-width of the uniform parameter spread.
    sample_time : float
        0.2 or 0.1 s (designs and twins).
    controllers : sequence of str
        Names of :data:`~trms.experiments.ch8_designs.CONTROLLERS`.

    Returns
    -------
    Robustness

    Examples
    --------
    >>> r = controller_robustness(1, controllers=["H-infinity, robust weight"])
    >>> # the design damps the mode, so it does not hold the LTI certificate (max |W_I T| < 1; the table's note)
    >>> [(c.controller, c.statuses, c.peak < 1.0) for c in r.controllers]
    [('H-infinity, robust weight', ('settled',), False)]
    """
    n = int(check_in_range("n_samples", n_samples, 1, 100_000))
    ts = float(check_choice("sample_time", float(sample_time), (0.2, 0.1), error=InputError))
    names = [check_choice("controller", c, CONTROLLERS, error=InputError) for c in controllers]
    drawn = [sample_parameters(seed, i, spread) for i in range(n)]
    designs = designs_at(ts)
    plants = [make_plant("twin", "1dof", ts, gusts=True, parameters=p, seed=s) for p, s in drawn]
    built = [controllers_for(designs, plant) for plant in plants]
    peaks = robust_stability(built[0][0], input_uncertainty_weight(**SPREAD_WEIGHT), ts)
    reference = square_reference(ts)
    rows = []
    for name in names:
        if name in built[0][1]:
            rows.append(ControllerSpread(name, (), (), (), None, (), f"not flown: {built[0][1][name]}"))
            continue
        result = batch_closed_loop(
            plants,
            [b[0][name] for b in built],
            reference,
            reference_prefilter(ts),
            seeds=[s for _, s in drawn],
            metadata=[{"controller_name": name, "sample": i, "study_seed": int(seed)} for i in range(n)],
        )
        measured = [measure(_LOOP_1DOF, record) for record in result.records]
        rows.append(
            ControllerSpread(
                name,
                tuple(m[0] for m in measured),
                tuple(float(m[1]) for m in measured),
                tuple(float(m[2]) for m in measured),
                peaks[name],
                tuple(float(np.min(r.inputs[:, 0])) if r is not None else np.nan for r in result.records),
            )
        )
    w, bound = input_uncertainty(n, seed, spread, ts)
    cover = float(np.max(bound / np.abs(input_uncertainty_weight(**SPREAD_WEIGHT)(1j * w))))
    return Robustness(
        tuple(rows), dict(SPREAD_WEIGHT), n, int(seed), float(spread), ts, cover, cancelling_certificate(ts)
    )


def _median_range(values: Sequence[float]) -> tuple[float, float, float]:
    v = np.asarray([x for x in values if np.isfinite(x)])
    return (float(np.median(v)), float(v.min()), float(v.max())) if v.size else (np.nan, np.nan, np.nan)


def robust_verdict(spread: ControllerSpread, twin_failure: str | None) -> str:
    """``"robust"`` when the LTI certificate holds (``max |W_I T| < 1``), every spread sample settled and the twin's
    flights held (``twin_failure`` empty); else ``"no: "`` and what failed (``twin_failure`` None: the twin's
    flights were not judged).

    Examples
    --------
    >>> row = ControllerSpread("PID", ("settled", "settled"), (12.0, 13.0), (9.0, 8.0), 0.97)
    >>> robust_verdict(row, ""), robust_verdict(row, "moving air: 3/8 steps unsettled")
    ('robust', 'no: twin (moving air: 3/8 steps unsettled)')
    >>> robust_verdict(ControllerSpread("H", ("settled", "hit the stops"), (1.0, 9.0), (1.0, 9.0), 1.2), None)
    'no: LTI certificate (max |W_I T| = 1.2), spread (1/2 settled), twin (not judged)'
    """
    failed = []
    if spread.peak is None or not spread.peak < 1.0:
        failed.append("LTI certificate" + ("" if spread.peak is None else f" (max |W_I T| = {spread.peak:.3g})"))
    if spread.status != "flown" or spread.successes < len(spread.statuses):
        failed.append(f"spread ({spread.successes}/{len(spread.statuses)} settled)")
    if twin_failure is None:
        failed.append("twin (not judged)")
    elif twin_failure:
        failed.append(f"twin ({twin_failure})")
    return "robust" if not failed else "no: " + ", ".join(failed)


def table_robustness(result: Robustness, twin_failures: Mapping[str, str] | None = None) -> ComparisonTable:
    """One row per controller: success rate, overshoot and settling over the successes, robust-stability peak, and
    the robustness verdict (:func:`robust_verdict`) given the twin's flights' failures (``twin_failures``: name ->
    what failed, empty when they held; None: not judged).

    Examples
    --------
    >>> row = ControllerSpread("PID", ("settled", "hit the stops"), (12.0, 80.0), (9.0, 60.0), 2.3)
    >>> t = table_robustness(Robustness((row,), dict(SPREAD_WEIGHT), 2, 0, 0.2, 0.2))
    >>> t.rows[0][:5]
    ['PID', '1/2', 12.0, 12.0, 12.0]
    """
    table = ComparisonTable(
        f"Ch. 8 controllers over the twin's parameter spread (+-{result.spread:.0%}, seed {result.seed}, "
        f"{result.n_samples} samples, Ts = {result.sample_time:g} s)",
        [
            "controller",
            "success",
            "overshoot median (%)",
            "overshoot min (%)",
            "overshoot max (%)",
            "settling 5 % median (s)",
            "settling 5 % min (s)",
            "settling 5 % max (s)",
            "max |W_I T|",
            "LTI certificate (max |W_I T| < 1)",
            "robust (LTI certificate, spread and twin)",
            "lowest main-rotor command, median (V)",
            "samples commanding below 0 V",
        ],
    )
    for c in result.controllers:
        ok = [i for i, s in enumerate(c.statuses) if s == "settled"]
        # a success settles its last step; an earlier one may never have (its worst settling is then not finite)
        unsettled = "an earlier step unsettled" if ok else "no success"
        success = f"{c.successes}/{len(c.statuses)}" if c.status == "flown" else c.status
        table.rows.append(
            [
                c.controller,
                success,
                *(finite_or(v, "no success") for v in _median_range([c.overshoot[i] for i in ok])),
                *(finite_or(v, unsettled) for v in _median_range([c.settling[i] for i in ok])),
                "-" if c.peak is None else c.peak,
                "-" if c.peak is None else ("yes" if c.peak < 1.0 else "no"),
                robust_verdict(c, None if twin_failures is None else twin_failures.get(c.controller)),
                finite_or(_median_range(c.lowest_command)[0], "diverged") if c.lowest_command else "-",
                f"{sum(v < 0.0 for v in c.lowest_command)}/{len(c.lowest_command)}" if c.lowest_command else "-",
            ]
        )
    wt = result.weight
    table.notes += [
        "Every controller designed once on eq. (3.11), flown on the comparison's square wave on the same sampled "
        "twins (gusts, noise) as the LQG robustness study; success: no divergence, no stops, the last step settled "
        "within 5 %; overshoot and settling (worst step of a run) over the successful samples.",
        f"W_I(s) = ({wt['tau']:g} s + {wt['r0']:g}) / (({wt['tau']:g} / {wt['r_inf']:g}) s + 1), stated above the "
        "linearised sampled twins' input uncertainty l_I = max_i |(G_i - G0) / G0| against eq. (3.11)"
        + (
            f" (on this study's {result.n_samples} samples max l_I / |W_I| = {result.coverage:.3g}"
            + (": it covers them)" if result.coverage <= 1.0 else ": it does not cover them all)")
            if np.isfinite(result.coverage)
            else ""
        )
        + "; max |W_I T| < 1: stable for every plant within it (MPC: its law while no constraint acts). The "
        "certificate's scope is linear, time-invariant uncertainty at hover within W_I: it says nothing of the thrust "
        "curve's large-signal gain, the stops or turbulence. A design is called robust only when the certificate, "
        "every spread sample and its flights on the twin (the comparison: overshoot within 10 points of the design "
        "model's, every still-air step and all but one in eight moving-air steps settled) all hold; otherwise the "
        "column names what failed.",
        "Robust stability is a small-signal statement: a loop that commands the main rotor below 0 V reverses it, "
        "where its thrust (proportional to w |w|) has almost no gain, which no linearisation at hover, and so no "
        "W_I measured on them, contains.",
    ]
    peak, damping = result.cancelling
    damped = [c.peak for c in result.controllers if c.peak is not None]
    if np.isfinite(peak) and damped:
        table.notes.append(
            f"Measured here: every design damps the pitch mode (>= 0.1) and none holds the certificate (max |W_I T| "
            f"{min(damped):.3g} to {max(damped):.3g}); the spread design without its input-disturbance channel holds "
            f"it (max |W_I T| = {peak:.3g}) by cancelling the mode (closed-loop damping {damping:.3g}, the plant's "
            "own). Damping the mode needs loop gain at the resonance, where W_I is 2.2 because the spread moves the "
            "mode's frequency: an unstructured multiplicative weight cannot tell a moved mode from an unknown gain."
        )
    failing = [c for c in result.controllers if c.lowest_command and 2 * c.successes < len(c.statuses)]
    passing = [c for c in result.controllers if c.lowest_command and 2 * c.successes >= len(c.statuses)]
    if failing and passing:
        low = {c.controller: _median_range(c.lowest_command)[0] for c in failing}
        floor = min(_median_range(c.lowest_command)[0] for c in passing)
        table.notes.append(
            "Measured here: the loops that fail on most samples command the rotor down to "
            + ", ".join(f"{v:.2f} V ({k})" for k, v in low.items())
            + f" (median of each run's lowest); those that succeed on most, no lower than {floor:.2f} V."
        )
    return table
