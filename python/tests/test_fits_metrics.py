"""Least-squares fits and metrics on synthetic data with a known truth."""
import math

import numpy as np
import pytest

import piezoshift as ps


def test_matrix_fit_recovers_truth():
    rng = np.random.default_rng(1)
    a_true = ps.TransmissionMatrix().a  # the paper's A
    z = rng.uniform(0.0, 10.0, size=(12, 3))
    s = z @ a_true.T  # S = A Z per pose
    fit = ps.fit_transmission_matrix(s, z)
    np.testing.assert_allclose(fit.a.a, a_true, atol=1e-12)
    assert fit.poses == 12
    assert fit.rms_residual_um < 1e-12


def test_matrix_fit_with_noise():
    rng = np.random.default_rng(2)
    a_true = np.array([[1.0, 0.2, 0.0], [0.1, 0.9, 0.3], [0.0, 0.4, 1.1]])
    z = rng.uniform(0.0, 10.0, size=(200, 3))
    s = z @ a_true.T + rng.normal(0.0, 1e-3, size=(200, 3))
    fit = ps.fit_transmission_matrix(s, z)
    np.testing.assert_allclose(fit.a.a, a_true, atol=5e-4)
    assert fit.rms_residual_um == pytest.approx(1e-3, rel=0.2)


def test_matrix_fit_rank_deficient_is_fit_error():
    z = np.tile([1.0, 2.0, 3.0], (5, 1))  # one pose repeated: Z has rank 1
    with pytest.raises(ps.FitError):
        ps.fit_transmission_matrix(z, z)
    with pytest.raises(ps.InputError, match="n x 3"):
        ps.fit_transmission_matrix(np.zeros((4, 2)), np.zeros((4, 2)))


def test_cubic_fit_recovers_truth():
    p_true = ps.CubicPolynomial()  # the paper's p
    m = np.linspace(0.0, 11.0, 12)
    c = np.array([p_true(x) for x in m])
    fit = ps.fit_cubic_polynomial(m, c)
    for name in ("p3", "p2", "p1", "p0"):
        assert getattr(fit.p, name) == pytest.approx(getattr(p_true, name), abs=1e-10)
    assert fit.points == 12
    assert fit.max_abs_residual_um < 1e-10


def test_cubic_fit_too_few_points():
    with pytest.raises(ps.FitError):
        ps.fit_cubic_polynomial([0.0, 1.0, 2.0], [0.0, 1.0, 2.0])


def test_step_metrics_first_order():
    tau = 0.01
    t = np.arange(-0.1, 0.5, 1e-4)
    y = np.where(t < 0.0, 0.0, 11.0 * (1.0 - np.exp(-np.maximum(t, 0.0) / tau)))
    opts = ps.StepResponseOptions()
    opts.median_window = 1
    m = ps.step_response_metrics(t, y, opts)
    assert m.step_um == pytest.approx(11.0, abs=1e-6)
    assert m.rise_time_s == pytest.approx(tau * math.log(9.0), abs=2e-4)
    # settling to 2 %: exp(-t/tau) = 0.02
    assert m.settling_time_pct_s == pytest.approx(tau * math.log(50.0), abs=2e-4)
    assert m.overshoot_pct == pytest.approx(0.0, abs=1e-9)


def test_linearity_metrics_known_bow():
    x = np.arange(0.0, 12.0)
    y = x + 0.01 * x * (11.0 - x) / 30.25  # a bow of 10 nm at mid-span
    m = ps.linearity_metrics(x, y)
    assert m.span_um == pytest.approx(11.0)
    assert m.max_deviation_zero_end_um == pytest.approx(0.01 * 30.0 / 30.25, rel=1e-9)
    assert m.linearity_zero_end_pct == pytest.approx(100 * 0.01 * 30.0 / 30.25 / 11.0, rel=1e-9)
    assert m.deviation_zero_end_um.shape == (12,)
    with pytest.raises(ps.MetricsError):
        ps.linearity_metrics([0.0, 1.0], [0.0, 1.0])


def test_repeatability_is_sample_std():
    z = np.array([5.001, 4.999, 5.002, 4.998, 5.0])
    m = ps.repeatability_metrics(z)
    assert m.repeatability_nm == pytest.approx(np.std(z, ddof=1) * 1e3, rel=1e-9)
    assert m.n == 5 and m.mean_um == pytest.approx(5.0)
