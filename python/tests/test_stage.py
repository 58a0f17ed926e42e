"""The real-time loop from Python (docs/python.md): piezoshift.Stage on the twin at the loop's
rate (daq="sim-rt"), its loop on its own thread. A move, a wait on target, a recorder read, an
injected fault raising by its name, and the ramp to 0 V at the `with` exit. Timeouts are failure
guards only: nothing asserts on wall-clock time."""
import numpy as np
import pytest

import piezoshift as ps


def test_a_move_waits_on_target_and_the_recorder_follows_it():
    with ps.Stage(daq="sim-rt", rate_Hz=1000, seed=1) as stage:
        assert stage.daq == "sim" and stage.rate_Hz == 1000
        stage.servo(True)
        assert stage.servo_on
        before = stage.target()  # where servo on closed the loop
        stage.record(samples=300, every=1, signals=["target", "position", "output_V"])
        stage.move(z_um=5.0)
        stage.wait_on_target(timeout_s=10)
        assert stage.on_target
        z, tip, tilt = stage.position()
        assert abs(z - 5.0) <= 0.01  # the on-target band of Z, 10 nm
        assert abs(tip) <= 0.5 and abs(tilt) <= 0.5
        # The axes not named keep the targets servo on took from the gauges.
        np.testing.assert_array_equal(stage.target(), [5.0, before[1], before[2]])
        r = stage.read_recording(timeout_s=10)
        assert set(r) == {"time_s", "target", "position", "output_V", "every", "ticks_missed"}
        assert r["time_s"].shape == (300,) and r["position"].shape == (300, 3)
        assert r["ticks_missed"] == 0
        # One point a tick: 1 ms apart, or whole periods more where a late tick skipped slots.
        periods = np.diff(r["time_s"]) / 1e-3
        assert np.all(periods >= 1 - 1e-6)
        np.testing.assert_allclose(periods, np.round(periods), atol=1e-6)
        assert r["target"][0, 0] == before[0]  # before the move
        assert r["target"][-1, 0] == 5.0
        assert r["position"][0, 0] < 1.0 < 4.9 < r["position"][-1, 0]
        assert r["output_V"][-1, 0] > 1.0


def test_an_unreachable_move_is_refused_with_the_reason():
    with ps.Stage(daq="sim-rt", free_run=True) as stage:
        with pytest.raises(RuntimeError, match="the servo is off"):
            stage.move(z_um=1.0)
        stage.servo(True)
        with pytest.raises(ps.InputError, match="out of reach"):
            stage.move(z_um=50.0)
        with pytest.raises(ps.InputError, match="recorder signal 'volts'"):
            stage.record(samples=10, signals=["volts"])


def test_an_injected_fault_raises_with_its_name():
    with ps.Stage(daq="sim-rt", faults=["sgs-open@0.3:2"], free_run=True) as stage:
        stage.servo(True)
        stage.move(z_um=4.0)
        stage.wait_on_target(timeout_s=10)  # well before the fault
        # Half a second of the loop: the recorder reads through the fault.
        stage.record(samples=500, signals=["position"])
        assert stage.read_recording(timeout_s=10)["time_s"].shape == (500,)
        with pytest.raises(ps.StageFault) as caught:
            stage.move(z_um=6.0)
        assert caught.value.name == "sgs-rail"
        assert caught.value.channel == 2
        assert isinstance(caught.value, RuntimeError)
        assert "sgs-rail on channel 2" in str(caught.value)
        assert stage.fault["name"] == "sgs-rail"
        assert not stage.servo_on


def test_a_wait_that_cannot_end_times_out():
    with ps.Stage(daq="sim-rt", free_run=True, on_target_um=1e-9) as stage:
        stage.servo(True)
        stage.move(z_um=3.0)
        with pytest.raises(ps.StageTimeout, match="not on target after 0.05 s") as caught:
            stage.wait_on_target(timeout_s=0.05)
        assert isinstance(caught.value, TimeoutError)


def test_leaving_the_with_block_ramps_to_zero_volts():
    with ps.Stage(daq="sim-rt") as stage:
        stage.servo(True)
        stage.move(z_um=8.0)
        stage.wait_on_target(timeout_s=10)
        assert stage.output_V()[0] > 0.5
    assert stage.closed
    np.testing.assert_array_equal(stage.output_V(), [0.0, 0.0, 0.0])
    stage.close()  # idempotent
    with pytest.raises(RuntimeError, match="the stage is closed"):
        stage.move(z_um=1.0)


def test_bad_options_name_themselves():
    with pytest.raises(ps.InputError, match="--rate-hz"):
        ps.Stage(rate_Hz=50)
    with pytest.raises(ps.InputError, match="sgs-open@x"):
        ps.Stage(faults=["sgs-open@x"])
    with pytest.raises(ps.InputError, match="free_run"):
        ps.Stage(daq="comedi:/dev/comedi9", free_run=True)
