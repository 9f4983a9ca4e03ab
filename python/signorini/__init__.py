"""signorini: dynamic contact mechanics, with weak forms, contact laws, time schemes and
problems written in .wf files, run from Python with the results as numpy arrays.

    import signorini
    run = signorini.run("bar", scheme="hht", params={"alpha": 0.1}, dt=1e-3)
    run.series["t"], run.series["E_aug"]   # numpy arrays by column
    run.summary["steps"], run.u, run.mesh.coords

The functions mirror the command line (``signorini run``, ``check``, ``emit``, ``list``,
``verify``): every option of ``signorini run`` is a keyword argument (``--t-end`` is
``t_end``), read and checked by the command line's own parser, so a run gives the series of
the same command line run bit for bit, and a refused option the same message. docs/python.md
has the whole API.
"""

from __future__ import annotations

import builtins
import difflib
import json
import os
from pathlib import Path
from typing import Callable, Dict, Iterable, Optional, Union

from . import _signorini
from ._progress import Progress
from .errors import Diagnostic, InputError, Interrupted, RunError, SignoriniError, WfError, diagnostic, raise_from
from .results import Expectation, Mesh, Run

__all__ = [
    "run", "check", "emit", "list", "verify", "options",
    "Run", "Mesh", "Expectation", "Diagnostic", "Diagnostics", "Library", "Verification",
    "SignoriniError", "InputError", "WfError", "RunError", "Interrupted",
]

# The library's files (forms/, and the meshes its problems name) as the installed package
# carries them; a build from the repository reads its own.
_LIBRARY = Path(__file__).resolve().parent / "library"
if (_LIBRARY / "forms").is_dir():
    _signorini._use_library(str(_LIBRARY))

# The options of `signorini run`: name (with dashes), takes a value, repeatable, help.
_OPTIONS = {name: (takes, repeated, text) for name, takes, repeated, text in _signorini.run_options()}


def options() -> Dict[str, str]:
    """Every keyword argument :func:`run` takes, with its help (the command line's)."""
    return {name.replace("-", "_"): text for name, (_, _, text) in _OPTIONS.items()}


def _number(name: str, value) -> str:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        try:
            import numpy as np

            if isinstance(value, np.generic) and np.issubdtype(type(value), np.number):
                return _number(name, value.item())
        except ImportError:
            pass
        raise TypeError(f"{name} must be a number, not {type(value).__name__} {value!r}")
    # repr: the shortest text that reads back to the same double.
    return repr(float(value)) if isinstance(value, float) else str(value)


def _argument(name: str, value) -> builtins.list:
    """One keyword argument as the command line's words."""
    flag = "--" + name.replace("_", "-")
    takes, repeated, _ = _OPTIONS[name.replace("_", "-")]
    if not takes:
        if not isinstance(value, bool):
            raise TypeError(f"{name} is a switch: True or False, not {type(value).__name__} {value!r}")
        return [flag] if value else []
    if value is None:
        return []
    if repeated and not isinstance(value, (str, os.PathLike)):
        return [w for v in value for w in (flag, _word(name, v))]
    return [flag, _word(name, value)]


def _word(name: str, value) -> str:
    if isinstance(value, (str, os.PathLike)):
        return os.fspath(value)
    if isinstance(value, (int, float)) or type(value).__module__ == "numpy":
        return _number(name, value)
    raise TypeError(f"{name} must be a number, a name or a path, not {type(value).__name__} {value!r}")


def _unknown(name: str, known: Iterable[str], what: str) -> TypeError:
    close = difflib.get_close_matches(name, builtins.list(known), n=1)
    hint = f"; did you mean `{close[0]}`?" if close else ""
    return TypeError(f"{what} got an unexpected keyword argument `{name}`{hint}")


def _args(problem, params: Optional[Dict[str, float]], kwargs: dict, what: str) -> builtins.list:
    words = [os.fspath(problem)]
    known = [n.replace("-", "_") for n in _OPTIONS]
    for name, value in kwargs.items():
        if name not in known or name in ("param", "all"):
            raise _unknown(name, [k for k in known if k not in ("param", "all")] + ["params"], what)
        words += _argument(name, value)
    for name, value in (params or {}).items():
        if not isinstance(name, str):
            raise TypeError(f"params: a param's name is a string, not {type(name).__name__} {name!r}")
        words += ["--param", f"{name}={_number(f'params[{name!r}]', value)}"]
    return words


def run(
    problem: Union[str, os.PathLike],
    *,
    params: Optional[Dict[str, float]] = None,
    on_step: Optional[Callable[[dict], Optional[bool]]] = None,
    progress: Optional[bool] = None,
    **options,
) -> Run:
    """Runs a problem: a library problem by name (``"bar"``, ``"disc"``; :func:`list` shows
    them), a problem file (``"my_problem.wf"``) or a case file (``"case.toml"``).

    Keyword arguments are the options of ``signorini run`` (``scheme``, ``contact``,
    ``material``, ``forms``, ``mass``, ``dt``, ``t_end``, ``t_start``, ``adaptive``,
    ``dt_min``, ``dt_max``, ``event_dt``, ``mesh``, ``out``, ``force``, ``vtu_every``,
    ``checkpoint_every``, ``resume``, ``solver``, ...: :func:`options` lists them); ``params``
    sets the problem's, the scheme's and the form files' params (``{"alpha": 0.1, "ne": 40}``,
    or ``"owner.name"``). Nothing is written unless ``out`` is given.

    ``on_step(row)`` sees each row (a dict of ``t``, every column, and ``t_end``) as the run
    measures it; returning False stops the run after that step. ``progress`` shows how far the
    run is (default: in a notebook or a terminal, once it has lasted a second). Ctrl-C stops
    the run after its step and raises :class:`Interrupted` with the rows so far.
    """
    args = _args(problem, params, options, "run()")
    shown = Progress()
    show = shown.enabled() if progress is None else bool(progress)

    def watcher(row):
        if show:
            shown.show(row)
        if on_step is not None:
            return on_step(row)
        return None

    try:
        data = _signorini.run(args, watcher if (show or on_step is not None) else None)
    except _signorini.Failure as failure:
        raise_from(failure, Run)
    except BaseException as e:
        # The watcher's own exception, with the rows up to there.
        partial = getattr(e, "partial", None)
        if isinstance(partial, dict):
            e.partial = Run(partial)
        raise
    finally:
        if show:
            shown.finish()
    return Run(data)


class Diagnostics(builtins.list):
    """The diagnostics of :func:`check` (a list of :class:`Diagnostic`), with ``bound``: for a
    problem file that binds, the line saying what was bound (mesh, regions, files in use)."""

    def __init__(self, items, bound: Optional[str]):
        super().__init__(items)
        self.bound = bound

    @property
    def errors(self) -> builtins.list:
        return [d for d in self if d.is_error]

    @property
    def ok(self) -> bool:
        """No error (warnings allowed)."""
        return not self.errors

    def __str__(self) -> str:
        return "".join(str(d) + "\n" for d in self) + (self.bound + "\n" if self.bound else "")


def check(path: Union[str, os.PathLike]) -> Diagnostics:
    """Checks a .wf file as ``signorini check`` does (a problem file is also bound to its mesh
    and files): every diagnostic, errors and warnings, located. Raises :class:`InputError` for
    a file that cannot be read."""
    try:
        items, bound = _signorini.check(os.fspath(path))
    except _signorini.Failure as failure:
        raise_from(failure, Run)
    return Diagnostics([diagnostic(d) for d in items], bound)


def emit(path: Union[str, os.PathLike], stage: str = "scheme", dim: int = 2) -> str:
    """A compilation stage of a .wf file as text (``ast``, ``ir``, ``scheme``, ``rust``,
    ``energy``), as ``signorini emit`` prints it; :class:`WfError` if the file does not check."""
    try:
        return _signorini.emit(os.fspath(path), stage, dim)
    except _signorini.Failure as failure:
        raise_from(failure, Run)


class Library:
    """The library as its files describe it (``signorini list``): ``schemes``,
    ``contact_laws``, ``forms``, ``problems`` (each a list of dicts: name, doc, file, items,
    params) and ``references``."""

    def __init__(self, data: dict):
        self.schemes = data["schemes"]
        self.contact_laws = data["contact_laws"]
        self.forms = data["forms"]
        self.problems = data["problems"]
        self.references = data["references"]

    def names(self, what: str) -> builtins.list:
        """The names of ``schemes``, ``contact_laws``, ``forms`` or ``problems``."""
        return [e["name"] for e in getattr(self, what)]

    def __repr__(self) -> str:
        return "<signorini.Library " + "; ".join(
            f"{w}: {', '.join(self.names(w))}" for w in ("schemes", "contact_laws", "forms", "problems")
        ) + ">"


def list() -> Library:  # noqa: A001 (mirrors `signorini list`)
    """Every scheme, contact law, form file, problem and reference of the library, with their
    params (defaults and ranges as written, where declared, docs)."""
    return Library(json.loads(_signorini.catalogue()))


class Verification:
    """``signorini verify --scheme``: ``data`` (verify_NAME.json's content), ``markdown`` (the
    report's text), and ``verdicts``: each claim of the scheme's file against what was
    measured."""

    def __init__(self, data: dict, markdown: str):
        self.data = data
        self.markdown = markdown
        self.scheme = data.get("scheme")
        self.verdicts = data.get("verdicts", [])

    @property
    def holds(self) -> bool:
        """Whether every claim of the file holds."""
        return all(v.get("holds") for v in self.verdicts)

    def _repr_markdown_(self) -> str:
        return self.markdown

    def __repr__(self) -> str:
        return f"<signorini.Verification {self.scheme}: {len(self.verdicts)} claims, {'all hold' if self.holds else 'some contradicted'}>"


def verify(
    scheme: Union[str, os.PathLike],
    *,
    contact: Optional[str] = None,
    material: Optional[str] = None,
    forms: Iterable[Union[str, os.PathLike]] = (),
    params: Optional[Dict[str, float]] = None,
    line_search: bool = False,
    out: Optional[Union[str, os.PathLike]] = None,
) -> Verification:
    """Verifies a scheme of the library or a scheme file against its claims (``signorini
    verify --scheme``): orders, spectral radius, energy balance, the bar and the disc. Writes
    verify_NAME.md, .json and .png to ``out`` when given."""
    words = ["--scheme", os.fspath(scheme)]
    for flag, value in (("--contact", contact), ("--material", material)):
        if value is not None:
            words += [flag, os.fspath(value)]
    for f in forms:
        words += ["--forms", os.fspath(f)]
    for name, value in (params or {}).items():
        words += ["--param", f"{name}={_number(f'params[{name!r}]', value)}"]
    if line_search:
        words.append("--line-search")
    try:
        data, markdown = _signorini.verify(words, None if out is None else os.fspath(out))
    except _signorini.Failure as failure:
        raise_from(failure, Run)
    return Verification(json.loads(data), markdown)
