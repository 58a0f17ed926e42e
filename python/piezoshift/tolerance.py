"""Tolerance studies on a Dask cluster, or on local threads (docs/tolerance.md).

``run_study`` runs a study as ``piezoshift tolerance`` does and writes the same files. Given a
``dask.distributed.Client``, each sample is a task on the cluster's workers: a worker is handed the
study's description (the tolerance and configuration files' text, the seed, the procedure), so it
needs the piezoshift package but neither the files nor a shared filesystem. A sample depends on
(seed, index) alone and comes back as the JSON text of its record, which reads back bit for bit, so
the study's ``tolerance.json`` has the same bytes whatever ran it. Each finished sample is recorded
under ``<out>/samples`` as it arrives: a study interrupted and run again resumes from them.

``python3 -m piezoshift.tolerance --scheduler tcp://host:8786 --tolerances FILE ...`` is the
command line (``piezoshift tolerance --scheduler ...`` runs it).
"""

import argparse
import re
import sys
import time

from . import _piezoshift as _ext

__all__ = ["run_study", "main"]


def _run_sample(description, index):
    """One sample, on a Dask worker."""
    return _ext.tolerance_run_sample(description, index)


def _run_sensitivity(description, k):
    """One run of the sensitivity table, on a Dask worker."""
    return _ext.tolerance_run_sensitivity(description, k)


def _on_cluster(client, function, description, indices, what, progress, on_result):
    """function(description, i) for each i on the cluster; on_result(i, text) as each arrives."""
    from distributed import as_completed

    futures = {client.submit(function, description, i, pure=False): i for i in indices}
    lines = _ext.tolerance_progress_lines(what) if progress else None
    start = time.monotonic()
    for done, future in enumerate(as_completed(futures), start=1):
        on_result(futures[future], future.result())
        if lines is not None:
            lines(done, len(futures), time.monotonic() - start)


def run_study(tolerances, *, samples=100, seed=1, config=None, spec=None, procedure="paper",
              experiments="quick", out="tolerance-study", figures=False, sensitivity=False,
              client=None, jobs=0, progress=True):
    """Runs a tolerance study and writes its files in ``out`` (docs/tolerance.md).

    tolerances, config, spec: file paths (config None: the built-in defaults; spec None: none).
    client: a ``dask.distributed.Client`` whose workers run the samples; None runs them on ``jobs``
    local threads (0: every core). Returns the yield: a dict with ``samples``, ``valid``, ``pass``,
    ``fraction`` and the report's paths ``markdown`` and ``html``. Bad files raise InputError.
    """
    study = _ext.load_tolerance_study(tolerances, config or "", spec or "", samples, seed,
                                      procedure, experiments)
    if client is None:  # resumes, runs and records as `piezoshift tolerance` does
        results = dict(enumerate(study.run_local(out, list(range(samples)), jobs)))
    else:
        results = {}
        for i in range(samples):
            text = study.resumed(out, i)
            if text is not None:
                results[i] = text
        todo = [i for i in range(samples) if i not in results]
        if len(todo) < samples and progress:
            print(f"piezoshift: tolerance: {samples - len(todo)} sample(s) resumed from "
                  f"{out}/samples", file=sys.stderr)

        def keep(i, text):
            study.record(out, text)
            results[i] = text

        _on_cluster(client, _run_sample, study.description, todo, "tolerance", progress, keep)
    runs = None
    if sensitivity:
        if client is None:
            runs = study.run_sensitivity_local(jobs)
        else:
            found = {}
            _on_cluster(client, _run_sensitivity, study.description,
                        range(study.sensitivity_runs), "tolerance sensitivity", progress,
                        found.__setitem__)
            runs = [found[k] for k in range(study.sensitivity_runs)]
    return study.write_outputs(out, [results[i] for i in range(samples)], figures, runs)


MAX_SAMPLES = 1_000_000  # tolerance::kMaxSamples (docs/tolerance.md)
_SCHEDULER_FORM = ("give SCHEME://HOST:PORT (tcp, tls, ws, wss or ucx; e.g. tcp://127.0.0.1:8786) "
                   "or inproc://NAME")


def scheduler_problem(text):
    """Empty when text is a Dask scheduler's address, else why not (as `piezoshift tolerance`)."""
    if any(ord(c) < 0x20 or c in " \x7f" for c in text):
        return f"'{text}' holds a space or a control character; {_SCHEDULER_FORM}"
    scheme, sep, rest = text.partition("://")
    if not sep:
        return f"'{text}' is not a scheduler address; {_SCHEDULER_FORM}"
    if scheme == "inproc":
        return "" if rest else f"'{text}' names no process; {_SCHEDULER_FORM}"
    if scheme not in ("tcp", "tls", "ws", "wss", "ucx"):
        return f"'{text}': unknown scheme '{scheme}'; {_SCHEDULER_FORM}"
    host, colon, port = rest.rpartition(":")
    if (not colon or not host or not re.fullmatch(r"[0-9]{1,5}", port)
            or not 1 <= int(port) <= 65535 or any(c in rest for c in "/?#@")):
        return f"'{text}' needs a host and a port 1..65535; {_SCHEDULER_FORM}"
    return ""


def _arguments(argv):
    p = argparse.ArgumentParser(
        prog="python3 -m piezoshift.tolerance",
        description="A tolerance study on a Dask cluster (docs/tolerance.md)")
    p.add_argument("--scheduler", help="Dask scheduler address, tcp://host:8786; without it, "
                   "local threads")
    p.add_argument("--tolerances", required=True, help="TOML tolerance file")
    p.add_argument("--config", help="TOML configuration: the nominal stage")
    p.add_argument("--spec", help="TOML file with [spec] <metric>_min / <metric>_max")
    p.add_argument("--samples", type=int, default=100, help="Monte Carlo samples")
    p.add_argument("--seed", type=int, default=1, help="study seed")
    p.add_argument("--procedure", choices=["paper", "improved"], default="paper")
    p.add_argument("--experiments", choices=["quick", "table4"], default="quick")
    p.add_argument("--out", default="tolerance-study", help="output folder")
    p.add_argument("--jobs", type=int, default=0, help="local threads without --scheduler")
    p.add_argument("--figures", action="store_true", help="histograms of the metrics (gnuplot)")
    p.add_argument("--sensitivity", action="store_true",
                   help="each tolerance alone at its limits")
    p.add_argument("--timeout-s", type=float, default=30.0,
                   help="how long to wait for the scheduler")
    return p.parse_args(argv)


def main(argv=None):
    """The command line; returns the exit status (2: bad input or no scheduler)."""
    a = _arguments(sys.argv[1:] if argv is None else argv)
    if not 1 <= a.samples <= MAX_SAMPLES or a.seed < 0 or a.jobs < 0:
        print(f"piezoshift: error: tolerance: --samples must be 1 to {MAX_SAMPLES}, --seed and "
              "--jobs not negative", file=sys.stderr)
        return 2
    if a.scheduler and scheduler_problem(a.scheduler):
        print(f"piezoshift: error: tolerance --scheduler: {scheduler_problem(a.scheduler)}",
              file=sys.stderr)
        return 2
    client = None
    try:
        if a.scheduler:
            from distributed import Client
            try:
                client = Client(a.scheduler, timeout=f"{a.timeout_s}s")
            except (OSError, TimeoutError) as e:
                print(f"piezoshift: error: tolerance: no Dask scheduler at {a.scheduler}: {e}",
                      file=sys.stderr)
                return 2
        y = run_study(a.tolerances, samples=a.samples, seed=a.seed, config=a.config, spec=a.spec,
                      procedure=a.procedure, experiments=a.experiments, out=a.out,
                      figures=a.figures, sensitivity=a.sensitivity, client=client, jobs=a.jobs)
    except _ext.InputError as e:
        print(f"piezoshift: error: {e}", file=sys.stderr)
        return 2
    finally:
        if client is not None:
            client.close()
    print(f"piezoshift tolerance: {y['samples']} samples, {y['valid']} valid, {y['pass']} meet "
          f"the spec ({100.0 * y['fraction']:.1f} %)")
    print(f"report: {y['markdown']} and {y['html']}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
