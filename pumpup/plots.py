"""The figures of ``figures/``: one function per figure, called by the scripts of ``scripts/make/`` and by the
documentation's gallery (``docs/examples/``), so the two draw the same thing.

The exact sphere images (Lewis's shaders, 002 Figs. 3, 6, 10; lobe widths; pumped Phong and Blinn; the white
furnace) take ``size`` (pixels per side) and an output directory and return the path of the PNG grid they write;
the study figures (:func:`compensation`, :func:`metals`) draw a dataset the study scripts write to ``tables/``.
:func:`show` puts a written PNG into a matplotlib figure, pixel for pixel (for notebooks and the gallery).

Lewis's shaders are rendered in his units: a directional light of irradiance E = pi, kd = (1 - k_s) / pi and
ks = k_s / pi in pumpup's BRDF parameters, so the radiance is his eq. 4 with L_d = 1: (1 - k_s)(N.S) + k_s F_s
(Fig. 3), and the lobe width is his half-angle beta, n = -ln 2 / ln cos(beta).  His Figs. 3 and 6 use Blinn's
F_s^B; pumpup's ``phong_shader`` and ``lewis_phong`` have Phong's F_s^P (002 eq. 5), so those two grids are his
configuration with Phong's lobe.  Fig. 10 (``phong_blinn``, 002 eq. 24) is his shader.
"""

from __future__ import annotations

import math
import os

import numpy as np

from . import render
from .core import load
from .operators.compensate import compensate
from .operators.pumping import pump
from .tables import atomic_path, max_constant

__all__ = ["MAKERS", "blinn_pumped", "compensation", "furnace_grid", "lewis_fig10", "lewis_fig3", "lewis_fig6",
           "lobes", "metals", "phong_stretched_pumped", "show"]

LIGHTS = [0.0, 30.0, 60.0, 80.0]
GRAZING = [0.0, 60.0, 110.0, 130.0, 150.0]  # past 90 the light is behind the sphere: grazing highlights
N_PUMP = 20  # exponent of 001 Figs. 3-6


def _lewis_rows(make, ks_values, betas):
    rows, labels = [], []
    for beta in betas:
        n = render.lewis_exponent(beta)
        for ks in ks_values:
            rows.append(make(n, ks))
            labels.append(f"beta={beta:g} deg (n={n:.3g})\nk={ks:g}")
    return rows, labels


def _row_of_lights(spec, lights, size, irradiance):
    return [render.sphere(spec, phi, size, irradiance=irradiance) for phi in lights]


def _print_peaks(name, rows, labels, lights):
    print(f"{name}: peak radiance, Phi_L = {', '.join(f'{v:g}' for v in lights)} deg")
    for lab, row in zip(labels, rows):
        print(f"  {lab.replace(chr(10), ', '):44s} " + " ".join(f"{float(im.radiance.max()):8.4g}" for im in row))


def lewis_fig3(size, out):
    """002 Fig. 3 configuration, Phong's shader (002 eq. 8) with F_s^P, k_d = 1 - k_s."""
    rows, labels = _lewis_rows(lambda n, ks: {"type": "phong_shader", "n": n, "ks": ks / math.pi,
                                              "kd": (1 - ks) / math.pi}, [0.25, 0.75], [10.0, 30.0])
    ims = [_row_of_lights(s, LIGHTS, size, math.pi) for s in rows]
    _print_peaks("lewis_fig3 (phong_shader)", ims, labels, LIGHTS)
    return render.grid_figure(ims, os.path.join(out, "render_lewis_fig3.png"), row_labels=labels,
                         col_labels=[f"Phi_L = {v:g} deg" for v in LIGHTS],
                         title="Phong's shader (002 eq. 8, F_s^P): (1 - k_s)(N.S) + k_s (render.V)^n, L_d = 1")


def lewis_fig6(size, out):
    """002 Fig. 6 configuration, the energy-conserving Phong shader (002 eq. 22), k_rho = 1."""
    rows, labels = _lewis_rows(lambda n, ks: {"type": "lewis_phong", "n": n, "k_rho": 1.0, "k_sigma": ks},
                               [0.25, 0.75], [10.0, 30.0])
    labels = [lab.replace("k=", "k_sigma=") for lab in labels]
    ims = [_row_of_lights(s, LIGHTS, size, math.pi) for s in rows]
    _print_peaks("lewis_fig6 (lewis_phong)", ims, labels, LIGHTS)
    return render.grid_figure(ims, os.path.join(out, "render_lewis_fig6.png"), row_labels=labels,
                         col_labels=[f"Phi_L = {v:g} deg" for v in LIGHTS],
                         title="energy-conserving Phong (002 eq. 22, F_s^P, k_rho = 1), L_d = 1")


def lewis_fig10(size, out):
    """002 Fig. 10: the reciprocal Phong-Blinn shader (002 eq. 24), k_d = 1 - k_s."""
    rows, labels = _lewis_rows(lambda n, ks: {"type": "phong_blinn", "n": n, "ks": ks / math.pi,
                                              "kd": (1 - ks) / math.pi}, [0.25, 0.75], [10.0, 30.0])
    labels = [lab.replace("k=", "k_s=") for lab in labels]
    ims = [_row_of_lights(s, LIGHTS, size, math.pi) for s in rows]
    _print_peaks("lewis_fig10 (phong_blinn)", ims, labels, LIGHTS)
    return render.grid_figure(ims, os.path.join(out, "render_lewis_fig10.png"), row_labels=labels,
                         col_labels=[f"Phi_L = {v:g} deg" for v in LIGHTS],
                         title="reciprocal Phong-Blinn (002 eq. 24): [(1 - k_s) + k_s (N.H)^n] (N.S), L_d = 1")


def lobes(size, out):
    """Phong, stretched Phong and once-pumped Phong at Lewis's half-angles beta = 10 and 30 degrees, each row lit
    so that its peak at Phi_L = 0 is 1 (Lewis's normalisation of his Fig. 4).
    """
    specs, labels = [], []
    for beta in (10.0, 30.0):
        n = render.lewis_exponent(beta)
        base = {"type": "phong", "n": n}
        for s in (base, {"type": "stretched_phong", "n": n}, pump(base, g="g1").spec):
            specs.append(s)
            labels.append(f"{render.label(s).replace(f'n={n:.4g}', 'n=' + format(n, '.3g'))}\nbeta={beta:g} deg")
    ims = []
    for s in specs:
        e = 1.0 / float(render.sphere(s, 0.0, size).radiance.max())
        ims.append(_row_of_lights(s, LIGHTS, size, e))
    _print_peaks("lobes (peak at Phi_L = 0 scaled to 1)", ims, labels, LIGHTS)
    return render.grid_figure(ims, os.path.join(out, "render_lobes.png"), row_labels=labels,
                         col_labels=[f"Phi_L = {v:g} deg" for v in LIGHTS],
                         title="Phong, stretched Phong (000 eq. 7), pumped Phong (001 eq. 20); light scaled per row")


def _blinn_spec():
    c, _ = max_constant(load({"type": "blinn", "n": N_PUMP}))
    return {"type": "blinn", "n": N_PUMP, "c": c}


def phong_stretched_pumped(size, out):
    """Reciprocal Phong n = 20, stretched Phong (000 eq. 7) and Phong pumped 1-3 times (001 sec. 3)."""
    base = {"type": "phong", "n": N_PUMP}
    specs = [base, {"type": "stretched_phong", "n": N_PUMP}] + [pump(base, g="g1", levels=k).spec
                                                                   for k in (1, 2, 3)]
    labels = [render.label(s) for s in specs]
    ims = [_row_of_lights(s, GRAZING, size, 1.0) for s in specs]
    _print_peaks("phong_pumped", ims, labels, GRAZING)
    return render.grid_figure(ims, os.path.join(out, "render_phong_pumped.png"), row_labels=labels,
                         col_labels=[f"Phi_L = {v:g} deg" for v in GRAZING], exposure=-2.0,
                         title="Phong n = 20: original, stretched (000 eq. 7), pumped with g1 (= g2 for Phong)")


def blinn_pumped(size, out):
    """Blinn n = 20 at its maximum constant, pumped 1-3 times with g1 and with g2 (001 Figs. 4, 6)."""
    base = _blinn_spec()
    specs = [base] + [pump(base, g=g, levels=k).spec for g in ("g1", "g2") for k in (1, 2, 3)]
    labels = [render.label(s) for s in specs]
    ims = [_row_of_lights(s, GRAZING, size, 1.0) for s in specs]
    _print_peaks("blinn_pumped", ims, labels, GRAZING)
    return render.grid_figure(ims, os.path.join(out, "render_blinn_pumped.png"), row_labels=labels,
                         col_labels=[f"Phi_L = {v:g} deg" for v in GRAZING], exposure=-1.0,
                         title=f"Blinn n = 20, c = {base['c']:.4f} (its maximum constant): g1 and g2 pumping")


def furnace_grid(size, out):
    """White furnace: Phong and its pumped levels, Blinn with g1 and g2, and other models."""
    phong = {"type": "phong", "n": N_PUMP}
    blinn = _blinn_spec()
    rows = [
        [phong] + [pump(phong, g="g1", levels=k).spec for k in (1, 2, 3)]
        + [{"type": "stretched_phong", "n": N_PUMP}],
        [blinn] + [pump(blinn, g=g, levels=k).spec for g in ("g1", "g2") for k in (1, 3)],
        [{"type": "lambert", "albedo": 0.8}, {"type": "ggx", "alpha": 0.3}, {"type": "cook_torrance", "m": 0.3},
         {"type": "phong_shader", "n": N_PUMP}, {"type": "stretched_phong", "n": 5000}],
        # energy compensation (pumpup.compensate): Kulla-Conty's added lobe and the 1/E(wo) scaling
        [compensate(load(b), method=m) for b in (phong, {"type": "ggx", "alpha": 0.3})
         for m in ("kulla_conty", "scale")],
    ]
    ims = [[render.furnace(s, size) for s in row] for row in rows]
    print("furnace: a(mu_V) minimum over the sphere / centre / maximum, error bound")
    for row in ims:
        for im in row:
            v = im.radiance[im.mask]
            c = im.radiance[size // 2, size // 2]
            note = "  (integrated over wi: not reciprocal)" if im.params["transposed"] else ""
            print(f"  {render.label(im.spec):40s} {float(v.min()):.4f} / {float(c):.6f} / {float(v.max()):.6f}"
                  f"  bound {im.error:.2g}{note}")

    def text(im):
        v = im.radiance[im.mask]
        return f"{render.label(im.spec)}\nmin {float(v.min()):.3f}, max {float(v.max()):.4f}"

    return render.grid_figure(ims, os.path.join(out, "render_furnace.png"), tile_text=text, tile_inches=1.9,
                         row_labels=["Phong n=20", "Blinn n=20", "others", "compensated"],
                         title="white furnace (sky radiance 1): pixel = albedo a(mu_V); min and max over the sphere")


MAKERS = {"lewis_fig3": lewis_fig3, "lewis_fig6": lewis_fig6, "lewis_fig10": lewis_fig10,
          "lobes": lobes, "phong_pumped": phong_stretched_pumped, "blinn_pumped": blinn_pumped, "furnace": furnace_grid}


def compensation(ds, path):
    """figures/compensation.png from the compensation study's dataset (``tables/compensation.nc``): the white furnace,
    the point-light radiance in the mirror direction against the base's, and the intermediate-metalness furnace.

    Methods that give the same values (Kulla-Conty and scaling both reach 1 in the furnace; scaling, g1 and g2 all
    divide by E(mu) in the mirror direction) are drawn as nested lines, the first thickest, each with its own
    marker, so every series stays visible.  Written atomically; returns ``path``.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    colors = {"base": "k", "kulla_conty": "C0", "scale": "C1", "g1": "C2", "g2": "C3"}
    # drawing order, line width and marker: coincident series nest inside each other
    style = {"base": (5.0, "o", 7), "kulla_conty": (4.0, "s", 6), "scale": (2.8, "^", 5), "g1": (1.7, "v", 4),
             "g2": (0.9, "x", 4)}

    def kw(method, ls):
        lw, marker, ms = style[str(method)]
        return {"ls": ls, "color": colors[str(method)], "lw": lw, "marker": marker, "ms": ms, "alpha": 0.85,
                "markerfacecolor": "none" if lw > 2 else colors[str(method)]}

    fig, ax = plt.subplots(1, 3, figsize=(16, 5.2))
    theta_o = np.degrees(np.arccos(ds.mu.values))
    for model, ls in (("ggx alpha=0.3", "-"), ("ggx alpha=1", "--")):
        if model not in ds.model.values:
            continue
        for method in ds.method.values:
            ax[0].plot(theta_o, ds.furnace.sel({"model": model, "method": method}), **kw(method, ls),
                       label=f"{method} ({model})")
    ax[0].set_xlabel("viewing angle theta_o [deg]")
    ax[0].set_ylabel("white furnace (albedo)")
    ax[0].set_title("furnace, GGX alpha 0.3 (solid) and 1 (dashed)", fontsize=10)
    ax[0].set_ylim(0.0, 1.04)  # room below the curves for the legend
    ax[0].legend(fontsize=6.5, ncol=2, loc="lower right")
    for method in ds.method.values[1:]:
        for model, ls in (("ggx alpha=0.3", "-"), ("phong n=20", ":")):
            if model in ds.model.values:
                ax[1].plot(ds.theta_i, ds.mirror_ratio.sel({"model": model, "method": method}), **kw(method, ls),
                           label=f"{method} ({model})")
    ax[1].set_yscale("log")
    ax[1].set_xlabel("theta_i [deg]")
    ax[1].set_ylabel("f_c(wi, R) / f(wi, R)")
    ax[1].set_title("point light, mirror direction, against the base\n(scale, g1, g2 coincide where g = E(mu))",
                    fontsize=10)
    ax[1].legend(fontsize=6.5)
    for method in ds.method.values:
        for arrangement, ls in (("lobe", "-"), ("mix", "--")):
            r = ds.metal_residual.sel({"alpha": ds.alpha.values[0], "arrangement": arrangement, "method": method})
            ax[2].semilogy(ds.metalness, np.maximum(r, 1e-17), **kw(method, ls), label=f"{method} ({arrangement})")
    ax[2].axhline(1e-6, color="gray", lw=0.8)
    ax[2].set_xlabel("metalness m")
    ax[2].set_ylabel("max |1 - a|")
    ax[2].set_title(f"(1 - m) Lambert + m GGX {float(ds.alpha.values[0]):g}\n(lobe: solid, mix: dashed)", fontsize=10)
    ax[2].legend(fontsize=6, ncol=2)
    fig.tight_layout()
    with atomic_path(path) as tmp:  # no half PNG if interrupted
        fig.savefig(tmp, dpi=110, format="png")
    plt.close(fig)
    return path


def metals(ds, path):
    """figures/metals.png from ``tables/metals.nc``: the albedo of the four metals per wavelength and the sRGB colour
    of each albedo spectrum.  Written atomically; returns ``path``.
    """
    import matplotlib

    matplotlib.use("Agg")
    import colour
    import matplotlib.pyplot as plt

    from . import spectral

    fig, axes = plt.subplots(2, 4, figsize=(14, 6.5), sharex=True, sharey=True)
    w = ds["wavelength"].values
    line_rgb = np.clip(colour.XYZ_to_sRGB(colour.wavelength_to_XYZ(w)), 0, None)
    line_rgb = line_rgb / line_rgb.max(axis=1, keepdims=True)
    theta = ds["theta"].values
    for j, n in enumerate(ds["exponent"].values):
        for i, m in enumerate(ds["metal"].values):
            ax = axes[j, i]
            for v, style in zip(ds["variant"].values, ["-", "--", ":"]):
                a = ds["albedo"].sel(metal=m, exponent=n, variant=v).values
                for q in range(w.size):
                    ax.plot(theta, a[:, q], style, color=line_rgb[q], lw=1.2)
                rgb = np.clip(spectral.to_srgb(a, w, encoded=True), 0, 1)
                y0 = {"stretched": 0.02, "pumped": 0.08, "colour_keeping": 0.14}[str(v)]
                ax.scatter(theta, np.full(theta.size, y0), c=rgb, s=60, marker="s", edgecolors="k", linewidths=0.3)
            ax.set_title(f"{m}, n = {n:g}")
            ax.set_ylim(0, 1.05)
            ax.grid(alpha=0.3)
    for ax in axes[-1]:
        ax.set_xlabel("theta_i [deg]")
    for ax in axes[:, 0]:
        ax.set_ylabel("albedo")
    fig.suptitle("Albedo per wavelength (line colour = wavelength, 400-680 nm): eq. 28 solid, pumped per wavelength "
                 "dashed, colour-keeping pumped dotted;\nsquares: sRGB of the albedo spectrum (bottom to top: eq. 28, "
                 "pumped, colour-keeping)", fontsize=9)
    fig.tight_layout()
    with atomic_path(path) as tmp:  # no half PNG if interrupted
        fig.savefig(tmp, dpi=110, format="png")
    plt.close(fig)
    return path


def show(path, dpi: float = 100.0):
    """A matplotlib figure (pyplot, so notebooks and the gallery display it) holding the PNG at ``path`` pixel for
    pixel; returns the figure.
    """
    import matplotlib.pyplot as plt

    image = plt.imread(os.fspath(path))
    height, width = image.shape[:2]
    fig = plt.figure(figsize=(width / dpi, height / dpi), dpi=dpi)
    fig.figimage(image, resize=False)
    return fig
