"""The importance-sampling efficiency study of 000 sec. 4.2 (issue 8, item 4).

Writes tables/sampling_efficiency.nc (variance per sample of the Phong-lobe estimator for
reciprocal Phong and stretched Phong, against the viewing angle, for several n; computed by
the albedo engine, no Monte Carlo) and figures/sampling_efficiency.png, and prints the
grazing-angle check of 000 eq. 26.  The regression test (tests/apps/test_sampling.py) calls the
same function, :func:`pumpup.sampling.efficiency_dataset`.

    python scripts/make/sampling_efficiency.py [--out tables] [--figures figures]
"""

import argparse
import os

from pumpup.sampling import efficiency_dataset, plot_efficiency
from pumpup.tables.provenance import write_generated


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default="tables")
    ap.add_argument("--figures", default="figures")
    a = ap.parse_args(argv)
    ds = efficiency_dataset()
    os.makedirs(a.out, exist_ok=True)
    os.makedirs(a.figures, exist_ok=True)
    path = os.path.join(a.out, "sampling_efficiency.nc")
    write_generated(ds, path)
    fig = plot_efficiency(ds, os.path.join(a.figures, "sampling_efficiency.png"))
    print(f"wrote {path} and {fig}")
    print(f"000 eq. 26, stretched Phong at mu = {float(ds.mu[-1]):.0e}:")
    for n in ds.n.values:
        a_ = float(ds.albedo.sel(model="stretched_phong", n=n)[-1])
        print(f"  n = {n:6g}: a = {a_:.10f}, (n+2)/(2(n+1)) = {(n + 2) / (2 * (n + 1)):.10f}, "
              f"acceptance = {float(ds.acceptance.sel(model='stretched_phong', n=n)[-1]):.10f}")
    print("relative variance (variance / a^2), Phong / stretched:")
    for n in ds.n.values:
        r = ds.relative_variance.sel(n=n)
        row = ", ".join(f"{t:g}deg {float(p):.3g}/{float(s):.3g}" for t, p, s in
                        zip(ds.theta.values[::3], r.sel(model="phong").values[::3], r.sel(model="stretched_phong").values[::3]))
        print(f"  n = {n:g}: {row}")


if __name__ == "__main__":
    main()
