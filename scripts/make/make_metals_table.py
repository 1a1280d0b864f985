"""tables/metals.nc and figures/metals.png: spectral albedo of the paper's four metals (000 sec. 5).

Albedo a(mu) of the eq. 28 metal ("stretched": c cos^n(alpha) / cos(Theta_min) F(Theta_min)), of
its g1 pumping ("pumped": 001 sec. 3, each wavelength divided by its own g, which also divides out
the colour) and of the colour-keeping pumped metal ("colour_keeping":
pumpup.spectral.SpectralPumpedLobe, the F = 1 lobe pumped once with g1, times F(Theta_min) per
wavelength) for Au, Ag, Cu, Al at n = 20 and n = 5000, on 21 fixed mu (uniform in theta plus decades down to 1e-4) and the 8 default
wavelengths, with the error estimate of every value and the optical-constant provenance.

    PYTHONPATH=. python scripts/make/make_metals_table.py          # a few minutes
    PYTHONPATH=. python scripts/make/make_metals_table.py --figure  # only redraw the figure from the file
"""

import json
import sys

import numpy as np

METALS = ["Au", "Ag", "Cu", "Al"]
EXPONENTS = [20.0, 5000.0]
VARIANTS = ["stretched", "pumped", "colour_keeping"]


def build(path="tables/metals.nc"):
    import xarray as xr

    import pumpup
    from pumpup.spectral import optical
    from pumpup import spectral
    from pumpup.tables import default_grid

    mu = default_grid(n_theta=17, mu_min=1e-4)
    w = np.array(optical.DEFAULT_WAVELENGTHS)
    shape = (len(METALS), len(EXPONENTS), len(VARIANTS), mu.size, w.size)
    val = np.empty(shape)
    err = np.empty(shape)
    eta = np.empty((len(METALS), w.size))
    kk = np.empty_like(eta)
    for i, m in enumerate(METALS):
        for j, n in enumerate(EXPONENTS):
            s = spectral.SpectralMetal(m, n=n)
            eta[i], kk[i] = s.eta, s.k
            for v, model in enumerate([s, s.pump(), spectral.SpectralPumpedLobe(s)]):
                val[i, j, v], err[i, j, v] = model.albedo(mu, return_error=True)
                print(m, n, VARIANTS[v], "max albedo", float(val[i, j, v].max()), flush=True)
    ds = xr.Dataset(
        {
            "albedo": (("metal", "exponent", "variant", "mu", "wavelength"), val),
            "albedo_error": (("metal", "exponent", "variant", "mu", "wavelength"), err),
            "eta": (("metal", "wavelength"), eta),
            "k": (("metal", "wavelength"), kk),
        },
        coords={"metal": METALS, "exponent": EXPONENTS, "variant": VARIANTS, "mu": mu,
                "theta": ("mu", np.degrees(np.arccos(mu))), "wavelength": w},
        attrs={
            "title": "Directional albedo of the 000 eq. 28 metal, its g1 pumping per wavelength and the "
                     "colour-keeping g1 pumping (pumped F = 1 lobe x F(Theta_min)), per wavelength",
            "pumpup_kind": "pumpup spectral metals table",
            "method": "pumpup.albedo per wavelength (adaptive cubature), pumpup.pump g1; colour_keeping: "
                      "pumpup.spectral.SpectralPumpedLobe (g1, one level)",
            "pumpup_version": pumpup.__version__,
            "optical_constants": json.dumps({m: optical.metadata(m) for m in METALS}, sort_keys=True),
        },
    )
    ds["wavelength"].attrs["units"] = "nm"
    from pumpup.tables.provenance import write_generated

    write_generated(ds, path)  # with the commit of the code that made it (tests/project/test_generated_data.py)
    return ds


def figure(ds, path="figures/metals.png"):
    """figures/metals.png: :func:`pumpup.plots.metals` (the gallery draws it with the same function)."""
    from pumpup.plots import metals

    return metals(ds, path)


if __name__ == "__main__":
    import pumpup

    ds = pumpup.open_table("tables/metals.nc") if "--figure" in sys.argv else build()
    figure(ds)
