"""calibrate(), the paper's experiments and reproduce() from Python, against the C++ results."""
import numpy as np
import pytest

import piezoshift as ps

PAPER_A = np.array([[-0.4218, 0.6030, 0.6547], [0.3482, -0.1491, 0.6962],
                    [0.6321, 0.4397, -0.2980]])


@pytest.fixture(scope="module")
def calibration():
    options = ps.CalibrationOptions()
    options.pid = ps.PidChoice.PAPER
    return ps.calibrate(ps.ProjectConfig(), ps.SemiClosedLoopParams(), 1, options)


def test_calibration_identifies_papers_a(calibration):
    a = calibration.controller.matrix.a
    assert a.shape == (3, 3)
    assert np.abs(a - PAPER_A).max() < 0.05
    assert calibration.matrix.ds_um.shape[1] == 3
    assert calibration.matrix.fit.condition_number == pytest.approx(np.linalg.cond(a), rel=1e-6)


def test_calibration_polynomial_near_identity(calibration):
    # the twin's SGS is linear to 0.1 % of full scale: p is close to c = m
    p = calibration.controller.polynomial
    assert p.p1 == pytest.approx(1.0, abs=0.02)
    assert abs(p.p0) < 0.05
    assert calibration.polynomial.fit.rms_residual_um < 0.01
    assert calibration.controller.gains.kp == 0.6  # the paper's gains kept


def test_step_response_settles(calibration):
    r = ps.run_step_response(ps.ProjectConfig(), calibration.controller, 1)
    assert isinstance(r.measured_um, np.ndarray)
    assert r.time_s.shape == r.measured_um.shape == r.desired_um.shape
    # Section 4.1: settles within 0.3 s after an 11 um step
    assert r.metrics.settling_time_pct_s < 0.3
    assert r.metrics.step_um == pytest.approx(11.0, abs=0.05)
    assert r.measured_um[-100:].mean() == pytest.approx(11.0, abs=0.02)


def test_step_response_is_deterministic(calibration):
    a = ps.run_step_response(ps.ProjectConfig(), calibration.controller, 5)
    b = ps.run_step_response(ps.ProjectConfig(), calibration.controller, 5)
    np.testing.assert_array_equal(a.measured_um, b.measured_um)


def test_repeatability_short(calibration):
    opts = ps.RepeatabilityOptions()
    opts.moves = 20
    r = ps.run_repeatability(ps.ProjectConfig(), calibration.controller, 1, opts)
    assert r.measured_um.shape == (20,)
    assert r.metrics.repeatability_nm == pytest.approx(np.std(r.measured_um, ddof=1) * 1e3)
    assert r.metrics.mean_um == pytest.approx(5.0, abs=0.02)


def test_reproduce_quick_summary():
    options = ps.ReproduceOptions()
    options.quick = True
    result = ps.reproduce(ps.ProjectConfig(), options)
    summary = result.summary()
    assert summary == ps.summary_json(result)
    assert summary["seed"] == 1
    np.testing.assert_allclose(summary["identified_A"], result.calibration.controller.matrix.a)
    assert summary["step_settling_time_s"] == pytest.approx(
        result.step.metrics.settling_time_pct_s)
    assert summary["step_settling_time_s"] < 0.3
    assert np.abs(np.array(summary["identified_A"]) - PAPER_A).max() < 0.05
