"""Large signals: the twin's pitch steps from hover beside Feedback's published nonlinear model.

Small-signal fidelity (eq. 3.11) must not cost large-signal sense. Three 1-DOF steps from
hover are run on the twin and on the published model (:mod:`trms.twin.published`):
+-10 V (the time to pass +-1 rad: how fast full thrust throws the beam) and a +0.5 V step
(where it settles and how far it overshoots). The twin's input gain per volt is calibrated
to the thesis's DC gain, which is larger than the published model's; the +0.5 V step is
therefore also compared at the *equivalent* input, ``0.5 V x k_published / k_twin``, the
step that asks the twin's main rotor for the same change of rotor state as 0.5 V asks of
the published rotor. The published model has no transport delay, the twin has the rig's
(its phase needs it: :mod:`trms.calibration.fit`), so the times to pass +-1 rad are also
given from the end of the twin's delay (its ``input_delay``, read from the model in the run).
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np

from trms.twin.published import PUBLISHED, StepResponse, pitch_step
from trms.twin.twin import Twin

__all__ = ["LargeSignalCheck", "large_signal_checks", "twin_pitch_step", "TOLERANCE"]

#: Relative tolerance of every large-signal comparison.
TOLERANCE = 0.30


@dataclass(frozen=True)
class LargeSignalCheck:
    """One large-signal figure of the twin beside the published model's.

    Parameters
    ----------
    name : str
        The figure.
    published, twin : float
        Its value on the published model and on the twin (in ``unit``).
    unit : str
        Their unit (s or rad).

    Examples
    --------
    >>> c = LargeSignalCheck("settled pitch after a +0.5 V step", 0.4, 0.48, "rad")
    >>> round(c.ratio, 2), c.met
    (1.2, True)
    """

    name: str
    published: float
    twin: float
    unit: str

    @property
    def ratio(self) -> float:
        """twin / published."""
        return self.twin / self.published if self.published else float("nan")

    @property
    def met(self) -> bool:
        """Within :data:`TOLERANCE` of the published value."""
        return bool(np.isfinite(self.ratio) and abs(self.ratio - 1.0) <= TOLERANCE)

    @classmethod
    def from_dict(cls, data: dict) -> LargeSignalCheck:
        """From :meth:`to_dict`'s form (its derived fields are recomputed).

        Examples
        --------
        >>> c = LargeSignalCheck("settled pitch after a +0.5 V step", 0.4, 0.48, "rad")
        >>> LargeSignalCheck.from_dict(c.to_dict()) == c
        True
        """
        return cls(str(data["name"]), float(data["published"]), float(data["twin"]), str(data["unit"]))

    def to_dict(self) -> dict:
        """JSON-serialisable form."""
        return {
            "name": self.name,
            "published": self.published,
            "twin": self.twin,
            "unit": self.unit,
            "ratio": self.ratio,
            "met": self.met,
            "tolerance": f"+-{100 * TOLERANCE:g} %",
        }


def twin_pitch_step(
    spec: mujoco.MjSpec, delta_volts: float, duration: float = 20.0, sample_time: float = 0.01
) -> StepResponse:
    """The 1-DOF twin's true pitch (rad from flat) after a main-rotor step of ``delta_volts`` from hover.

    Parameters
    ----------
    spec : mujoco.MjSpec
        The model.
    delta_volts : float
        The step from the hover voltage (V; the input saturates at the voltage limit).
    duration : float
        Length of the run (s).
    sample_time : float
        Sample time (s).

    Returns
    -------
    StepResponse
        Time (s) and the true pitch (rad), noise-free.

    Examples
    --------
    >>> from trms.twin import load_spec
    >>> step = twin_pitch_step(load_spec(), 0.5, duration=3.0)
    >>> len(step.time), bool(step.peak > 0)
    (300, True)
    """
    twin = Twin("1dof", sample_time, spec=spec, counts_per_rev=0)
    n = int(round(duration / sample_time))
    rec = twin.run(np.full((n, 1), twin.operating_point.inputs[0] + delta_volts))
    return StepResponse(rec.time, rec.extras["true_angles"][:, 0])


def large_signal_checks(spec: mujoco.MjSpec, duration: float = 20.0) -> list[LargeSignalCheck]:
    """The twin's large-signal figures beside the published model's (see the module docstring).

    Examples
    --------
    >>> from trms.twin import load_spec
    >>> [c.name for c in large_signal_checks(load_spec(), duration=5.0)][0]
    'time to pass +1 rad at +10 V'
    """
    twin = Twin("1dof", 0.1, spec=spec)
    k_ratio = PUBLISHED["k1"] / PUBLISHED["T10"] / twin.curves[0].k
    out = []
    for dv in (10.0, -10.0):
        # A step of +-10 V from hover saturates at the +-10 V limit on both: full voltage.
        pub, tw = pitch_step(dv, 3.0), twin_pitch_step(spec, dv, 3.0)
        sign = "+" if dv > 0 else "-"
        t_pub, t_twin = pub.time_to_pass(np.sign(dv)), tw.time_to_pass(np.sign(dv))
        out.append(LargeSignalCheck(f"time to pass {sign}1 rad at {sign}10 V", t_pub, t_twin, "s"))
        out.append(
            LargeSignalCheck(
                f"time to pass {sign}1 rad at {sign}10 V after the twin's {twin.input_delay:.3g} s transport delay",
                t_pub,
                t_twin - twin.input_delay,
                "s",
            )
        )
    pub = pitch_step(0.5, duration)
    for label, dv in (("a +0.5 V", 0.5), (f"an equivalent +{0.5 * k_ratio:.3g} V", 0.5 * k_ratio)):
        tw = twin_pitch_step(spec, dv, duration)
        out.append(LargeSignalCheck(f"settled pitch after {label} step", pub.final, tw.final, "rad"))
        out.append(LargeSignalCheck(f"peak pitch after {label} step", pub.peak, tw.peak, "rad"))
    return out
