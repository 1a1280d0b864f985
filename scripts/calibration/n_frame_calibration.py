"""How honest is frame 6's error estimate?

Frame 6 (pumpup.engine.normal_frame._integrate_n) integrates GGX and Beckmann with F = 1 (both Smith G, exact or Walter's G1) and
Schlick's model about N, with the weight's azimuth in closed form.  Its reference here is frame 4, the rule on h's arc these models took before
(using(without={"normal", "lobe_normal"})), at rtol 1e-13, an independent path (other variables, other cuts, an inner rule), and
where it is honest the nested engine at 1e-13 (using(engine="nested")).  For every model, 60 mu uniform in theta
plus 1e-3, 1e-5, 1e-8 and 1e-300 (frame 4 at 1e-100 there: the albedo is flat to ~mu), and rtol 1e-6 ... 1e-12: the
worst max(|a - ref| - ref_err, 0) / estimate (above 1: a dishonest estimate), the worst estimate / (rtol a), the
evaluations per mu and the time of a 257-point table at rtol 1e-10 against frame 4's.

    PYTHONPATH=. python scripts/calibration/n_frame_calibration.py          # about 2 minutes (45 models)
"""

import warnings

import numpy as np

import pumpup
from pumpup.engine import polar as _polar
from pumpup.costs import _best  # (warm-up, then the best of ``repeat``)
from pumpup.engine.routes import using

SPECS = ([{"type": "ggx", "alpha": a} for a in (1e-8, 1e-5, 0.001, 0.02, 0.1, 0.3, 0.5, 0.8, 1.0)]
         + [{"type": "ggx", "alpha": a, "shadowing": "correlated"} for a in (1e-8, 1e-4, 0.01, 0.1, 0.3, 0.6, 0.9, 1.0)]
         + [{"type": "schlick", "r": r} for r in (1e-12, 1e-8, 1e-4, 0.001, 0.01, 0.1, 0.5, 0.9, 1.0)]
         + [{"type": "beckmann", "alpha": a} for a in (1e-8, 1e-5, 0.001, 0.02, 0.1, 0.3, 0.5, 0.8, 1.0)]
         + [{"type": "beckmann", "alpha": a, "shadowing": "correlated"} for a in (1e-6, 0.01, 0.1, 0.5, 1.0)]
         + [{"type": "beckmann", "alpha": a, "g1": "walter", **sh} for a, sh in ((1e-4, {}), (0.05, {}), (0.3, {}),
                                                                              (0.7, {"shadowing": "correlated"}), (1.0, {}))])
RTOLS = (1e-6, 1e-8, 1e-10, 1e-12)


def main():
    warnings.simplefilter("ignore")
    th = np.linspace(0.0, np.pi / 2, 61)[1:]
    mu = np.sort(np.concatenate([np.cos(th), [1e-3, 1e-5, 1e-8, 1e-300]]))
    mu_ref = np.where(mu < 1e-100, 1e-100, mu)
    grid = np.linspace(1e-3, 1.0, 257)
    worst_all = 0.0
    print(f"{'model':58s} {'worst true/estimate per rtol':44s} {'est/(rtol a)':>12s} {'evals':>6s} {'ms':>6s} {'frame 4 ms':>10s}")
    for spec in SPECS:
        f = pumpup.load(spec)
        with using(without={"normal", "lobe_normal"}):
            ref, ref_e = pumpup.albedo(f, mu_ref, return_error=True, rtol=1e-13)
        ratios, loose = [], 0.0
        for rtol in RTOLS:
            a, e = pumpup.albedo(f, mu, return_error=True, rtol=rtol)
            ratios.append(float((np.maximum(np.abs(a - ref) - ref_e, 0.0) / e).max()))
            loose = max(loose, float((e / (rtol * a)).max()))
        worst_all = max(worst_all, *ratios)
        ev = int(np.mean(_polar.albedo_1d(f, grid, 1e-10, 0.0, 200)[3]))
        t6 = _best(lambda: pumpup.albedo(f, grid, rtol=1e-10), 3)
        with using(without={"normal", "lobe_normal"}):
            t4 = _best(lambda: pumpup.albedo(f, grid, rtol=1e-10), 3)
        print(f"{str(spec):58s} {' '.join(f'{r:10.3g}' for r in ratios):44s} {loose:12.3g} {ev:6d} {t6 * 1e3:6.1f} {t4 * 1e3:10.1f}")
    print(f"worst true error / estimate: {worst_all:.3g}")


if __name__ == "__main__":
    main()
