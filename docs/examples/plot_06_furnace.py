"""
The white furnace
=================

A sphere under a uniform white sky: each pixel shows the albedo a(mu_V) at its viewing angle, from an adaptive table
with a stated error bound. A model that conserves energy is a uniform disc of value 1; one that loses energy darkens
towards the rim. ``figures/render_furnace.png`` is the same function at 160 pixels per side; here 64.
"""

import tempfile

from pumpup import plots

plots.show(plots.furnace_grid(64, tempfile.mkdtemp()))
