"""`python3 -m piezoshift.tolerance`'s refusals before any study or scheduler: a --scheduler that
is not a Dask address (it ended in a traceback, exit 1) and a sample count out of 1..10^6."""
import pytest

from piezoshift import tolerance


@pytest.mark.parametrize("address", ["tcp://127.0.0.1:8786", "tls://[::1]:8786",
                                     "ws://scheduler.example:443", "inproc://192.168.1.2/1234/1"])
def test_dask_addresses_are_accepted(address):
    assert tolerance.scheduler_problem(address) == ""


@pytest.mark.parametrize("address, why", [
    ("garbage", "is not a scheduler address"),
    ("tcp://host", "needs a host and a port 1..65535"),
    ("tcp://host:0", "needs a host and a port 1..65535"),
    ("tcp://host:99999", "needs a host and a port 1..65535"),
    ("http://host:80", "unknown scheme 'http'"),
    ("tcp://host:8786\n", "holds a space or a control character"),
])
def test_other_addresses_are_refused_saying_why(address, why):
    assert why in tolerance.scheduler_problem(address)


def test_main_exits_2_before_it_starts(tmp_path, capsys):
    tol = str(tmp_path / "none.toml")  # never read: the arguments are refused first
    assert tolerance.main(["--scheduler", "garbage", "--tolerances", tol]) == 2
    err = capsys.readouterr().err
    assert "tolerance --scheduler: 'garbage' is not a scheduler address" in err
    assert tolerance.main(["--samples", "1000001", "--tolerances", tol]) == 2
    assert "--samples must be 1 to 1000000" in capsys.readouterr().err
