"""Phase-shifting interferometry from Python: numpy frames in, surface maps out (docs/psi.md)."""
import math

import numpy as np
import pytest

import piezoshift as ps


def frames_of(phi, steps, a=1.0, b=0.8):
    return np.stack([a + b * np.cos(phi + d) for d in steps])


def test_analyze_recovers_a_known_surface():
    n = 96
    y, x = np.mgrid[0:n, 0:n]
    xn, yn = (x - 47.5) / 47.5, (47.5 - y) / 47.5
    mask = (xn**2 + yn**2) <= 1.0
    lam = 632.8
    h = 30.0 * (2 * (xn**2 + yn**2) - 1)  # defocus, nm of surface height
    phi = 4 * math.pi * h / lam
    r = ps.psi_analyze(frames_of(phi, [k * math.pi / 2 for k in range(5)]), mask,
                       algorithm="hariharan5")
    assert r["algorithm"] == "hariharan5"
    s = r["surface_nm"]
    assert s.shape == (n, n)
    assert np.isnan(s[0, 0])
    truth = h - h[mask].mean()
    # tilt is removed too; the surface is pure power, so piston removal is the whole difference
    assert np.nanmax(np.abs(s[mask] - truth[mask])) < 1e-6
    assert len(r["zernike_nm"]) == 37
    assert r["surface_rms_nm"] == pytest.approx(np.std(truth[mask]), rel=1e-6)


def test_aia_and_tilt_aia_return_steps_and_planes():
    n = 64
    y, x = np.mgrid[0:n, 0:n]
    phi = 0.3 * x + 0.2 * y
    steps = [0.0, 1.4, 3.2, 4.6, 6.4]
    r = ps.psi_analyze(frames_of(phi, steps), None, algorithm="aia")
    assert np.allclose(r["steps_rad"], steps, atol=1e-6)
    assert r["converged"] and r["reason"] == ""
    # 19 + 13 rad of phase over the frame: spread evenly over fringes, the conditioning is near
    # its 0.5 (docs/psi.md); a flat phase would be 0
    assert 0.45 < r["step_conditioning"] <= 0.5
    # fringes over the whole frame: the pupil found from their modulation is the whole frame
    assert r["pupil"]["source"] == "modulation" and r["pupil"]["pixels"] == n * n
    t = ps.psi_analyze(frames_of(phi, steps), None, algorithm="tilt-aia")
    assert len(t["tip_rad"]) == 5 and len(t["piston_rad"]) == 5
    assert t["converged"]
    # the residual is the model's rounding: no noise here
    assert t["residual_rms"] < 1e-6


def test_a_fit_that_does_not_converge_returns_no_surface():
    n = 64
    y, x = np.mgrid[0:n, 0:n]
    phi = 0.3 * x + 0.2 * y
    # steps 1.5 rad beyond the commanded k pi/2: found, and refused
    steps = [0.0] + [k * math.pi / 2 + 1.5 for k in range(1, 5)]
    r = ps.psi_analyze(frames_of(phi, steps), None, algorithm="aia")
    assert not r["converged"]
    assert "from the commanded" in r["reason"]
    assert r["surface_nm"] is None and r["phase_rad"] is None


def test_pupil_found_from_the_modulation():
    n = 80
    y, x = np.mgrid[0:n, 0:n]
    disk = (x - 39.5)**2 + (y - 39.5)**2 <= 30**2
    phi = 0.4 * x
    frames = np.stack([1.0 + np.where(disk, 0.8 * np.cos(phi + k * math.pi / 2), 0.0)
                       for k in range(5)])
    r = ps.psi_analyze(frames, None, algorithm="hariharan5")
    assert r["pupil"]["pixels"] == disk.sum()
    assert np.array_equal(r["pupil"]["mask"] != 0, disk)
    with pytest.raises(ps.InputError, match="too few pixels with fringe modulation"):
        ps.psi_analyze(np.ones((5, 16, 16)), None, algorithm="aia")


def test_bad_input_raises_input_error():
    with pytest.raises(ps.InputError):
        ps.psi_analyze(np.zeros((2, 8, 8)))
    with pytest.raises(ps.InputError):
        ps.psi_analyze(np.zeros((5, 8, 8)), algorithm="nonsense")
    with pytest.raises(ps.InputError):
        ps.psi_analyze(np.zeros((4, 8, 8)), algorithm="hariharan5")


def test_zernike_fit_and_unwrap():
    n = 64
    y, x = np.mgrid[0:n, 0:n]
    xn, yn = (x - 31.5) / 31.5, (31.5 - y) / 31.5
    mask = (xn**2 + yn**2) <= 1.0
    # the unit disk is the pupil of the mask: centroid and largest pixel distance (grid.hpp)
    r = np.sqrt((x - 31.5)**2 + (y - 31.5)**2)[mask].max()
    z2 = 2 * (x - 31.5) / r  # Noll Z2
    c = ps.zernike_fit(np.where(mask, 5.0 * z2, np.nan), mask, 11)
    assert c[1] == pytest.approx(5.0, abs=1e-9)
    phi = 0.8 * x
    u = ps.psi_unwrap(np.angle(np.exp(1j * phi)), mask)
    d = u[mask] - phi[mask]
    assert np.ptp(d) < 1e-9


def test_simulate_on_the_twin(config, controller):
    r = ps.psi_simulate(config, controller, algorithm="hariharan5", size_px=64, seed=2)
    assert r["frames"].shape == (5, 64, 64)
    assert r["surface_error_rms_nm"] < 1.0
    assert r["stage_step_nm"][1] == pytest.approx(632.8 / 8, abs=5.0)
