"""
Pumped Phong and Blinn on a sphere
==================================

Phong n = 20 against stretched Phong and Phong pumped one to three times, and Blinn n = 20 at its maximum constant
pumped with g1 and g2, lit from the front to behind the sphere (grazing highlights). Pumping brightens the
highlight near grazing incidence, where the original lost energy. ``figures/render_phong_pumped.png`` and
``figures/render_blinn_pumped.png`` are the same functions at 160 pixels per side; here 64.
"""

import tempfile

from pumpup import plots

out = tempfile.mkdtemp()

# %%
# Phong (g1 equals g2 for reciprocal Phong).
plots.show(plots.phong_stretched_pumped(64, out))

# %%
# Blinn with g1 and g2.
plots.show(plots.blinn_pumped(64, out))
