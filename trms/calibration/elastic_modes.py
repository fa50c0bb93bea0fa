"""The thesis's 0.25 and 0.46 Hz "modes" of the 1-DOF pitch PSD, settled by measurement.

The thesis reads three peaks off the 1-DOF pitch spectrum (0.25, 0.34 and 0.46 Hz) and a
fourth-order ARMAX with one lightly damped pair (eq. 3.11, 0.342 Hz). Two questions decide
whether the twin should carry a 0.25 Hz mode:

1. **Could the thesis's estimator have produced the side peaks from a one-mode rig?**
   :func:`estimator_statistics` runs the 1-DOF protocol on the twin (one lightly damped mode)
   at many seeds and counts how often a peak at least 1 dB prominent appears within
   +-0.03 Hz of 0.25 and of 0.46 Hz, in a full-record periodogram of the thesis's 60 s at
   10 Hz (0.017 Hz bins, no averaging), in a single 256-sample periodogram (0.039 Hz bins,
   the resolution of the thesis's plots) and with Welch averaging (256-sample segments).
2. **Is there a physically defensible place for a sub-Hz elastic mode?**
   :func:`structural_candidates` builds the compliant elements one could add to the rig --
   a soft beam root, a counterweight on its own hinge, soft motor-pod mounts, a compliant
   yaw lock in 1-DOF -- each with the stiffness that puts a mode at 0.25 Hz, and measures
   what that costs: the modes it gives, how far the compliant joint deflects per volt of
   main-rotor input (a rig that bends radians per volt is not the rig), and which of its
   sub-Hz modes appear in 2-DOF, where Table 3.1 lists only 0.1 and 0.34 Hz.

Both run in the calibration report, on the model being calibrated.
"""

from __future__ import annotations

import functools
import re
from collections.abc import Sequence
from dataclasses import dataclass

import mujoco
import numpy as np
import scipy.optimize
import scipy.signal

from trms.calibration.targets import SIDE_PEAKS_HZ
from trms.errors import TrmsError
from trms.identification import spectral
from trms.measurement.protocol import THESIS_PROTOCOLS, repeated_records
from trms.twin.twin import Twin

__all__ = [
    "EstimatorStatistics",
    "estimator_statistics",
    "StructuralCandidate",
    "structural_candidates",
    "CANDIDATES",
    "side_peak_evidence",
    "format_evidence",
]

#: The window a side peak must fall in (+-Hz).
WINDOW_HZ = 0.03


@dataclass(frozen=True)
class EstimatorStatistics:
    """How often each side peak appears in the twin's 1-DOF pitch spectra, by estimator.

    ``rates[estimator][f]`` is the fraction of ``n_seeds`` runs with a >= 1 dB peak within
    +-``WINDOW_HZ`` of ``f`` (Hz); ``both[estimator]`` the fraction with both side peaks at once.

    Parameters
    ----------
    n_seeds : int
        Runs counted.
    rates : dict of str to dict of float to float
        Per estimator, per side peak (Hz), the fraction of runs showing it.
    both : dict of str to float
        Per estimator, the fraction of runs showing both.

    Examples
    --------
    >>> s = EstimatorStatistics(2, {"Welch": {0.25: 0.5, 0.46: 0.0}}, {"Welch": 0.0})
    >>> s.to_dict()["rates"]
    {'Welch': {'0.25': 0.5, '0.46': 0.0}}
    """

    n_seeds: int
    rates: dict[str, dict[float, float]]
    both: dict[str, float]

    def to_dict(self) -> dict:
        """JSON-serialisable form."""
        return {
            "n_seeds": self.n_seeds,
            "window_hz": WINDOW_HZ,
            "rates": {e: {f"{f:g}": r for f, r in d.items()} for e, d in self.rates.items()},
            "both": self.both,
        }


def _has_peak(f: np.ndarray, p: np.ndarray, target: float) -> bool:
    found = spectral.find_modes(f, p, (0.02, 1.0), min_prominence_db=1.0)
    return any(abs(pk.frequency - target) <= WINDOW_HZ for pk in found)


def estimator_statistics(spec: mujoco.MjSpec, seeds: Sequence[int] = range(1000, 1100)) -> EstimatorStatistics:
    """Count side peaks in the twin's 1-DOF protocol spectra at ``seeds`` (see the module docstring).

    Examples
    --------
    >>> from trms.twin import load_spec
    >>> s = estimator_statistics(load_spec(), seeds=range(3))
    >>> sorted(s.rates)
    ['Welch, 256-sample segments', 'full-record periodogram', 'single 256-sample periodogram']
    """
    protocol = next(p for p in THESIS_PROTOCOLS if p.config == "1dof")
    seeds = [int(s) for s in seeds]
    records = repeated_records(spec, protocol, seeds)
    estimators = {
        "full-record periodogram": lambda y, fs: scipy.signal.periodogram(y, fs, window="hann"),
        "single 256-sample periodogram": lambda y, fs: scipy.signal.periodogram(y[:256], fs, window="hann"),
        "Welch, 256-sample segments": lambda y, fs: scipy.signal.welch(y, fs, nperseg=256),
    }
    hits = {e: {f: 0 for f in SIDE_PEAKS_HZ} for e in estimators}
    both = {e: 0 for e in estimators}
    for rec in records:
        _, dy = rec.deviations()
        y = dy[:, 0] - dy[:, 0].mean()
        for name, estimate in estimators.items():
            f, p = estimate(y, 1.0 / rec.sample_time)
            found = [_has_peak(f[1:], p[1:], target) for target in SIDE_PEAKS_HZ]
            for target, ok in zip(SIDE_PEAKS_HZ, found):
                hits[name][target] += ok
            both[name] += all(found)
    n = len(records)
    return EstimatorStatistics(
        n, {e: {f: h / n for f, h in d.items()} for e, d in hits.items()}, {e: b / n for e, b in both.items()}
    )


# ----------------------------------------------------------------------------------- structures
@dataclass(frozen=True)
class StructuralCandidate:
    """A compliant element tuned to put a mode at 0.25 Hz, and what it costs.

    Attributes
    ----------
    name : str
        The candidate (one of :data:`CANDIDATES`).
    joint : str
        The compliant joint added (or softened).
    stiffness : float
        Its stiffness (N m/rad) for a mode at 0.25 Hz; NaN when none in the searched range does.
    modes_1dof_hz : list of float
        1-DOF modes below 1 Hz with it.
    deflection_per_volt : float
        Static deflection of the compliant joint per volt of main-rotor input at hover (rad/V).
    modes_2dof_hz : list of float
        2-DOF modes below 1 Hz with it (Table 3.1: 0.1 and 0.34 Hz only).
    reached : bool
        Whether any stiffness puts a new mode within 0.005 Hz of the target (if not, the
        figures are those of the closest stiffness found).

    Examples
    --------
    >>> c = StructuralCandidate("soft beam root", "main_flex1", 38.1, [0.357], 0.0106, [0.1, 0.358], False)
    >>> c.to_dict()["stiffness_n_m_per_rad"], c.to_dict()["reached"]
    (38.1, False)
    """

    name: str
    joint: str
    stiffness: float
    modes_1dof_hz: list[float]
    deflection_per_volt: float
    modes_2dof_hz: list[float]
    reached: bool = True

    def to_dict(self) -> dict:
        """JSON-serialisable form."""
        return {
            "name": self.name,
            "joint": self.joint,
            "stiffness_n_m_per_rad": self.stiffness,
            "modes_1dof_hz": self.modes_1dof_hz,
            "deflection_rad_per_volt": self.deflection_per_volt,
            "modes_2dof_hz": self.modes_2dof_hz,
            "reached": self.reached,
        }


def _wrap(xml: str, pattern: str, body: str, joint: str, axis: str, pos: str) -> str:
    """Move the elements matching ``pattern`` (consecutive lines) into a new body with a hinge ``joint``."""
    match = re.search(pattern, xml, re.S)
    if match is None:
        raise ValueError(f"pattern {pattern!r} not in the model")
    inner = match.group(0)
    new = (
        f'<body name="{body}" pos="{pos}"><joint name="{joint}" type="hinge" axis="{axis}" stiffness="1" '
        f'damping="0.001"/>{_shift(inner, pos)}</body>'
    )
    return xml[: match.start()] + new + xml[match.end() :]


def _shift(inner: str, pos: str) -> str:
    """Express the ``pos`` attributes of ``inner`` relative to ``pos`` (the new body's origin)."""
    origin = np.array([float(x) for x in pos.split()])

    def one(m: re.Match) -> str:
        p = np.array([float(x) for x in m.group(1).split()]) - origin
        return f'pos="{" ".join(f"{x:.6g}" for x in p)}"'

    return re.sub(r'pos="([^"]*)"', one, inner)


def _candidate_xml(xml: str, name: str) -> tuple[str, str, str]:
    """(modified MJCF, compliant joint, configuration it lives in) for a candidate."""
    if name == "soft beam root":
        return xml, "main_flex1", "1dof"
    if name == "counterweight hinge":
        pattern = r'<geom name="counterweight_arm"[^>]*/>\s*<geom name="counterweight"[^>]*/>'
        return _wrap(xml, pattern, "cw_body", "cw_hinge", "0 -1 0", "0 0 0"), "cw_hinge", "1dof"
    if name == "soft motor-pod mount":
        pattern = r'<geom name="main_motor".*?</body>'
        return _wrap(xml, pattern, "main_pod", "pod_hinge", "0 -1 0", "0.08 0 0"), "pod_hinge", "1dof"
    if name == "compliant yaw lock":
        return xml, "yaw", "1dof"
    raise ValueError(f"unknown candidate {name!r}")


#: The structural candidates measured.
CANDIDATES = ("soft beam root", "counterweight hinge", "soft motor-pod mount", "compliant yaw lock")


def _with_stiffness(xml: str, joint: str, k: float, config: str) -> tuple[mujoco.MjSpec, str]:
    spec = mujoco.MjSpec.from_string(xml)
    j = spec.joint(joint)
    j.stiffness[0] = k
    if joint == "yaw" and config == "1dof":
        return spec, "2dof"  # the lock becomes a spring: the yaw joint stays, its stiffness is the lock's
    return spec, config


def _modes(spec: mujoco.MjSpec, config: str) -> list[float]:
    return sorted(m.frequency_hz for m in Twin(config, 0.1, spec=spec).modes() if m.frequency_hz < 1.0)


def _new_mode_error(
    log_k: float, *, xml: str, joint: str, config: str, base: Sequence[float], target_hz: float
) -> float:
    """Distance (Hz) from ``target_hz`` of the nearest mode below 1 Hz that the rig had not had before.

    ``log_k`` is the natural log of the candidate joint's stiffness, ``base`` the rig's modes (Hz) without it.
    """
    s, c = _with_stiffness(xml, joint, float(np.exp(log_k)), config)
    try:
        modes = _modes(s, c)
    except TrmsError:  # too soft to hold the beam flat at any voltage
        return np.inf
    new = [f for f in modes if all(abs(f - b) > 0.015 for b in base)]
    return min((abs(f - target_hz) for f in new), default=np.inf)


def structural_candidates(
    spec_xml: str, target_hz: float = SIDE_PEAKS_HZ[0], names: Sequence[str] = CANDIDATES
) -> list[StructuralCandidate]:
    """Tune each candidate's stiffness for a mode at ``target_hz`` and measure it (module docstring).

    Parameters
    ----------
    spec_xml : str
        The MJCF text of the model (e.g. ``spec.to_xml()``).
    target_hz : float
        The mode's frequency (Hz).
    names : sequence of str
        Candidates from :data:`CANDIDATES`.

    Returns
    -------
    list of StructuralCandidate

    Examples
    --------
    >>> from trms.twin import load_spec
    >>> (c,) = structural_candidates(load_spec().to_xml(), names=("soft beam root",))
    >>> c.joint, c.stiffness > 0
    ('main_flex1', True)
    """
    out = []
    for name in names:
        xml, joint, config = _candidate_xml(spec_xml, name)

        base = _modes(mujoco.MjSpec.from_string(spec_xml), "2dof" if joint == "yaw" else config)

        error = functools.partial(_new_mode_error, xml=xml, joint=joint, config=config, base=base, target_hz=target_hz)
        grid = np.linspace(np.log(1e-4), np.log(50.0), 25)
        values = np.array([error(g) for g in grid])
        k, reached = float("nan"), False
        i = int(np.argmin(values))
        if np.isfinite(values[i]):
            lo, hi = grid[max(i - 1, 0)], grid[min(i + 1, grid.size - 1)]
            sol = scipy.optimize.minimize_scalar(error, bounds=(lo, hi), method="bounded", options={"xatol": 1e-4})
            best = sol.x if sol.fun <= values[i] else grid[i]
            k = float(np.exp(best))
            reached = bool(error(best) <= 0.005)
        if not np.isfinite(k):
            out.append(StructuralCandidate(name, joint, k, [], float("nan"), [], False))
            continue
        s, c = _with_stiffness(xml, joint, k, config)
        twin = Twin(c, 0.1, spec=s)
        lin = twin.linearise()
        A, B = np.asarray(lin.continuous.A), np.asarray(lin.continuous.B)
        steady = -np.linalg.solve(A, B[:, 0])  # static state change per volt of u1
        deflection = float(steady[lin.state_names.index(joint)])
        # In 2-DOF the yaw lock is released, so that candidate leaves the 2-DOF rig as it is.
        two = _modes(mujoco.MjSpec.from_string(spec_xml) if joint == "yaw" else s, "2dof")
        out.append(StructuralCandidate(name, joint, k, _modes(s, c), deflection, two, reached))
    return out


def side_peak_evidence(
    spec: mujoco.MjSpec, seeds: Sequence[int] = range(1000, 1100), candidates: Sequence[str] = CANDIDATES
) -> dict:
    """Both measurements of the module docstring, as one JSON-serialisable dict (the calibration report's section).

    Parameters
    ----------
    spec : mujoco.MjSpec
        The model.
    seeds : sequence of int
        Seeds of the 1-DOF protocol runs whose spectra are counted.
    candidates : sequence of str
        Compliant elements tuned (:data:`CANDIDATES`).

    Returns
    -------
    dict
        ``estimator_statistics`` (:meth:`EstimatorStatistics.to_dict`) and ``structural_candidates``
        (:meth:`StructuralCandidate.to_dict` each).

    Examples
    --------
    >>> from trms.twin import load_spec
    >>> ev = side_peak_evidence(load_spec(), seeds=range(2), candidates=("soft beam root",))
    >>> ev["estimator_statistics"]["n_seeds"], [c["name"] for c in ev["structural_candidates"]]
    (2, ['soft beam root'])
    """
    stats = estimator_statistics(spec, seeds)
    structures = structural_candidates(spec.to_xml(), names=candidates)
    return {"estimator_statistics": stats.to_dict(), "structural_candidates": [s.to_dict() for s in structures]}


def format_evidence(evidence: dict) -> str:
    """The evidence as two Markdown tables.

    Parameters
    ----------
    evidence : dict
        What :func:`side_peak_evidence` returned.

    Returns
    -------
    str
        The side peaks' rates by estimator (%), and each compliant element's stiffness (N m/rad), modes (Hz)
        and deflection per volt (rad/V).

    Examples
    --------
    >>> stats = EstimatorStatistics(2, {"Welch": {0.25: 0.5, 0.46: 0.0}}, {"Welch": 0.0})
    >>> c = StructuralCandidate("soft beam root", "main_flex1", 38.1, [0.357], 0.0106, [0.1, 0.358], False)
    >>> table = format_evidence({"estimator_statistics": stats.to_dict(), "structural_candidates": [c.to_dict()]})
    >>> print(table.splitlines()[4])
    | Welch | 50 % | 0 % | 0 % |
    """
    stats = evidence["estimator_statistics"]
    lines = [
        f"Side peaks in the twin's 1-DOF pitch PSD over {stats['n_seeds']} seeds (a >= 1 dB peak within "
        f"+-{stats['window_hz']:g} Hz):",
        "",
        "| estimator | " + " | ".join(f"{f} Hz" for f in next(iter(stats["rates"].values()))) + " | both |",
        "|---|" + "---|" * (len(next(iter(stats["rates"].values()))) + 1),
    ]
    for name, rates in stats["rates"].items():
        lines.append(
            f"| {name} | "
            + " | ".join(f"{100 * r:.0f} %" for r in rates.values())
            + f" | {100 * stats['both'][name]:.0f} % |"
        )
    lines += [
        "",
        f"Compliant elements tuned for a {SIDE_PEAKS_HZ[0]:g} Hz mode:",
        "",
        "| candidate | stiffness (N m/rad) | 1-DOF modes < 1 Hz | deflection per volt (rad/V) | 2-DOF modes < 1 Hz |",
        "|---|---|---|---|---|",
    ]
    for c in evidence["structural_candidates"]:
        modes1 = ", ".join(f"{f:.3f}" for f in c["modes_1dof_hz"]) or "-"
        modes2 = ", ".join(f"{f:.3f}" for f in c["modes_2dof_hz"]) or "-"
        missed = "" if c["reached"] else f" (no {SIDE_PEAKS_HZ[0]:g} Hz mode reached)"
        k = f"{c['stiffness_n_m_per_rad']:.3g}{missed}"
        lines.append(f"| {c['name']} | {k} | {modes1} | {c['deflection_rad_per_volt']:.3g} | {modes2} |")
    return "\n".join(lines)
