"""The calibration: linear inner fit, ambient fit and spectral coupling fit, alternated, then verification.

1. Linear fit (:mod:`.fit`): counterweight, shield mass, pitch damping, main motor gain and
   lag, transport delay, cable stiffness, against the model target (frequency response and
   step), the peak frequencies and the rest pose.
2. Ambient fit (:mod:`.ambient`): the rotors' turbulence and the pitch electronics noise,
   against the rig's motion at rest and Table 5.1's residual variance.
3. Spectral fit (:mod:`.coupling`): the main rotor's lean and spin inertia and the tail
   rotor's reaction torque, on the nonlinear quantised twin with its ambient excitation,
   against the gyroscopic coupling and the 2-DOF spectra.
4. Repeat 1-3 until the spectral fit returns the coupling the linear fit saw (at most
   ``max_passes``): the coupling also moves the linear figures, so the stages interact.
   Later passes run a compass search at the finer step from the earlier pass's coupling.
5. Verify every target with the thesis's protocols (:mod:`.verify`).
"""

from __future__ import annotations

import math
import sys
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import IO, Any

import mujoco

from trms.calibration.ambient import AMBIENT_PARAMETERS, fit_ambient
from trms.calibration.coupling import DEFAULT_COUPLING, fit_coupling
from trms.calibration.fit import DEFAULT_FIT, fit_linear
from trms.calibration.large_signal import LargeSignalCheck
from trms.calibration.protocol import THESIS_PROTOCOLS, VERIFY_SEEDS, Protocol
from trms.calibration.static_pitch import StaticPitch
from trms.calibration.targets import Targets
from trms.calibration.verify import Verification, verify
from trms.errors import DesignError
from trms.twin.model import load_spec
from trms.twin.parameters import PARAMETERS, read_parameters, with_parameters

__all__ = ["Progress", "CalibrationResult", "calibrate"]


class Progress:
    """One tqdm progress bar per calibration stage on stderr; silent when disabled or when stderr is not a terminal.

    Parameters
    ----------
    enabled : bool
        Draw the bars at all.
    stream : file-like, optional
        Where to draw (default ``sys.stderr``).

    Examples
    --------
    Not on a terminal, the bars stay silent:

    >>> import io
    >>> out = io.StringIO()
    >>> progress = Progress(stream=out)
    >>> progress.update("fit", 0.5, "10 evaluations")
    >>> progress.done("fit")
    >>> progress.enabled, out.getvalue()
    (False, '')
    """

    def __init__(self, enabled: bool = True, stream: IO[str] | None = None) -> None:
        self.stream = stream or sys.stderr
        self.enabled = bool(enabled) and bool(getattr(self.stream, "isatty", lambda: False)())
        self._bar: Any = None
        self._stage = ""

    def _bar_for(self, stage: str) -> Any:
        if self._bar is None or self._stage != stage:
            self.close()
            from tqdm import tqdm

            self._bar = tqdm(
                total=1000,
                desc=f"[calibrate] {stage}",
                file=self.stream,
                leave=True,
                bar_format="{desc:<34} {percentage:5.1f}% |{bar:30}| {postfix}",
            )
            self._stage = stage
        return self._bar

    def update(self, stage: str, fraction: float, detail: str = "") -> None:
        """Show ``stage`` at ``fraction`` (0-1) done, with ``detail``."""
        if not self.enabled:
            return
        bar = self._bar_for(stage)
        bar.n = int(round(1000 * min(max(fraction, 0.0), 1.0)))
        bar.set_postfix_str(detail, refresh=False)
        bar.refresh()

    def evaluations(self, stage: str) -> Callable[[int, float], None]:
        """The callback ``(n, cost)`` of an inner fit: ``stage`` at ``n`` of about 100 evaluations."""
        return lambda n, cost: self.update(stage, n / 100, f"{n} evaluations, cost {cost:.3g}")

    def candidates(self, stage: str) -> Callable[[int, int], None]:
        """The callback ``(done, total)`` of a candidate batch: ``stage`` at ``done / total``."""
        return lambda done, total: self.update(stage, done / total, f"{done}/{total} candidates")

    def done(self, stage: str, detail: str = "") -> None:
        """Finish a stage's bar."""
        if self.enabled:
            self.update(stage, 1.0, detail)
            self.close()

    def close(self) -> None:
        """Close the current bar (idempotent)."""
        if self._bar is not None:
            self._bar.close()
            self._bar = None


@dataclass
class CalibrationResult:
    """What a calibration found and how long it took.

    Attributes
    ----------
    start, values : dict of str to float
        Fitted parameters before and after (SI units of :data:`~trms.twin.parameters.PARAMETERS`).
    verification : Verification
        Every target measured on the calibrated nonlinear twin.
    unreachable : list of str
        Targets missed at some verification seed by the calibrated parameters (the best the local fits found
        within the bounds, not a proof that no parameter set meets them), with the achieved values.
    timings : dict of str to float
        Wall time (s) of the linear fits, the ambient fits, the spectral fits and the verification.
    targets : Targets
        What the calibration aimed at.
    passes : int
        Alternations of the linear and the spectral fit that ran.
    evaluations : dict of str to int
        Linearisations of the linear fits, runs of the ambient fits and candidates of the spectral fits.
    large_signal : list of LargeSignalCheck
        The large-signal checks of the calibrated model.
    converged : bool
        Whether the last pass's spectral fit kept the coupling its linear fit saw and its compass search
        ended at a point better than its neighbours, and its ambient fit solved both of its figures (False:
        ``max_passes`` ran out while the fit still moved; the values are the last pass's).
    static_pitch : StaticPitch, optional
        The calibrated model's static pitch curve beside the published model's (its large signals, stated).

    Examples
    --------
    >>> from trms.calibration.checks import Check
    >>> from trms.calibration.verify import Verification
    >>> ver = Verification([Check("peak", 0.34, 0.34, "+-0.03 Hz", True, "Hz", seed=101)], seeds=(101,))
    >>> r = CalibrationResult({"counterweight_mass": 0.2}, {"counterweight_mass": 0.21}, ver, [], {}, Targets())
    >>> r.to_dict()["parameters"]["counterweight_mass"]["calibrated"], r.to_dict()["all_met"]
    (0.21, True)
    """

    start: dict[str, float]
    values: dict[str, float]
    verification: Verification
    unreachable: list[str]
    timings: dict[str, float]
    targets: Targets
    passes: int = 0
    evaluations: dict[str, int] = field(default_factory=dict)
    large_signal: list[LargeSignalCheck] = field(default_factory=list)
    converged: bool = True
    static_pitch: StaticPitch | None = None

    def to_dict(self) -> dict[str, Any]:
        """JSON-serialisable summary (the ``calibration.json`` report)."""
        return {
            "targets": self.targets.to_dict(),
            "parameters": {
                n: {
                    "start": self.start[n],
                    "calibrated": self.values[n],
                    "unit": PARAMETERS[n].unit,
                    "bounds": list(PARAMETERS[n].bounds),
                    "description": PARAMETERS[n].description,
                    "role": PARAMETERS[n].role,
                    "published": PARAMETERS[n].published,
                    "source": PARAMETERS[n].source,
                    "departure": _finite_or_none(PARAMETERS[n].departure(self.values[n])),
                    "stands_for": PARAMETERS[n].stands_for or None,
                }
                for n in self.values
            },
            "verification_seeds": list(self.verification.seeds),
            "checks": self.verification.summary(),
            "all_met": self.verification.all_met,
            "large_signal": [c.to_dict() for c in self.large_signal],
            "unreachable": self.unreachable,
            "timings_s": self.timings,
            "passes": self.passes,
            "converged": self.converged,
            "evaluations": self.evaluations,
            "static_pitch": None if self.static_pitch is None else self.static_pitch.to_dict(),
        }


def _finite_or_none(x: float) -> float | None:
    """``x``, or None (JSON's null) where it is not finite."""
    return x if math.isfinite(x) else None


def calibrate(
    targets: Targets | None = None,
    spec: mujoco.MjSpec | None = None,
    linear: Sequence[str] = DEFAULT_FIT,
    coupling: Sequence[str] = DEFAULT_COUPLING,
    ambient: Sequence[str] = AMBIENT_PARAMETERS,
    protocols: Sequence[Protocol] = THESIS_PROTOCOLS,
    max_passes: int = 3,
    progress: Progress | None = None,
    cluster: dict | None = None,
    seeds: Sequence[int] = VERIFY_SEEDS,
) -> CalibrationResult:
    """Calibrate the twin's named parameters against ``targets`` (default: the thesis's).

    Parameters
    ----------
    targets : Targets, optional
        What to aim at (default: :meth:`Targets.thesis`).
    spec : mujoco.MjSpec, optional
        Starting model (default: the shipped MJCF). Not modified.
    linear, coupling : sequence of str
        Parameters of the linear and of the spectral stage (either may be empty).
    ambient : sequence of str
        :data:`~trms.calibration.ambient.AMBIENT_PARAMETERS` to run the ambient stage (when the targets
        have an ambient target), empty to keep the model's ambient excitation.
    protocols : sequence of Protocol
        The excitation experiments.
    max_passes : int
        Most alternations of the stages (from the published values the thesis's calibration reaches its fixed point
        at the third: the second pass's linear and ambient refits leave the first's coupling a compass step off).
    progress : Progress, optional
        Terminal progress bar (none by default).
    cluster : dict, optional
        Run the spectral stage's candidates as Dask tasks: keyword arguments of
        :func:`trms.batch.distributed.map_items` (``workers``, ``scheduler``, ...).
    seeds : sequence of int
        The verification's unseen seeds (:func:`~trms.calibration.verify.verify`).

    Returns
    -------
    CalibrationResult
        The parameters (SI units of :data:`~trms.twin.parameters.PARAMETERS`) before and after, and the
        verification of the calibrated twin.

    Examples
    --------
    The counterweight's mass fitted to the 1-DOF pitch mode, verified at one seed:

    >>> from trms.calibration.protocol import THESIS_PROTOCOLS
    >>> from trms.calibration.target_kinds import PeakTarget
    >>> targets = Targets([PeakTarget("1dof", "u1->pitch", 0.34, 0.05)])
    >>> r = calibrate(targets, linear=["counterweight_mass"], coupling=(), ambient=(),
    ...               protocols=THESIS_PROTOCOLS[:1], seeds=(101,))
    >>> list(r.values), r.verification.all_met
    (['counterweight_mass'], True)
    """
    targets = targets or Targets.thesis()
    spec = spec if spec is not None else load_spec()
    progress = progress or Progress(enabled=False)
    if ambient and set(ambient) != set(AMBIENT_PARAMETERS):
        raise DesignError(
            f"the ambient stage fits {list(AMBIENT_PARAMETERS)} together, or nothing; got {list(ambient)}"
        )
    run_ambient = bool(ambient) and targets.ambient is not None
    names = list(dict.fromkeys([*linear, *(AMBIENT_PARAMETERS if run_ambient else ()), *coupling]))
    start = read_parameters(spec, names)
    timings = {"linear_fit": 0.0, "ambient_fit": 0.0, "spectral_fit": 0.0, "verification": 0.0}
    evaluations = {"linear": 0, "ambient": 0, "spectral": 0}
    current = spec
    unreachable_idx: list[int] = []
    passes = 0
    converged = True
    ambient_solved = True
    # The coupling the linear fit sees: a pass whose spectral fit returns it unchanged is converged.
    previous: dict[str, float] = read_parameters(spec, coupling) if coupling else {}
    for passes in range(1, max_passes + 1):
        if linear:
            t0 = time.perf_counter()
            stage = f"linear fit {passes}"
            lf = fit_linear(
                current,
                targets,
                linear,
                progress=progress.evaluations(stage),
            )
            current = with_parameters(current, lf.values)
            unreachable_idx = lf.unreachable
            timings["linear_fit"] += time.perf_counter() - t0
            evaluations["linear"] += lf.n_evaluations
            progress.done(stage, f"{lf.n_evaluations} evaluations, cost {lf.cost:.3g}")
        if run_ambient:
            assert targets.ambient is not None
            t0 = time.perf_counter()
            stage = f"ambient fit {passes}"
            progress.update(stage, 0.0, "hover and ch. 5 runs")
            af = fit_ambient(current, targets.ambient)
            current = with_parameters(current, af.values)
            timings["ambient_fit"] += time.perf_counter() - t0
            evaluations["ambient"] += af.evaluations
            ambient_solved = af.converged
            progress.done(stage, f"{af.evaluations} evaluations, hover {1e3 * af.hover_rms:.2f} mrad")
        if not coupling or not (
            any(p.config == "2dof" for p in targets.peaks) or any(c.config == "2dof" for c in targets.coherences)
        ):
            break  # the coupling parameters show only in 2-DOF spectra
        t0 = time.perf_counter()
        stage = f"spectral fit {passes}"
        cf = fit_coupling(
            current,
            targets,
            coupling,
            protocols=protocols,
            cluster=cluster,
            coarse=passes == 1,
            progress=progress.candidates(stage),
        )
        current = with_parameters(current, cf.values)
        timings["spectral_fit"] += time.perf_counter() - t0
        evaluations["spectral"] += cf.n_candidates
        progress.done(stage, f"{cf.n_candidates} candidates, violation {cf.score:.3g}")
        kept = all(abs(cf.values[n] - previous[n]) <= 1e-9 for n in coupling)
        converged = kept and cf.converged
        if kept:
            break
        previous = cf.values
    converged = converged and ambient_solved
    # imported here: ``python -m trms.calibration.evidence`` runs that module, which the package must not import first
    from trms.calibration.evidence import measured, measured_large_signal, measured_static_pitch

    t0 = time.perf_counter()
    progress.update("verification", 0.0, "thesis protocol runs")
    if targets.source == "thesis" and tuple(protocols) == THESIS_PROTOCOLS and tuple(seeds) == VERIFY_SEEDS:
        ver = measured(current, side_peaks=False)[0]  # the thesis's verification: computed once per model and code
    else:
        ver = verify(current, targets, protocols, seeds=seeds)
    timings["verification"] = time.perf_counter() - t0
    progress.done("verification", f"{sum(c.met for c in ver.checks)}/{len(ver.checks)} targets met")
    unreachable = []
    missed = {(row["name"], row["target"]) for row in ver.summary() if not row["met"]}
    misses: dict[tuple[str, float], list] = {}
    for c in ver.checks:
        if not c.met and (c.name, c.target) in missed:
            misses.setdefault((c.name, c.target), []).append(c)
    for (name, target), checks in misses.items():
        structural = any(
            targets.peaks[i].name == name and targets.peaks[i].frequency_hz == target for i in unreachable_idx
        )
        why = (
            "no mode of the model is left to put there (a parameter set moves modes, it cannot add one)"
            if structural
            else "outside its tolerance at the best parameters the fit found within their bounds"
        )
        unit = checks[0].unit
        got = ", ".join(f"{c.achieved:.4g}" + (f" (seed {c.seed})" if c.seed is not None else "") for c in checks)
        unreachable.append(f"{name} = {target:g} {unit}: achieved {got} {unit} ({why})")
    t0 = time.perf_counter()
    large = measured_large_signal(current)  # stored with the thesis's verification, else measured now
    timings["large_signal"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    static = measured_static_pitch(current)  # the same
    timings["static_pitch"] = time.perf_counter() - t0
    return CalibrationResult(
        start,
        read_parameters(current, names),
        ver,
        unreachable,
        timings,
        targets,
        passes,
        evaluations,
        large,
        converged,
        static,
    )
