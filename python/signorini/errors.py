"""The exceptions of the package. Their messages are the command line's, word for word."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import List, Optional


@dataclass(frozen=True)
class Diagnostic:
    """A diagnostic of the compiler: where (file, 1-based line and column of its span's start
    and end) and what (code, message, label, notes, help). ``str(d)`` is its rendering, as
    ``signorini check`` prints it."""

    severity: str
    code: Optional[str]
    message: str
    file: str
    line: Optional[int]
    column: Optional[int]
    end_line: Optional[int]
    end_column: Optional[int]
    label: str
    notes: List[str] = field(default_factory=list)
    help: Optional[str] = None
    rendered: str = ""

    @property
    def is_error(self) -> bool:
        return self.severity == "error"

    def __str__(self) -> str:
        return self.rendered.rstrip("\n") or self.message


class SignoriniError(Exception):
    """What went wrong, in the command line's words (``message``)."""

    def __init__(self, message: str):
        super().__init__(message)
        self.message = message


class InputError(SignoriniError, ValueError):
    """Bad input: an option or param refused, a file that cannot be read, a case file."""


class WfError(InputError):
    """A .wf file that does not check, or a line of a problem its binding refuses:
    ``diagnostics`` holds each located diagnostic."""

    def __init__(self, message: str, diagnostics: List[Diagnostic]):
        super().__init__(message)
        self.diagnostics = diagnostics


class RunError(SignoriniError, RuntimeError):
    """A run that stopped before its end (a step Newton could not solve, an energy that grew,
    a step below the adaptive minimum): ``partial`` is the :class:`Run` up to the last good
    step (None if the run never started)."""

    def __init__(self, message: str, partial=None):
        super().__init__(message)
        self.partial = partial


class Interrupted(KeyboardInterrupt):
    """Ctrl-C (or the notebook's interrupt) stopped the run after its step: ``partial`` is the
    :class:`Run` up to there, with the files of ``out`` written, as the command line does on
    SIGINT."""

    def __init__(self, message: str, partial=None):
        super().__init__(message)
        self.message = message
        self.partial = partial


def diagnostic(d: dict) -> Diagnostic:
    return Diagnostic(**d)


def raise_from(failure: Exception, wrap_run):
    """Raises the package's exception for the extension module's ``Failure(kind, message,
    diagnostics, partial)``; ``wrap_run`` turns a partial run's data into a :class:`Run`."""
    kind, message, *rest = failure.args
    diagnostics = [diagnostic(d) for d in (rest[0] if rest else [])]
    partial = rest[1] if len(rest) > 1 else None
    partial = wrap_run(partial) if partial is not None else None
    if kind == "wf":
        raise WfError(message, diagnostics) from None
    if kind == "option":
        raise InputError(message) from None
    if kind == "interrupted":
        raise Interrupted(message, partial) from None
    raise RunError(message, partial) from None
