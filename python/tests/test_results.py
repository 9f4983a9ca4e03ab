"""What a run returns, checked against what the mathematics says of it: the last state and the
mesh (a disc in free fall, whose Newmark steps are exact for a quadratic motion), the summary
and the `expect` lines."""

import numpy as np
import pytest

import signorini
from conftest import REPO


def test_the_free_falling_disc_s_last_state_is_exact():
    # First contact at √40 ≈ 6.32: at t = 2 the disc still falls freely, u = −g t²/2, v = −g t.
    run = signorini.run("disc", params={"h": 2.0}, t_end=2.0)
    assert run.t == pytest.approx(2.0, abs=1e-12)
    assert run.u.shape == run.mesh.coords.shape and run.mesh.dim == 2
    assert np.allclose(run.u[:, 1], -0.05 * 4.0, rtol=0, atol=1e-12)
    assert np.allclose(run.u[:, 0], 0.0, atol=1e-12)
    assert np.allclose(run.v[:, 1], -0.1 * 2.0, rtol=0, atol=1e-12)
    # The series' columns read the same state: the nodal mean, and the lowest node.
    assert run.series["uy_mean_nodal"][-1] == pytest.approx(run.u[:, 1].mean(), rel=1e-13)
    lowest = np.argmin(run.mesh.coords[:, 1])
    assert run.series["uy_lowest"][-1] == run.u[lowest, 1]


def test_the_mesh_is_the_problem_s():
    run = signorini.run("disc", params={"h": 2.0}, t_end=0.1)
    m = run.mesh
    assert m.kind == "P2 triangle" and m.cells.shape[1] == 6  # curved P2 triangles
    assert m.cells.min() == 0 and m.cells.max() == len(m.coords) - 1
    # The disc of radius 10 centred at (0, 12): every node within it, the boundary's on it.
    r = np.hypot(m.coords[:, 0], m.coords[:, 1] - 12.0)
    assert r.max() == pytest.approx(10.0, rel=1e-12)
    facets = m.regions["Gamma_C"]
    assert facets.shape[1] == 3
    assert np.allclose(np.hypot(m.coords[facets, 0], m.coords[facets, 1] - 12.0), 10.0, rtol=1e-12)
    # The contact region faces down.
    assert (m.coords[facets, 1] < 12.0 + 1e-12).all()
    assert m.triangles().shape == (len(m.cells), 3)


def test_the_summary_and_the_expect_lines():
    run = signorini.run("bar", t_end=0.5)
    assert run.summary["case"] == "bar" and run.summary["steps"] == len(run.series["t"]) - 1
    assert run.summary["scheme"] and run.summary["contact"]
    for e in run.expected:
        assert isinstance(e, signorini.Expectation) and e.key in run.summary


def test_a_static_problem_has_no_velocity():
    run = signorini.run("static_block")
    assert run.v is None and run.u.shape == run.mesh.coords.shape
    assert len(run.series["t"]) == 1


def test_the_semi_discrete_bar_s_middle_node():
    # The struck bar's middle node against its semi-discrete solution sin(ω_h t)/ω_h.
    run = signorini.run(REPO / "tests/problems/plucked_bar.wf", t_end=1.0, dt=0.005)
    ne = 20
    h = 1 / ne
    wh = np.sqrt(6 * (1 - np.cos(np.pi * h)) / (h**2 * (2 + np.cos(np.pi * h))))
    middle = np.argmin(np.abs(run.mesh.coords[:, 0] - 0.5))
    exact = np.sin(wh * run.t) / wh
    assert run.u[middle, 0] == run.series["middle"][-1]
    # Newmark's period error, (ωΔt)²/12 per radian: about 1e-5 at t = 1 here.
    assert abs(run.u[middle, 0] - exact) < 1e-4
    assert run.series["error"][-1] == pytest.approx(abs(run.u[middle, 0] - exact), rel=1e-9, abs=1e-15)


def test_a_column_that_is_not_there_says_which_are():
    run = signorini.run("bar", t_end=0.1)
    with pytest.raises(KeyError, match="did you mean `energy`"):
        run["enrgy"]


def test_the_frame_has_the_series_columns():
    pd = pytest.importorskip("pandas")
    run = signorini.run("bar", t_end=0.1)
    df = run.frame()
    assert isinstance(df, pd.DataFrame) and list(df.columns) == list(run.series)
