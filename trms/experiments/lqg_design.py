"""One integral LQG design for given weights, as data: gains, poles, estimator and prefilter
(the JSON of ``trms design``), and back (:func:`design_from_dict`, what ``trms run --design`` flies).

The design model is eq. (3.11) for ``1dof`` (the thesis's) or the reduced twin model for ``2dof``
(:func:`trms.worlds.design_model`); the weights are ``Q = q I``, ``R = r I``, or for ``2dof`` without them the
autopilot's per-channel weights (:func:`trms.experiments.ch8_mimo_lqg.weights`,
:func:`~trms.experiments.ch8_mimo_lqg.control_weights`); the estimator is the thesis's current estimator with
``Qe = I``, ``Re = 1`` (:data:`trms.experiments.ch67_lqg.ESTIMATOR_QE`); a CSAS case adds its command prefilter
(:func:`trms.experiments.ch67_lqg.prefilters`).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import control
import numpy as np

from trms.control.lqg import LQGDesign, design_lqg
from trms.control.shaping import CommandFilter
from trms.errors import InputError
from trms.experiments.ch67_lqg import ESTIMATOR_QE, ESTIMATOR_RE, prefilters
from trms.worlds import design_model

__all__ = ["IntegralDesign", "integral_design", "design_from_dict"]


@dataclass(frozen=True)
class IntegralDesign:
    """An integral LQG designed on a configuration's design model, with its prefilter.

    Attributes
    ----------
    config : str
        ``1dof`` or ``2dof``.
    q, r : float or None
        The weights ``Q = q I``, ``R = r I`` (None: the autopilot's per-channel weights, ``2dof``).
    model : control.StateSpace
        The design model (deviations: V in, rad out).
    design : LQGDesign
        Gains, estimator and poles.
    prefilter : CommandFilter or None
        The CSAS command prefilter; ``None`` for SAS.
    """

    config: str
    q: float | None
    r: float | None
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
            "Q": float(self.q) if self.q is not None else d.Q.tolist(),
            "R": float(self.r) if self.r is not None else d.R.tolist(),
            "weights": "Q = q I, R = r I" if self.q is not None else "the autopilot's per-channel weights",
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


def integral_design(config: str, q: float | None = None, r: float | None = None, case: str = "SAS") -> IntegralDesign:
    """Design the integral LQG on ``config``'s design model with ``Q = q I``, ``R = r I``, and ``case``'s prefilter.

    Parameters
    ----------
    config : {"1dof", "2dof"}
    q, r : float, optional
        State and control weights (``q > 0`` keeps integral action, ``r > 0``); without them, ``1dof`` takes
        ``q = 1``, ``r = 125`` and ``2dof`` the autopilot's per-channel weights (both or neither).
    case : str
        ``SAS`` (no prefilter) or a CSAS case of :func:`trms.experiments.ch67_lqg.prefilters`,
        e.g. ``"CSAS LPF 0.2 Hz"``.

    Returns
    -------
    IntegralDesign

    Raises
    ------
    InputError
        An unknown case, one weight without the other on ``2dof``, or weights the design refuses (one line).

    Examples
    --------
    >>> integral_design("1dof", 1.0, 75.0, "CSAS LPF 0.2 Hz").prefilter.name[:23]
    'Butterworth LPF order 2'
    >>> from trms.experiments.ch8_mimo_lqg import controllers
    >>> auto = integral_design("2dof").design
    >>> bool(np.array_equal(auto.K, controllers(design_model("2dof"))["MIMO LQG"].design.K))
    True
    """
    model = design_model(config)
    if config == "2dof" and (q is None) != (r is None):
        raise InputError("give both --q and --r (Q = q I, R = r I) or neither (the autopilot's per-channel weights)")
    if config == "2dof" and q is None:
        from trms.experiments.ch8_mimo_lqg import control_weights, weights

        Q: float | np.ndarray = weights(model)
        R: float | np.ndarray = control_weights()
    else:
        q = 1.0 if q is None else q
        r = 125.0 if r is None else r
        Q, R = q, r
    design = design_lqg(model, Q=Q, R=R, Qe=ESTIMATOR_QE, Re=ESTIMATOR_RE)
    filt = None
    if case != "SAS":
        table = prefilters(model.dt)
        if case not in table:
            raise InputError(f"unknown case {case!r}; allowed: {', '.join(repr(c) for c in table)}")
        filt = table[case]
    return IntegralDesign(config, q, r, model, design, filt)


def design_from_dict(data: Mapping[str, Any]) -> LQGDesign:
    """The integral LQG a ``trms design`` JSON holds (:meth:`IntegralDesign.to_dict`), re-designed from its weights on
    its configuration's design model and checked against its gains: a file whose model or gains do not match what
    its weights give here (another model, an edited gain) is refused in one line.

    Raises
    ------
    InputError
        Missing keys, or a model or gains that do not match.

    Examples
    --------
    >>> d = integral_design("2dof")
    >>> bool(np.array_equal(design_from_dict(d.to_dict()).K, d.design.K))
    True
    >>> bad = dict(d.to_dict(), K=np.zeros_like(d.design.K).tolist())
    >>> design_from_dict(bad)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    trms.errors.InputError: the design's gains K differ from what its weights give on the 2dof design model ...
    """
    try:
        config = str(data["config"])
        Q, R, K, stored = data["Q"], data["R"], np.asarray(data["K"], float), data["design_model"]
    except (KeyError, TypeError, ValueError) as exc:
        raise InputError(f"not a trms design file: {exc!s:.80} (missing or unreadable)") from None
    if config not in ("1dof", "2dof"):
        raise InputError(f"the design's config {config!r} is not one of '1dof', '2dof'")
    model = design_model(config)
    A = np.asarray(stored.get("A"), float) if isinstance(stored, Mapping) else None
    if A is None or A.shape != np.asarray(model.A).shape or not np.allclose(A, model.A, rtol=1e-9, atol=1e-12):
        raise InputError(
            f"the design was made on another {config} design model than this twin's (a recalibrated model?); "
            "design it again with trms design"
        )
    design = design_lqg(model, Q=np.asarray(Q, float), R=np.asarray(R, float), Qe=ESTIMATOR_QE, Re=ESTIMATOR_RE)
    if K.shape != design.K.shape or not np.allclose(K, design.K, rtol=1e-8, atol=1e-10):
        diff = float(np.max(np.abs(K - design.K))) if K.shape == design.K.shape else float("inf")
        raise InputError(
            f"the design's gains K differ from what its weights give on the {config} design model (largest "
            f"difference {diff:.3g}); was the file edited? Design it again with trms design"
        )
    return design
