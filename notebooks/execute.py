"""Execute a notebook of this folder in place, keeping its outputs (the committed notebooks
show them), with parameters as NAME=VALUE environment variables for its kernel.

    python notebooks/execute.py learning_progression.ipynb LEAS_NB_CHECKPOINTS=4
    python notebooks/execute.py scenarios.ipynb LEAS_NB_RUN=checkpoints/leas_talos LEAS_NB_WORKERS=2

Cells run from the repository root, so relative paths in the parameters are from there.
tests/test_eval_notebooks.py executes the same notebooks on small parameters without writing them.
"""

import os
import sys
import time
from pathlib import Path

import nbformat
from nbclient import NotebookClient

ROOT = Path(__file__).resolve().parents[1]


def main(argv: list[str]) -> int:
    if not argv or not argv[0].endswith(".ipynb"):
        print(__doc__, file=sys.stderr)
        return 2
    path = Path(__file__).resolve().parent / argv[0]
    params = dict(arg.split("=", 1) for arg in argv[1:])
    os.environ.update(params)  # the kernel inherits them
    os.environ["PYTHONPATH"] = os.pathsep.join(filter(None, [str(ROOT), os.environ.get("PYTHONPATH")]))
    notebook = nbformat.read(path, as_version=4)
    start = time.perf_counter()
    NotebookClient(
        notebook, timeout=None, kernel_name="python3", resources={"metadata": {"path": str(ROOT)}}
    ).execute()
    nbformat.write(notebook, path)
    print(f"executed {path.name} in {time.perf_counter() - start:.0f} s with {params or 'the defaults'}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
