"""A saved BRDF is read from one file: loads racing atomic saves of the same path give one writer's object, never a
mixture of two files' groups (tables.snapshot)."""

import multiprocessing
import os
import shutil

import numpy as np
import pytest

import pumpup
from pumpup.operators import pumping
from pumpup.tables.validate import TableError

SPEC = {"type": "pumped", "base": {"type": "phong", "n": 20}, "g": "g2", "levels": 2}


def _replace_forever(target, sources, stop):
    """A writer: atomic saves of the same path, alternating between two files (as save_pumped's rename does)."""
    i = 0
    while not stop.is_set():
        tmp = f"{target}.{i}.tmp"
        shutil.copyfile(sources[i % 2], tmp)
        os.replace(tmp, target)
        i += 1


def _levels(f):
    return [np.asarray(level.table().dataset["albedo"].values) for level in f.chain()]


def test_loads_racing_saves_give_one_writers_object(tmp_path, monkeypatch):
    monkeypatch.setattr(pumping, "_TABLES", {})  # (tables of this test only: it clears them, and builds some on
    # another grid)
    a_path, b_path = str(tmp_path / "a.nc"), str(tmp_path / "b.nc")
    pumpup.save_pumped(pumpup.load(SPEC), a_path)
    pumping._TABLES.clear()
    monkeypatch.setattr(pumping, "TABLE_RTOL", 1e-6)  # the same spec, tables on another grid
    monkeypatch.setattr(pumping, "TABLE_INTERP_TOL", 1e-4)
    pumpup.save_pumped(pumpup.load(SPEC), b_path)
    pumping._TABLES.clear()
    a, b = _levels(pumpup.load_pumped(a_path)), _levels(pumpup.load_pumped(b_path))
    assert any(x.shape != y.shape for x, y in zip(a, b))  # the two files differ in every level's table

    target = str(tmp_path / "target.nc")
    shutil.copyfile(a_path, target)
    ctx = multiprocessing.get_context("spawn")
    stop = ctx.Event()
    writer = ctx.Process(target=_replace_forever, args=(target, (a_path, b_path), stop))
    writer.start()
    seen = {"a": 0, "b": 0}
    try:
        for _ in range(60):
            levels = _levels(pumpup.load_pumped(target))
            same_a = all(x.shape == y.shape and np.array_equal(x, y) for x, y in zip(levels, a))
            same_b = all(x.shape == y.shape and np.array_equal(x, y) for x, y in zip(levels, b))
            assert same_a or same_b, "a load mixed the groups of two files"
            seen["a" if same_a else "b"] += 1
    finally:
        stop.set()
        writer.join(10)
    assert writer.exitcode == 0
    assert seen["a"] and seen["b"]  # the race happened: loads saw both writers' files


def test_snapshot_refuses_a_fifo_at_once(tmp_path):
    fifo = str(tmp_path / "p.nc")
    os.mkfifo(fifo)
    with pytest.raises(TableError, match="not a regular file"):
        pumpup.load_pumped(fifo)
    with pytest.raises(TableError, match="not a regular file"):
        pumpup.load_compensated(fifo)
