"""Watching a run as it goes: a callback per row that may stop it, Ctrl-C stopping it after the
step (as SIGINT does on the command line), and the interpreter free while it steps."""

import os
import signal
import threading
import time

import numpy as np
import pytest

import signorini


def test_on_step_sees_every_row_in_order():
    seen = []
    run = signorini.run("bar", t_end=0.2, on_step=lambda row: seen.append((row["t"], row["energy"])))
    assert [t for t, _ in seen] == list(run.series["t"])
    assert [e for _, e in seen] == list(run.series["energy"])


def test_on_step_returning_false_stops_after_that_step():
    with pytest.raises(signorini.Interrupted) as e:
        signorini.run("bar", t_end=1.0, on_step=lambda row: row["t"] < 0.1)
    partial = e.value.partial
    assert isinstance(e.value, KeyboardInterrupt)
    # The row at which it said stop is the last.
    t = partial.series["t"]
    assert t[-1] >= 0.1 and t[-2] < 0.1 and t[-1] < 1.0
    assert "interrupted at t = " in e.value.message


def test_an_exception_of_on_step_is_raised_with_the_rows():
    def boom(row):
        if row["t"] > 0.05:
            raise ZeroDivisionError("from the callback")

    with pytest.raises(ZeroDivisionError, match="from the callback") as e:
        signorini.run("bar", t_end=1.0, on_step=boom)
    assert e.value.partial.series["t"][-1] > 0.05


def test_ctrl_c_stops_the_run_after_the_step_and_the_next_run_is_whole():
    sent = []

    def interrupt(row):
        if row["t"] > 0.1 and not sent:
            sent.append(row["t"])
            os.kill(os.getpid(), signal.SIGINT)

    with pytest.raises(signorini.Interrupted) as e:
        signorini.run("bar", t_end=1.0, on_step=interrupt)
    t = e.value.partial.series["t"]
    # Stopped at the end of the step the signal came in (here, while its row was shown), or the
    # next: long before the end.
    assert t[-1] >= sent[0] and len(t) <= np.searchsorted(t, sent[0]) + 2 and t[-1] < 0.5
    whole = signorini.run("bar", t_end=0.3)
    assert whole.series["t"][-1] == pytest.approx(0.3)


def test_the_interpreter_runs_while_the_run_steps():
    ticks = []
    done = threading.Event()

    def count():
        while not done.is_set():
            ticks.append(time.monotonic())
            time.sleep(0.005)

    worker = threading.Thread(target=count)
    worker.start()
    start = time.monotonic()
    try:
        signorini.run("disc", params={"h": 0.5}, t_end=10.0)
    finally:
        done.set()
        worker.join()
    took = time.monotonic() - start
    during = [t for t in ticks if start < t < start + took]
    # The other thread held the interpreter many times while the run stepped.
    assert took > 0.2 and len(during) > 10


def test_list_emit_and_options():
    lib = signorini.list()
    assert {"newmark", "hht", "trbdf2"} <= set(lib.names("schemes"))
    assert {"bar", "disc"} <= set(lib.names("problems"))
    hht = next(s for s in lib.schemes if s["name"] == "hht")
    assert any(p["name"] == "alpha" for p in hht["params"])
    opts = signorini.options()
    assert {"scheme", "t_end", "dt", "adaptive", "out", "force"} <= set(opts)


def test_verify_a_scheme():
    v = signorini.verify("newmark")
    assert v.scheme == "newmark" and v.verdicts and v.holds
    assert "newmark" in v.markdown
