"""Both notebooks execute top to bottom on small parameters (a tiny policy trained here)."""

import os
from pathlib import Path

import nbformat
from nbclient import NotebookClient

from leas_jax.files import REPO_ROOT

NOTEBOOKS = REPO_ROOT / "notebooks"
FLAT_SCENARIO = """name = "flat_scenario"
bounds = [[0.0, 0.0], [6.0, 4.0]]
void_height = -2.0
resolution = 0.05
[[box]]
center = [3.0, 2.0, -0.1]
size = [6.0, 4.0, 0.2]
[scenario]
target = [3.0, 2.0]
start_region = [[1.4, 1.9], [1.6, 2.1]]
start_yaw_deg = [-20.0, 20.0]
start_speed = [0.0, 0.05]
n_starts = 60
seed = 0
"""


def _execute(name: str, env: dict, cwd: Path):
    notebook = nbformat.read(NOTEBOOKS / name, as_version=4)
    old = {k: os.environ.get(k) for k in env}
    os.environ.update(env)  # the kernel inherits the parameters from this process
    try:
        NotebookClient(
            notebook, timeout=120, kernel_name="python3", resources={"metadata": {"path": str(cwd)}}
        ).execute()
    finally:
        for k, v in old.items():
            if v is None:
                os.environ.pop(k, None)
            else:
                os.environ[k] = v
    return notebook


def _outputs(notebook) -> str:
    return "".join(
        o.get("text", "") + str(o.get("data", {}).get("text/markdown", ""))
        for cell in notebook.cells
        if cell.cell_type == "code"
        for o in cell.outputs
    )


def test_learning_progression_notebook_runs(run_dir, tmp_path):
    notebook = _execute(
        "learning_progression.ipynb",
        {"LEAS_NB_RUN": str(run_dir), "LEAS_NB_N": "2", "LEAS_NB_STEPS": "20", "LEAS_NB_CHECKPOINTS": "2"},
        tmp_path,
    )
    text = _outputs(notebook)
    assert "checkpoints:" in text and "valid starts of 4" in text
    assert any(
        o.get("output_type") == "display_data" and "image/png" in o.get("data", {})
        for cell in notebook.cells
        if cell.cell_type == "code"
        for o in cell.outputs
    )


def test_scenarios_notebook_runs(run_dir, tmp_path):
    terrain = tmp_path / "flat.toml"
    terrain.write_text(FLAT_SCENARIO)
    out = tmp_path / "eval"
    notebook = _execute(
        "scenarios.ipynb",
        {
            "LEAS_NB_RUN": str(run_dir),
            "LEAS_NB_N": "1",
            "LEAS_NB_METHODS": "rblin,leas",
            "LEAS_NB_WORKERS": "0",
            "LEAS_NB_OUT": str(out),
            "LEAS_NB_TERRAIN": str(terrain),
            "LEAS_NB_HOLE_WIDTHS": "0.6",
        },
        tmp_path,
    )
    assert (out / "results.json").is_file() and (out / "flat_scenario.png").is_file()
    assert (out / "hole_sweep" / "hole_sweep.png").is_file()
    text = _outputs(notebook)
    assert "flat_scenario" in text and "| 0.6 |" in text
