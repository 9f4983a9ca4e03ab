"""Bad input gets a Python exception with the command line's located message, never a crash
of the interpreter: unknown keyword arguments, params of the wrong type or out of range,
paths that do not exist, files that do not check, runs that fail."""

import re

import pytest

import signorini
from conftest import REPO

TYPO = """// A problem with a misspelt coef.
problem typo(
    ne = 10 in [1, 100],
) {
    mesh interval(length = 1, cells = ne)
    region Gamma_D = boundary
    run dt = 0.01, t_end = 0.1
    coef f = [0]
    dirichlet Gamma_D: u = [0]
    initial v = [sin(pi*x[0])]
    series energy = enrgy
}
"""


def message(stderr: str) -> str:
    """The command line's message: its stderr without the `error: ` the shell line starts with."""
    return re.sub(r"^error: ", "", stderr.strip())


def test_an_unknown_keyword_argument_is_a_type_error_with_a_suggestion():
    with pytest.raises(TypeError, match="unexpected keyword argument `t_ned`; did you mean `t_end`"):
        signorini.run("bar", t_ned=1.0)


def test_a_param_of_the_wrong_type():
    with pytest.raises(TypeError, match=r"params\['alpha'\] must be a number, not str"):
        signorini.run("bar", scheme="hht", params={"alpha": "0.1"})
    with pytest.raises(TypeError, match="must be a number, not bool"):
        signorini.run("bar", params={"ne": True})
    with pytest.raises(TypeError, match="force is a switch"):
        signorini.run("bar", force="yes")


@pytest.mark.parametrize(
    "args,kwargs",
    [
        (["bar", "--scheme", "hht", "--param", "alpha=0.9"], {"scheme": "hht", "params": {"alpha": 0.9}}),
        (["bar", "--scheme", "hhtt"], {"scheme": "hhtt"}),
        (["bra"], {}),
        (["no/such/problem.wf"], {}),
        (["bar", "--dt", "-1"], {"dt": -1}),
        (["bar", "--mass", "lumpy"], {"mass": "lumpy"}),
        (["bar", "--param", "nosuch=1"], {"params": {"nosuch": 1}}),
    ],
    ids=["out-of-range", "unknown-scheme", "unknown-problem", "missing-file", "negative-dt", "bad-choice", "unknown-param"],
)
def test_refused_as_on_the_command_line(args, kwargs, run_cli):
    code, _, err = run_cli("run", *args)
    assert code != 0
    with pytest.raises(signorini.InputError) as e:
        signorini.run(args[0], **kwargs)
    assert isinstance(e.value, ValueError)
    # The message is the command line's (clap's usage lines aside).
    assert message(err).split("\n\nUsage:")[0].strip() == e.value.message


def test_a_problem_file_that_does_not_check(tmp_path, run_cli):
    path = tmp_path / "typo.wf"
    path.write_text(TYPO)
    diags = signorini.check(path)
    assert not diags.ok and diags.bound is None
    [d] = diags.errors
    assert (d.code, d.line, d.file) == ("E0101", 11, str(path))
    assert TYPO.splitlines()[d.line - 1][d.column - 1 : d.end_column - 1] == "enrgy"
    assert "energy" in (d.help or "") + " ".join(d.notes) + d.label + d.message
    with pytest.raises(signorini.WfError) as e:
        signorini.run(path)
    assert [x.code for x in e.value.diagnostics] == ["E0101"]
    assert e.value.diagnostics[0].line == 11
    code, _, err = run_cli("run", path)
    assert code != 0 and message(err) == e.value.message
    code, _, err = run_cli("check", path)
    assert code != 0 and str(d) in err


def test_check_of_a_good_problem_binds_it():
    diags = signorini.check(REPO / "forms/problems/disc.wf")
    assert diags.ok and "problem `disc` checked and bound" in diags.bound


def test_check_of_a_missing_file():
    with pytest.raises(signorini.InputError, match="missing.wf"):
        signorini.check("missing.wf")


def test_emit_of_a_scheme_and_of_a_bad_file(tmp_path, run_cli):
    text = signorini.emit(REPO / "forms/schemes/newmark.wf", "scheme")
    code, out, _ = run_cli("emit", "forms/schemes/newmark.wf", "--stage", "scheme")
    assert code == 0 and text == out
    bad = tmp_path / "bad.wf"
    bad.write_text("scheme broken(\n")
    with pytest.raises(signorini.WfError) as e:
        signorini.emit(bad)
    assert e.value.diagnostics and e.value.diagnostics[0].code == "E0001"
    with pytest.raises(signorini.InputError, match="not a stage"):
        signorini.emit(REPO / "forms/schemes/newmark.wf", "assembly")


def test_a_run_that_fails_keeps_its_rows(run_cli):
    # Central differences far above their critical step, let run: the energy guard stops it.
    args = ["bar", "--scheme", "central", "--dt", "0.05", "--allow-unstable-dt", "--t-end", "5"]
    code, _, err = run_cli("run", *args)
    assert code != 0
    with pytest.raises(signorini.RunError) as e:
        signorini.run("bar", scheme="central", dt=0.05, allow_unstable_dt=True, t_end=5)
    assert isinstance(e.value, RuntimeError) and message(err) == e.value.message
    partial = e.value.partial
    assert isinstance(partial, signorini.Run) and 1 < len(partial.series["t"]) < 101


def test_emit_of_a_missing_file_is_bad_input_not_a_wf_error():
    with pytest.raises(signorini.InputError) as e:
        signorini.emit("missing.wf")
    assert not isinstance(e.value, signorini.WfError) and "missing.wf" in e.value.message
