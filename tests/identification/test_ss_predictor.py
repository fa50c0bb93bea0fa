"""The innovations predictor and its analytic gradient, against a sample-by-sample loop and central differences."""

import numpy as np
import pytest

from trms.identification.ss_predictor import _Layout, _prediction_gradient, _predictor_output


def _case(rng: np.random.Generator, layout: _Layout) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    n, m, p = layout.n, layout.m, layout.p
    a = np.diag([0.9, 0.5, -0.3]) + 0.05 * rng.standard_normal((n, n))
    theta = layout.pack(
        a,
        rng.standard_normal((n, m)),
        rng.standard_normal((p, n)),
        0.05 * rng.standard_normal((n, p)),
        rng.standard_normal((p, m)),
        rng.standard_normal(n),
    )
    return theta, rng.standard_normal((300, p)), rng.standard_normal((300, m))


@pytest.mark.parametrize("initial_state", [False, True])
@pytest.mark.parametrize("feedthrough", [False, True])
def test_the_prediction_is_the_recursion_run_sample_by_sample(feedthrough, initial_state):
    layout = _Layout(3, 2, 2, feedthrough, initial_state)
    theta, y, u = _case(np.random.default_rng(40), layout)
    a, b, c, k, d, x0 = layout.unpack(theta)
    x, expected = x0.copy(), []
    for t in range(y.shape[0]):
        expected.append(c @ x + d @ u[t])
        x = (a - k @ c) @ x + (b - k @ d) @ u[t] + k @ y[t]
    got = _predictor_output(a, b, c, d, k, y, u, x0 if initial_state else None)
    np.testing.assert_allclose(got, np.array(expected), rtol=1e-10, atol=1e-10)
    if not initial_state:
        assert not np.any(x0)


@pytest.mark.parametrize("initial_state", [False, True])
@pytest.mark.parametrize("feedthrough", [False, True])
def test_the_analytic_gradient_is_the_central_difference_one(feedthrough, initial_state):
    layout = _Layout(3, 2, 2, feedthrough, initial_state)
    theta, y, u = _case(np.random.default_rng(41), layout)

    def predicted(th: np.ndarray) -> np.ndarray:
        a, b, c, k, d, x0 = layout.unpack(th)
        return _predictor_output(a, b, c, d, k, y, u, x0 if initial_state else None)

    e, grad = _prediction_gradient(layout, theta, y, u)
    step = 1e-6
    numeric = np.stack(
        [(predicted(theta + step * col) - predicted(theta - step * col)) / (2 * step) for col in np.eye(theta.size)],
        axis=2,
    )
    np.testing.assert_array_equal(e, y - predicted(theta))
    assert grad.shape == (300, 2, theta.size) == numeric.shape
    np.testing.assert_allclose(grad, numeric, atol=1e-6 * np.abs(numeric).max())


def test_the_local_coordinates_leave_out_the_similarity_transforms_of_the_free_entries():
    rng = np.random.default_rng(42)
    layout = _Layout(3, 2, 2, False, True)
    theta = _case(rng, layout)[0]
    everything = layout.local_basis(theta, np.ones(layout.size, bool), similarity=True)
    assert everything.shape == (layout.size, layout.size - 9)  # n^2 = 9 transform directions
    plant = ~layout.block("K")
    theta[layout.block("K")] = 0.0  # with K = 0 held, the transforms move A, B, C and x0 alone
    oe = layout.local_basis(theta, plant, similarity=True)
    assert oe.shape == (layout.size, plant.sum() - 9) and not np.any(oe[layout.block("K")])
    noise = layout.local_basis(theta, layout.block("K"), similarity=False)
    assert noise.shape == (layout.size, 6) and np.allclose(noise.T @ noise, np.eye(6))
