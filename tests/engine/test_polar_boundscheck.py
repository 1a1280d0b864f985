"""Compiled kernels under numba's bounds checking (slow: a subprocess compiles them anew with NUMBA_BOUNDSCHECK=1).

numba does not check indices by default: a write past an array's end corrupts memory and surfaces later, elsewhere,
as an abort.  test_properties.py's slow hypothesis test aborted the process that way (in numpy, under the nested
engine); rerun with bounds checking it named the cause, the 1-D path's first intervals overflowing their buffer (one
per piece, up to MAX_PIECES = 128, in room for max_regions + 64): Blinn n = 0 at mu = 1.3e-47 with max_regions = 50.
It also found frame 4's pieces themselves overflowing their 128 slots (GGX alpha = 1e-8 at mu = 1e-100, rtol
1e-13: a heap corruption that aborted the process), and frame 6 (GGX, Schlick) runs here too, down to mu = 1e-300.
"""

import os
import subprocess
import sys

import pytest

SCRIPT = r"""
import numpy as np, pumpup
cases = [({"type": "blinn", "n": 0}, 1.3116097664514833e-47, 50),
         ({"type": "metal", "n": 20, "eta": 0.999, "k": 0.001}, 1e-8, 1),
         ({"type": "fresnel", "base": {"type": "phong", "n": 1}, "eta": 1.1, "k": 30.0}, 1e-3, 1),
         ({"type": "ggx", "alpha": 0.001}, 0.59, 1)]
for spec, mu, regions in cases:
    a, e = pumpup.albedo(pumpup.load(spec), mu, rtol=1e-10, max_regions=regions, return_error=True)
    assert np.isfinite(a) and np.isfinite(e), (spec, a, e)
p = pumpup.pump({"type": "metal", "n": 0.5, "eta": 0.999, "k": 0.01}, g="g2", levels=2)
a, e = pumpup.albedo(p, [1e-8, 0.5], rtol=1e-10, max_regions=1, return_error=True)
assert np.all(np.isfinite(a)), a
import helpers
for spec in ({"type": "ggx", "alpha": 1e-8, "ior": 1.5}, {"type": "ggx", "alpha": 1e-8}):
    with helpers.without_normal_frames():
        a, e = pumpup.albedo(pumpup.load(spec), [1e-100, 1e-60], rtol=1e-13, return_error=True)
    assert np.all(np.isfinite(a)), (spec, a)
for spec in ({"type": "ggx", "alpha": 1e-8, "shadowing": "correlated"}, {"type": "schlick", "r": 1e-12}):
    a, e = pumpup.albedo(pumpup.load(spec), [1e-300, 1e-8, 0.5, 1.0], rtol=1e-13, max_regions=1, return_error=True)
    assert np.all(np.isfinite(a)), (spec, a)
print("ok")
"""


@pytest.mark.slow
def test_one_d_path_within_bounds(tmp_path):
    env = dict(os.environ, NUMBA_BOUNDSCHECK="1", NUMBA_CACHE_DIR=str(tmp_path / "numba"))
    r = subprocess.run([sys.executable, "-c", SCRIPT], env=env, capture_output=True, text=True, timeout=1800)
    assert r.returncode == 0 and r.stdout.strip().endswith("ok"), r.stderr[-3000:]
