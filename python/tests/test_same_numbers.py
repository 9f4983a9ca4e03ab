"""A run from Python gives the series of the same command-line run, bit for bit: every column
of series.csv (and stages.csv) read back equals the Python array exactly, and `out` writes the
same files. The time column is the exception by design: series.csv writes each time as its
level is written (`0.03`, not 0.030000000000000002), the Python series holds the double."""

import csv

import numpy as np
import pytest

import signorini
from conftest import REPO

CASES = [
    # (problem, keyword arguments, the same as command-line words)
    ("bar", {"scheme": "trbdf2", "t_end": 0.4}, ["--scheme", "trbdf2", "--t-end", "0.4"]),
    ("bar", {"scheme": "hht", "params": {"alpha": 0.2, "ne": 30}, "mass": "redistributed", "t_end": 0.3},
     ["--scheme", "hht", "--param", "alpha=0.2", "--param", "ne=30", "--mass", "redistributed", "--t-end", "0.3"]),
    ("disc", {"params": {"h": 2.0}, "t_end": 7.0, "dt": 0.05}, ["--param", "h=2.0", "--t-end", "7.0", "--dt", "0.05"]),
    (str(REPO / "tests/problems/plucked_bar.wf"), {"scheme": "central", "t_end": 1.0}, ["--scheme", "central", "--t-end", "1.0"]),
]


def same(name, python, text):
    """The Python column against series.csv's text of it: equal doubles (NaN where NaN), the
    time to its written digits."""
    written = np.array([float(x) for x in text])
    if name == "t":
        return np.allclose(python, written, rtol=1e-14, atol=1e-14)
    return np.array_equal(python, written, equal_nan=True)


def read_csv(path):
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    return rows[0], rows[1:]


@pytest.mark.parametrize("problem,kwargs,words", CASES, ids=["bar-trbdf2", "bar-hht", "disc", "plucked_bar-file"])
def test_series_and_stages_are_the_command_line_s(problem, kwargs, words, run_cli, tmp_path):
    code, _, err = run_cli("run", problem, *words, "--out", tmp_path / "cli")
    assert code == 0, err
    run = signorini.run(problem, **kwargs)
    header, rows = read_csv(tmp_path / "cli" / "series.csv")
    assert len(rows) == len(run.series["t"]) > 10
    for j, name in enumerate(header):
        # The text written is the shortest that reads back to the same double.
        assert same(name, run.series[name], [r[j] for r in rows]), name
    stages = tmp_path / "cli" / "stages.csv"
    if stages.exists():
        header, rows = read_csv(stages)
        assert [r[0] for r in rows] == list(run.stages["stage"])
        for j, name in enumerate(header[1:], start=1):
            assert same(name, run.stages[name], [r[j] for r in rows]), name
    else:
        assert len(run.stages["stage"]) == 0


def test_out_writes_the_command_line_s_files(run_cli, tmp_path):
    code, _, err = run_cli("run", "bar", "--t-end", "0.2", "--out", tmp_path / "cli")
    assert code == 0, err
    signorini.run("bar", t_end=0.2, out=tmp_path / "py")
    for name in ["series.csv", "bar.png"]:
        assert (tmp_path / "py" / name).read_bytes() == (tmp_path / "cli" / name).read_bytes(), name
    import json

    cli = json.loads((tmp_path / "cli" / "summary.json").read_text())
    py = json.loads((tmp_path / "py" / "summary.json").read_text())
    # The same keys and values, but for what the clock and the memory say.
    timed = {"wall_seconds", "seconds_per_step", "peak_memory_bytes", "step_seconds", "stepping_seconds"}
    assert cli.keys() == py.keys()
    assert {k: v for k, v in cli.items() if k not in timed and "seconds" not in k} == {
        k: v for k, v in py.items() if k not in timed and "seconds" not in k
    }


def test_a_case_file_runs_as_on_the_command_line(run_cli, tmp_path):
    case = tmp_path / "case.toml"
    case.write_text(f'case = "bar"\nscheme = "newmark"\nt_end = 0.2\nout = "{tmp_path / "cli"}"\n')
    code, _, err = run_cli("run", case, "--force")
    assert code == 0, err
    run = signorini.run(case, force=True)
    header, rows = read_csv(tmp_path / "cli" / "series.csv")
    for j, name in enumerate(header):
        assert same(name, run.series[name], [r[j] for r in rows]), name
