"""The numbers printed in the source papers, as data with their source.

Values are kept as the printed strings, so that the number of printed digits is part of
the data: a computed value *agrees* when it rounds to the printed string (same number of
decimals; for values printed in scientific notation, the same significant digits).  Exact
claims (the n -> infinity row of Table 3, the fractions of 000 eq. 26) must match to 1e-6.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

__all__ = ["Published", "TABLE2", "TABLE3", "TABLE4", "TEXT", "agrees"]

POWERS = [1, 2, 4, 8, 16, 32, 64, 128, 256, 512]


@dataclass(frozen=True)
class Published:
    """One printed number: where it is, what it is, and how it was printed."""

    source: str  #: paper and place, e.g. "000 Table 2"
    row: str  #: row label as printed
    column: str  #: column label
    text: str  #: the number exactly as printed ("2/3" for an exact fraction)
    exact: bool = False  #: an exact claim (a limit, a closed form), not a rounded number

    @property
    def value(self) -> float:
        """The printed number as a float (a fraction such as "2/3" divided out)."""
        if "/" in self.text:
            num, den = self.text.split("/")
            return float(num) / float(den)
        return float(self.text)


def agrees(computed: float, published: Published, error: float = 0.0) -> bool:
    """Whether ``computed`` (with its error estimate ``error``) matches the printed value to the printed rounding:
    whether some value within ``error`` of it rounds to the printed string, half a unit of the last printed digit
    either way (the ends included: 000 printed Phong n = 4's exact 0.6875 as 0.688, and a computed 0.6875 - 1e-16
    rounds the other way).

    "0.350" has 3 decimals; "20.6" has 1; "7.8e-3" has 2 significant digits.
    """
    text = published.text
    if published.exact:  # a limit or a closed form: the computed value must be that number
        return math.isclose(computed, published.value, rel_tol=1e-6)
    scale, mant = 1.0, text
    if "e" in text.lower():
        mant, exp = text.lower().split("e")
        scale = 10.0 ** int(exp)
    decimals = len(mant.split(".")[1]) if "." in mant else 0
    half = 0.5 * 10.0 ** -decimals * scale
    return abs(computed - float(mant) * scale) <= half * (1.0 + 1e-12) + abs(error)


# 000 Table 2: the maximum C_n constants of Blinn and of stretched Blinn (Blinn / cos(theta_min))
_T2_BLINN = ["0.350", "0.382", "0.449", "0.592", "0.895", "1.52", "2.79", "5.34", "10.4", "20.6"]
_T2_STRETCHED = ["0.293", "0.368", "0.449", "0.592", "0.895", "1.52", "2.79", "5.34", "10.4", "20.6"]
TABLE2 = [Published("000 Table 2", str(n), "blinn", v) for n, v in zip(POWERS, _T2_BLINN)] + [
    Published("000 Table 2", str(n), "stretched_blinn", v) for n, v in zip(POWERS, _T2_STRETCHED)
]

# 000 Table 3: mean albedo (000 eq. 33); the last row is n -> infinity
_T3 = {
    "phong": ["0.737", "0.708", "0.688", "0.676", "0.670", "0.668", "0.667", "0.667", "0.667", "0.667", "0.5"],
    "stretched_phong": ["0.934", "0.902", "0.887", "0.888", "0.901", "0.919", "0.937", "0.953", "0.966", "0.975", "1"],
    "blinn": ["0.879", "0.800", "0.706", "0.620", "0.562", "0.531", "0.516", "0.508", "0.504", "0.502", "0.5"],
    "stretched_blinn": ["0.941", "0.952", "0.863", "0.748", "0.679", "0.648", "0.639", "0.640", "0.644", "0.649", "1"],
}
TABLE3 = [
    Published("000 Table 3", str(n), col, v, exact=(n == "inf"))  # the last row is a limit: exact
    for col, vals in _T3.items()
    for n, v in zip(POWERS + ["inf"], vals)
]

# 000 Table 4: the maximum C_max of modified Ward
TABLE4 = [
    Published("000 Table 4", m, "modified_ward", v)
    for m, v in [("0.4", "1.63"), ("0.2", "1.16"), ("0.1", "1.04"), ("0.05", "1.011"), ("0.02", "1.005"),
                 ("0.01", "1.002"), ("0.005", "1.002")]
]

# numbers stated in the text
TEXT = [
    # 000 sec. 6.2: the C_max that makes Schlick's model (000 eq. 36) plausible
    Published("000 sec. 6.2", "r = 0.5", "schlick C_max", "2.14"),
    Published("000 sec. 6.2", "r = 0.1", "schlick C_max", "0.72"),
    Published("000 sec. 6.2", "r = 0.01", "schlick C_max", "0.21"),
    Published("000 sec. 6.2", "r = 0.001", "schlick C_max", "0.042"),
    # 000 sec. 2.2: stretched Phong n = 1 with c = (n+2)/(2 pi) overshoots by 0.0003 at 13 degrees
    Published("000 sec. 2.2", "n = 1", "stretched_phong overshoot", "0.0003"),
    Published("000 sec. 2.2", "n = 1", "stretched_phong overshoot angle [deg]", "13"),
    # 000 eq. 26: grazing albedo of stretched Phong, (n + 2) / (2 (n + 1))
    Published("000 eq. 26", "n = 1", "stretched_phong a(90 deg)", "3/4", exact=True),
    Published("000 eq. 26", "n = 2", "stretched_phong a(90 deg)", "2/3", exact=True),
    # 000 sec. 6.2: Ward m = 0.1 near grazing
    Published("000 sec. 6.2", "89.995", "ward m=0.1 a(theta)", "1.2"),
    Published("000 sec. 6.2", "89.999", "ward m=0.1 a(theta)", "2.6"),
    Published("000 sec. 6.2", "89.9995", "ward m=0.1 a(theta)", "3.8"),
    # 000 sec. 6.1.1: Blinn n = 128 at 90 degrees, with the Table 2 constant
    Published("000 sec. 6.1.1", "n = 128", "blinn a(90 deg)", "7.8e-3"),
    Published("000 sec. 6.1.1", "n = 128", "stretched_blinn a(90 deg)", "3.7e-2"),
    # 000 sec. 6.1.1: mean albedo of Blinn n = 128 before and after stretching
    Published("000 sec. 6.1.1", "n = 128", "blinn mean albedo", "0.508"),
    Published("000 sec. 6.1.1", "n = 128", "stretched_blinn mean albedo", "0.640"),
]
