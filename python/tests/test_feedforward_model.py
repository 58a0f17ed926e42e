"""The controller's feedforward models from Python, exact both ways: the paper's cubic p and
matrix A, and the improved controller's hysteresis and creep model of each actuator
(ImprovedParams.model, three HysteresisCreepParams with their lists)."""
import math

import numpy as np
import pytest

import piezoshift as ps

# Values with all 17 significant digits in use, so that any rounding on the way shows.
THIRD = 1.0 / 3.0
SEVENTH_PI = math.pi / 7.0


def model(channel):
    """A channel's model with every list in use, different per channel."""
    m = ps.HysteresisCreepParams()
    m.offset_um = -THIRD * (channel + 1)
    m.linear_weight = 0.5 + SEVENTH_PI / (channel + 2)
    m.set_operators([SEVENTH_PI * (j + 1) + channel for j in range(4)],
                    [THIRD / (j + 1) for j in range(4)])
    m.creep_time_constant_s = [0.003 * 10.0 ** (k / 3.0) for k in range(5 + channel)]
    m.creep_gain = 0.01 * SEVENTH_PI / (channel + 1)
    return m


def improved_controller():
    c = ps.SemiClosedLoopParams()
    c.kind = ps.ControllerKind.improved
    c.improved.model = [model(i) for i in range(3)]
    return c


def fields(m):
    return (m.offset_um, m.linear_weight, m.threshold_um, m.weight, m.creep_time_constant_s,
            m.creep_gain)


def test_the_default_model_is_linear_with_empty_lists(controller):
    models = controller.improved.model
    assert len(models) == 3
    assert fields(models[2]) == (0.0, 1.0, [], [], [], 0.0)


def test_the_model_round_trips_exactly_and_per_channel():
    c = improved_controller()
    for i, m in enumerate(c.improved.model):
        assert fields(m) == fields(model(i))  # == on floats: exact
    assert c.improved.model[1].weight[3] == THIRD / 4
    assert len(c.improved.model[2].creep_time_constant_s) == 7
    assert c.problem(1e-3) == ""


def test_the_model_edits_in_place_or_is_set_whole(controller):
    # The list is new at each read, its elements are the controller's own (like the scaling).
    controller.improved.model[0].linear_weight = 2.0
    assert [m.linear_weight for m in controller.improved.model] == [2.0, 1.0, 1.0]
    models = [model(2), model(1), model(0)]
    controller.improved.model = models
    assert fields(controller.improved.model[0]) == fields(model(2))
    with pytest.raises(TypeError):
        controller.improved.model = models[:2]  # one per actuator, three


def test_the_loop_sees_the_model():
    c = improved_controller()
    models = c.improved.model
    models[1].creep_gain = float("nan")
    c.improved.model = models
    assert "not a finite number" in c.problem(1e-3)


def test_the_model_survives_the_calibration_file_exactly(tmp_path):
    c = improved_controller()
    path = str(tmp_path / "improved.toml")
    ps.write_calibration_file(path, c)
    loaded, _ = ps.load_calibration_file(path)
    assert loaded.kind == ps.ControllerKind.improved
    for i in range(3):
        assert fields(loaded.improved.model[i]) == fields(model(i))


def test_operator_lists_keep_one_count():
    m = model(0)
    m.weight = [0.0, 0.25, 0.5, 1.0]  # same count: new values
    assert m.weight == [0.0, 0.25, 0.5, 1.0]
    with pytest.raises(ps.InputError, match="weight: 3 values for 4 operators"):
        m.weight = [1.0, 1.0, 1.0]
    with pytest.raises(ps.InputError, match="3 weights for 2 thresholds"):
        m.set_operators([1.0, 2.0], [1.0, 1.0, 1.0])
    assert m.threshold_um == model(0).threshold_um  # a refused set changes nothing
    m.set_operators([], [])
    assert (m.threshold_um, m.weight) == ([], [])


def test_lists_the_controller_would_misread_are_refused():
    m = ps.HysteresisCreepParams()
    with pytest.raises(ps.InputError, match="at most 16 values, not 17"):
        m.set_operators([float(j + 1) for j in range(17)], [0.0] * 17)
    with pytest.raises(ps.InputError, match=r"threshold_um\[1\] = 1: must be positive and incr"):
        m.set_operators([2.0, 1.0], [0.0, 0.0])
    with pytest.raises(ps.InputError, match=r"weight\[0\] = -0.5: must be >= 0"):
        m.set_operators([1.0], [-0.5])
    with pytest.raises(ps.InputError, match="creep_time_constant_s: at most 12 values"):
        m.creep_time_constant_s = [1.0] * 13
    with pytest.raises(ps.InputError, match=r"creep_time_constant_s\[0\] = 0: must be positive"):
        m.creep_time_constant_s = [0.0]
    assert fields(m) == fields(ps.HysteresisCreepParams())


def test_polynomial_and_matrix_round_trip_exactly(controller, tmp_path):
    controller.polynomial = ps.CubicPolynomial(-THIRD * 1e-3, SEVENTH_PI * 1e-2, 1.0 + THIRD,
                                               -SEVENTH_PI)
    a = np.array([[1.0 + THIRD, -THIRD, SEVENTH_PI],
                  [THIRD / 7, 1.0 - SEVENTH_PI, 2.0 ** -40],
                  [-1e-17, THIRD, 0.9999999999999999]])
    controller.matrix.a = a
    p = controller.polynomial
    assert [p.p3, p.p2, p.p1, p.p0] == [-THIRD * 1e-3, SEVENTH_PI * 1e-2, 1.0 + THIRD,
                                         -SEVENTH_PI]
    assert np.array_equal(controller.matrix.a, a)
    path = str(tmp_path / "paper.toml")
    ps.write_calibration_file(path, controller)
    loaded, _ = ps.load_calibration_file(path)
    assert np.array_equal(loaded.matrix.a, a)
    assert loaded.polynomial.p0 == -SEVENTH_PI and loaded.polynomial.p3 == -THIRD * 1e-3
