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
