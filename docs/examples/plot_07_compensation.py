"""
Energy compensation side by side
================================

Kulla-Conty's added lobe, 1/E scaling, and one level of pumping (g1, g2) on GGX, Beckmann, Phong, Blinn and Ward.
The full study (``python scripts/make/compensation_study.py``, about 15 minutes) writes
``tables/compensation.nc``; this example draws ``figures/compensation.png`` from that file with the same function,
and first measures one row of it again.
"""

import os
import tempfile
from pathlib import Path

import pumpup
from pumpup import plots

base = pumpup.load({"type": "ggx", "alpha": 0.3})
mu = [1.0, 0.5, 0.1, 0.01]
print("white furnace toward the viewer, GGX alpha = 0.3, mu_o =", mu)
print(f"{'base':12s}", pumpup.albedo(base, mu).round(6))
for method in ("kulla_conty", "scale", "g1", "g2"):
    c = pumpup.compensate(base, method=method)
    print(f"{method:12s}", pumpup.furnace(c, mu).round(6))

# %%
# The stored study, drawn by the function the study script calls.
ds = pumpup.open_table(Path(pumpup.__file__).resolve().parents[1] / "tables" / "compensation.nc")
plots.show(plots.compensation(ds, os.path.join(tempfile.mkdtemp(), "compensation.png")))
