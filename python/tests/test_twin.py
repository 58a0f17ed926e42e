"""The digital twin and the bench from Python: determinism, the converter, open-loop travel."""
import numpy as np
import pytest

import piezoshift as ps


def test_same_seed_same_outputs(config):
    a, b, c = ps.Twin(config, 7), ps.Twin(config, 7), ps.Twin(config, 8)
    ya, _ = a.run([4.0, 5.0, 6.0], 200)
    yb, _ = b.run([4.0, 5.0, 6.0], 200)
    yc, _ = c.run([4.0, 5.0, 6.0], 200)
    assert ya.shape == (200, 3)
    np.testing.assert_array_equal(ya, yb)
    assert not np.array_equal(ya, yc)
    assert a.ticks == 200 and a.time_s == pytest.approx(0.2)


def test_cavity_in_the_truth_and_in_the_fringes_only_when_on(config):
    # plant/fizeau_cavity.hpp: the truth carries the cavity's drift; the fringes see it when on.
    assert config.twin.cavity.gap_m == pytest.approx(0.05)
    assert not config.twin.cavity.in_fringes
    t = ps.Twin(config, 3)
    t.run([2.0, 2.0, 2.0], 500)
    tr = t.truth()
    assert tr.cavity_drift_nm != 0.0
    assert tr.cavity_path_nm == pytest.approx(1000.0 * tr.plate_z_um + tr.cavity_drift_nm)
    assert t.fringe_piston_nm == pytest.approx(1000.0 * tr.plate_z_um)
    config.twin.cavity.in_fringes = True
    on = ps.Twin(config, 3)
    on.run([2.0, 2.0, 2.0], 500)
    assert on.fringe_piston_nm == pytest.approx(on.truth().cavity_path_nm)
    config.twin.cavity.gap_m = 20.0
    assert (ps.twin_params_problem(config.design, config.twin)
            == "twin.cavity.gap_m = 20 must be in [0, 10]")


def test_converter_status(config):
    t = ps.Twin(config, 1)
    assert t.write_ao([11.0, 0.0, 0.0]) == ps.AoStatus.CLAMPED
    assert t.write_ao([float("nan"), 0.0, 0.0]) == ps.AoStatus.INVALID


def test_open_loop_travel(config):
    # Section 4.1: 12.931 um of open-loop travel at 150 V after 1.5 s (the contact's calibration
    # point, ContactParams); truth, so no interferometer noise.
    t = ps.Twin(config, 1)
    _, points = t.run([10.0, 10.0, 10.0], 1500)
    assert points[-1].mean() == pytest.approx(12.931, abs=0.1)
    np.testing.assert_allclose(t.truth().amplifier_V, [150.0] * 3, atol=1.0)


def test_bench_tracks_points(config, controller):
    # The twin's true A is the paper's (GeometryParams) and its SGS is near-linear, so with
    # p = identity the loop puts the points at Z_d.
    controller.polynomial = ps.CubicPolynomial.identity()
    bench = ps.Bench(config, controller, 1)
    bench.drive_points([5.0, 5.0, 5.0])
    rec = bench.record(1.0)
    assert bench.mode == ps.DriveMode.POINTS
    assert rec["time_s"].shape == (1000,)
    assert rec["mean_points_um"][-1] == pytest.approx(5.0, abs=0.05)
    m = bench.measure_static()
    assert m.points_um.mean() == pytest.approx(5.0, abs=0.05)
    assert bench.twin.ticks == bench.ticks


def test_bench_applies_papers_polynomial(config, controller):
    # With the paper's p (fitted on the real SGS), the twin goes to about p(Z_d) instead.
    p = controller.polynomial
    assert p(5.0) == pytest.approx(-0.0001009 * 125 + 0.000389 * 25 + 1.014 * 5 + 0.2914)
    bench = ps.Bench(config, controller, 1)
    bench.drive_points([5.0, 5.0, 5.0])
    bench.run(1.0)
    assert bench.measure_static().points_um.mean() == pytest.approx(p(5.0), abs=0.05)
