"""How honest is the error estimate of the 1-D path with 000 eq. 28's Fresnel factor?

The lobe frame with F(Theta_min) (pumpup.engine.polar frame 5, _k_lobe_fresnel: metal, plastic with an index, the fresnel
wrapper of a Phong-family lobe) and the pumped lobe's frame of N with it (a pumped metal, the fresnel wrapper of a
pumped lobe), over every index the rule takes of eta in {0.05, 0.3, 0.6, 0.9, 0.999, 1.001, 1.1, 1.5, 3, 20} x
k in {0, 0.001, 0.002, 0.01, 0.3, 3, 30} (the near-kinks, Im sqrt(1 - (eta + i k)^2) < 1e-3, go to the nested
engine, and with a pumped lobe those below 1e-2), five lobes (stretched Phong n = 0, 7.5, 500 and Phong n = 20, 1 under the fresnel wrapper) and, with
``--pumped``, a g1-pumped metal n = 20 per index; at 60 mu uniform in theta plus 1e-3, 1e-5, 1e-8 and rtol 1e-6,
1e-8, 1e-10, 1e-12: the ratio of the true error to the estimate, the truth being the nested engine at rtol 1e-13
(using(engine="nested")), its own error counted in the 1-D path's favour: max(|a - ref| - ref_err, 0) / estimate.
A ratio above 1 is a dishonest estimate.  Prints one row per index and lobe (worst ratio@mu/evaluations per mu for
each rtol) and the worst overall.

    PYTHONPATH=. python scripts/calibration/lobe_fresnel_calibration.py            # about 5 minutes on one core
    PYTHONPATH=. python scripts/calibration/lobe_fresnel_calibration.py --pumped   # the pumped metals only (about 10 minutes)
"""

import sys
import time
import warnings

import numpy as np

import pumpup
from pumpup.engine import polar as _polar
from pumpup.engine import lobe_fresnel as _lobe_fresnel
from pumpup.physics import fresnel as _fresnel_mod
from pumpup.engine.routes import one_d_everywhere, using

ETAS = (0.05, 0.3, 0.6, 0.9, 0.999, 1.001, 1.1, 1.5, 3.0, 20.0)
KS = (0.0, 0.001, 0.002, 0.01, 0.3, 3.0, 30.0)
LOBES = ({"type": "stretched_phong", "n": 0.0}, {"type": "stretched_phong", "n": 7.5}, {"type": "stretched_phong", "n": 8},
         {"type": "stretched_phong", "n": 500}, {"type": "phong", "n": 20}, {"type": "phong", "n": 1},
         {"type": "phong", "n": 2000})
RTOLS = (1e-6, 1e-8, 1e-10, 1e-12)


def worst_per_rtol(f, mu, rtols, atol=1e-14):
    """For each rtol, (the worst (|a - ref| - ref_err) / estimate of the 1-D path over ``mu``, the mu where it lies, the
    mean evaluations per mu), against the nested engine at rtol 1e-13 (``using(engine="nested")``), its own error counted in
    the path's favour (negative where the difference is within it).  Also for scripts/studies/breaks_scan.py."""
    with using(engine="nested"), warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ref, ref_err = pumpup.albedo(f, mu, rtol=1e-13, return_error=True)
    out = []
    for rtol in rtols:
        a, e, _, ev = _polar.albedo_1d(f, mu, rtol, atol, 10000)
        r = (np.abs(a - ref) - ref_err) / e
        i = int(np.argmax(r))
        out.append((float(r[i]), float(mu[i]), float(ev.mean())))
    return out


def main():
    pumped = "--pumped" in sys.argv
    mu = np.r_[np.cos(np.linspace(0, np.pi / 2, 61)[:-1]), 1e-3, 1e-5, 1e-8]
    t0 = time.perf_counter()
    worst = 0.0
    for eta in ETAS:
        for k in KS:
            if not _lobe_fresnel.lobe_fresnel_ok(eta, k):
                continue
            x0, y0 = _fresnel_mod.fresnel_branch(eta, k)
            if pumped:
                models = [("pumped metal n 20", pumpup.pump({"type": "metal", "n": 20, "eta": eta, "k": k}))]
            else:
                models = [(f"{b['type'][:9]} n {b['n']:g}", pumpup.load({"type": "fresnel", "base": b, "eta": eta, "k": k}))
                          for b in LOBES]
            for name, f in models:
                if not one_d_everywhere(f, mu):
                    print(f"eta {eta:6g} k {k:6g} (x0 {x0:7.3g} y0 {y0:7.3g}) {name:20s} the nested engine's (a near-kink)")
                    continue
                cells = []
                for r, m, ev in worst_per_rtol(f, mu, RTOLS):
                    r = max(r, 0.0)
                    worst = max(worst, r)
                    cells.append(f"{r:7.2g}@{m:<7.2g}/{ev:<5.0f}")
                print(f"eta {eta:6g} k {k:6g} (x0 {x0:7.3g} y0 {y0:7.3g}) {name:20s} " + " ".join(cells), flush=True)
    print(f"worst true error / estimate {worst:.3g} ({time.perf_counter() - t0:.0f} s)")


if __name__ == "__main__":
    main()
