"""Configuration loading and the C++ errors as Python exceptions."""
import pytest

import piezoshift as ps


def test_paper_toml_equals_defaults(paper_toml, config):
    loaded = ps.load_project_config(paper_toml)
    ev_loaded = ps.evaluate_design(loaded.design)
    ev_default = ps.evaluate_design(config.design)
    assert ev_loaded.mechanism_stiffness_N_per_um == ev_default.mechanism_stiffness_N_per_um
    assert loaded.twin.daq.sample_time_s == pytest.approx(1e-3)
    assert loaded.twin.physics_rate_Hz == config.twin.physics_rate_Hz


def test_missing_file_is_input_error(tmp_path):
    path = tmp_path / "absent.toml"
    with pytest.raises(ps.InputError, match="absent.toml"):
        ps.load_project_config(str(path))


def test_bad_value_names_the_key(tmp_path):
    path = tmp_path / "bad.toml"
    path.write_text("[hinge]\nthickness_m = -1.0\n")
    with pytest.raises(ps.InputError, match="thickness_m"):
        ps.load_project_config(str(path))


def test_unknown_key_is_rejected(tmp_path):
    path = tmp_path / "typo.toml"
    path.write_text("[hinge]\nthicknes_m = 2e-3\n")
    with pytest.raises(ps.InputError, match="thicknes_m"):
        ps.load_project_config(str(path))


def test_error_hierarchy():
    assert issubclass(ps.InputError, ValueError)
    assert issubclass(ps.FitError, ps.InputError)
    assert issubclass(ps.MetricsError, ps.InputError)


def test_to_dict_and_repr_use_the_field_names(config):
    d = ps.to_dict(config)
    assert d["design"]["hinge"]["thickness_m"] == 2e-3
    assert d["twin"]["sgs"]["nonlinearity_shape"] == "BOW"
    assert d["twin"]["contact"]["stiffness_N_per_um"] is None
    assert len(d["twin"]["geometry"]["transmission_matrix"]) == 3
    assert "thickness_m=0.002" in repr(config.design.hinge)


def test_params_built_in_python_meet_the_readers_ranges():
    # One list of ranges (plant/twin_ranges.hpp) for the TOML reader and the bindings.
    twin = ps.TwinParams()
    twin.physics_rate_Hz = 2e12
    assert (ps.twin_params_problem(ps.DesignInputs(), twin)
            == "twin.physics_rate_Hz = 2000000000000 must be in [1, 10000000]")
    with pytest.raises(ValueError, match="twin.physics_rate_Hz"):
        ps.Twin(ps.DesignInputs(), twin, 1)


def test_safety_section_is_accepted_and_checked(tmp_path):
    ok = tmp_path / "site.toml"
    ok.write_text("[safety]\noutput_max_V = 8.0\n")
    assert ps.load_project_config(str(ok)).twin.physics_rate_Hz == 20000.0
    bad = tmp_path / "bad_site.toml"
    bad.write_text("[safety]\noutput_max_V = 11.0\n")
    with pytest.raises(ps.InputError, match=r"bad_site.toml:2:16: safety.output_max_V"):
        ps.load_project_config(str(bad))
