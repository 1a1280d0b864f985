"""
Lobe widths: Phong, stretched and pumped
========================================

Phong, stretched Phong (000 eq. 7) and once-pumped Phong (001 eq. 20) at Lewis's half-angles beta = 10 and 30
degrees, each row lit so that its peak at Phi_L = 0 is 1. ``figures/render_lobes.png`` is the same function at 160
pixels per side; here 64.
"""

import tempfile

from pumpup import plots

plots.show(plots.lobes(64, tempfile.mkdtemp()))
