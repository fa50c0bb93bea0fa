"""The one-step predictor of a discrete innovations state-space model, its analytic gradient, and the
prediction-error search on it: the engine of :func:`~trms.identification.ssest.ssest` and of the refinement of
:func:`~trms.identification.subspace.n4sid`.

The model is ``x(t+1) = A x(t) + B u(t) + K e(t)``, ``y(t) = C x(t) + D u(t) + e(t)`` from ``x(0) = x0``; its
predictor ``x^(t+1) = (A - K C) x^ + (B - K D) u + K y``, ``y^ = C x^ + D u`` gives the prediction errors
``e = y - y^``. With ``K = 0`` the predictor is the simulation and ``e`` the output error.

The parameters ``theta = [vec A, vec B, vec C, vec K (, vec D) (, x0)]`` (row-major ``vec``) leave the ``n^2``
directions of the similarity transforms ``x -> T x`` along which the predictor does not change; a search runs in
local coordinates ``theta = theta0 + Q eta``, ``Q`` an orthonormal basis of the free parameters' directions that
are not such a transform (:meth:`_Layout.local_basis`).
"""

from __future__ import annotations

import numpy as np
import scipy.optimize
import scipy.signal

#: Relative size below which a singular value of the similarity tangent counts as zero.
_RANK_TOL = 1e-10
#: Most evaluations of the errors per Levenberg-Marquardt iteration allowed (``max_nfev = _EVALUATIONS * max_iter``).
_EVALUATIONS = 4
#: A refused (unstable-predictor) point costs this many times the start's whitened residuals.
_PENALTY = 1e3
#: A simulation error below this fraction of the output's root mean square is an exact fit (noise-free data).
_EXACT = 1e-10
#: Most searches (each re-centres the local coordinates and, with several outputs, re-weights the criterion).
_PASSES = 6
#: A search that lowers ``det`` of the error covariance by less than this (relative) ends the passes.
_SETTLED = 1e-10


class _Layout:
    """``theta = [vec A, vec B, vec C, vec K (, vec D) (, x0)]`` of ``n`` states, ``m`` inputs, ``p`` outputs."""

    def __init__(self, n: int, m: int, p: int, feedthrough: bool, initial_state: bool = False) -> None:
        self.n, self.m, self.p, self.feedthrough, self.initial_state = n, m, p, feedthrough, initial_state
        self.shapes = [(n, n), (n, m), (p, n), (n, p)] + ([(p, m)] if feedthrough else []) + ([(n,)] * initial_state)
        sizes = [int(np.prod(s)) for s in self.shapes]
        self.cuts = np.cumsum(sizes)[:-1]
        self.size = int(sum(sizes))

    def pack(
        self, a: np.ndarray, b: np.ndarray, c: np.ndarray, k: np.ndarray, d: np.ndarray, x0: np.ndarray | None = None
    ) -> np.ndarray:
        parts = [a, b, c, k] + ([d] if self.feedthrough else [])
        if self.initial_state:
            parts.append(np.zeros(self.n) if x0 is None else x0)
        return np.concatenate([np.ravel(x) for x in parts])

    def unpack(self, theta: np.ndarray) -> tuple[np.ndarray, ...]:
        """``A, B, C, K, D, x0`` (``D = 0`` without feedthrough, ``x0 = 0`` without an initial state)."""
        parts = [x.reshape(s) for x, s in zip(np.split(theta, self.cuts), self.shapes)]
        d = parts[4] if self.feedthrough else np.zeros((self.p, self.m))
        x0 = parts[-1] if self.initial_state else np.zeros(self.n)
        return parts[0], parts[1], parts[2], parts[3], d, x0

    @property
    def names(self) -> tuple[str, ...]:
        """The blocks of ``theta`` in order: ``"A" "B" "C" "K"`` (then ``"D"``, ``"x0"`` where present)."""
        return ("A", "B", "C", "K") + ("D",) * self.feedthrough + ("x0",) * self.initial_state

    def block(self, name: str) -> np.ndarray:
        """Boolean mask of the entries of ``theta`` in block ``name`` (all false for an absent one)."""
        mask = np.zeros(self.size, bool)
        for part, cut in zip(self.names, np.split(np.arange(self.size), self.cuts)):
            mask[cut] |= part == name
        return mask

    def local_basis(self, theta: np.ndarray, free: np.ndarray, similarity: bool) -> np.ndarray:
        """Orthonormal basis (columns, ``(size, k)``) of the directions of the ``free`` entries, less the tangent
        of the similarity transforms at ``theta`` when ``similarity`` (those moving only free entries: with
        ``K = 0`` fixed, the transforms of ``A, B, C, D, x0``)."""
        n = self.n
        a, b, c, k, d, x0 = self.unpack(theta)
        basis = np.eye(self.size)[:, free]
        if not similarity or n == 0:
            return basis
        tangent = []
        for i in range(n):
            for j in range(n):
                x = np.zeros((n, n))
                x[i, j] = 1.0
                tangent.append(self.pack(a @ x - x @ a, -x @ b, c @ x, -x @ k, np.zeros_like(d), -x @ x0)[free])
        left, s, _ = np.linalg.svd(np.column_stack(tangent), full_matrices=True)
        rank = int(np.sum(s > _RANK_TOL * s[0])) if s.size and s[0] > 0 else 0
        return basis @ left[:, rank:]


def _predictor(
    a: np.ndarray,
    b: np.ndarray,
    c: np.ndarray,
    d: np.ndarray,
    k: np.ndarray,
    y: np.ndarray,
    u: np.ndarray,
    x0: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, list[np.ndarray]]:
    """One-step prediction ``y^`` ``(N, p)`` of the innovations model from ``x^(0) = x0`` (default 0), its states
    ``x^`` ``(N, n)``, the characteristic polynomial ``c`` of ``A_bar = A - K C`` and ``M_0 .. M_(n-1)``.

    The predictor has inputs ``w = [u, y]``, ``A_bar = A - K C``, ``B_bar = [B - K D, K]``. Its state is
    ``x^ = sum_(j=1..n) M_(j-1) B_bar q^-j w / c(q^-1)`` with ``M_0 = I``, ``M_j = A_bar M_(j-1) + c_j I``
    (Faddeev-LeVerrier): ``w`` is filtered by ``1 / c`` once and the ``n`` lagged products summed. The initial
    state enters as one more input, an impulse at ``t = 0`` through ``A_bar x0`` (so ``x^(t) = A_bar^t x0`` from
    it for ``t >= 1``), plus ``x0`` itself at ``t = 0``.
    """
    n = a.shape[0]
    if n == 0:
        return u @ d.T, np.zeros((y.shape[0], 0)), np.ones(1), []
    abar = a - k @ c
    w, bbar = np.hstack([u, y]), np.hstack([b - k @ d, k])
    free_response = x0 is not None and np.any(x0)
    if free_response:
        w = np.hstack([w, np.eye(y.shape[0], 1)])
        bbar = np.hstack([bbar, (abar @ x0)[:, None]])
    poly = np.real(np.poly(abar))
    filtered = scipy.signal.lfilter([1.0], poly, w, axis=0)
    x = np.zeros((y.shape[0], n))
    ms = [np.eye(n)]
    for j in range(1, n + 1):
        x[j:] += filtered[:-j] @ (ms[-1] @ bbar).T
        if j < n:
            ms.append(abar @ ms[-1] + poly[j] * np.eye(n))
    if free_response:
        x[0] += x0
    return x @ c.T + u @ d.T, x, poly, ms


def _predictor_output(
    a: np.ndarray,
    b: np.ndarray,
    c: np.ndarray,
    d: np.ndarray,
    k: np.ndarray,
    y: np.ndarray,
    u: np.ndarray,
    x0: np.ndarray | None = None,
) -> np.ndarray:
    """One-step prediction ``y^`` ``(N, p)`` of the innovations model from ``x^(0) = x0`` (:func:`_predictor`)."""
    return _predictor(a, b, c, d, k, y, u, x0)[0]


def _prediction_gradient(
    layout: _Layout, theta: np.ndarray, y: np.ndarray, u: np.ndarray, blocks: tuple[str, ...] | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """Prediction errors ``e`` ``(N, p)`` and the gradient ``d y^ / d theta`` ``(N, p, columns)``, analytic: the
    columns of the ``blocks`` named (``"A" "B" "C" "K" "D" "x0"``, in ``theta``'s order; default all of them).

    A parameter's sensitivity ``xi = d x^ / d theta_k`` obeys the predictor's own recursion with one injected
    signal, ``xi(t+1) = A_bar xi + e_i s(t)``: ``s = x^_j`` for ``A_ij``, ``u_k`` for ``B_ik``, ``e_l`` for
    ``K_il`` (``x^(t+1) = A x^ + B u + K e``), and ``C_li``, ``D_lk`` inject ``-K_(:,l) x^_i`` and
    ``-K_(:,l) u_k`` besides their direct term ``e_l x^_i``, ``e_l u_k`` in ``y^``; ``x0`` gives ``C A_bar^t``,
    the response to an impulse at ``t = 0`` times ``A_bar`` (``C`` itself at ``t = 0``). So every sensitivity
    is a combination of the ``n`` responses ``C (q I - A_bar)^-1 e_i`` to the signals ``[x^, u, e, impulse]``
    (those the blocks need): they are filtered by ``1 / c`` once (as the predictor's inputs) and summed over the
    ``n`` lags with the weights ``C M_(j-1)``.
    """
    a, b, c, k, d, x0 = layout.unpack(theta)
    n, m, p = layout.n, layout.m, layout.p
    names = layout.names if blocks is None else tuple(b_ for b_ in layout.names if b_ in blocks)
    yhat, x, poly, ms = _predictor(a, b, c, d, k, y, u, x0 if layout.initial_state else None)
    e = y - yhat
    t = y.shape[0]
    need = {"x": {"A", "C"}, "u": {"B", "D"}, "e": {"K"}, "impulse": {"x0"}}
    source = {"x": x, "u": u, "e": e, "impulse": np.eye(t, 1)}
    used = [key for key, owners in need.items() if owners & set(names)]
    signals = np.hstack([source[key] for key in used]) if used else np.zeros((t, 0))
    filtered = scipy.signal.lfilter([1.0], poly, signals, axis=0) if n else signals
    ns = signals.shape[1]
    lagged = np.zeros((t, ns, n))
    for j in range(n):
        lagged[j + 1 :, :, j] = filtered[: t - j - 1]
    # resp[t, s, l, i]: output l of C (qI - A_bar)^-1 e_i driven by signal s
    weights = np.stack([c @ mj for mj in ms]).reshape(n, p * n) if n else np.zeros((0, 0))
    resp = (lagged.reshape(t * ns, n) @ weights).reshape(t, ns, p, n)
    cuts = np.cumsum([0] + [source[key].shape[1] for key in used])
    r = {key: resp[:, cuts[i] : cuts[i + 1]] for i, key in enumerate(used)}
    eye_p = np.eye(p)

    def direct(sig: np.ndarray, rs: np.ndarray) -> np.ndarray:
        """``C_qi`` (``sig = x^``) or ``D_qk`` (``sig = u``): ``delta_lq sig_i - sum_r K_rq rs[t, i, l, r]``."""
        through = np.tensordot(rs, k, axes=([3], [0]))  # (t, i, l, q)
        own = eye_p[None, None, :, :] * sig[:, :, None, None]
        return (own - through).transpose(0, 2, 3, 1).reshape(t, p, -1)

    def column(name: str) -> np.ndarray:
        if name == "A":
            return r["x"].transpose(0, 2, 3, 1).reshape(t, p, n * n)  # A_ij: column i * n + j
        if name == "B":
            return r["u"].transpose(0, 2, 3, 1).reshape(t, p, n * m)  # B_ik
        if name == "C":
            return direct(x, r["x"])  # C_qi
        if name == "K":
            return r["e"].transpose(0, 2, 3, 1).reshape(t, p, n * p)  # K_il
        if name == "D":
            return direct(u, r["u"])  # D_qk
        free = r["impulse"][:, 0] @ (a - k @ c)  # x0: C A_bar^(t-1) A_bar for t >= 1
        free[0] = c
        return free

    return e, np.concatenate([column(name) for name in names], axis=2)


def _covariance_of(errors: np.ndarray) -> np.ndarray:
    lam = errors.T @ errors / errors.shape[0]
    return (lam + lam.T) / 2


def _loss(lam: np.ndarray) -> float:
    return float(np.linalg.det(lam))


def _errors(layout: _Layout, theta: np.ndarray, y: np.ndarray, u: np.ndarray) -> np.ndarray:
    a, b, c, k, d, x0 = layout.unpack(theta)
    return y - _predictor_output(a, b, c, d, k, y, u, x0 if layout.initial_state else None)


def _search(
    layout: _Layout,
    theta: np.ndarray,
    y: np.ndarray,
    u: np.ndarray,
    lam: np.ndarray,
    max_iter: int,
    tol: float,
    free: np.ndarray,
    similarity: bool,
) -> tuple[np.ndarray, scipy.optimize.OptimizeResult, np.ndarray]:
    """One least-squares search of the ``free`` entries in local coordinates at ``theta``, weighted by
    ``lam^-1``, with the analytic Jacobian (:func:`_prediction_gradient`); a point whose predictor is unstable is
    refused (a large constant residual)."""
    basis = layout.local_basis(theta, free, similarity)
    white = np.linalg.inv(np.linalg.cholesky(lam)).T  # W = white white^T = lam^-1

    def stable(eta: np.ndarray) -> bool:
        a, _, c, k, _, _ = layout.unpack(theta + basis @ eta)
        return not layout.n or bool(np.max(np.abs(np.linalg.eigvals(a - k @ c))) < 1.0)

    def errors(eta: np.ndarray) -> np.ndarray:
        return (_errors(layout, theta + basis @ eta, y, u) @ white).ravel()

    zero = np.zeros(basis.shape[1])
    penalty = _PENALTY * errors(zero)  # the start's predictor is stable

    def whitened(eta: np.ndarray) -> np.ndarray:
        return errors(eta) if stable(eta) else penalty

    blocks = tuple(name for name in layout.names if np.any(free & layout.block(name)))
    rows = np.any([layout.block(name) for name in blocks], axis=0)  # the basis is zero off the free blocks

    def jacobian(eta: np.ndarray) -> np.ndarray:
        # least_squares asks for the Jacobian only at accepted points, never at a refused (unstable) one
        grad = _prediction_gradient(layout, theta + basis @ eta, y, u, blocks)[1]  # d y^ / d theta, (N, p, cols)
        return -(np.tensordot(grad, white, axes=([1], [0])).transpose(0, 2, 1).reshape(-1, grad.shape[2]) @ basis[rows])

    res = scipy.optimize.least_squares(
        whitened,
        zero,
        jac=jacobian,
        method="lm",
        x_scale="jac",
        ftol=tol,
        xtol=tol,
        gtol=tol,
        max_nfev=_EVALUATIONS * max_iter,
    )
    return theta + basis @ res.x, res, basis


def _minimise(
    layout: _Layout,
    theta: np.ndarray,
    y: np.ndarray,
    u: np.ndarray,
    max_iter: int,
    tol: float,
    free: np.ndarray,
    similarity: bool,
    settled: float = _SETTLED,
    most: int = _PASSES,
) -> tuple[np.ndarray, scipy.optimize.OptimizeResult, np.ndarray, np.ndarray, int, int]:
    """``det`` of the error covariance minimised over the ``free`` entries from ``theta`` (stable predictor).

    Each pass is a weighted least-squares search (:func:`_search`) with the weight the inverse of the error
    covariance at its start; the passes end when ``det`` falls by less than ``settled`` (relative; at most
    ``most``): that fixed point is a
    stationary point of ``det(E' E / N)``. Returns ``theta``, the last search's result and basis, the error
    covariance, the passes and the evaluations of the errors.
    """
    lam = _covariance_of(_errors(layout, theta, y, u))
    passes = evaluations = 0
    res = basis = None
    while passes < most:
        passes += 1
        theta, res, basis = _search(layout, theta, y, u, lam, max_iter, tol, free, similarity)
        evaluations += int(res.nfev)
        new = _covariance_of(_errors(layout, theta, y, u))
        done = _loss(lam) - _loss(new) <= settled * _loss(lam)
        lam = new
        if done:
            break
    assert res is not None and basis is not None
    return theta, res, basis, lam, passes, evaluations


def _refine_simulation(
    a: np.ndarray,
    b: np.ndarray,
    c: np.ndarray,
    d: np.ndarray,
    x0: np.ndarray,
    y: np.ndarray,
    u: np.ndarray,
    max_iter: int,
    tol: float,
) -> tuple[tuple[np.ndarray, ...], np.ndarray, np.ndarray, dict[str, float | int]] | None:
    """A stable subspace model refined by the prediction-error method with ``K = 0`` (the simulation error, an
    output-error fit: unbiased under any output disturbance independent of the input), then its noise model.

    Step 1 minimises the simulation errors over ``A, B, C, D, x0`` (similarity transforms left out), step 2 the
    one-step prediction errors over the Kalman gain ``K`` alone with that plant held: one search each
    (:func:`_search`), the errors weighted by the inverse covariance of the start's (the re-weighted passes of
    :func:`_minimise` that reach ``det``'s minimum cost a third more time and change no damping estimate of the
    benchmark's Monte Carlo by more than one point). Returns ``(A, B, C, D, x0)``, ``K``, the innovation
    covariance and an info dict (``simulation_loss`` before and after, ``passes``, ``evaluations``), or None for
    an unstable (or static) start,
    whose simulation has no stable predictor to search from, for a start that simulates the data exactly, and
    for a refinement that does not lower the simulation loss.
    """
    n, m, p = a.shape[0], u.shape[1], y.shape[1]
    if n == 0 or np.max(np.abs(np.linalg.eigvals(a))) >= 1.0:
        return None
    layout = _Layout(n, m, p, feedthrough=True, initial_state=True)
    theta0 = layout.pack(a, b, c, np.zeros((n, p)), d, x0)
    start = _covariance_of(_errors(layout, theta0, y, u))
    if np.all(np.diag(start) <= _EXACT**2 * np.mean(y**2, axis=0)):
        return None  # the subspace model simulates the data exactly (noise-free data): nothing to refine
    before = _loss(start)
    theta, _, _, lam_sim, passes, evaluations = _minimise(
        layout, theta0, y, u, max_iter, tol, ~layout.block("K"), similarity=True, most=1
    )
    if not _loss(lam_sim) < before:
        return None
    theta, _, _, lam, passes_k, evaluations_k = _minimise(
        layout, theta, y, u, max_iter, tol, layout.block("K"), similarity=False, most=1
    )
    a, b, c, k, d, x0 = layout.unpack(theta)
    info = {
        "subspace_simulation_loss": before,
        "simulation_loss": _loss(lam_sim),
        "passes": passes + passes_k,
        "evaluations": evaluations + evaluations_k,
    }
    return (a, b, c, d, x0), k, lam, info
