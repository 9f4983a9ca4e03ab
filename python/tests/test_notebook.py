"""The example notebook runs from top to bottom (its cells assert what the mathematics says of
the results)."""

import os

import nbformat
from nbclient import NotebookClient

from conftest import REPO


def test_the_example_notebook_runs():
    path = REPO / "examples/notebooks/sweep_and_disc.ipynb"
    nb = nbformat.read(path, as_version=4)
    os.environ.setdefault("MPLBACKEND", "Agg")
    NotebookClient(nb, timeout=600, kernel_name="python3", resources={"metadata": {"path": str(REPO)}}).execute()
    errors = [o for c in nb.cells if c.cell_type == "code" for o in c.get("outputs", []) if o.output_type == "error"]
    assert not errors


def test_a_run_in_a_notebook_shows_its_progress():
    # A run that lasts over a second (its watcher sleeps) shows a line that updates in place.
    nb = nbformat.v4.new_notebook()
    nb.cells = [
        nbformat.v4.new_code_cell(
            "import time, signorini\n"
            "run = signorini.run('bar', t_end=0.4, on_step=lambda row: time.sleep(0.03))\n"
            "print(len(run.series['t']))"
        )
    ]
    NotebookClient(nb, timeout=120, kernel_name="python3").execute()
    outputs = nb.cells[0].outputs
    shown = [o for o in outputs if o.output_type in ("display_data", "update_display_data")]
    assert shown, outputs
    assert all(o.data["text/plain"].startswith("t = ") for o in shown)
    assert "41" in "".join(o.get("text", "") for o in outputs if o.output_type == "stream")
