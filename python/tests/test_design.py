"""Design bindings against the paper's numbers and hand calculations (Eqs. 1 to 3)."""
import math

import pytest

import piezoshift as ps


def test_paper_design_values(config):
    ev = ps.evaluate_design(config.design)
    # Eq. 3 with Table 2 and 3: the paper's 6.776 N/um
    assert ev.mechanism_stiffness_N_per_um == pytest.approx(6.776, abs=5e-4)
    # Eq. 1 by hand: x_m = k_a x_a / (k_a + k_m)
    k_m = ev.mechanism_stiffness_N_per_um
    assert ev.available_displacement_um == pytest.approx(70.0 * 16.0 / (70.0 + k_m), rel=1e-12)
    assert ev.rule_ka_over_10_ok
    assert ev.stiffness_rule_limit_N_per_um == pytest.approx(7.0)
    # the moving mass was fitted to the FEA mode of 1839 Hz (Figure 2c)
    assert ev.natural_frequency_Hz == pytest.approx(1839.0, abs=1.0)
    assert ev.thickness_to_radius == pytest.approx(2.0 / 6.0)


def test_free_functions_match_evaluation(config):
    d = config.design
    k_m = ps.mechanism_stiffness_N_per_um(d.material, d.hinge)
    assert k_m == pytest.approx(ps.evaluate_design(d).mechanism_stiffness_N_per_um, rel=1e-15)
    assert ps.available_displacement_um(d.actuator, k_m) == pytest.approx(
        16.0 * 70.0 / (70.0 + k_m))


def test_nested_fields_edit_in_place(config):
    ev0 = ps.evaluate_design(config.design)
    config.design.hinge.thickness_m = 2.5e-3
    assert config.design.hinge.thickness_m == 2.5e-3
    ev1 = ps.evaluate_design(config.design)
    # Eq. 2 goes with t^(5/2) for t << R: a thicker neck is stiffer
    assert ev1.mechanism_stiffness_N_per_um > 1.5 * ev0.mechanism_stiffness_N_per_um


def test_unphysical_inputs_raise_value_error(config):
    config.design.material.poisson_ratio = 0.7
    assert "poisson" in config.design.problem().lower()
    with pytest.raises(ValueError, match="(?i)poisson"):
        ps.evaluate_design(config.design)


def test_defaults_are_the_papers_tables():
    d = ps.DesignInputs()
    assert d.actuator.stiffness_N_per_um == 70.0
    assert d.material.elastic_modulus_Pa == 2.1e11
    assert (d.hinge.width_m, d.hinge.thickness_m, d.hinge.radius_m,
            d.hinge.link_length_m) == (8e-3, 2e-3, 6e-3, 18e-3)
    assert math.isclose(d.mechanism.moving_mass_kg, 0.05075)
