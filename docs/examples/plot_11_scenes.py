"""
The papers' scenes, path-traced
===============================

000 Figs. 8, 9 and 10 and 001 Fig. 8: spheres, cubes, teapots and a plate with the measured metals and a plastic,
the original model beside the stretched or pumped one, path-traced by Mitsuba 3 with the ``pumpup`` plugin (needs
the ``render`` extra). ``python scripts/make/make_scenes.py`` renders ``figures/000-fig8.png`` and the others at
256 x 256 pixels, each at its own sample count (64 or 2048 per pixel), with the same functions; this example renders
them at 96 x 96 and 16 samples per pixel, so they are noisier.
"""

import tempfile

import pumpup.scenes as S
from pumpup import plots

out = tempfile.mkdtemp()
for name in S.SCENES:
    variant, rows, times = S.render_scene(name, spp=16, size=96, progress=False)
    print(f"{name}: {variant}, {len(times)} panels in {sum(times):.1f} s")
    paths = S.write_scene(name, rows, out, variant=variant, spp=16, exr=False)
    plots.show(paths[-1])
