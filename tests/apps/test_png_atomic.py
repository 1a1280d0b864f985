"""Figures are written atomically: an interrupted PNG write leaves neither a half file nor a temporary."""

import importlib
import os

import numpy as np
import pytest
import xarray as xr

divergence = importlib.import_module("pumpup.divergence")  # the module (pumpup.divergence is the function)


def _ds():
    mu = np.logspace(-4, 0, 5)
    return xr.Dataset(
        {"albedo": (("model", "mu"), np.ones((1, 5))), "lower_bound": (("model", "mu"), np.full((1, 5), np.nan)),
         "verdict": ("model", ["bounded"]), "k": ("model", [0.0])},
        coords={"model": ["lambert"], "mu": mu},
    )


def test_divergence_plot_writes_a_png(tmp_path):
    path = divergence.plot(_ds(), str(tmp_path / "d.png"))
    with open(path, "rb") as fh:
        assert fh.read(8) == b"\x89PNG\r\n\x1a\n"
    assert os.listdir(tmp_path) == ["d.png"]


def test_interrupted_png_write_leaves_nothing(tmp_path, monkeypatch):
    from matplotlib.figure import Figure

    real = Figure.savefig

    def broken(self, fname, *a, **kw):
        real(self, fname, *a, **kw)  # the bytes reach the temporary, then the process is "interrupted"
        raise KeyboardInterrupt

    monkeypatch.setattr(Figure, "savefig", broken)
    target = tmp_path / "d.png"
    target.write_bytes(b"old")
    with pytest.raises(KeyboardInterrupt):
        divergence.plot(_ds(), str(target))
    assert target.read_bytes() == b"old"  # the previous file is untouched
    assert sorted(os.listdir(tmp_path)) == ["d.png"]  # and no temporary is left
