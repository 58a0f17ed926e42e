"""The controller's full parameters from Python: the kind, the signal scaling and the improved
controller's parts, and the check the loop runs before it takes a parameter set."""
import pytest

import piezoshift as ps


def test_the_papers_parameters_run_at_their_rate(controller):
    assert controller.kind == ps.ControllerKind.paper
    assert controller.problem(1e-3) == ""
    assert "sample time" in controller.problem(1e-4)


def test_an_improved_controller_runs_only_at_the_rate_it_was_designed_at(controller):
    controller.kind = ps.ControllerKind.improved
    assert controller.problem(1e-3) == ""
    controller.improved.sample_time_s = 1e-4  # edits in place
    assert controller.improved.sample_time_s == 1e-4
    assert "improved controller" in controller.problem(1e-3)


def test_the_scaling_is_set_whole_and_inverts(controller):
    scaling = controller.scaling
    assert len(scaling) == 3
    assert scaling[0].drive_V_per_um == 0.625  # Section 4: 10 V over the 16 um stroke
    assert scaling[0].dac_to_um(scaling[0].um_to_dac(5.0)) == pytest.approx(5.0, abs=1e-14)
    scaling[1].drive_V_per_um = 0.0
    controller.scaling = scaling
    assert "scaling" in controller.problem(1e-3)


def test_shaper_taps_are_a_whole_list(controller):
    shaper = controller.improved.shaper
    assert shaper.taps == [1.0]
    shaper.taps = [0.25, 0.5, 0.25]
    assert controller.improved.shaper.taps == [0.25, 0.5, 0.25]
    with pytest.raises(ps.InputError, match="taps"):
        shaper.taps = []


def test_a_calibration_is_checked_as_its_file_is_at_load(controller, tmp_path):
    # The loop's floor above, and the calibration's list (controller_ranges.hpp): ranges, p, A,
    # and gains stable on the nominal inner loop.
    assert ps.controller_problem(controller) == ""
    assert ps.controller_problem(controller, 1e-4) == ""
    gains = controller.gains
    gains.kp, gains.ki, gains.kd = 5.0, 3.0, 2.0
    controller.gains = gains
    assert "unstable on the nominal inner loop" in ps.controller_problem(controller)
    path = str(tmp_path / "unstable.toml")
    ps.write_calibration_file(path, controller)
    with pytest.raises(ps.InputError, match="unstable.toml"):
        ps.load_calibration_file(path)


def test_a_controller_from_python_passes_the_files_check_before_a_loop_runs_it(config, tmp_path):
    # The same check as the file's loader and SPA over GCS, whatever the door.
    unstable = ps.SemiClosedLoopParams()
    unstable.gains = ps.PidGains(5.0, 3.0, 2.0)
    with pytest.raises(ps.InputError, match="unstable on the nominal inner loop"):
        ps.Bench(config, unstable, 1)
    bench = ps.Bench(config, ps.SemiClosedLoopParams(), 1)
    with pytest.raises(ps.InputError, match="unstable on the nominal inner loop"):
        bench.set_controller(unstable)
    steep = ps.SemiClosedLoopParams()
    steep.polynomial = ps.CubicPolynomial(0.0, 0.0, 1000.0, 0.0)  # full stroke for 1 um
    with pytest.raises(ps.InputError, match="slope over the 0 to 16 um stroke"):
        ps.run_step_response(config, steep, 1)
    # A travel beyond the stroke is neither written nor read.
    with pytest.raises(ps.InputError, match="z_max_um"):
        ps.write_calibration_file(str(tmp_path / "far.toml"), ps.SemiClosedLoopParams(),
                                  z_max_um=1e308)
    far = tmp_path / "far.toml"
    far.write_text("[controller]\nkp = 0.6\n[travel]\nz_max_um = 1e308\n")
    with pytest.raises(ps.InputError, match="far.toml:4:.*z_max_um"):
        ps.load_calibration_file(str(far))
