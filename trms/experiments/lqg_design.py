"""One integral LQG design for given weights, as data: gains, poles, estimator and prefilter
(the JSON of ``trms design``).

The design model is eq. (3.11) for ``1dof`` (the thesis's) or the reduced twin model for ``2dof``
(:func:`trms.worlds.design_model`); the estimator is the thesis's current estimator with ``Qe = I``,
``Re = 1`` (:data:`trms.experiments.ch67_lqg.ESTIMATOR_QE`); a CSAS case adds its command prefilter
(:func:`trms.experiments.ch67_lqg.prefilters`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import control
import numpy as np

from trms.control.lqg import LQGDesign, design_lqg
from trms.control.shaping import CommandFilter
from trms.errors import InputError
from trms.experiments.ch67_lqg import ESTIMATOR_QE, ESTIMATOR_RE, prefilters
from trms.worlds import design_model

__all__ = ["IntegralDesign", "integral_design"]


@dataclass(frozen=True)
class IntegralDesign:
    """An integral LQG designed on a configuration's design model, with its prefilter.

    Attributes
    ----------
    config : str
        ``1dof`` or ``2dof``.
    q, r : float
        The weights ``Q = q I``, ``R = r I``.
    model : control.StateSpace
        The design model (deviations: V in, rad out).
    design : LQGDesign
        Gains, estimator and poles.
    prefilter : CommandFilter or None
        The CSAS command prefilter; ``None`` for SAS.
    """

    config: str
    q: float
    r: float
    model: control.StateSpace
    design: LQGDesign
    prefilter: CommandFilter | None

    def to_dict(self) -> dict[str, Any]:
        """The design as JSON-ready data: weights, design model matrices and states, ``K``, ``Lc``, regulator and
        estimator poles as ``[real, imag]`` pairs, whether the estimator is faster, the prefilter's sections.

        Examples
        --------
        >>> d = integral_design("1dof", 1.0, 125.0).to_dict()
        >>> np.array(d["K"]).shape, d["prefilter"], d["estimator_faster"]
        ((1, 5), None, True)
        """
        z = lambda v: [[float(c.real), float(c.imag)] for c in v]  # noqa: E731
        m, d, f = self.model, self.design, self.prefilter
        return {
            "config": self.config,
            "sample_time": d.sample_time,
            "Q": float(self.q),
            "R": float(self.r),
            "design_model": {
                "A": np.asarray(m.A).tolist(),
                "B": np.asarray(m.B).tolist(),
                "C": np.asarray(m.C).tolist(),
                "states": list(m.state_labels),
            },
            "K": d.K.tolist(),
            "Lc": d.Lc.tolist(),
            "regulator_poles": z(d.regulator_poles),
            "estimator_poles": z(d.estimator_poles),
            "estimator_faster": d.estimator_faster,
            "prefilter": None if f is None else {"name": f.name, "sos": f.sos.tolist()},
        }


def integral_design(config: str, q: float, r: float, case: str = "SAS") -> IntegralDesign:
    """Design the integral LQG on ``config``'s design model with ``Q = q I``, ``R = r I``, and ``case``'s prefilter.

    Parameters
    ----------
    config : {"1dof", "2dof"}
    q, r : float
        State and control weights (``q > 0`` keeps integral action, ``r > 0``).
    case : str
        ``SAS`` (no prefilter) or a CSAS case of :func:`trms.experiments.ch67_lqg.prefilters`,
        e.g. ``"CSAS LPF 0.2 Hz"``.

    Returns
    -------
    IntegralDesign

    Raises
    ------
    InputError
        An unknown case, or weights the design refuses (one line).

    Examples
    --------
    >>> integral_design("1dof", 1.0, 75.0, "CSAS LPF 0.2 Hz").prefilter.name[:23]
    'Butterworth LPF order 2'
    """
    model = design_model(config)
    design = design_lqg(model, Q=q, R=r, Qe=ESTIMATOR_QE, Re=ESTIMATOR_RE)
    filt = None
    if case != "SAS":
        table = prefilters(model.dt)
        if case not in table:
            raise InputError(f"unknown case {case!r}; allowed: {', '.join(repr(c) for c in table)}")
        filt = table[case]
    return IntegralDesign(config, q, r, model, design, filt)
