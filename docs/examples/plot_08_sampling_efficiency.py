"""
Sampling efficiency (000 sec. 4.2)
==================================

The variance per sample of the Phong-lobe importance sampler (000 eq. 19-22), divided by the albedo squared, for
Phong and stretched Phong. The variance is an integral too, so the albedo engine computes it exactly: no Monte
Carlo. ``python scripts/make/sampling_efficiency.py`` draws ``figures/sampling_efficiency.png`` with the same
functions.
"""

import os
import tempfile

from pumpup import plots
from pumpup.sampling import efficiency_dataset, plot_efficiency

ds = efficiency_dataset()
print(ds)
path = plot_efficiency(ds, os.path.join(tempfile.mkdtemp(), "sampling_efficiency.png"))
plots.show(path)
