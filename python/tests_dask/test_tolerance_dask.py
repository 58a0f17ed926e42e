"""A distributed study's promise, on a local Dask cluster: the same 16-sample study run
with --jobs 1, --jobs 2, two shards merged, `piezoshift tolerance --scheduler` and
run_study(client=...) on a cluster of two worker processes writes the same bytes; a scheduler
that is not there is exit 2."""
import os
import pathlib
import subprocess
import sys

import pytest
from distributed import Client, LocalCluster, get_task_stream

import piezoshift.tolerance as tolerance

SOURCE_DIR = pathlib.Path(
    os.environ.get("PIEZOSHIFT_SOURCE_DIR", pathlib.Path(__file__).resolve().parents[2]))
TOLERANCES = str(SOURCE_DIR / "configs" / "tolerances" / "paper_stage.toml")
CLI = os.environ.get("PIEZOSHIFT_CLI", "piezoshift")
STUDY = ["tolerance", "--tolerances", TOLERANCES, "--samples", "16", "--seed", "5"]


def cli(args, **kw):
    r = subprocess.run([CLI] + args, capture_output=True, text=True, timeout=600, **kw)
    assert r.returncode == 0, r.stderr
    return r


def test_threads_shards_and_a_dask_cluster_give_the_same_bytes(tmp_path):
    out = {name: tmp_path / name for name in ("j1", "j2", "shards", "cli_dask", "api_dask")}
    cli(STUDY + ["--jobs", "1", "--out", str(out["j1"])])
    cli(STUDY + ["--jobs", "2", "--out", str(out["j2"])])
    for shard in ("0/2", "1/2"):
        cli(STUDY + ["--jobs", "1", "--shard", shard, "--out", str(out["shards"])])
    cli(["tolerance", "merge", str(out["shards"] / "shard-0-of-2.json"),
         str(out["shards"] / "shard-1-of-2.json"), "--out", str(out["shards"])])
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                      dashboard_address=None) as cluster:
        env = dict(os.environ, PIEZOSHIFT_PYTHON=sys.executable)
        r = cli(STUDY + ["--scheduler", cluster.scheduler_address, "--out", str(out["cli_dask"])],
                env=env)
        assert "16 samples" in r.stdout
        with Client(cluster) as client, get_task_stream(client) as stream:
            y = tolerance.run_study(TOLERANCES, samples=16, seed=5, out=str(out["api_dask"]),
                                    client=client)
        # both worker processes ran samples: the cluster, not one process, made the bytes
        assert len({task["worker"] for task in stream.data}) == 2
    assert y["samples"] == 16
    assert 0 < y["valid"] <= 16
    reference = (out["j1"] / "tolerance.json").read_bytes()
    assert b'"index": 15' in reference
    for name in ("j2", "shards", "cli_dask", "api_dask"):
        assert (out[name] / "tolerance.json").read_bytes() == reference, name
        assert (out[name] / "tolerance.csv").read_bytes() == (
            out["j1"] / "tolerance.csv").read_bytes(), name
    # every sample was recorded as it arrived: a rerun resumes them all and runs none
    again = subprocess.run([sys.executable, "-m", "piezoshift.tolerance", "--tolerances",
                            TOLERANCES, "--samples", "16", "--seed", "5", "--out",
                            str(out["api_dask"])], capture_output=True, text=True, timeout=120)
    assert again.returncode == 0, again.stderr
    assert "16 sample(s) resumed" in again.stderr
    assert (out["api_dask"] / "tolerance.json").read_bytes() == reference


def test_no_scheduler_there_is_exit_2_naming_it(tmp_path):
    r = subprocess.run([sys.executable, "-m", "piezoshift.tolerance", "--scheduler",
                        "tcp://127.0.0.1:9", "--timeout-s", "1", "--tolerances", TOLERANCES,
                        "--samples", "2", "--out", str(tmp_path)],
                       capture_output=True, text=True, timeout=120)
    assert r.returncode == 2
    assert "no Dask scheduler at tcp://127.0.0.1:9" in r.stderr


def test_a_bad_tolerance_file_is_refused_before_the_cluster_is_asked(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text('[tolerance.hinge.no_such_m]\ndistribution = "uniform"\nlo = 0\nhi = 1\n'
                   'source = "x"\n')
    with pytest.raises(tolerance._ext.InputError, match="no_such_m"):
        tolerance.run_study(str(bad), samples=2, out=str(tmp_path / "o"))
