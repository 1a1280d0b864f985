"""Shared helpers for the tests (importable: tests/ is on pytest's pythonpath)."""

import numpy as np


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


def phong_albedo_1d(n, mu, stretched=False):
    """Independent albedo of reciprocal (c = (n+2)/(2 pi)) or stretched Phong.

    The azimuth about R in closed form, then a 1-D mpmath quadrature at 30 digits
    (scripts/independent_reference.py, which never imports pumpup).  Returns
    (value, error estimate).
    """
    import independent_reference as ref

    return ref.phong_1d(ref.SPHONG if stretched else ref.PHONG, n, mu)
