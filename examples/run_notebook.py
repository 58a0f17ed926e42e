#!/usr/bin/env python3
"""Runs a Jupyter notebook's code cells in order, headless (matplotlib's Agg backend).

By default in one namespace, as a kernel would, with no Jupyter at all: a failing cell fails with
its traceback and the cell's number. With --kernel, through nbclient and a real IPython kernel
(Debian's python3-nbclient and python3-ipykernel), as Jupyter runs it; the kernel is this very
interpreter, through a kernel spec written to a temporary directory, so that neither a `python3`
first on PATH nor the machine's kernel specs decide what runs.

    PYTHONPATH=build/release/python python3 examples/run_notebook.py examples/design_simulate_calibrate.ipynb
    PYTHONPATH=build/release/python python3 examples/run_notebook.py --kernel examples/calibrate_measure_stage.ipynb
"""
import json
import os
import sys
import tempfile

KERNEL_NAME = "piezoshift-notebook"


def run_in_namespace(path, notebook):
    namespace = {"__name__": "__main__"}
    cells = [c for c in notebook["cells"] if c["cell_type"] == "code"]
    for number, cell in enumerate(cells, 1):
        source = "".join(cell["source"])
        print(f"--- cell {number} of {len(cells)}")
        exec(compile(source, f"{path}, cell {number}", "exec"), namespace)  # noqa: S102
    print(f"ran {len(cells)} cells of {path}")


def run_in_kernel(path):
    import nbformat
    from nbclient import NotebookClient

    with tempfile.TemporaryDirectory(prefix="piezoshift-kernel-") as jupyter_dir:
        spec_dir = os.path.join(jupyter_dir, "kernels", KERNEL_NAME)
        os.makedirs(spec_dir)
        with open(os.path.join(spec_dir, "kernel.json"), "w", encoding="utf-8") as f:
            json.dump({"argv": [sys.executable, "-Xfrozen_modules=off", "-m",
                                "ipykernel_launcher", "-f", "{connection_file}"],
                       "display_name": "piezoshift", "language": "python"}, f)
        os.environ["JUPYTER_PATH"] = jupyter_dir
        os.environ.setdefault("JUPYTER_RUNTIME_DIR", os.path.join(jupyter_dir, "runtime"))
        os.environ.setdefault("IPYTHONDIR", os.path.join(jupyter_dir, "ipython"))
        notebook = nbformat.read(path, as_version=4)
        client = NotebookClient(notebook, timeout=600, kernel_name=KERNEL_NAME,
                                resources={"metadata": {"path": os.getcwd()}})
        client.execute()
    cells = sum(1 for c in notebook.cells if c.cell_type == "code")
    print(f"ran {cells} cells of {path} in an IPython kernel")


def main():
    args = sys.argv[1:]
    kernel = "--kernel" in args
    args = [a for a in args if a != "--kernel"]
    if len(args) != 1:
        sys.exit("usage: run_notebook.py [--kernel] NOTEBOOK.ipynb")
    os.environ.setdefault("MPLBACKEND", "Agg")
    if kernel:
        run_in_kernel(args[0])
        return
    with open(args[0], encoding="utf-8") as f:
        notebook = json.load(f)
    run_in_namespace(args[0], notebook)


if __name__ == "__main__":
    main()
