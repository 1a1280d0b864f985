"""
Pumping up the albedo (001 Figs. 3-7)
=====================================

Reciprocal Phong and Blinn (n = 20) pumped with g1 and the controlled g2, levels 0-3: the albedo, the radiance in
the mirror direction, and the radiance across the plane of incidence; and the albedo of stretched Phong for several
exponents (000 Fig. 3). ``python scripts/make/pumping_figures.py`` draws ``figures/pumping_*.png`` and
``figures/stretched_phong_albedo.png`` with the same functions.
"""

import tempfile

from pumpup import figures, plots

ds = figures.pumping_dataset()          # every level's albedo (with its error) and radiance
st = figures.stretched_dataset()
paths = figures.plot_all(ds, st, tempfile.mkdtemp())
print(f"largest albedo of any level: {float(ds.albedo.max()):.8f} (never above 1: 001 eq. 18)")

# %%
# Phong: g1 and g2 coincide, because reciprocal Phong's albedo is never below mu.
plots.show(paths[0])

# %%
# Blinn at its maximum constant: g2 differs from g1.
plots.show(paths[1])

# %%
# Stretched Phong's albedo, c = (n + 2) / (2 pi) (000 Fig. 3).
plots.show(paths[2])
