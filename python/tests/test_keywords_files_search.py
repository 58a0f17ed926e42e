"""Keyword construction of every parameter struct, readable signatures, calibration files, the
hinge search (docs/python.md)."""
import inspect

import numpy as np
import pytest

import piezoshift as ps


def test_every_parameter_struct_takes_its_fields_as_keywords():
    h = ps.HingeParams(thickness_m=1.5e-3, radius_m=5e-3)
    assert h.thickness_m == 1.5e-3 and h.radius_m == 5e-3
    assert h.width_m == ps.HingeParams().width_m  # the others keep the paper's values
    inputs = ps.DesignInputs(hinge=h)
    assert inputs.hinge.thickness_m == 1.5e-3
    opts = ps.CalibrationOptions(pid=ps.PidChoice.PAPER)
    assert opts.pid == ps.PidChoice.PAPER
    with pytest.raises(TypeError, match="unexpected keyword argument 'thickness'"):
        ps.HingeParams(thickness=1e-3)
    # Positional constructors still work alongside.
    g = ps.PidGains(1.0, 2.0, 3.0)
    assert (g.kp, g.ki, g.kd) == (1.0, 2.0, 3.0)


def test_signatures_name_the_fields_and_defaults_print_readably():
    sig = inspect.signature(ps.HingeParams)
    assert list(sig.parameters) == ["width_m", "thickness_m", "radius_m", "link_length_m"]
    assert sig.parameters["thickness_m"].default == 2e-3  # Table 3
    for f in (ps.run_step_response, ps.calibrate, ps.reproduce, ps.search_hinge_designs):
        assert "object at 0x" not in f.__doc__, f.__name__


def test_a_calibration_file_round_trips(tmp_path):
    params = ps.SemiClosedLoopParams()
    params.matrix = ps.TransmissionMatrix(np.array([[1.0, 0.1, 0.0], [0.0, 1.1, 0.0],
                                                    [0.0, 0.0, 0.9]]))
    path = tmp_path / "cal.toml"
    ps.write_calibration_file(str(path), params, "test", z_max_um=11.25)
    back, z_max_um = ps.load_calibration_file(str(path))
    assert z_max_um == 11.25
    np.testing.assert_allclose(back.matrix.a, params.matrix.a, rtol=0, atol=1e-12)
    assert back.gains.kp == params.gains.kp
    text = ps.format_calibration(params, "a header")
    assert text.startswith("# a header\n") and "\n[controller]\n" in text
    with pytest.raises(ps.InputError, match="missing.toml"):
        ps.load_calibration_file(str(tmp_path / "missing.toml"))


def test_the_hinge_search_finds_the_papers_neighbourhood():
    result = ps.search_hinge_designs(ps.DesignInputs(), max_candidates=3)
    assert result.evaluated_count > 1000
    assert 0 < result.feasible_count <= result.evaluated_count
    assert len(result.candidates) == 3
    f = [c.evaluation.natural_frequency_Hz for c in result.candidates]
    assert f == sorted(f, reverse=True)  # best first
    for c in result.candidates:
        assert c.evaluation.mechanism_stiffness_N_per_um <= 0.1 * 70.0 + 1e-9  # k_m <= k_a / 10
