"""Output-error and Box-Jenkins models by the prediction-error method (MATLAB ``oe``, ``bj``).

* output-error (OE): ``y = B / F u + e``; the prediction error is the simulation error
  ``y - B / F u``, so the fit targets the input-output dynamics alone and stays unbiased
  under any (coloured) output disturbance, at the price of an unmodelled noise spectrum;
* Box-Jenkins (BJ): ``y = B / F u + C / D e``; independent dynamics for the plant and the
  disturbance (ARMAX forces them to share the poles ``A``). With coloured disturbances
  that do not share the plant's poles, ARMAX of the true order is biased; BJ is not.

Both minimise the same criterion as :func:`trms.identification.linear.armax` with the same
damped Gauss-Newton search (:mod:`trms.identification.pem`) and return the same
:class:`~trms.identification.polynomial.PolynomialModel` (with ``F`` and ``D``), its
parameter covariance ``lambda (psi^T psi)^-1`` and :meth:`~PolynomialModel.to_tf`.

Initial estimates
-----------------
* ``B, F``: Steiglitz-McBride iterations: refit ARX of orders ``(nf, nb, nk)`` to ``y`` and
  ``u`` both filtered by the last ``1 / F`` (roots of ``F`` reflected into the unit circle),
  which converges to the output-error estimate for white noise;
* ``C, D`` (BJ): Hannan-Rissanen on the output-error residual ``v = y - B / F u``: a
  high-order AR fit gives innovations ``e``, then ``v`` is regressed on its own past (``D``)
  and the past innovations (``C``).

Multistart
----------
The criterion of OE and BJ has local minima (often with a spurious root of ``F`` near the unit
circle) in which a search from one start stops without a sign. The search is therefore run
from up to ``starts`` (default :data:`STARTS` = 4) initial estimates and the lowest loss is kept:

0. the Steiglitz-McBride estimate above;
1. the high-order ARX reduction: an ARX model of order 20 (fewer for short data) is simulated
   (its output without the noise) and ``(nb, nf, nk)`` fitted to that output by least squares;
2. the subspace start, structurally different from both: :func:`~trms.identification.subspace.n4sid`
   of order ``nf`` (the subspace model, ``refine="none"``), ``F`` its characteristic polynomial and ``B``
   refitted by least squares for that ``F``;
3. (BJ with ``nd > 0``) the same of order ``nf + nd``, the plant's and the noise's dynamics together,
   ``F`` from the ``nf`` modes that weigh most in its input-output response (:func:`_dominant_roots`).
   Where starts 0 and 1 lose a lightly damped slow mode (a spurious real pole or a heavily damped one
   in its place), the subspace models keep it: on two modes (0.1 and 0.34 Hz, zeta 0.03 and 0.05,
   Ts 0.2 s) under AR(1) noise at N = 300 and a signal-to-noise ratio of 3, 8 of 183 BJ fits from
   starts 0, 1 and two perturbations ended above the minimum a search from the truth reaches (by up
   to 10 %), 3 of them with no warning; with these starts, none (``benchmarks/bench_identification_mc.py
   --only bj``);
4. and on: seeded perturbations of start 0 (the roots of ``F`` moved inward and rotated, ``B``
   refitted by least squares for that ``F``).

When the structurally different searches (0 to 3) all end at the same minimum (losses within a
relative ``1e-5``, no root of ``F`` on the stability boundary) the perturbed starts are skipped, so
a fit costs three or four searches, and at most ``starts`` (two agreeing searches are no proof: both
can lose the slow mode the subspace start keeps). Each start's own loss is checked against the kept fit's: a
start that predicts better than the fit returned (its search failed) is a better point known, and
warned (:class:`LocalMinimumWarning`). Data whose ARX fit of orders ``(nf, nb, nk)`` has a pole outside the
unit circle are refused (an unstable plant, which no stable ``B / F`` describes), and so is a best
fit with a root of ``F`` on the stability boundary: the loss falls towards a pole on the unit
circle, as for a lightly damped mode that these data cannot tell from an unstable one (the message
says what to try).
"""

from __future__ import annotations

import functools
import warnings
from collections.abc import Callable, Iterable, Iterator, Mapping

import control
import numpy as np
import scipy.signal

from trms.errors import EstimationError, InputError, check_int
from trms.identification.data import SisoData, check_excitation, lag_matrix, siso_data
from trms.identification.linear import _check_size, _regressors, _solve_ls, _stabilise
from trms.identification.pem import _EXACT, MAX_ITER, Structure, check_search, fit, max_root
from trms.identification.polynomial import PolynomialModel
from trms.identification.subspace import UnstableModelWarning, n4sid
from trms.record import Record

__all__ = ["oe", "bj", "LocalMinimumWarning", "STARTS"]

#: Most Steiglitz-McBride iterations for the initial ``B, F``.
_SM_ITERATIONS = 30

#: Default number of starts of the search: Steiglitz-McBride, the high-order ARX reduction, the subspace start,
#: and the second subspace start (BJ with a noise denominator) or a seeded perturbation of the first (see the
#: module docstring).
STARTS = 4

#: OE's intervals are withheld below this many effective independent samples per parameter (see :func:`oe`).
MIN_EFFECTIVE_PER_PARAMETER = 20

#: Largest root radius of ``F`` in the subspace start (a lightly damped mode's pole lies close to the circle).
_SUBSPACE_RADIUS = 0.999

#: Seed of the perturbed starts (the fit is a deterministic function of the data and the orders).
_PERTURBATION_SEED = 0

#: Most iterations of a search from a start after the first (a search that creeps on beyond it, from a start far
#: from every minimum the others reach, is dropped: in the tests one such search ran 1000 iterations to no end).
_LATER_ITER = 200

#: A start whose search ends with a loss this much (relative) above the kept one ended at another minimum.
_WORSE = 0.01

#: Two searches whose losses differ by less than this (relative) ended at the same minimum.
_AGREE = 1e-5

#: A root of ``F`` at least this far out, where the search stopped for stability, is on the boundary.
_BOUNDARY = 0.999


class LocalMinimumWarning(UserWarning):
    """The first (Steiglitz-McBride) start of an OE/BJ search ended at a local minimum that another start beat."""


def _steiglitz_mcbride(d: SisoData, nb: int, nf: int, nk: int) -> np.ndarray:
    """Initial ``[b1..b_nb, f1..f_nf]``: ARX of ``(y, u)`` prefiltered by ``1 / F``, iterated."""
    start = max(nf, nk + nb - 1)
    f = np.ones(1)
    theta = np.zeros(nb + nf)
    for _ in range(_SM_ITERATIONS if nf else 1):
        yf, uf = scipy.signal.lfilter([1.0], f, d.y), scipy.signal.lfilter([1.0], f, d.u)
        phi = _regressors(SisoData(yf, uf, d.sample_time), nf, nb, nk, start)
        est = _solve_ls(phi, yf[start:], "initial Steiglitz-McBride ARX")
        f_new = _stabilise(np.concatenate([[1.0], est[:nf]]))
        theta_new = np.concatenate([est[nf:], f_new[1:]])
        done = np.allclose(theta_new, theta, rtol=1e-8, atol=1e-10)
        theta, f = theta_new, f_new
        if done:
            break
    return theta


def _high_order_start(d: SisoData, nb: int, nf: int, nk: int) -> np.ndarray:
    """Initial ``[b, f]`` from a high-order ARX model: an ARX model of orders ``(nf, nb, nk)`` fitted by
    least squares to its simulated output (nearly noise-free, so the equation error is nearly unbiased)."""
    high = int(min(max(20, 3 * (nb + nf)), max(nb + nf + 1, len(d) // 10)))
    start = max(high, nk + high - 1)
    if len(d) - start < 8 * high:
        raise EstimationError(f"{len(d)} samples are too few for a high-order ARX ({high}, {high}) start")
    theta = _solve_ls(_regressors(d, high, high, nk, start), d.y[start:], f"initial high-order ARX ({high}, {high})")
    a = _stabilise(np.concatenate([[1.0], theta[:high]]))
    b = np.concatenate([np.zeros(nk), theta[high:]])
    reduced = SisoData(scipy.signal.lfilter(b, a, d.u), d.u, d.sample_time)
    start = max(nf, nk + nb - 1)
    est = _solve_ls(_regressors(reduced, nf, nb, nk, start), reduced.y[start:], "reduction of the high-order ARX")
    return np.concatenate([est[nf:], _stabilise(np.concatenate([[1.0], est[:nf]]))[1:]])


def _subspace_start(d: SisoData, nb: int, nf: int, nk: int, nd: int = 0) -> np.ndarray:
    """Initial ``[b, f]`` from a state-space model: n4sid of order ``nf + nd`` (the plant's and the noise's
    dynamics; the subspace model, whose own refinement can lose a slow mode and costs more than the search it
    starts), ``F`` the ``nf`` modes that carry most of its input-output
    response (:func:`_dominant_roots`; roots reflected into the unit circle, at most 0.999) and ``B`` the
    least-squares fit of the output error for that ``F``. Order ``nf`` alone reads its horizon for orders up to
    ``nf`` (n4sid's default for ``max_order = nf``), ``nf + nd`` for orders up to 10."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UnstableModelWarning)
        model = n4sid(
            d.y, d.u, nf + nd, sample_time=d.sample_time, max_order=max(nf + nd, 1 if nd == 0 else 10), refine="none"
        )
    f = _stabilise(np.real(np.poly(_dominant_roots(model, nf))), radius=_SUBSPACE_RADIUS)
    return _numerator_for(d, f, nb, nf, nk, "subspace start")


def _dominant_roots(model: control.StateSpace, nf: int) -> np.ndarray:
    """The ``nf`` eigenvalues of ``A`` whose modes weigh most in the input-output response: each mode's residue
    ``|c_i b_i|`` over its distance ``1 - |lambda_i|`` from the unit circle (at least 1e-3), a complex pair kept
    or left out whole (a zero root fills a place no real mode is left for)."""
    lam, vec = np.linalg.eig(np.asarray(model.A, float))
    if lam.size <= nf:
        return lam
    residue = (np.asarray(model.C, float) @ vec).ravel() * np.linalg.solve(vec, np.asarray(model.B, float)).ravel()
    weight = np.abs(residue) / np.maximum(1.0 - np.abs(lam), 1e-3)
    kept: list[complex] = []
    for i in np.argsort(-weight):
        if lam[i].imag < 0:
            continue  # its conjugate (same weight) brings it
        pair = [lam[i], np.conj(lam[i])] if lam[i].imag > 0 else [lam[i]]
        if len(kept) + len(pair) <= nf:
            kept += pair
    return np.array(kept + [0.0] * (nf - len(kept)))


def _numerator_for(d: SisoData, f: np.ndarray, nb: int, nf: int, nk: int, what: str) -> np.ndarray:
    """``[b, f]`` with ``B`` the least-squares fit of the output error ``y - B / F u`` for the given ``F``."""
    start = max(nf, nk + nb - 1)
    uf = scipy.signal.lfilter([1.0], f, d.u)
    b = _solve_ls(lag_matrix(uf, range(nk, nk + nb), start), d.y[start:], what)
    return np.concatenate([b, f[1:]])


def _perturbed_start(d: SisoData, bf: np.ndarray, nb: int, nf: int, nk: int, rng: np.random.Generator) -> np.ndarray:
    """``[b, f]`` with the roots of ``F`` of ``bf`` moved inward (radius times 0.3-1) and rotated
    (+-0.3 rad, standard deviation), and ``B`` the least-squares fit of the output error for that ``F``."""
    roots = np.roots(np.concatenate([[1.0], bf[nb:]]))
    moved = roots * rng.uniform(0.3, 1.0) * np.exp(1j * np.sign(roots.imag) * rng.normal(0.0, 0.3))
    return _numerator_for(d, np.real(np.poly(moved)), nb, nf, nk, "perturbed start")


def _plant_starts(
    d: SisoData, nb: int, nf: int, nk: int, starts: int, nd: int = 0
) -> Iterator[tuple[np.ndarray, bool]]:
    """Up to ``starts`` initial ``[b, f]``, made when asked for, each with whether it is a perturbation:
    Steiglitz-McBride, the high-order ARX reduction, the subspace starts (of order ``nf``, and ``nf + nd`` for a
    noise denominator), then seeded perturbations of the first (only the first when ``nf = 0``: the fit is
    linear)."""
    first = _steiglitz_mcbride(d, nb, nf, nk)
    yield first, False
    if nf == 0:
        return
    made = 1
    makers = [_high_order_start, _subspace_start] + [functools.partial(_subspace_start, nd=nd)] * (nd > 0)
    for make in makers:
        if made >= starts:
            return
        try:
            other = make(d, nb, nf, nk)
        except (EstimationError, InputError, np.linalg.LinAlgError):
            continue  # too short, or dependent regressors (noise-free data of a low order): the other starts remain
        made += 1
        yield other, False
    rng = np.random.default_rng(_PERTURBATION_SEED)
    while made < starts:
        made += 1
        yield _perturbed_start(d, first, nb, nf, nk, rng), True


def _on_f_boundary(model: PolynomialModel) -> bool:
    """Whether the search stopped for stability with a root of ``F`` on the unit circle."""
    return bool(model.info["on_stability_boundary"]) and max_root(model.F) >= _BOUNDARY


def _check_stable_plant(d: SisoData, structure: Structure, name: str) -> None:
    """Refuse data whose ARX fit of orders ``(nf, nb, nk)`` has a pole outside the unit circle
    (beyond ``1 / _BOUNDARY``): an unstable plant, which no stable ``B / F`` simulates."""
    nb, nf, nk = structure.nb, structure.nf, structure.nk
    if nf == 0:
        return
    start = max(nf, nk + nb - 1)
    try:
        theta = _solve_ls(_regressors(d, nf, nb, nk, start), d.y[start:], "ARX check of the plant's stability")
    except EstimationError:
        return  # dependent regressors (noise-free data of a lower order): nothing to check
    pole = max_root(np.concatenate([[1.0], theta[:nf]]))
    if pole > 1.0 / _BOUNDARY:
        raise EstimationError(
            f"{name}: the data come from an unstable plant (an ARX fit of orders nf={nf}, nb={nb}, nk={nk} has a "
            f"pole at |z| = {pole:.4f}; an output-error model needs all |z| < 1): use arx or armax"
        )


def _agree(fits: list[PolynomialModel | None]) -> bool:
    """Whether the searches all ended at the same minimum (losses within ``_AGREE``), off the stability boundary."""
    if len(fits) < 2 or any(m is None or _on_f_boundary(m) for m in fits):
        return False
    losses = [m.loss for m in fits if m is not None]
    return max(losses) - min(losses) <= _AGREE * min(losses)


def _multistart(
    d: SisoData,
    structure: Structure,
    plant_starts: Iterable[tuple[np.ndarray, bool]],
    noise_start: Callable[[np.ndarray], np.ndarray],
    *,
    name: str,
    method: str,
    max_iter: int,
    tol: float,
    coloured: bool = False,
) -> PolynomialModel:
    """Search from every start (``[b, f]`` completed to ``[b, c, d, f]`` by ``noise_start``), keep the
    lowest loss; refuse a kept fit with ``F`` on the stability boundary.

    A start whose search fails (no convergence; a start after the first has at most :data:`_LATER_ITER`
    iterations) is dropped; if all fail, the first one's error is raised.
    :class:`LocalMinimumWarning` when a better point than the kept fit is known (a start whose own loss is
    lower: its search failed), or when the first start's search ended on the stability boundary or more
    than 1 % above the kept loss (a local minimum a single search would have returned).
    """
    _check_stable_plant(d, structure, name)
    nb = structure.nb
    exact = float(_EXACT**2 * (d.y @ d.y)) / max(len(d) - structure.start, 1)
    fits: list[PolynomialModel | None] = []
    own: list[float] = []  # each start's loss before its search (inf for an unstable predictor)
    first_error: EstimationError | None = None
    for bf, perturbed in plant_starts:
        if perturbed and _agree(fits):
            break  # the structurally different starts all end at the same interior minimum: no perturbation needed
        theta0 = np.concatenate([bf[:nb], noise_start(bf), bf[nb:]])
        eps0 = structure.errors(theta0, d) if structure.stable(theta0) else np.full(1, np.inf)
        own.append(float(eps0 @ eps0) / eps0.size)
        iterations = max_iter if not fits else min(max_iter, _LATER_ITER)
        try:
            model = fit(d, structure, theta0, name=name, method=method, max_iter=iterations, tol=tol, coloured=coloured)
        except EstimationError as exc:
            first_error = first_error or exc
            fits.append(None)
            continue
        fits.append(model)
        if model.loss <= exact:
            break  # an exact fit (noise-free data): no other start can do better
    done = [(m.loss, i) for i, m in enumerate(fits) if m is not None]
    if not done:
        assert first_error is not None
        raise first_error
    best = min(done)[1]
    kept = fits[best]
    assert kept is not None
    if _on_f_boundary(kept):
        alone = "; with starts = 1 the search may also have stopped at a local minimum" if len(fits) == 1 else ""
        inside = [(m.loss, i) for i, m in enumerate(fits) if m is not None and not _on_f_boundary(m)]
        interior = (
            f"; the best fit inside the boundary (start {min(inside)[1]}) has a loss "
            f"{100 * (min(inside)[0] / kept.loss - 1):.1f} % higher"
            if inside
            else ""
        )
        raise EstimationError(
            f"{name} ended on the stability boundary: the best fit of {len(fits)} start(s) has a root of F at "
            f"|z| = {max_root(kept.F):.4f} (a stable model needs |z| < 1){interior}: the loss keeps falling towards "
            f"a pole on the unit circle, as for a lightly damped or integrating mode these data cannot tell from an "
            f"unstable one, or an unstable plant; try a longer record or a larger input (a higher signal-to-noise "
            f"ratio), a lower nf, or a model that allows such a pole (arx, armax, n4sid){alone}"
        )
    losses = tuple(float("nan") if m is None else m.loss for m in fits)
    local = tuple(
        i
        for i, m in enumerate(fits)
        if m is not None and i != best and (m.loss > (1 + _WORSE) * kept.loss or _on_f_boundary(m))
    )
    kept.info.update(
        starts=len(fits), start_losses=losses, best_start=best, local_minima=local, initial_losses=tuple(own)
    )
    better = [i for i, loss in enumerate(own) if loss < kept.loss * (1 - _AGREE)]
    if better:
        i = min(better, key=own.__getitem__)
        warnings.warn(
            f"{name}: a better point than the fit returned is known: start {i}'s initial estimate has a loss "
            f"{own[i]:.4g} below the kept {kept.loss:.4g} (its search failed: {first_error}); the fit is at a local "
            "minimum: raise max_iter or check the orders",
            LocalMinimumWarning,
            stacklevel=3,
        )
    if 0 in local:
        first = fits[0]
        assert first is not None
        warnings.warn(
            f"{name}: the Steiglitz-McBride start ended at a local minimum (loss {first.loss:.4g}, "
            f"{100 * (first.loss / kept.loss - 1):.0f} % above the kept {kept.loss:.4g}; largest root of F "
            f"|z| = {max_root(first.F):.4f}); start {best} of {len(fits)} was kept",
            LocalMinimumWarning,
            stacklevel=3,
        )
    return kept


def _hannan_rissanen_arma(v: np.ndarray, nc: int, nd: int) -> np.ndarray:
    """Initial ``[c1..c_nc, d1..d_nd]`` of ``D v = C e`` (noise-free ``v`` gives ``C = D = 1``)."""
    if nc == 0 and nd == 0:
        return np.zeros(0)
    n = v.size
    high = int(min(max(20, 3 * max(nc, nd)), max(max(nc, nd) + 1, n // 10)))
    phi_hi = -lag_matrix(v, range(1, high + 1), high)
    if not np.any(phi_hi):
        return np.zeros(nc + nd)
    try:
        ar = _solve_ls(phi_hi, v[high:], f"initial high-order AR ({high}) of the noise")
    except EstimationError:
        return np.zeros(nc + nd)
    e_hat = np.zeros(n)
    e_hat[high:] = v[high:] - phi_hi @ ar
    s = high + nc
    phi = np.hstack([lag_matrix(e_hat, range(1, nc + 1), s), -lag_matrix(v, range(1, nd + 1), s)])
    try:
        cd = _solve_ls(phi, v[s:], "initial ARMA regression of the noise")
    except EstimationError:
        return np.zeros(nc + nd)
    c = _stabilise(np.concatenate([[1.0], cd[:nc]]))
    dd = _stabilise(np.concatenate([[1.0], cd[nc:]]))
    return np.concatenate([c[1:], dd[1:]])


def _prepare(
    data: Record | object,
    u: object | None,
    orders: Mapping[str, tuple[object, int]],
    sample_time: float | None,
    input: str | None,
    output: str | None,
    max_iter: object,
    tol: object,
) -> tuple[SisoData, dict[str, int], Structure, int, float]:
    """Data, checked orders (``nb nc nd nf nk``; absent ones 0), the structure and the search settings.

    Refuses orders the data cannot support and an input that does not excite ``nb + nf`` parameters.
    """
    d = siso_data(data, u, sample_time=sample_time, input=input, output=output)
    o = {"nc": 0, "nd": 0} | {name: check_int(name, value, low) for name, (value, low) in orders.items()}
    max_iter, tol = check_search(max_iter, tol)
    structure = Structure(0, o["nb"], o["nc"], o["nd"], o["nf"], o["nk"])
    _check_size(len(d), structure.start, structure.n_parameters, structure.describe())
    check_excitation(d.u, o["nb"] + o["nf"])
    return d, o, structure, max_iter, tol


def oe(
    data: Record | object,
    u: object | None = None,
    nb: int = 2,
    nf: int = 2,
    nk: int = 1,
    *,
    sample_time: float | None = None,
    input: str | None = None,
    output: str | None = None,
    max_iter: int = MAX_ITER,
    tol: float = 1e-7,
    starts: int = STARTS,
) -> PolynomialModel:
    """Output-error model ``y = B / F u + e`` by the prediction-error method (MATLAB ``oe``).

    Parameters
    ----------
    data : Record or array_like
        A Record (deviations are used) or the output ``y`` (shape ``(N,)``, output unit).
    u : array_like, optional
        Input with an array ``y`` (shape ``(N,)``, input unit, e.g. V).
    nb, nf, nk : int
        ``nb >= 1`` numerator coefficients, ``nf >= 0`` poles, input delay ``nk >= 0`` samples.
    sample_time : float, optional
        Seconds per sample (required with arrays).
    input, output : str, optional
        Channel names in a multi-channel Record.
    max_iter : int
        Most Gauss-Newton iterations (default :data:`~trms.identification.pem.MAX_ITER`).
    tol : float
        Convergence: the Gauss-Newton step's predicted relative decrease of the loss (as
        :func:`~trms.identification.linear.armax`).
    starts : int
        Initial estimates searched from, ``>= 1`` (module docstring, "Multistart"); ``1`` is the
        Steiglitz-McBride start alone. With ``nf = 0`` the fit is linear and one start is used.

    Returns
    -------
    PolynomialModel
        ``A = C = D = 1``, ``method = "oe-pem"``; the covariance of ``[b1..b_nb, f1..f_nf]`` holds
        for a coloured output disturbance (:func:`~trms.identification.pem.sandwich_covariance`: the output
        error's autocovariance from an AR model of it, its order in ``info["noise_ar_order"]``, 0 for white
        errors, where it is MATLAB's ``lambda (psi' psi)^-1``). It is asymptotic: where the errors' correlation
        leaves fewer than :data:`MIN_EFFECTIVE_PER_PARAMETER` (20) effective independent samples per parameter
        (``info["effective_samples"]``), ``info["intervals_withheld"]`` says so and ``std_errors`` and the
        frequency-response bands refuse with that reason (``benchmarks/bench_identification_mc.py --only oe``,
        AR(1) noise of pole 0.9: the lowest per-parameter coverage of 95 % intervals ranges from 0.85 to 0.96
        over the cells with 2-4 and about 14 effective samples per parameter, column "withheld min", not reliably
        0.90, and is 0.92-0.93 at 26); ``info`` as for
        :func:`~trms.identification.pem.fit` (``initial_parameters`` those of the kept start), and
        ``starts`` (how many were searched), ``start_losses`` (each one's final loss, NaN where its
        search failed), ``initial_losses`` (each start's own loss), ``best_start`` (the kept one) and
        ``local_minima`` (the starts that ended more than 1 % above the kept loss or with ``F`` on the
        stability boundary).

    Raises
    ------
    InputError
        Bad data, orders too large for the data, an input that is not persistently exciting.
    EstimationError
        No convergence within ``max_iter`` from any start, linearly dependent regressors, data of an
        unstable plant, or the best fit on the stability boundary (a root of ``F`` at ``|z| = 1``: a
        lightly damped or integrating mode the data cannot tell from an unstable one, or an unstable plant).

    Warns
    -----
    LocalMinimumWarning
        A start predicts better than the fit returned (its search failed), or the Steiglitz-McBride start
        (start 0) ended at a local minimum that another start beat.

    Examples
    --------
    >>> import numpy as np, scipy.signal
    >>> u = np.sign(np.random.default_rng(0).standard_normal(500))
    >>> y = scipy.signal.lfilter([0, 0.5], [1, -0.8], u) + 0.05 * np.random.default_rng(1).standard_normal(500)
    >>> model = oe(y, u, nb=1, nf=1, nk=1, sample_time=0.1)
    >>> bool(abs(model.F[1] + 0.8) < 0.01)
    True

    The three structurally different starts ended at the same minimum, so no perturbed one was needed:

    >>> model.info["starts"], model.info["best_start"], model.info["local_minima"]
    (3, 0, ())
    """
    orders = {"nb": (nb, 1), "nf": (nf, 0), "nk": (nk, 0)}
    d, o, structure, max_iter, tol = _prepare(data, u, orders, sample_time, input, output, max_iter, tol)
    n_starts = check_int("starts", starts, 1)
    plant = _plant_starts(d, o["nb"], o["nf"], o["nk"], n_starts)
    model = _multistart(
        d,
        structure,
        plant,
        lambda bf: np.zeros(0),
        name="OE PEM",
        method="oe-pem",
        max_iter=max_iter,
        tol=tol,
        coloured=True,
    )
    effective, order = model.info["effective_samples"], model.info["noise_ar_order"]
    if effective < MIN_EFFECTIVE_PER_PARAMETER * structure.n_parameters:
        model.info["intervals_withheld"] = (
            f"the output error is coloured (AR({order})): its {len(d)} samples are worth about {effective:.0f} "
            f"independent ones, {effective / structure.n_parameters:.1f} per parameter, fewer than "
            f"{MIN_EFFECTIVE_PER_PARAMETER}: the covariance, which holds for records long against the error's "
            "correlation, would understate the spread; use a longer record or a noise model (bj)"
        )
    return model


def bj(
    data: Record | object,
    u: object | None = None,
    nb: int = 2,
    nc: int = 2,
    nd: int = 2,
    nf: int = 2,
    nk: int = 1,
    *,
    sample_time: float | None = None,
    input: str | None = None,
    output: str | None = None,
    max_iter: int = MAX_ITER,
    tol: float = 1e-7,
    starts: int = STARTS,
) -> PolynomialModel:
    """Box-Jenkins model ``y = B / F u + C / D e`` by the prediction-error method (MATLAB ``bj``).

    Parameters
    ----------
    data : Record or array_like
        A Record (deviations are used) or the output ``y`` (shape ``(N,)``, output unit).
    u : array_like, optional
        Input with an array ``y`` (shape ``(N,)``, input unit, e.g. V).
    nb, nc, nd, nf, nk : int
        MATLAB's order names: ``nb >= 1`` numerator coefficients, ``nc >= 0`` and ``nd >= 0``
        noise numerator and denominator orders, ``nf >= 0`` poles of the plant, input delay
        ``nk >= 0`` samples.
    sample_time : float, optional
        Seconds per sample (required with arrays).
    input, output : str, optional
        Channel names in a multi-channel Record.
    max_iter : int
        Most Gauss-Newton iterations (default :data:`~trms.identification.pem.MAX_ITER`).
    tol : float
        Convergence: the Gauss-Newton step's predicted relative decrease of the loss.
    starts : int
        Initial estimates searched from, ``>= 1``, as for :func:`oe` (each completed with its
        own Hannan-Rissanen ``C, D``).

    Returns
    -------
    PolynomialModel
        ``A = 1``, ``method = "bj-pem"``; the covariance covers ``[b, c, d, f]``; ``info`` as for
        :func:`oe`. ``nc = nd = 0`` is the output-error model (``C = D = 1``): the same fit as :func:`oe`.

    Raises
    ------
    InputError
        Bad data, orders too large for the data, an input that is not persistently exciting.
    EstimationError
        As for :func:`oe`.

    Warns
    -----
    LocalMinimumWarning
        As for :func:`oe`.

    Examples
    --------
    >>> import numpy as np, scipy.signal
    >>> rng = np.random.default_rng(0)
    >>> u = np.sign(rng.standard_normal(2000))
    >>> noise = scipy.signal.lfilter([1, 0.3], [1, -0.9], 0.05 * rng.standard_normal(2000))
    >>> y = scipy.signal.lfilter([0, 0.5], [1, -0.8], u) + noise
    >>> model = bj(y, u, nb=1, nc=1, nd=1, nf=1, nk=1, sample_time=0.1)
    >>> bool(abs(model.dc_gain() - 2.5) < 0.1)
    True
    """
    orders = {"nb": (nb, 1), "nc": (nc, 0), "nd": (nd, 0), "nf": (nf, 0), "nk": (nk, 0)}
    d, o, structure, max_iter, tol = _prepare(data, u, orders, sample_time, input, output, max_iter, tol)
    n_starts = check_int("starts", starts, 1)
    nb, nk = o["nb"], o["nk"]

    def noise_start(bf: np.ndarray) -> np.ndarray:
        b, f = np.concatenate([np.zeros(nk), bf[:nb]]), np.concatenate([[1.0], bf[nb:]])
        return _hannan_rissanen_arma(d.y - scipy.signal.lfilter(b, f, d.u), o["nc"], o["nd"])

    plant = _plant_starts(d, nb, o["nf"], nk, n_starts, nd=o["nd"])
    return _multistart(d, structure, plant, noise_start, name="BJ PEM", method="bj-pem", max_iter=max_iter, tol=tol)
