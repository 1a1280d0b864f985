"""Data and plots of 001 Figures 3-7 and 000 Figure 3, and the measurement of 001 eq. 22.

    python scripts/make/pumping_figures.py

writes tables/pumping_figures.nc, tables/stretched_phong_albedo.nc and figures/*.png, and
prints how close each level of controlled pumping of Phong comes to c (R.V)^n / max(N.L, N.V).
"""

import time

from pumpup.figures import eq22_convergence, make_figures

if __name__ == "__main__":
    t = time.perf_counter()
    for p in make_figures():
        print("wrote", p)
    print(f"figures: {time.perf_counter() - t:.0f} s")
    print("001 eq. 22: repeated g2 pumping of Phong n = 20 against c (R.V)^n / max(N.L, N.V), c = (n+2)/(2 pi)")
    print(f"{'level':>5s} {'max rel BRDF diff':>18s} {'median rel diff':>16s} {'max albedo diff':>16s}")
    for r in eq22_convergence():
        print(f"{r['level']:5d} {r['max_rel_brdf_diff']:18.4g} {r['median_rel_brdf_diff']:16.4g} {r['max_albedo_diff']:16.4g}")
