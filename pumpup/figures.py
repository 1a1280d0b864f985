"""Data and plots of the pumping figures: 001 Figures 3-6 (reciprocal Phong and Blinn, n = 20,
pumped with g1 and g2, levels 0-3), 000 Figure 3 / 001 Figure 7 (stretched Phong albedo for
several n), and the measurement of the claim of 001 eq. 22.

Radiance: a point light of power 4 pi at distance 1 in direction L gives irradiance
cos(theta_L), so the reflected radiance towards V is f(L, V) cos(theta_L) (001 eq. 3).
"""

from __future__ import annotations

import math
import os

import numpy as np

from .core import load
from .engine.cubature import albedo
from .operators.pumping import Pumped, pump
from .tables import atomic_path, max_constant

THETA = np.linspace(0.0, 89.9, 300)  # incidence angles of the albedo and mirror-radiance curves [deg]
THETA_IN = np.array([0.0, 30.0, 60.0, 80.0])  # incidence angles of the in-plane radiance curves [deg]
THETA_OUT = np.linspace(-89.9, 89.9, 361)  # viewing angle in the plane of incidence, + = mirror side
N_FIG = 20
STRETCHED_N = [1, 2, 5, 10, 20, 50, 100, 1000, 5000]


def _dir(theta_deg, sign=1.0):
    t = np.radians(theta_deg)
    return np.stack([sign * np.sin(t), np.zeros_like(t), np.cos(t)], axis=-1)


def _chain(base_spec, g, levels=3):
    top = pump(base_spec, g=g, levels=levels)
    out = [top]
    while isinstance(out[-1], Pumped):
        out.append(out[-1].base)
    return out[::-1]  # level 0 (the original) first


def pumping_dataset(progress: bool | None = None):
    """The data of 001 Figures 3-6 as an xarray.Dataset (albedo and radiance per level)."""
    import xarray as xr

    c_blinn, _ = max_constant(load({"type": "blinn", "n": N_FIG}))
    bases = {"phong": {"type": "phong", "n": N_FIG}, "blinn": {"type": "blinn", "n": N_FIG, "c": c_blinn}}
    mu = np.cos(np.radians(THETA))
    shape = (len(bases), 2, 4)
    alb = np.zeros(shape + (len(THETA),))
    alb_err = np.zeros_like(alb)
    mirror = np.zeros_like(alb)
    plane = np.zeros(shape + (len(THETA_IN), len(THETA_OUT)))
    for i, spec in enumerate(bases.values()):
        for j, g in enumerate(("g1", "g2")):
            for k, f in enumerate(_chain(spec, g)):
                a, e = albedo(f, mu, return_error=True, rtol=1e-9)
                alb[i, j, k], alb_err[i, j, k] = a, e
                L, R = _dir(THETA), _dir(THETA, -1.0)
                mirror[i, j, k] = f.eval(L, R) * np.cos(np.radians(THETA))
                for q, ti in enumerate(THETA_IN):
                    Lq = _dir(np.array(ti))
                    V = _dir(np.abs(THETA_OUT), -np.sign(THETA_OUT + 1e-300))
                    plane[i, j, k, q] = f.eval(Lq, V) * math.cos(math.radians(ti))
    ds = xr.Dataset(
        {
            "albedo": (("model", "g", "level", "theta"), alb, {"long_name": "directional albedo", "units": "1"}),
            "albedo_error": (("model", "g", "level", "theta"), alb_err, {"long_name": "estimated error", "units": "1"}),
            "mirror_radiance": (("model", "g", "level", "theta"), mirror,
                                {"long_name": "radiance f(L, R) cos(theta_L) in the mirror direction, "
                                              "point light 4 pi at distance 1", "units": "1"}),
            "plane_radiance": (("model", "g", "level", "theta_in", "theta_out"), plane,
                               {"long_name": "radiance f(L, V) cos(theta_L) across the plane of incidence",
                                "units": "1"}),
        },
        coords={
            "model": list(bases),
            "g": ["g1", "g2"],
            "level": ("level", np.arange(4), {"long_name": "pumping level (0 = original)"}),
            "theta": ("theta", THETA, {"long_name": "incidence angle", "units": "degree"}),
            "theta_in": ("theta_in", THETA_IN, {"long_name": "incidence angle", "units": "degree"}),
            "theta_out": ("theta_out", THETA_OUT,
                          {"long_name": "viewing angle in the plane of incidence (+: mirror side)",
                                                   "units": "degree"}),
        },
        attrs={"pumpup_kind": "pumpup figure data", "title": "001 Figures 3-6: pumped Phong and Blinn, n = 20",
               "blinn_c": c_blinn, "phong_c": (N_FIG + 2) / (2 * math.pi)},
    )
    return ds


def stretched_dataset():
    """000 Figure 3 / 001 Figure 7: albedo of stretched Phong for several n."""
    import xarray as xr

    mu = np.cos(np.radians(THETA))
    a = np.zeros((len(STRETCHED_N), len(THETA)))
    e = np.zeros_like(a)
    for i, n in enumerate(STRETCHED_N):
        a[i], e[i] = albedo(load({"type": "stretched_phong", "n": n}), mu, return_error=True, rtol=1e-10)
    return xr.Dataset(
        {"albedo": (("n", "theta"), a, {"long_name": "directional albedo", "units": "1"}),
         "albedo_error": (("n", "theta"), e, {"long_name": "estimated error", "units": "1"})},
        coords={"n": STRETCHED_N, "theta": ("theta", THETA, {"units": "degree"})},
        attrs={"pumpup_kind": "pumpup figure data",
               "title": "000 Figure 3: albedo of stretched Phong, c = (n+2)/(2 pi)"},
    )


def eq22_convergence(levels: int = 5):
    """How close repeated controlled pumping of Phong comes to c (R.V)^n / max(N.L, N.V) (001 eq. 22).

    Returns a list of dicts per level: the largest relative BRDF difference over a grid of
    direction pairs inside the lobe, and the largest albedo difference.
    """
    target = load({"type": "stretched_phong", "n": N_FIG})
    chain = _chain({"type": "phong", "n": N_FIG}, "g2", levels)
    rng = np.random.default_rng(22)
    mu = np.cos(np.radians(THETA[::10]))
    a_target = albedo(target, mu)
    wi = _dir(rng.uniform(0, 89.5, 4000))
    phi = rng.uniform(-0.3, 0.3, 4000)
    wo = _dir(rng.uniform(0, 89.5, 4000), -1.0)
    wo = np.stack([wo[:, 0] * np.cos(phi), wo[:, 0] * np.sin(phi) * -1, wo[:, 2]], axis=-1)
    wo /= np.linalg.norm(wo, axis=-1, keepdims=True)
    ft = target.eval(wi, wo)
    inside = ft > 1e-3 * ft.max()
    rows = []
    for k, f in enumerate(chain):
        fk = f.eval(wi, wo)
        rows.append({
            "level": k,
            "max_rel_brdf_diff": float(np.max(np.abs(fk[inside] - ft[inside]) / ft[inside])),
            "median_rel_brdf_diff": float(np.median(np.abs(fk[inside] - ft[inside]) / ft[inside])),
            "max_albedo_diff": float(np.max(np.abs(albedo(f, mu) - a_target))),
        })
    return rows


def plot_all(ds, st, outdir):
    """Plot the pumping figures of ``ds`` (per model and g: albedo, radiance in the mirror direction and across the
    plane of incidence, level by level) and 000 Fig. 3 of ``st`` into ``outdir``; returns the paths of the PNG files.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    paths = []
    for model in ds.model.values:
        fig, axes = plt.subplots(2, 3, figsize=(14, 8), constrained_layout=True)
        for j, g in enumerate(ds.g.values):
            sub = ds.sel(model=model, g=g)
            for k in ds.level.values:
                lab = "original" if k == 0 else f"level {k}"
                axes[j, 0].plot(ds.theta, sub.albedo.sel(level=k), label=lab)
                axes[j, 1].plot(ds.theta, sub.mirror_radiance.sel(level=k), label=lab)
                axes[j, 2].plot(ds.theta_out, sub.plane_radiance.sel(level=k, theta_in=60.0), label=lab)
            axes[j, 0].set(title=f"{model} n={N_FIG}, {g}: albedo", xlabel="incidence angle [deg]", ylim=(0, 1.05))
            axes[j, 1].set(title=f"{g}: radiance in the mirror direction", xlabel="incidence angle [deg]")
            axes[j, 2].set(title=f"{g}: radiance across the plane, theta_L = 60 deg", xlabel="viewing angle [deg]")
            for ax in axes[j]:
                ax.legend(fontsize=8)
                ax.grid(alpha=0.3)
        path = os.path.join(outdir, f"pumping_{model}.png")
        with atomic_path(path) as tmp:  # an interrupted write leaves no half PNG
            fig.savefig(tmp, dpi=90, format="png")
        plt.close(fig)
        paths.append(path)
    fig, ax = plt.subplots(figsize=(7, 5), constrained_layout=True)
    for n in st.n.values:
        ax.plot(st.theta, st.albedo.sel(n=n), label=f"n = {n}")
    ax.set(title="Stretched Phong, c = (n+2)/(2 pi): albedo (000 Fig. 3)", xlabel="incidence angle [deg]",
           ylabel="albedo", ylim=(0.45, 1.01))
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    path = os.path.join(outdir, "stretched_phong_albedo.png")
    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=90, format="png")
    plt.close(fig)
    return paths + [path]


def make_figures(table_dir="tables", figure_dir="figures"):
    """Write the figure data to ``table_dir`` (netCDF) and the plots to ``figure_dir`` (PNG)."""
    os.makedirs(table_dir, exist_ok=True)
    os.makedirs(figure_dir, exist_ok=True)
    ds = pumping_dataset()
    from .tables.provenance import write_generated

    write_generated(ds, os.path.join(table_dir, "pumping_figures.nc"))
    st = stretched_dataset()
    write_generated(st, os.path.join(table_dir, "stretched_phong_albedo.nc"))
    return plot_all(ds, st, figure_dir)
