"""Progress of a run as it goes: in a notebook a line that updates in place, in a terminal a
line on stderr rewritten with a carriage return; shown once a run has lasted a second, as the
command line's bar is."""

from __future__ import annotations

import sys
import time


def _in_notebook() -> bool:
    try:
        from IPython import get_ipython  # type: ignore

        shell = get_ipython()
        return shell is not None and shell.__class__.__name__ == "ZMQInteractiveShell"
    except Exception:
        return False


class Progress:
    def __init__(self):
        self.start = time.monotonic()
        self.last = 0.0
        self.rows = 0
        self.handle = None
        self.notebook = _in_notebook()
        self.terminal = not self.notebook and sys.stderr.isatty()

    def enabled(self) -> bool:
        return self.notebook or self.terminal

    def line(self, t: float, t_end: float) -> str:
        elapsed = time.monotonic() - self.start
        share = 0.0 if t_end <= 0 else min(max(t / t_end, 0.0), 1.0)
        return f"t = {t:.6g} of {t_end:.6g} ({100 * share:.0f} %), {self.rows} rows, {elapsed:.1f} s"

    def show(self, row: dict) -> None:
        self.rows += 1
        now = time.monotonic()
        if now - self.start < 1.0 or now - self.last < 0.2:
            return
        self.last = now
        text = self.line(row["t"], row["t_end"])
        if self.notebook:
            from IPython.display import display  # type: ignore

            if self.handle is None:
                self.handle = display({"text/plain": text}, raw=True, display_id=True)
            else:
                self.handle.update({"text/plain": text}, raw=True)
        elif self.terminal:
            sys.stderr.write("\r" + text)
            sys.stderr.flush()

    def finish(self) -> None:
        if self.terminal and self.last > 0:
            sys.stderr.write("\n")
            sys.stderr.flush()
