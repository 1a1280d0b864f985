"""Regenerate the exact sphere images committed under figures/ (pumpup.render; no renderer).

    python scripts/make/make_images.py [--size 160] [--out figures] [--only lewis_fig3 ... furnace]

Writes labelled grids (PNG, tone map stated on each) and prints, for every grid, the numbers
the README quotes (peak radiance per row and light angle; furnace rim and maximum with the
table's error bound).  About 3-6 minutes on 2 cores: the pumped models tabulate their albedo.

Lewis's shaders (002 Figs. 3, 6, 10) are rendered in his units: a directional light of
irradiance E = pi, kd = (1 - k_s) / pi and ks = k_s / pi in pumpup's BRDF parameters, so the
radiance is his eq. 4 with L_d = 1: (1 - k_s)(N.S) + k_s F_s (Fig. 3), and the lobe width is
his half-angle beta, n = -ln 2 / ln cos(beta).  His Figs. 3 and 6 use Blinn's F_s^B; pumpup's
``phong_shader`` and ``lewis_phong`` have Phong's F_s^P (002 eq. 5), so those two grids are
his configuration with Phong's lobe.  Fig. 10 (``phong_blinn``, 002 eq. 24) is his shader.
"""

from __future__ import annotations

import argparse
import math
import os
import sys
import time
import warnings

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))  # this checkout's pumpup

import pumpup  # noqa: E402
import pumpup.render as R  # noqa: E402

LIGHTS = [0.0, 30.0, 60.0, 80.0]
GRAZING = [0.0, 60.0, 110.0, 130.0, 150.0]  # past 90 the light is behind the sphere: grazing highlights
N_PUMP = 20  # exponent of 001 Figs. 3-6


def _lewis_rows(make, ks_values, betas):
    rows, labels = [], []
    for beta in betas:
        n = R.lewis_exponent(beta)
        for ks in ks_values:
            rows.append(make(n, ks))
            labels.append(f"beta={beta:g} deg (n={n:.3g})\nk={ks:g}")
    return rows, labels


def _row_of_lights(spec, lights, size, irradiance):
    return [R.sphere(spec, phi, size, irradiance=irradiance) for phi in lights]


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
    return R.grid_figure(ims, os.path.join(out, "render_lewis_fig3.png"), row_labels=labels,
                         col_labels=[f"Phi_L = {v:g} deg" for v in LIGHTS],
                         title="Phong's shader (002 eq. 8, F_s^P): (1 - k_s)(N.S) + k_s (R.V)^n, L_d = 1")


def lewis_fig6(size, out):
    """002 Fig. 6 configuration, the energy-conserving Phong shader (002 eq. 22), k_rho = 1."""
    rows, labels = _lewis_rows(lambda n, ks: {"type": "lewis_phong", "n": n, "k_rho": 1.0, "k_sigma": ks},
                               [0.25, 0.75], [10.0, 30.0])
    labels = [lab.replace("k=", "k_sigma=") for lab in labels]
    ims = [_row_of_lights(s, LIGHTS, size, math.pi) for s in rows]
    _print_peaks("lewis_fig6 (lewis_phong)", ims, labels, LIGHTS)
    return R.grid_figure(ims, os.path.join(out, "render_lewis_fig6.png"), row_labels=labels,
                         col_labels=[f"Phi_L = {v:g} deg" for v in LIGHTS],
                         title="energy-conserving Phong (002 eq. 22, F_s^P, k_rho = 1), L_d = 1")


def lewis_fig10(size, out):
    """002 Fig. 10: the reciprocal Phong-Blinn shader (002 eq. 24), k_d = 1 - k_s."""
    rows, labels = _lewis_rows(lambda n, ks: {"type": "phong_blinn", "n": n, "ks": ks / math.pi,
                                              "kd": (1 - ks) / math.pi}, [0.25, 0.75], [10.0, 30.0])
    labels = [lab.replace("k=", "k_s=") for lab in labels]
    ims = [_row_of_lights(s, LIGHTS, size, math.pi) for s in rows]
    _print_peaks("lewis_fig10 (phong_blinn)", ims, labels, LIGHTS)
    return R.grid_figure(ims, os.path.join(out, "render_lewis_fig10.png"), row_labels=labels,
                         col_labels=[f"Phi_L = {v:g} deg" for v in LIGHTS],
                         title="reciprocal Phong-Blinn (002 eq. 24): [(1 - k_s) + k_s (N.H)^n] (N.S), L_d = 1")


def lobes(size, out):
    """Phong, stretched Phong and once-pumped Phong at Lewis's half-angles beta = 10 and 30 degrees, each row lit
    so that its peak at Phi_L = 0 is 1 (Lewis's normalisation of his Fig. 4)."""
    specs, labels = [], []
    for beta in (10.0, 30.0):
        n = R.lewis_exponent(beta)
        base = {"type": "phong", "n": n}
        for s in (base, {"type": "stretched_phong", "n": n}, pumpup.pump(base, g="g1").spec):
            specs.append(s)
            labels.append(f"{R.label(s).replace(f'n={n:.4g}', 'n=' + format(n, '.3g'))}\nbeta={beta:g} deg")
    ims = []
    for s in specs:
        e = 1.0 / float(R.sphere(s, 0.0, size).radiance.max())
        ims.append(_row_of_lights(s, LIGHTS, size, e))
    _print_peaks("lobes (peak at Phi_L = 0 scaled to 1)", ims, labels, LIGHTS)
    return R.grid_figure(ims, os.path.join(out, "render_lobes.png"), row_labels=labels,
                         col_labels=[f"Phi_L = {v:g} deg" for v in LIGHTS],
                         title="Phong, stretched Phong (000 eq. 7), pumped Phong (001 eq. 20); light scaled per row")


def _blinn_spec():
    c, _ = pumpup.max_constant(pumpup.load({"type": "blinn", "n": N_PUMP}))
    return {"type": "blinn", "n": N_PUMP, "c": c}


def phong_stretched_pumped(size, out):
    """Reciprocal Phong n = 20, stretched Phong (000 eq. 7) and Phong pumped 1-3 times (001 sec. 3)."""
    base = {"type": "phong", "n": N_PUMP}
    specs = [base, {"type": "stretched_phong", "n": N_PUMP}] + [pumpup.pump(base, g="g1", levels=k).spec
                                                                   for k in (1, 2, 3)]
    labels = [R.label(s) for s in specs]
    ims = [_row_of_lights(s, GRAZING, size, 1.0) for s in specs]
    _print_peaks("phong_pumped", ims, labels, GRAZING)
    return R.grid_figure(ims, os.path.join(out, "render_phong_pumped.png"), row_labels=labels,
                         col_labels=[f"Phi_L = {v:g} deg" for v in GRAZING], exposure=-2.0,
                         title="Phong n = 20: original, stretched (000 eq. 7), pumped with g1 (= g2 for Phong)")


def blinn_pumped(size, out):
    """Blinn n = 20 at its maximum constant, pumped 1-3 times with g1 and with g2 (001 Figs. 4, 6)."""
    base = _blinn_spec()
    specs = [base] + [pumpup.pump(base, g=g, levels=k).spec for g in ("g1", "g2") for k in (1, 2, 3)]
    labels = [R.label(s) for s in specs]
    ims = [_row_of_lights(s, GRAZING, size, 1.0) for s in specs]
    _print_peaks("blinn_pumped", ims, labels, GRAZING)
    return R.grid_figure(ims, os.path.join(out, "render_blinn_pumped.png"), row_labels=labels,
                         col_labels=[f"Phi_L = {v:g} deg" for v in GRAZING], exposure=-1.0,
                         title=f"Blinn n = 20, c = {base['c']:.4f} (its maximum constant): g1 and g2 pumping")


def furnace(size, out):
    """White furnace: Phong and its pumped levels, Blinn with g1 and g2, and other models."""
    phong = {"type": "phong", "n": N_PUMP}
    blinn = _blinn_spec()
    rows = [
        [phong] + [pumpup.pump(phong, g="g1", levels=k).spec for k in (1, 2, 3)]
        + [{"type": "stretched_phong", "n": N_PUMP}],
        [blinn] + [pumpup.pump(blinn, g=g, levels=k).spec for g in ("g1", "g2") for k in (1, 3)],
        [{"type": "lambert", "albedo": 0.8}, {"type": "ggx", "alpha": 0.3}, {"type": "cook_torrance", "m": 0.3},
         {"type": "phong_shader", "n": N_PUMP}, {"type": "stretched_phong", "n": 5000}],
        # energy compensation (pumpup.compensate): Kulla-Conty's added lobe and the 1/E(wo) scaling
        [pumpup.compensate(pumpup.load(b), method=m) for b in (phong, {"type": "ggx", "alpha": 0.3})
         for m in ("kulla_conty", "scale")],
    ]
    ims = [[R.furnace(s, size) for s in row] for row in rows]
    print("furnace: a(mu_V) at the rim pixel / centre / maximum, error bound")
    for row in ims:
        for im in row:
            v = im.radiance[im.mask]
            c = im.radiance[size // 2, size // 2]
            note = "  (integrated over wi: not reciprocal)" if im.params["transposed"] else ""
            print(f"  {R.label(im.spec):40s} {float(v.min()):.4f} / {float(c):.6f} / {float(v.max()):.6f}"
                  f"  bound {im.error:.2g}{note}")

    def text(im):
        v = im.radiance[im.mask]
        return f"{R.label(im.spec)}\nrim {float(v.min()):.3f}, max {float(v.max()):.4f}"

    return R.grid_figure(ims, os.path.join(out, "render_furnace.png"), tile_text=text, tile_inches=1.9,
                         row_labels=["Phong n=20", "Blinn n=20", "others", "compensated"],
                         title="white furnace (sky radiance 1): pixel = albedo a(mu_V)")


MAKERS = {"lewis_fig3": lewis_fig3, "lewis_fig6": lewis_fig6, "lewis_fig10": lewis_fig10,
          "lobes": lobes, "phong_pumped": phong_stretched_pumped, "blinn_pumped": blinn_pumped, "furnace": furnace}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--size", type=int, default=160)
    ap.add_argument("--out", default="figures")
    ap.add_argument("--only", nargs="+", choices=sorted(MAKERS))
    args = ap.parse_args(argv)
    R.check_size(args.size)
    os.makedirs(args.out, exist_ok=True)
    warnings.simplefilter("error", pumpup.albedo_module.AlbedoWarning)  # an unconverged table is a failure here
    for name in args.only or MAKERS:
        t = time.perf_counter()
        path = MAKERS[name](args.size, args.out)
        print(f"wrote {path} in {time.perf_counter() - t:.1f} s", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
