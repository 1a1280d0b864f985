"""Time budgets (max_seconds=): long work ends with one clear error instead of running on, soon after the budget;
bad budgets are refused before any work."""

import time

import numpy as np
import pytest

import pumpup
from pumpup.core import budget
from pumpup.core.budget import BudgetExceeded

#: every budgeted call must stop within this of its budget: one piece of work (a chunk of albedo values, a round of
#: the cubature, a lut column) plus compiling a kernel on a cold cache
LATE = 20.0


def _stops_within(call, max_seconds, what):
    t0 = time.monotonic()
    with pytest.raises(BudgetExceeded, match=rf"^{what}: stopped after .* past its max_seconds {max_seconds:g}") as e:
        call(max_seconds)
    assert time.monotonic() - t0 < max_seconds + LATE
    assert "\n" not in str(e.value) and isinstance(e.value, TimeoutError)


def test_tabulate_albedo_pump_compensate_lut_and_sweep_stop_at_their_budget(tmp_path):
    slow = pumpup.load("cook_torrance:m=0.3")
    _stops_within(lambda s: pumpup.albedo(slow, np.linspace(0.05, 1, 16), engine="2d", rtol=1e-13, max_seconds=s),
                  0.2, "albedo")
    _stops_within(lambda s: pumpup.tabulate(pumpup.pump(slow, levels=3), max_seconds=s), 0.3, "tabulate")
    _stops_within(lambda s: pumpup.pump("cook_torrance:m=0.31", levels=6, max_seconds=s), 0.3, "pump")
    _stops_within(lambda s: pumpup.compensate("ggx:alpha=0.31", max_seconds=s), 1e-3, "compensate")
    _stops_within(lambda s: pumpup.lut("ggx", preset="filament", max_seconds=s), 0.3, "lut")
    out = tmp_path / "s.nc"
    _stops_within(lambda s: pumpup.sweep("cook_torrance", {"m": [0.2, 0.25, 0.3, 0.35]}, chunks=1, out=out,
                                         scheduler="synchronous", max_seconds=s), 1e-3, "sweep")
    assert not out.exists()


def test_a_budget_that_suffices_changes_nothing():
    f = pumpup.load("phong:n=20")
    a = pumpup.albedo(f, [0.1, 0.5, 1.0], max_seconds=600)
    np.testing.assert_array_equal(a, pumpup.albedo(f, [0.1, 0.5, 1.0]))
    from pumpup.operators import pumping

    p = pumpup.pump("phong:n=21", levels=2, max_seconds=600)  # every level's table is built now, not on first use
    assert all(pumping._key(level.base) in pumping._TABLES for level in p.chain())


@pytest.mark.parametrize("bad", [0, -1, float("nan"), "10", True, [1]])
def test_bad_budgets_are_refused_before_any_work(bad, monkeypatch):
    monkeypatch.setattr(pumpup.operators.pumping, "pump_model", lambda *a: pytest.fail("work started"))
    for call in (lambda: pumpup.pump("phong:n=3", max_seconds=bad),
                 lambda: pumpup.tabulate(pumpup.load("phong:n=3"), max_seconds=bad),
                 lambda: pumpup.albedo(pumpup.load("phong:n=3"), 0.5, max_seconds=bad)):
        with pytest.raises(ValueError, match=r"max_seconds must be a number > 0 \(seconds\) or None"):
            call()


def test_inner_budget_cannot_outlast_the_outer_one():
    with budget.time_budget("outer", 1e-6) as outer:
        time.sleep(1e-3)
        with budget.time_budget("inner", 100.0) as inner:
            assert inner is outer
            with pytest.raises(BudgetExceeded, match="^outer: "):
                budget.check("testing")
    assert budget.current() is None


def test_command_line_budget_names_its_option(capsys):
    from pumpup.cli import main

    with pytest.raises(SystemExit) as e:
        main(["pump", "cook_torrance:m=0.33", "--levels", "5", "--max-seconds", "0.2"])
    assert e.value.code == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("pumpup: pump: stopped after") and "past its --max-seconds 0.2" in err and "\n" not in err
    with pytest.raises(SystemExit, match="--max-seconds must be a number > 0"):
        main(["table", "phong:n=3", "--out", "x.nc", "--max-seconds", "-2"])


def test_long_work_estimate_leaves_out_compiling(capsys):
    """The first values' time minus numba's compiling (which the rest of a table does not repeat) makes the estimate:
    the compiling is measured (a fresh kernel compiled in the block), and 40 s of values of which 39.5 s compiled
    announce nothing, while 40 s of values alone do, and the line names the compiling when there was some."""
    import time

    import numba
    from tqdm.auto import tqdm

    from pumpup import tables

    t0 = time.monotonic()
    with tables._compile_seconds() as compiling:
        numba.njit(cache=False)(lambda x: x * 2.5 + 1.0)(3.0)
    assert 0.0 < compiling[0] <= time.monotonic() - t0
    f = pumpup.load("ggx:alpha=0.2")
    silent = tqdm(total=1, disable=True)
    with tables._long_work_bar(silent, f, 40.0, 45, compiling=39.5) as bar:
        assert bar is silent
    assert capsys.readouterr().err == ""
    with tables._long_work_bar(silent, f, 40.0, 45) as bar:
        assert bar is not silent
    err = capsys.readouterr().err
    assert "will take about 120 s (its first 45 values took 40.0 s)" in err
    with tables._long_work_bar(silent, f, 40.0, 45, compiling=20.0):
        pass
    assert "will take about 60 s (its first 45 values took 40.0 s, 20.0 s of it compiling kernels)" in \
        capsys.readouterr().err


def test_long_table_announces_its_estimate_and_progress(monkeypatch, capsys):
    """A table estimated (from its first values) above LONG_WORK_SECONDS says so in one line on stderr, with a
    progress bar there, though stderr is no terminal; below it, nothing."""
    from pumpup import tables

    f = pumpup.load("ggx:alpha=0.2")
    pumpup.tabulate(f, progress=None)
    assert capsys.readouterr().err == ""
    monkeypatch.setattr(tables, "LONG_WORK_SECONDS", 0.0)
    pumpup.tabulate(pumpup.load("ggx:alpha=0.21"), progress=None)
    err = capsys.readouterr().err
    assert err.startswith("pumpup: the albedo table of pumpup.load(") and "will take about" in err
    assert "albedo ggx:" in err  # the bar
