"""
Fitting a compact model to GGX
==============================

Perceptual fitting (001 sec. 1.1): minimise the largest relative error of the point-light radiance
f cos(theta_L) and of the albedo together. ``figures/fitting_study.png`` draws the fitting study's results
(``python scripts/make/fitting_study.py``) with :func:`pumpup.fitting.plot_fits`; this example fits three families
to GGX alpha = 0.1 here and draws them with the same function.
"""

import os
import tempfile

import pumpup
from pumpup import plots
from pumpup.fitting import plot_fits

target = {"type": "ggx", "alpha": 0.1}
fits = [
    pumpup.fit(target, "phong", params={"n": (1, 1e4), "c": (1e-3, 1e3)}),
    pumpup.fit(target, "stretched_phong", params={"n": (1, 1e4), "c": (1e-3, 1e3)}),
    pumpup.fit(target, "modified_ward", params={"m": (0.01, 2.0), "c": (1e-3, 1e3)}),
]
for r in fits:
    print(f"{r.family:16s} point-light error {r.brdf_error:.3g}, albedo error {r.albedo_error:.3g}")
plots.show(plot_fits(fits, os.path.join(tempfile.mkdtemp(), "fits.png"), title="fits to GGX alpha = 0.1"))
