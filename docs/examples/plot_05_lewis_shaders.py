"""
Lewis's sphere test (002 Figs. 3, 6, 10)
========================================

An orthographic unit sphere under one directional light, rendered exactly from pumpup's evaluation of the BRDF (no
sampling noise), in Lewis's units. ``python scripts/make/make_images.py`` draws ``figures/render_lewis_fig*.png``
at 160 pixels per side with the same functions; here 64.
"""

import tempfile

from pumpup import plots

out = tempfile.mkdtemp()

# %%
# Phong's shader (002 eq. 8): not energy conserving.
plots.show(plots.lewis_fig3(64, out))

# %%
# Lewis's energy-conserving Phong (002 eq. 22).
plots.show(plots.lewis_fig6(64, out))

# %%
# The reciprocal Phong-Blinn shader (002 eq. 24).
plots.show(plots.lewis_fig10(64, out))
