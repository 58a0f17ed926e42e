#!/usr/bin/env python3
"""Runs the code cells of a Jupyter notebook in order, in one namespace, as a kernel would
(headless: matplotlib's Agg backend). CI uses it instead of jupyter-nbconvert, which Debian would
bring with a whole Jupyter stack: a failing cell fails with its traceback and the cell's number.

    PYTHONPATH=build/release/python python3 examples/run_notebook.py examples/design_simulate_calibrate.ipynb
"""
import json
import os
import sys


def main():
    if len(sys.argv) != 2:
        sys.exit("usage: run_notebook.py NOTEBOOK.ipynb")
    os.environ.setdefault("MPLBACKEND", "Agg")
    with open(sys.argv[1], encoding="utf-8") as f:
        notebook = json.load(f)
    namespace = {"__name__": "__main__"}
    cells = [c for c in notebook["cells"] if c["cell_type"] == "code"]
    for number, cell in enumerate(cells, 1):
        source = "".join(cell["source"])
        print(f"--- cell {number} of {len(cells)}")
        exec(compile(source, f"{sys.argv[1]}, cell {number}", "exec"), namespace)  # noqa: S102
    print(f"ran {len(cells)} cells of {sys.argv[1]}")


if __name__ == "__main__":
    main()
