"""Shared helpers for the tests (importable: tests/ is on pytest's pythonpath)."""

import math
import pathlib

import numpy as np

#: the repository root
ROOT = pathlib.Path(__file__).resolve().parent.parent
#: the tests' data files (tests/data)
DATA = ROOT / "tests" / "data"


def random_directions(rng, n, below=0.1, grazing=0.05):
    """Unit vectors: mostly upper hemisphere, a fraction below it and a fraction near grazing."""
    v = rng.normal(size=(n, 3))
    v /= np.linalg.norm(v, axis=-1, keepdims=True)
    v[:, 2] = np.abs(v[:, 2])
    k = int(n * below)
    v[:k, 2] *= -1
    g = int(n * grazing)
    mu = 10.0 ** rng.uniform(-8, -2, g)
    phi = rng.uniform(0, 2 * np.pi, g)
    s = np.sqrt(1 - mu**2)
    v[k : k + g] = np.stack([s * np.cos(phi), s * np.sin(phi), mu], axis=-1)
    return v


def direction_pairs(rng, n=10_000):
    """~n pairs: random (some below the horizon, some near grazing), exact mirror pairs,
    pairs at mu = 1e-8 exactly, and grazing pairs with wi nearly opposite wo.

    The special pairs fill rows 0-1100; for n < 1100 they are cut to fit."""
    wi = random_directions(rng, n)
    wo = random_directions(rng, n)[::-1].copy()
    wo[:500] = wi[:500] * np.array([-1, -1, 1])  # mirror pairs: H = N
    for k, sl in enumerate([slice(500, 700), slice(700, 900)]):
        phi = rng.uniform(0, 2 * np.pi, 200)
        w = np.stack([np.cos(phi), np.sin(phi), np.full(200, 1e-8)], axis=-1)
        target = wi if k == 0 else wo
        target[sl] = w[: len(target[sl])]
    phi = rng.uniform(0, 2 * np.pi, 200)
    mu = 10.0 ** rng.uniform(-8, -3, (2, 200))
    s = np.sqrt(1 - mu**2)
    m = len(wi[900:1100])
    wi[900:1100] = np.stack([s[0] * np.cos(phi), s[0] * np.sin(phi), mu[0]], axis=-1)[:m]
    wo[900:1100] = np.stack([-s[1] * np.cos(phi + 1e-6), -s[1] * np.sin(phi + 1e-6), mu[1]], axis=-1)[:m]
    return wi, wo


def polar(theta, phi=0.0):
    """Unit vector at polar angle theta and azimuth phi [rad]."""
    return np.array([math.sin(theta) * math.cos(phi), math.sin(theta) * math.sin(phi), math.cos(theta)])


def at_mu(mu, phi=0.0):
    """The direction with N.w = mu exactly (no round trip through an angle)."""
    s = math.sqrt((1 - mu) * (1 + mu))
    return np.array([s * math.cos(phi), s * math.sin(phi), mu])


def phong_albedo_1d(n, mu, stretched=False):
    """Independent albedo of reciprocal (c = (n+2)/(2 pi)) or stretched Phong.

    The azimuth about R in closed form, then a 1-D mpmath quadrature at 30 digits
    (tests/reference/independent_reference.py, which never imports pumpup).  Returns
    (value, error estimate).
    """
    from reference import independent_reference as ref

    return ref.phong_1d(ref.SPHONG if stretched else ref.PHONG, n, mu)


def nested_reference(f, mu, rtol=1e-12):
    """(value, error) of ``f`` by the nested engine at ``rtol`` (the 1-D path switched off alone; asserted to have run
    when ``f`` is one term, as the nested engine records its evaluations then)."""
    import warnings

    import pumpup
    from pumpup.engine import nested as _nested

    _nested.LAST_EVALS = None
    with without_1d(), warnings.catch_warnings():
        warnings.simplefilter("ignore")
        out = pumpup.albedo(f, np.asarray(mu, dtype=float), return_error=True, rtol=rtol)
    assert len(f.albedo_terms()) > 1 or _nested.LAST_EVALS is not None
    return out


def one_d_against_the_other_engines(f, mu, rtols=(1e-6, 1e-10), two_d_at=(0, 5, 7), whole=False, ref_rtol=1e-12):
    """The 1-D path (pumpup.engine.polar) against the nested engine at rtol ``ref_rtol`` (the 1-D path switched off
    alone) and, at mu[two_d_at] and the last rtol, the 2-D engine: at every rtol the estimate bounds the difference and
    meets the tolerance.  Returns (value, error) at the last rtol.  ``whole``: f is a sum whose terms take the path (not
    asked)."""
    import pumpup

    assert whole or takes_1d(f)
    mu = np.asarray(mu, dtype=float)
    b, eb = nested_reference(f, mu, ref_rtol)
    for rtol in rtols:
        a, e = pumpup.albedo(f, mu, return_error=True, rtol=rtol)
        assert np.all(np.abs(a - b) <= e + eb), (rtol, (np.abs(a - b) / (e + eb)).max())
        assert np.all(e <= rtol * a * 1.0001 + 1e-14)
    if len(two_d_at):
        idx = list(two_d_at)
        with two_d_only():
            c, ec = pumpup.albedo(f, mu[idx], return_error=True, rtol=rtols[-1])
        assert np.all(np.abs(a[idx] - c) <= e[idx] + ec)
    return a, e


def n_frame_integrand_against_eval(f, base):
    """Frame 6's compiled integrand of ``f`` (pumpup.engine.normal_frame.n_integrand: the rule's own arithmetic) against
    ``f``'s public ``eval`` times N.wo integrated over the azimuth by scipy (n_integrand_reference), to 1e-10, at mu =
    0.9, 0.4, 0.05 and elevations on both sides of mu; returns the smallest ratio of f's integrand to ``base``'s (a
    pumped or scaled model against its base)."""
    from pumpup.engine import normal_frame as _normal_frame

    low = math.inf
    for mu in (0.9, 0.4, 0.05):
        xmu = math.asin(mu)
        xs = np.array([0.02, 0.3, xmu - 0.05, xmu + 0.04, 1.2, 1.5])
        xs = xs[(xs > 0.0) & (xs < 0.5 * math.pi)]
        got = _normal_frame.n_integrand(f, mu, xs)
        ref = _normal_frame.n_integrand_reference(f, mu, xs)
        assert np.all(np.abs(got - ref) <= 1e-10 * np.abs(ref)), (mu, xs, got / ref - 1)
        low = min(low, float(np.min(got / _normal_frame.n_integrand(base, mu, xs))))
    return low


#: the Gauss-Legendre rule of :func:`rings` in the azimuth
_RINGS_GL = np.polynomial.legendre.leggauss(200)


def rings(f, mu, ring_cuts, mu_points):
    """integral of f(wi, wo) cos(theta_o) d omega_o, wi = (sqrt(1 - mu^2), 0, mu): quad over mu_o on
    the intervals between ``mu_points``, Gauss-Legendre (200 nodes) in phi_o on [0, pi] (the integrand is
    even in phi_o) between the cuts ``ring_cuts(mu_o)``.  An independent reference (it evaluates the BRDF's numpy
    ``reference`` only, never the engine) for the tests of the engines' breaks (tests/engine/test_cubature.py) and of
    the models and operators whose lobes carry tables in N.wo."""
    from scipy.integrate import quad

    s = math.sqrt((1.0 - mu) * (1.0 + mu))
    wi = np.array([s, 0.0, mu])
    xg, wg = _RINGS_GL

    def ring(mo):
        so = math.sqrt((1.0 - mo) * (1.0 + mo))
        cuts = ring_cuts(mo, so)
        total = 0.0
        for a, b in zip(cuts[:-1], cuts[1:]):
            ph = a + 0.5 * (b - a) * (xg + 1.0)
            wo = np.stack([so * np.cos(ph), so * np.sin(ph), np.full_like(ph, mo)], axis=-1)
            total += 0.5 * (b - a) * float(np.sum(wg * f.reference(wi, wo)))
        return 2.0 * total * mo

    pts = np.unique(np.concatenate([[0.0, 1.0], np.asarray(mu_points, float)]))
    pts = pts[(pts >= 0) & (pts <= 1)]
    return sum(quad(ring, a, b, epsabs=1e-16, epsrel=1e-13, limit=200)[0] for a, b in zip(pts[:-1], pts[1:]))


def load_script(path: str):
    """The module of a script of the repository's ``scripts/`` folder (``"make/compensation_study.py"``), imported
    from its file, for a test that runs one of its functions (scripts are programs, not a package)."""
    import importlib.util
    import os
    import sys

    full = str(ROOT / "scripts" / path)
    name = "script_" + os.path.splitext(os.path.basename(path))[0]
    if name in sys.modules:
        return sys.modules[name]
    spec = importlib.util.spec_from_file_location(name, full)
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    spec.loader.exec_module(module)
    return module


def default_sigint():
    """For ``subprocess.Popen(preexec_fn=...)``: SIGINT's default action in the child before exec, which Python turns
    into KeyboardInterrupt.  A test run started in the background of a shell inherits SIGINT ignored, and Python then
    keeps ignoring it."""
    import signal

    signal.signal(signal.SIGINT, signal.SIG_DFL)


# --- the engine's routes, for the tests ------------------------------------------------------------------------------

#: the values of mu at which a hint's routes are asked when a test does not say (as the routing table's mu ranges see
#: them: above and below N_FRESNEL_MU_MIN, grazing, normal)
ROUTE_MU = np.concatenate([np.geomspace(1e-6, 1.0, 61), [0.2, 0.3, 0.5, 0.9]])


def view(f):
    """``f``'s azimuth hint as the kernels read it (:func:`pumpup.engine.hint_view.kernel_view`), or None."""
    from pumpup.engine.hint_view import kernel_view

    hint = f.azimuth_hint()
    return None if hint is None else kernel_view(hint)


def hint_routes(f, mu=None) -> set:
    """The 1-D routes the routing table gives ``f``'s own hint (``f`` a BRDF or an AzimuthHint) at ``mu``."""
    from pumpup.core.hints import AzimuthHint
    from pumpup.engine.routes import hint_routes as routes

    hint = f if isinstance(f, AzimuthHint) else f.azimuth_hint()
    mu = ROUTE_MU if mu is None else np.asarray(mu, dtype=float).reshape(-1)
    return {route for route, _ in routes(hint, mu)} if hint is not None else set()


def one_d_mask(f, mu) -> np.ndarray:
    """The values of ``mu`` the 1-D routes of ``f``'s own hint take."""
    from pumpup.engine.routes import hint_routes as routes

    mu = np.asarray(mu, dtype=float).reshape(-1)
    out = np.zeros(mu.shape, bool)
    hint = f.azimuth_hint()
    for _, m in routes(hint, mu) if hint is not None else ():
        out |= m
    return out


def takes_1d(f, mu=None) -> bool:
    """Whether the 1-D routes of ``f``'s own hint take it at every mu (default :data:`ROUTE_MU`)."""
    return bool(one_d_mask(f, ROUTE_MU if mu is None else mu).all())


def two_d_only():
    """The 2-D cubature alone (the reference)."""
    from pumpup.engine.routes import using

    return using(engine="2d")


def without_1d():
    """No 1-D route: the nested quadrature where it applies, else the 2-D cubature."""
    from pumpup.engine.routes import using

    return using(engine="nested")


def without_normal_frames():
    """Every route but the frames of N (``normal``, ``lobe_normal``): GGX, Beckmann and Schlick then take the rule on
    h's arc (``half_arc``), a lobe with F(max) the lobe frame (``lobe_fresnel``), a pumped or scaled one of them the
    nested quadrature: the tests' second 1-D route for them."""
    from pumpup.engine.routes import using

    return using(without={"normal", "lobe_normal"})


def without_nested():
    """Every route but the nested quadrature (the 2-D cubature takes its values)."""
    from pumpup.engine.routes import using

    return using(without={"nested"})


def takes_normal(f) -> bool:
    """Whether the routing table gives ``f`` (a BRDF or a hint) the frame of N, ``normal``, at some mu."""
    return "normal" in hint_routes(f)


def takes_lobe_normal(f) -> bool:
    """Whether the routing table gives ``f`` (a BRDF or a hint) the lobe's frame of N, ``lobe_normal``, at some mu."""
    return "lobe_normal" in hint_routes(f)


class BareLobe:
    """A bare lobe c u^n / max(mu, N.wo)^p with c = (n + 2) / (2 pi), as the mpmath reference has it: only the
    azimuth hint the 1-D engine reads.
    """

    def __init__(self, n, p):
        self.n, self.p = n, p

    def azimuth_hint(self):
        from pumpup.core.hints import AzimuthHint, PowerLobe

        c = (self.n + 2) / (2 * math.pi)
        return AzimuthHint(PowerLobe(n=self.n, p=self.p), scale=lambda mu: np.full(np.shape(mu), c))
