"""A run's results: the series by column, the stages, the summary and its expectations, the
last state and the mesh."""

from __future__ import annotations

import json
from dataclasses import dataclass
from typing import Dict, List, Optional

import numpy as np


@dataclass(frozen=True)
class Mesh:
    """The run's mesh. ``coords``: nodes × dim; ``cells``: cells × nodes per cell (Gmsh's
    node order; ``kind`` names the element, e.g. ``P2 triangle``); ``regions``: each named
    boundary region's facets × nodes per facet; ``cell_groups`` and ``bodies``: cell indices."""

    kind: str
    coords: np.ndarray
    cells: np.ndarray
    regions: Dict[str, np.ndarray]
    cell_groups: Dict[str, np.ndarray]
    bodies: Dict[str, np.ndarray]

    @property
    def dim(self) -> int:
        return self.coords.shape[1]

    def triangles(self) -> np.ndarray:
        """The cells' corner triangles (a P2 triangle's first three nodes), for
        ``matplotlib.tri.Triangulation``; 2D meshes of triangles only."""
        if self.dim != 2 or not self.kind.endswith("triangle"):
            raise ValueError(f"a {self.dim}D mesh of {self.kind} cells has no triangles to draw")
        return self.cells[:, :3]


@dataclass(frozen=True)
class Expectation:
    """An ``expect`` line of the problem: its key's value against the expected one, the
    difference (relative, or ``absolute`` when the expected value is 0), the tolerance
    ``within``, whether it is ``met``, and whether its ``when`` held (``applies``)."""

    key: str
    value: Optional[float]
    expected: Optional[float]
    difference: Optional[float]
    absolute: bool
    within: float
    met: bool
    applies: bool = True


class Run:
    """A finished run (or the part of one that stopped: ``RunError.partial``).

    ``series``: the rows as numpy arrays by column, ``t`` first (every column the problem
    measures, those series.csv leaves out included); ``frame()``: the same as a pandas
    DataFrame. ``stages``: a multi-stage scheme's intermediate stages (``stage`` names, ``t``
    and the columns). ``summary``: summary.json's keys; ``expected``: the ``expect`` lines.
    ``t``, ``u``, ``v``: the last state (nodes × dim; ``v`` is None for a static problem or a
    scheme without a velocity); ``mesh``: the mesh.
    """

    def __init__(self, data: dict):
        columns: List[str] = data["columns"]
        values = data["values"]
        self.columns = list(columns)
        self.series: Dict[str, np.ndarray] = {"t": data["t"]}
        for i, c in enumerate(columns):
            self.series[c] = values[:, i]
        stages = data["stages"]
        self.stages: Dict[str, object] = {"stage": stages["stage"], "t": stages["t"]}
        for i, c in enumerate(columns):
            self.stages[c] = stages["values"][:, i]
        self.summary: dict = json.loads(data["summary"])
        self.expected = [Expectation(**e) for e in self.summary.get("expected", [])]
        fields = data.get("fields") or {}
        self.t: Optional[float] = fields.get("t")
        self.u: Optional[np.ndarray] = fields.get("u")
        self.v: Optional[np.ndarray] = fields.get("v")
        m = fields.get("mesh")
        self.mesh: Optional[Mesh] = Mesh(**m) if m is not None else None

    def __getitem__(self, column: str) -> np.ndarray:
        """A column of the series (``run["E_aug"]``)."""
        try:
            return self.series[column]
        except KeyError:
            import difflib

            close = difflib.get_close_matches(column, self.series, n=1)
            hint = f"; did you mean `{close[0]}`?" if close else ""
            raise KeyError(f"no column `{column}` in this run's series (it has: {', '.join(self.series)}){hint}") from None

    def frame(self):
        """The series as a pandas DataFrame indexed by nothing (``t`` is a column)."""
        try:
            import pandas as pd
        except ImportError as e:
            raise ImportError("Run.frame() needs pandas (pip install pandas); Run.series has the same columns as numpy arrays") from e
        return pd.DataFrame(self.series)

    @property
    def met(self) -> bool:
        """Whether every ``expect`` line that applies is met."""
        return all(e.met for e in self.expected if e.applies)

    def __repr__(self) -> str:
        s = self.summary
        return (
            f"<signorini.Run {s.get('case')}: {s.get('scheme')} {s.get('contact')}, {s.get('steps')} steps, "
            f"{len(self.series['t'])} rows, columns {', '.join(self.columns)}>"
        )
