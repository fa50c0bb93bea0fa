"""Disk margins on loops whose answer is known in closed form, and against python-control's grid search."""

import control
import numpy as np
import pytest

from trms.control.lqg import LQGController, design_lqg
from trms.control.margins import disk_margin
from trms.errors import InputError


def _stable(loop):
    return bool(np.all(np.abs(control.feedback(loop, 1).poles()) < 1.0))


@pytest.mark.parametrize("k", [0.1, 0.5, 0.9])
@pytest.mark.parametrize("delay", [1, 2])
def test_gain_on_a_sample_delay_has_the_analytic_disk_margin(k, delay):
    # L = k z^-d: |S - 1/2| = |z^d - k| / (2 |z^d + k|) peaks where z^d = -1, at (1 + k) / (2 (1 - k))
    ts = 0.2
    m = disk_margin(control.tf([k], [1.0] + [0.0] * delay, ts))
    alpha = 2.0 * (1.0 - k) / (1.0 + k)
    assert m.stable
    assert m.alpha == pytest.approx(alpha, rel=1e-12)
    assert m.gain_range == pytest.approx((k, 1.0 / k), rel=1e-12)
    assert m.gain_margin_db == pytest.approx(-20.0 * np.log10(k), rel=1e-12)
    assert m.phase_margin_deg == pytest.approx(np.degrees(2.0 * np.arctan((1.0 - k) / (1.0 + k))), rel=1e-12)
    assert m.frequency == pytest.approx(np.pi / (delay * ts), rel=1e-9)  # Nyquist (d = 1), half of it (d = 2)
    # the disk's upper gain is the exact gain margin here: 1 / k
    loop = control.tf([k], [1.0] + [0.0] * delay, ts)
    assert _stable(loop * (m.gain_range[1] * (1 - 1e-6))) and not _stable(loop * (m.gain_range[1] * (1 + 1e-6)))


def test_integrator_with_a_lag_has_the_analytic_disk_margin():
    # L = 1 / (s (s + 1)): |S - 1/2|^2 = 1/4 (1 + 4 w^2 / (w^4 - w^2 + 1)), largest (5/4) at w = 1 rad/s
    m = disk_margin(control.tf([1.0], [1.0, 1.0, 0.0]))
    assert m.alpha == pytest.approx(2.0 / np.sqrt(5.0), rel=1e-9)
    assert m.frequency == pytest.approx(1.0, rel=1e-4)
    assert m.gain_range == pytest.approx(((3.0 - np.sqrt(5.0)) / 2.0, (3.0 + np.sqrt(5.0)) / 2.0), rel=1e-9)
    assert m.phase_margin_deg == pytest.approx(np.degrees(2.0 * np.arctan(1.0 / np.sqrt(5.0))), rel=1e-9)


@pytest.mark.parametrize("k", [0.5, 3.0])
def test_first_order_lag_tolerates_any_gain_increase(k):
    # L = k / (s + 1): |S - 1/2| = |jw + 1 - k| / (2 |jw + 1 + k|) < 1/2, approached as w -> inf
    m = disk_margin(control.tf([k], [1.0, 1.0]))
    assert m.alpha == pytest.approx(2.0)
    assert m.gain_range == (0.0, np.inf) and m.phase_margin_deg == pytest.approx(90.0)
    assert m.frequency == np.inf


def test_unstable_closed_loop_has_no_disk_margin():
    m = disk_margin(control.tf([2.0], [1.0, 0.0], 0.2))  # closed-loop pole at z = -2
    assert not m.stable and m.alpha == 0.0 and m.gain_range == (1.0, 1.0) and m.phase_margin_deg == 0.0


def _lqg_loop_at_plant_input(model, r):
    comp = LQGController(design_lqg(model, Q=1.0, R=r)).compensator()
    c_y = control.ss(comp.A, comp.B[:, 1:2], comp.C, comp.D[:, 1:2], comp.dt)
    return control.series(control.ss(model), -c_y)


@pytest.mark.parametrize("r", [1.0, 75.0])
def test_lqg_loop_margin_agrees_with_the_grid_search_and_bounds_the_classic_margins(pitch_model, r):
    loop = _lqg_loop_at_plant_input(pitch_model, r)
    m = disk_margin(loop)
    w = np.linspace(1e-4, np.pi / loop.dt, 20001)
    alpha_grid, _, _ = control.disk_margins(loop, w)
    assert m.stable
    assert m.alpha == pytest.approx(float(alpha_grid), rel=1e-5)
    assert m.alpha <= float(alpha_grid) * (1 + 1e-12)  # the true peak is at least the grid's
    gm, pm, *_ = control.stability_margins(loop)
    assert m.gain_range[1] <= gm and m.phase_margin_deg <= pm  # one at a time tolerates more
    for g in np.linspace(m.gain_range[0], m.gain_range[1], 7)[1:-1]:
        assert _stable(loop * g)


@pytest.mark.parametrize(
    "loop, match",
    [
        ("L", r"loop must be a python-control LTI system, got str"),
        (control.ss(np.eye(1), np.ones((1, 2)), np.ones((1, 1)), np.zeros((1, 2)), 0.2), r"SISO .* got 1x2"),
        (control.tf([np.nan], [1.0, 1.0]), r"loop.num must be finite; found nan"),
        (control.tf([-1.0], [1.0]), r"D = -1.0 makes 1 \+ L\(inf\) = 0"),
        (control.tf([1.0], [1.0, 0.5], True), r"finite numeric sample time dt > 0 \(s\) or dt = 0, got dt = True"),
        (control.tf([1.0, 1.0, 0.0], [1.0, 1.0]), r"loop is improper: a numerator of degree 2 over a denominator"),
    ],
)
def test_bad_loops_are_refused(loop, match):
    with pytest.raises(InputError, match=match):
        disk_margin(loop)


def test_classical_margins_equal_python_controls_on_a_resonant_loop_and_find_the_crossings_it_misses():
    """Known truth: a lightly damped loop whose margins python-control's frequency-response method gets right
    (gain, phase), and a first-order lag whose phase crossover lies at Nyquist, where its polynomial method
    returns no gain margin though ``L(-1) = -1/3`` (9.54 dB)."""
    from trms.control.margins import classical_margins

    plant = control.c2d(control.tf([0.8], [1.0, 0.2, 1.0]) * control.tf([1.0], [0.5, 1.0]), 0.1)
    loop = control.ss(plant * control.tf([1.2, -1.0], [1.0, -0.6], 0.1))
    w = np.linspace(1e-3, np.pi / 0.1, 20000)
    gm, pm, *_ = control.stability_margins(control.frd(np.asarray(loop(np.exp(1j * w * 0.1))).ravel(), w))
    m = classical_margins(loop)
    assert len(m.gain_crossovers) == 2 and len(m.phase_crossovers) == 1
    assert m.gain_margin_db == pytest.approx(20 * np.log10(gm), abs=1e-6)
    assert m.phase_margin_deg == pytest.approx(pm, abs=1e-6)
    for wc in m.gain_crossovers:  # exact crossings, not grid points
        assert abs(abs(loop(np.exp(1j * wc * 0.1))) - 1.0) < 1e-9
    lag = classical_margins(control.tf([0.5], [1.0, -0.5], 1.0))
    assert lag.gain_margin_db == pytest.approx(20 * np.log10(3.0), abs=1e-9)
    assert lag.phase_crossovers == (pytest.approx(np.pi),)


def test_classical_margins_refuse_a_continuous_loop_and_too_few_points():
    from trms.control.margins import classical_margins
    from trms.errors import InputError

    with pytest.raises(InputError, match="discrete"):
        classical_margins(control.tf([1.0], [1.0, 1.0]))
    with pytest.raises(InputError, match="points = 10"):
        classical_margins(control.tf([0.5], [1.0, -0.5], 1.0), points=10)


def test_input_disk_margins_refuse_two_sample_times():
    from trms.control.margins import input_disk_margins

    g = control.ss([[0.5]], [[1.0]], [[1.0]], [[0.0]], 1.0)
    with pytest.raises(InputError, match="dt = 1.0 s and the feedback's dt = 0.5 s differ"):
        input_disk_margins(g, control.ss([], [], [], [[1.0]], 0.5))


@pytest.mark.parametrize("samples", [0, 1, 2, 3])
def test_the_delay_margin_falls_by_each_sample_of_delay_and_is_negative_once_the_loop_is_unstable(samples):
    """Known truth: ``L = 0.8 / (z - 0.5)`` at 1 s has one gain crossover, so ``m`` samples of delay take ``m`` s off
    its delay margin (1.868 s): stable with 1.868 - m > 0, unstable and negative past it (as its phase margin)."""
    from trms.control.margins import classical_margins

    lag = control.tf([0.8], [1.0, -0.5], 1.0)
    base = classical_margins(lag)
    m = classical_margins(lag * control.tf([1.0], [1.0] + [0.0] * samples, 1.0))
    assert m.delay_margin_s == pytest.approx(base.delay_margin_s - samples, abs=1e-9)
    assert m.stable == _stable(lag * control.tf([1.0], [1.0] + [0.0] * samples, 1.0)) == (m.delay_margin_s > 0)
    wc = m.gain_crossovers[0]
    assert m.delay_margin_s == pytest.approx(np.deg2rad(m.phase_margin_deg) / wc, abs=1e-9)


def test_an_unstable_loop_without_a_gain_crossover_tolerates_no_delay():
    from trms.control.margins import classical_margins

    m = classical_margins(control.tf([1.5], [1.0, 0.0], 1.0))  # |L| = 1.5 everywhere, closed-loop pole at -1.5
    assert not m.stable and m.delay_margin_s == -np.inf
