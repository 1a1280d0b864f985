"""The BRDF interface, the model registry, specs, user functions and the reciprocity check.

Conventions (every model in pumpup follows them)
------------------------------------------------------------
* Local shading frame: the surface normal is N = (0, 0, 1).  Directions are unit
  3-vectors on the last axis of an array; every function broadcasts over the
  leading axes.
* ``wi`` points from the surface towards the light (the papers' L, Lewis's S);
  ``wo`` points towards the viewer (V).
* ``BRDF.eval(wi, wo)`` returns f_r in 1/sr **without** the cosine factor (pbrt's
  convention).  It is 0 where either direction is at or below the horizon.
* ``mu`` is cos(theta_i).  Directional albedo
  a(mu) = integral over the hemisphere of f_r(wi, wo) cos(theta_o) d omega_o
  (000 eq. 2; 002 eq. 15).

This module is over 1,000 lines because ``BRDF``, ``Param`` and the registry are one unit: ``load`` builds a BRDF
from its type's ``Param`` declarations and ``BRDF.spec`` gives back the dict ``load`` reads.
"""

from __future__ import annotations

import json
import math
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING, Any, ClassVar

import numpy as np

if TYPE_CHECKING:
    from numpy.typing import ArrayLike

    from .hints import AzimuthHint

__all__ = [
    "BRDF",
    "Lobe",
    "Param",
    "register",
    "registry",
    "load",
    "from_function",
    "check_reciprocity",
    "ReciprocityResult",
    "SpecError",
    "parse_spec",
    "is_spectral_spec",
    "check_tolerance",
    "check_count",
    "check_open_unit",
]

#: Largest deviation of |w| from 1 that ``eval`` accepts for a direction.
UNIT_TOL = 1e-6

#: The range of a lobe's width parameter (an RMS slope m, a roughness alpha) and the largest lobe
#: exponent n where the albedo engine is accurate (issue 13 item 4).  The lobe's angular width is
#: about m, alpha or 1 / sqrt(n) rad; directions carry rounding errors of ~1e-16, so a lobe 1e-6 wide
#: is resolved to ~1e-10 relative (ggx alpha = 1e-20 gave 5551 +- 5e-7 at mu = 0.5, beckmann 1e-18
#: 30.8, phong n = 1e50 8.0 +- 2.8e36; at these ends the values are right: tests/core/test_param_ranges.py).
#: Beyond MAX_WIDTH a microfacet lobe is not a surface any more (and the engine slows: minutes for
#: pumped ward_aniso with ax = 1e6).  Models refuse values outside with a SpecError.
MIN_WIDTH = 1e-6
#: the microfacet roughness alpha of ggx and beckmann goes lower, to 1e-8: renderers clamp roughness at 1e-4
#: and square it (Blender Cycles' albedo tables, pumpup.luts), and there the engine agrees with the mirror
#: limit with Smith shadowing, E = G(wi, mirror) (1 - E = O(alpha^2 tan^2)), within its error for mu >= 1e-6
#: (tests/core/test_param_ranges.py)
MIN_ALPHA = 1e-8
MAX_WIDTH = 1e3
MAX_EXPONENT = 1e6
#: refractive indices (the real part eta, a dielectric's ior) and extinction coefficients k are taken
#: in [MIN_INDEX, MAX_INDEX] (k in [0, MAX_INDEX]): real materials lie well inside, and a subnormal eta
#: divided by zero in the Fresnel kernels
MIN_INDEX = 1e-3
MAX_INDEX = 1e3


class SpecError(ValueError):
    """A model spec or parameter is invalid; the message names the parameter and its range."""


# ----------------------------------------------------------------------------------------
# Parameters
# ----------------------------------------------------------------------------------------

REQUIRED = object()


@dataclass(frozen=True)
class Param:
    """Declaration of one model parameter: default and allowed range.

    ``default`` may be a value, ``REQUIRED``, or a callable of the other (already
    resolved) parameters, e.g. ``lambda p: (p["n"] + 2) / (2 * pi)``.
    ``lo``/``hi`` bound the value; ``lo_open``/``hi_open`` make the bound strict.
    ``kind`` is "float", "int", "str", "floats" (a list of floats) or "spec".
    """

    default: Any = REQUIRED
    lo: float = -math.inf
    hi: float = math.inf
    lo_open: bool = False
    hi_open: bool = False
    kind: str = "float"
    choices: tuple = ()
    doc: str = ""

    def range_text(self) -> str:
        """The allowed range as text: ``[lo, hi]`` with an open or infinite end in parentheses, or ``one of ...`` for
        choices.
        """
        if self.choices:
            return "one of " + ", ".join(repr(c) for c in self.choices)
        left = "(" if self.lo_open else "["
        right = ")" if self.hi_open else "]"
        lo = "-inf" if self.lo == -math.inf else f"{self.lo:g}"
        hi = "inf" if self.hi == math.inf else f"{self.hi:g}"
        if self.lo == -math.inf:
            left = "("
        if self.hi == math.inf:
            right = ")"
        return f"{left}{lo}, {hi}{right}"

    def check_number(self, model: str, name: str, value: Any) -> float:
        """``value`` as a float inside the range; otherwise a SpecError naming ``model`` and ``name`` (not a number,
        beyond the float range, not finite, or out of range).
        """
        if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
            raise SpecError(f"{model}: parameter {name!r} must be a number in {self.range_text()}, got {value!r}")
        try:
            v = float(value)
        except OverflowError:  # a Python int beyond the float range (c = 10**400)
            raise SpecError(f"{model}: parameter {name!r} is too large for a float (about {len(str(abs(value)))} "
                            f"digits); allowed range {self.range_text()}") from None
        if not math.isfinite(v):
            raise SpecError(f"{model}: parameter {name!r} must be finite, in {self.range_text()}; got {value!r}")
        bad_lo = v <= self.lo if self.lo_open else v < self.lo
        bad_hi = v >= self.hi if self.hi_open else v > self.hi
        if bad_lo or bad_hi:
            raise SpecError(f"{model}: parameter {name!r} = {v:g} is outside its allowed range {self.range_text()}")
        return v

    def check(self, model: str, name: str, value: Any) -> Any:
        """``value`` checked and converted for the parameter's ``kind`` (float, int, bool, str, floats, or spec, which
        is loaded); otherwise a SpecError naming ``model`` and ``name``.
        """
        if self.kind == "float":
            return self.check_number(model, name, value)
        if self.kind == "int":
            v = self.check_number(model, name, value)
            if v != int(v):
                raise SpecError(f"{model}: parameter {name!r} must be an integer in {self.range_text()}, got {value!r}")
            return int(v)
        if self.kind == "bool":
            if not isinstance(value, (bool, np.bool_)):
                raise SpecError(f"{model}: parameter {name!r} must be true or false, got {value!r}")
            return bool(value)
        if self.kind == "str":
            if not isinstance(value, str) or (self.choices and value not in self.choices):
                raise SpecError(f"{model}: parameter {name!r} must be {self.range_text()}, got {value!r}")
            return value
        if self.kind == "floats":
            if isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, bool):
                value = [value]
            if not isinstance(value, (list, tuple, np.ndarray)) or len(value) == 0:
                raise SpecError(f"{model}: parameter {name!r} must be a non-empty list of numbers in "
                                f"{self.range_text()}, got {value!r}")
            return [self.check_number(model, f"{name}[{i}]", v) for i, v in enumerate(value)]
        if self.kind == "spec":
            if isinstance(value, BRDF):
                return value
            if not isinstance(value, dict):
                raise SpecError(f"{model}: parameter {name!r} must be a model spec (a dict with a 'type'), got "
                                f"{value!r}")
            f = load(value)
            if getattr(f, "is_spectral", False):  # pumped / kulla_conty / scaled over one are spectral themselves
                raise SpecError(f"{model}: parameter {name!r} must be a single-channel model; a spectral spec (a "
                                "'material', 'wavelengths' or per-wavelength lists) is not supported here")
            return f
        raise AssertionError(self.kind)


# ----------------------------------------------------------------------------------------
# Quadrature hints
# ----------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Lobe:
    """A quadrature hint: where a BRDF's lobe is and how sharp it is (see ``pumpup.albedo``).

    The albedo engine integrates over directions d = A cos(alpha) + sin(alpha) (e1 cos(beta)
    + e2 sin(beta)) around an axis A, with the polar angle alpha reached through a radial
    map x -> alpha that absorbs the lobe's peak, so the integrand is smooth in x.

    Parameters
    ----------
    axis : {"normal", "mirror", "retro", "half"}
        A = N; A = R, the mirror direction of wi (000 eq. 8); A = wi; or d is the half
        vector h around N and wo = 2 (wi.h) h - wi, with d omega_o = 4 (wo.h) d omega_h.
    radial : {"cosine", "power", "beckmann", "ggx", "gaussian"}
        "cosine": sin^2(alpha) = x (exact for a Lambertian integrand around N).
        "power": cos(alpha) = x^(1/(n+1)) for a cos^n lobe (000 eq. 20).
        "beckmann": tan^2(alpha) = -m^2 ln x for exp(-tan^2/m^2).
        "ggx": tan^2(alpha) = r x / (1 - x) for r / (1 - (1 - r) cos^2)^2 (000 eq. 36).
        "gaussian": alpha = sqrt(-ln x) / c for exp(-(c alpha)^2) (002 D2).
    sharpness : float
        n, m, r or c of the radial map.
    levels : tuple of float
        Values u of N.wo = wo_z where the integrand has a kink (max(N.L, N.V) gives u = mu).
    kinks : callable or None
        ``kinks(mu, s, cos_a, sin_a) -> list of (a, b)``: further kinks where
        a + b cos(beta) = 0 (e.g. the Cook-Torrance geometry factor).
    symmetric : bool
        The integrand is even in beta (true for isotropic models and for anisotropy
        aligned with the x and y axes), so only beta in [0, pi] is integrated.
    """

    axis: str = "normal"
    radial: str = "cosine"
    sharpness: float = 0.0
    levels: tuple = ()
    kinks: Callable | None = None
    symmetric: bool = True
    # terms of the same lobe family added linearly are handled by BRDF.albedo_terms

    @property
    def generic(self) -> bool:
        """Whether this is the hint of a model without one (:meth:`BRDF.lobe`'s default: about the normal, the cosine
        map, not symmetric), which the 2-D engine's generic path integrates without trusting it.
        """
        return self.axis == "normal" and self.radial == "cosine" and not self.symmetric

    def with_levels(self, *more) -> Lobe:
        """The same hint with the levels of each iterable in ``more`` added (a factor of N.wo that the model multiplies
        its base by: a pumped level's g, a scaled model's 1 / U, a Fresnel factor's F(Theta_min)).
        """
        return replace(self, levels=tuple(sorted(set(self.levels).union(*more))))


# ----------------------------------------------------------------------------------------
# The BRDF base class and the registry
# ----------------------------------------------------------------------------------------

_REGISTRY: dict[str, type[BRDF]] = {}


def register(name: str) -> Callable[[type[BRDF]], type[BRDF]]:
    """Class decorator: make a BRDF class loadable as ``{"type": name, ...}``."""

    def deco(cls):
        if name in _REGISTRY:
            raise ValueError(f"model type {name!r} is registered twice")
        cls.type = name
        _REGISTRY[name] = cls
        return cls

    return deco


def registry() -> dict[str, type[BRDF]]:
    """The registered model types, name -> class (a copy), in registration order."""
    _ensure_models()
    return dict(_REGISTRY)


#: modules that register types (``@register``), loaders (:func:`register_loader`) or services (:func:`provide`) when
#: imported, in the order they are imported on the registry's first use.  The package root names pumpup's own
#: (``pumpup.PROVIDERS``: the operators, the models, the spectral models, the tables); another package adds its own
#: with :func:`add_provider`.
_PROVIDERS: list[str] = []
_PROVIDED = False  # every provider imported (to the end)
#: (applies, load): a spec that ``applies(spec)`` accepts is built by ``load(spec)`` (the spectral models)
_LOADERS: list[tuple[Callable[[Any], bool], Callable[[Any], Any]]] = []


#: what an upper layer offers the models by name: "max_albedo" (``pumpup.tables.max_albedo``, which plastic's energy
#: check calls while it is built); the provider modules register them
_SERVICES: dict[str, Callable[..., Any]] = {}


def provide(name: str, fn: Callable[..., Any]) -> None:
    """Offer ``fn`` to the lower layers as the service ``name`` (see :func:`service`)."""
    _SERVICES[name] = fn


def service(name: str) -> Callable[..., Any]:
    """The function an upper layer registered as ``name`` (:func:`provide`), its providers imported first."""
    _ensure_models()
    if name not in _SERVICES:
        raise LookupError(f"no provider offers the service {name!r}; known: {', '.join(sorted(_SERVICES)) or 'none'}")
    return _SERVICES[name]


def add_provider(module: str) -> None:
    """Have the registry import ``module`` (a dotted name) on its next use, so that its types register themselves."""
    global _PROVIDED
    if module not in _PROVIDERS:
        _PROVIDERS.append(module)
        _PROVIDED = False


def register_loader(applies: Callable[[Any], bool], loader: Callable[[Any], Any]) -> None:
    """Let :func:`load` hand every spec for which ``applies(spec)`` is true to ``loader(spec)``
    (before the registry).
    """
    _LOADERS.append((applies, loader))


def _ensure_models() -> None:
    """Import the provider modules (the package root's ``PROVIDERS`` first): their types register.  An imported one
    costs a look-up in ``sys.modules``; one that another thread is importing is waited for (the import lock), so no
    thread sees a registry half filled.
    """
    global _PROVIDED
    if _PROVIDED:
        return
    import importlib
    import sys

    if not _PROVIDERS:
        for module in importlib.import_module(__name__.rpartition(".")[0]).PROVIDERS:
            add_provider(module)
    for module in tuple(_PROVIDERS):
        importlib.import_module(module)
    # done once every provider has finished importing (not one this thread is still inside of): later loads skip this
    _PROVIDED = not any(getattr(sys.modules[m].__spec__, "_initializing", False) for m in _PROVIDERS)


def slabs(shape: tuple, block: int):
    """Index tuples that cut an array of ``shape`` into pieces of about ``block`` elements or fewer
    along its leading axes (a whole trailing axis longer than ``block`` is cut too): indexing a
    broadcast view with one of them gives a view whose copy costs at most a block.
    """
    if not shape:
        yield ()
        return
    inner = math.prod(shape[1:])
    if inner <= block:
        step = max(1, block // max(inner, 1))
        for a in range(0, shape[0], step):
            yield (slice(a, min(a + step, shape[0])),)
        return
    for a in range(shape[0]):
        for rest in slabs(shape[1:], block):
            yield (a,) + rest


def as_directions(w: Any, name: str) -> np.ndarray:
    """Check that ``w`` holds unit 3-vectors on its last axis; return it as float64.

    The check is one compiled pass (``pumpup.core.checks.first_bad``) with no temporaries, so its memory
    does not grow with the array (the numpy check once allocated 1.5 GB for 1e8 directions).
    """
    a = _as_vectors(w, name)
    check_directions(a, name)
    return a


def _as_vectors(w: Any, name: str) -> np.ndarray:
    """``w`` as a float64 array of 3-vectors on the last axis (no copy when it already is one); its
    values are not looked at (:func:`check_directions` does that).
    """
    try:
        a = np.asarray(w, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{name} must be an array of unit 3-vectors: {exc}") from None
    if a.ndim == 0 or a.shape[-1] != 3:
        raise ValueError(f"{name} must have 3 components on its last axis, got shape {a.shape}")
    return a


def check_directions(a: np.ndarray, name: str) -> None:
    """Raise the ValueError of :func:`as_directions` (naming ``name``) if a row of the float64
    array ``a`` (..., 3) is not finite or not of unit length within ``UNIT_TOL``.
    """
    from .checks import first_bad  # finiteness and unit length in one compiled pass

    lead = a.shape[:-1]
    bad_value, bad_norm = first_bad(a, UNIT_TOL)
    if bad_value >= 0:
        i = np.unravel_index(bad_value, lead) if lead else ()
        raise ValueError(f"{name} contains non-finite values (first at index {tuple(int(k) for k in i)})")
    if bad_norm >= 0:
        i = tuple(int(k) for k in np.unravel_index(bad_norm, lead)) if lead else ()
        norm = float(np.sqrt(np.sum(a[i] * a[i])))
        raise ValueError(f"{name} must be unit vectors (|w| = 1 within {UNIT_TOL:g}); |{name}{list(i)}| = {norm:.9g}")


class BRDF:
    """A bidirectional reflectance distribution function f_r(wi, wo) in 1/sr.

    Subclasses declare ``params`` (name -> :class:`Param`), set ``reciprocal`` and
    implement ``_eval`` (usually a compiled numba kernel, with the plain numpy
    ``reference`` beside it).  They may give the albedo engine a :class:`Lobe` hint.

    Conventions: N = (0, 0, 1); ``wi`` towards the light, ``wo`` towards the viewer;
    f_r excludes the cosine factor and is 0 below the horizon; ``mu`` = cos(theta_i).
    """

    type: ClassVar[str] = "?"
    params: ClassVar[dict[str, Param]] = {}
    reciprocal: ClassVar[bool] = True
    #: name of the scalar constant that multiplies the whole BRDF (for max_constant), or None
    constant: ClassVar[str | None] = "c"
    #: a few specs (without "type") that the common model tests run through every invariant
    examples: ClassVar[list[dict]] = []

    def __init__(self, **kwargs: Any) -> None:
        model = self.type
        unknown = sorted(set(kwargs) - set(self.params))
        if unknown:
            raise SpecError(
                f"{model}: unknown parameter(s) {', '.join(map(repr, unknown))}; "
                f"allowed: {', '.join(self.params) or 'none'}"
            )
        values: dict[str, Any] = {}
        for name, p in self.params.items():
            if name in kwargs and kwargs[name] is not None:
                values[name] = p.check(model, name, kwargs[name])
        for name, p in self.params.items():
            if name in values:
                continue
            if p.default is REQUIRED:
                raise SpecError(f"{model}: missing required parameter {name!r} (allowed range {p.range_text()})")
            if p.default is None:
                values[name] = None
                continue
            d = p.default(values) if callable(p.default) else p.default
            values[name] = p.check(model, name, d)
        self.p = values
        self._validate()

    def _validate(self) -> None:
        """Cross-parameter checks (override); raise SpecError."""

    # --- spec -------------------------------------------------------------------------
    @property
    def spec(self) -> dict:
        """The model as a plain-JSON dict; ``pumpup.load(f.spec)`` rebuilds it exactly."""
        out: dict[str, Any] = {"type": self.type}
        for k, v in self.p.items():
            if v is None:
                continue
            out[k] = v.spec if isinstance(v, BRDF) else v
        return out

    def with_params(self, **changes: Any) -> BRDF:
        """A copy of this model with some parameters changed."""
        s = self.spec
        s.update(changes)
        return load(s)

    def __repr__(self) -> str:
        return f"pumpup.load({json.dumps(self.spec)})"

    def __eq__(self, other: object) -> bool:
        return isinstance(other, BRDF) and self.spec == other.spec

    def __hash__(self) -> int:
        return hash(json.dumps(self.spec, sort_keys=True))

    # --- evaluation -------------------------------------------------------------------
    def eval(self, wi: ArrayLike, wo: ArrayLike) -> np.ndarray:
        """f_r(wi, wo) in 1/sr (no cosine factor), broadcast over the leading axes.

        Parameters
        ----------
        wi, wo : array_like, shape (..., 3)
            Unit vectors towards the light and towards the viewer, N = (0, 0, 1).

        Returns
        -------
        ndarray
            Shape: the broadcast of the leading axes.  0 where wi or wo is at or below
            the horizon.

        Raises
        ------
        ValueError
            One line naming the argument: not 3 components on the last axis, a non-finite
            value, a vector off unit length by more than ``UNIT_TOL``, or shapes that do not
            broadcast (wi's errors first).  A model with a ``rows_kernel`` checks arguments
            of one shape in the same compiled pass as it evaluates them and raises after
            that pass (it costs what a separate check would); others check before.
        """
        a = _as_vectors(wi, "wi")
        try:
            b = _as_vectors(wo, "wo")
        except ValueError:
            check_directions(a, "wi")  # the errors come in the order of the arguments
            raise
        try:
            check_pair(a, b)
        except ValueError:
            check_directions(a, "wi")
            check_directions(b, "wo")
            raise
        rows = self._rows(a, b)
        if rows is None:
            check_directions(a, "wi")
            check_directions(b, "wo")
            return self._eval(a, b)
        # checked while evaluated, in one compiled pass over both arguments (issue 14 item 6)
        from .checks import unit_bounds

        out = np.empty(a.shape[:-1])
        bad_i, bad_o = self.rows_kernel(*rows, out.reshape(-1), True, *unit_bounds(UNIT_TOL), *self.kernel_args())
        if bad_i >= 0:
            check_directions(a, "wi")  # raises the message of as_directions
        if bad_o >= 0:
            check_directions(b, "wo")
        return out

    #: optional: a compiled loop ``(wi, wo, out, check, lo2, hi2, *kernel_args) -> (bad_i, bad_o)``
    #: over the rows of C-contiguous (N, 3) arrays that writes ``kernel``'s values into ``out`` (N,)
    #: and, when ``check``, returns the first row of wi and of wo where ``pumpup.core.checks.off_unit``
    #: holds (-1 where none).  ``eval`` then checks its input in the same pass as it evaluates, and
    #: ``_eval`` uses it without the check, for arguments of one shape (``_rows``).  Used only while
    #: ``_eval`` is BRDF's own: a subclass that overrides ``_eval`` takes the check-then-``_eval`` path.
    rows_kernel: ClassVar[Callable | None] = None

    def _rows(self, wi: np.ndarray, wo: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
        """(wi, wo) as (N, 3) views for ``rows_kernel``, or None to take the broadcasting kernel (no
        rows kernel, shapes that differ, a single vector, an argument that is not a C-contiguous float64
        array).
        """
        if self.rows_kernel is None or not (isinstance(wi, np.ndarray) and isinstance(wo, np.ndarray)):
            return None
        if type(self)._eval is not BRDF._eval:  # a subclass that evaluates otherwise is never bypassed
            return None
        if (wi.ndim < 2 or wi.shape != wo.shape or not (wi.dtype == np.float64 == wo.dtype)
                or not (wi.flags.c_contiguous and wo.flags.c_contiguous)):
            return None
        return wi.reshape(-1, 3), wo.reshape(-1, 3)

    def _eval(self, wi: np.ndarray, wo: np.ndarray) -> np.ndarray:
        """Evaluate without input checks (the albedo engine calls this)."""
        rows = self._rows(wi, wo)
        if rows is not None:
            out = np.empty(wi.shape[:-1])
            self.rows_kernel(*rows, out.reshape(-1), False, 1.0, 1.0, *self.kernel_args())
            return out
        return self.kernel(*split(wi), *split(wo), *self.kernel_args())

    def eval_divided(self, wi: np.ndarray, wo: np.ndarray, chain) -> np.ndarray | None:
        """f_r divided by a pumped chain's g_1 ... g_k (001 eq. 16) in one compiled pass, or None (the default: the
        pumped model then evaluates this model and divides in a second pass).  ``chain`` is the chain's look-ups
        (``pumpup.physics.lookups.GChain``); a model that has a fused kernel returns exactly what the second pass gives
        (the same operations), for C-contiguous (N, 3)-shaped float64 ``wi`` and ``wo`` of one shape, else None.
        """
        return None

    def eval_plus_lobe(self, wi: np.ndarray, wo: np.ndarray, scale: float, bound: tuple) -> np.ndarray | None:
        """f_r + ``scale`` D(N.wi) D(N.wo) (the Kulla-Conty lobe, D = 1 - U clamped at 0; ``bound`` the look-up's
        arguments, ``pumpup.operators.compensate``) in one compiled pass, or None (the default: the compensated model
        then evaluates this model and adds the lobe in a second pass).  A model that has a fused kernel returns exactly
        what the second pass gives, for C-contiguous (N, 3)-shaped float64 ``wi`` and ``wo`` of one shape, else None.
        """
        return None

    def kernel_args(self) -> tuple:
        """Scalar parameters passed to the compiled kernel after the 6 direction components."""
        return tuple(self.p[k] for k in self.params)

    def reference(self, wi: ArrayLike, wo: ArrayLike) -> np.ndarray:
        """The plain numpy implementation, the readable reference for the kernel."""
        wi = np.asarray(wi, dtype=np.float64)
        wo = np.asarray(wo, dtype=np.float64)
        return self.reference_fn(wi, wo, *self.kernel_args())

    # --- hints for the albedo engine ---------------------------------------------------
    def lobe(self, mu: float) -> Lobe:
        """Quadrature hint for incidence cos(theta_i) = mu (default: no knowledge)."""
        return Lobe(axis="normal", radial="cosine", symmetric=False)

    def sampling_lobe(self, mu: float) -> Lobe:
        """Hint for importance sampling (``pumpup.sampling``), default :meth:`lobe`.

        Override where the quadrature hint's lobe has lighter tails than f (the weights
        f cos / p would then grow without bound): the sampling density must not fall off
        faster than f.
        """
        return self.lobe(mu)

    #: True where the model draws its own incidence directions (:meth:`sample_wi`, :meth:`pdf_wi`, e.g. a paper's
    #: importance sampling); otherwise ``pumpup.sample`` builds a mixture from the :meth:`sampling_lobe` hints
    own_sampler: ClassVar[bool] = False

    def sample_wi(self, wo: np.ndarray, u1: np.ndarray, u2: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The model's own sampling (where :attr:`own_sampler`): wi of shape (n, 3) drawn for one ``wo`` (3,) from the
        uniform numbers ``u1``, ``u2`` (n,), and their density [1/sr]; a rejected draw is wi = 0 with density 0.
        """
        raise NotImplementedError(f"{type(self).__name__} has no sampler of its own (own_sampler is False)")

    def pdf_wi(self, wi: np.ndarray, wo: np.ndarray) -> np.ndarray:
        """The density [1/sr] with which :meth:`sample_wi` draws ``wi`` (any leading shape) given ``wo`` (3,)."""
        raise NotImplementedError(f"{type(self).__name__} has no sampler of its own (own_sampler is False)")

    def albedo_terms(self) -> list[tuple[float, BRDF]]:
        """Linear decomposition f = sum w_k f_k used by the engine (default: itself)."""
        return [(1.0, self)]

    def albedo_breaks(self) -> tuple[float, ...]:
        """Incidences mu in (0, 1) where the albedo a(mu) has a kink, or a jump in a low derivative, that does not
        depend on wo (default: none), for a table's spline to be split there (``pumpup.tabulate``'s ``breaks``, the
        pumping operator's base tables, the compensation tables) and for :func:`pumpup.mean_albedo`'s first intervals
        to end there: a Fresnel factor's total reflection (:func:`pumpup.models.metal.fresnel_levels`), the jump of a''
        at mu = 1 / sqrt(2) of 001 eq. 10's geometry factor (:data:`pumpup.models.cook_torrance.RETRO_BREAK`).  A lobe
        that carries such a table in N.wo has a level at each (a pumped level's g, a 1/E scaling's U).  A pumped level's
        own kinks come from the pumping operator (:meth:`albedo_kinks`).
        """
        return ()

    def albedo_kinks(self, lo: float = 0.0, hi: float = 1.0) -> list[float] | None:
        """Every incidence in (lo, hi) where a table of this model's albedo must split its spline: its
        :meth:`albedo_breaks`, sorted, or None where it has none (an operator adds the kinks it makes: a pumped
        level's g changes its form at incidences that do not depend on wo).
        """
        out = sorted(v for v in self.albedo_breaks() if lo < v < hi)
        return out or None

    def azimuth_hint(self) -> AzimuthHint | None:
        """An :class:`~pumpup.core.hints.AzimuthHint` (the model's family, its scale and factors) when the azimuth of
        the albedo integral is closed-form or a rule on known arcs: the routing table (:mod:`pumpup.engine.routes`) then
        picks a 1-D route for it.  None (the default): the nested quadrature or the 2-D cubature.
        """
        return None

    #: the relative error of :meth:`eval` where it is a truncated series (He-Torrance's), added to the albedo's error
    #: estimate; 0 for an exact formula
    eval_rtol: float = 0.0

    #: ``delta_albedo(mu)``: the albedo of a delta lobe in the mirror direction (He-Torrance's specular part), added
    #: to the integral exactly; None (the default) for a model without one
    delta_albedo = None

    def fresnel_one(self) -> BRDF | None:
        """The same model with its Fresnel factor set to 1, the white model whose albedo E energy compensation
        tabulates (Kulla-Conty, 1/E), or None for a model without a Fresnel factor (the default).
        """
        return None

    def sampling_terms(self, mu: float) -> list[tuple[float, BRDF]]:
        """[(weight, term)] to sample from at incidence mu: the albedo terms (the default), or terms weighted for
        this mu (Kulla-Conty's mixture).
        """
        return self.albedo_terms()

    def slope_hint(self) -> tuple[float, float, float] | None:
        """(a_x, a_y, c) when the albedo is one ray integral per direction in slope space (anisotropic Ward, 000 eq.
        33: the ``slope`` route, :mod:`pumpup.engine.slope`), else None (the default).
        """
        return None

    def lobe_axis(self, mu: np.ndarray, phi: np.ndarray) -> tuple[float, np.ndarray, np.ndarray] | None:
        """(n, nu, scale) when, seen from wi at (mu, phi), the model is a power lobe scale (A.wo)_+^n about an axis A at
        elevation nu = N.A > 0, with no other dependence on wi (the engine then takes the 1-D path about A,
        :func:`pumpup.engine.polar.axis_albedo`), else None (the default).
        """
        return None

    def azimuth_range(self) -> float | None:
        """None if the albedo does not depend on the azimuth phi of wi (an isotropic model, the
        default); otherwise the length P of an interval [0, P] of phi on which a(mu, phi) takes
        all its values: pi / 2 for a model that is symmetric under the reflections y -> -y and
        x -> -x (anisotropy aligned with the tangent axes), 2 pi when nothing is known.
        """
        return None


def split(w: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The x, y, z components of an array of 3-vectors (views, no copy)."""
    return w[..., 0], w[..., 1], w[..., 2]


def dot(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """The dot product a . b over the last axis, summed x + y + z in the same order as the numba kernels."""
    return a[..., 0] * b[..., 0] + a[..., 1] * b[..., 1] + a[..., 2] * b[..., 2]


#: the deepest nesting of a spec (dicts and lists within each other) that :func:`load` reads: 64 pumping levels of a
#: model with a nested base, far beyond any use, and far below Python's recursion limit
MAX_SPEC_DEPTH = 64


def _check_depth(spec: Any) -> None:
    """A SpecError if ``spec`` nests dicts and lists more than :data:`MAX_SPEC_DEPTH` deep (walked without
    recursion).
    """
    stack = [(spec, 1)]
    while stack:
        node, depth = stack.pop()
        if depth > MAX_SPEC_DEPTH:
            raise SpecError(f"a spec may nest at most {MAX_SPEC_DEPTH} levels deep (dicts and lists within each other)")
        children = node.values() if isinstance(node, dict) else node
        stack.extend((c, depth + 1) for c in children if isinstance(c, (dict, list, tuple)))


def load(spec: Any) -> BRDF:
    """Build a BRDF from a spec: a dict ``{"type": name, param: value, ...}``, its JSON text, or
    the short form of the command line, ``"phong:n=20,c=1"`` (:func:`parse_spec`).

    Nested specs compose (``{"type": "pumped", "base": {...}}``).  A spec is data: it
    never imports or evaluates code.

    Examples
    --------
    >>> import pumpup
    >>> f = pumpup.load({"type": "phong", "n": 20})
    >>> pumpup.load(f.spec) == f
    True
    """
    _ensure_models()
    if isinstance(spec, BRDF) or getattr(spec, "is_spectral", False):
        return spec
    if isinstance(spec, str):
        spec = parse_spec(spec)
    if not isinstance(spec, dict):
        raise SpecError(f"a spec must be a dict with a 'type' key, got {type(spec).__name__}")
    _check_depth(spec)
    if "type" not in spec:
        raise SpecError(f"a spec needs a 'type' key; known types: {', '.join(_REGISTRY)}")
    bad_keys = [k for k in spec if not isinstance(k, str)]
    if bad_keys:
        raise SpecError(f"spec keys must be parameter names (strings), got {bad_keys[0]!r}")
    name = spec["type"]
    if not isinstance(name, str):
        raise SpecError(f"a spec's 'type' must be a model name (a string), got {name!r}; "
                        f"known types: {', '.join(_REGISTRY)}")
    for applies, loader in _LOADERS:  # a material or per-wavelength lists: the spectral models' loader
        if applies(spec):
            return loader(spec)
    if name not in _REGISTRY:
        raise SpecError(f"unknown model type {name!r}; known types: {', '.join(_REGISTRY)}")
    kwargs = {k: v for k, v in spec.items() if k != "type"}
    return _REGISTRY[name](**kwargs)


#: the keys whose presence makes a metal or plastic spec spectral, and the parameters that may be per-wavelength lists
_SPECTRAL_KEYS = ("material", "wavelengths")
_SPECTRAL_LISTS = ("eta", "k", "ad", "a_s")


def is_spectral_spec(spec: Any) -> bool:
    """True for a spec that :mod:`pumpup.spectral` builds: a ``metal`` or ``plastic`` with a
    ``material``, ``wavelengths`` or a per-wavelength list (``eta``, ``k``, ``ad``, ``a_s``), or a
    ``pumped`` / ``kulla_conty`` / ``scaled`` spec whose base is one (or a spectral object).
    """
    if getattr(spec, "is_spectral", False):
        return True
    if not isinstance(spec, dict):
        return False
    t = spec.get("type")
    if t in ("metal", "plastic"):
        return any(k in spec for k in _SPECTRAL_KEYS) or any(
            isinstance(spec.get(k), (list, tuple, np.ndarray)) for k in _SPECTRAL_LISTS)
    if t in ("pumped", "kulla_conty", "scaled"):
        return is_spectral_spec(spec.get("base"))
    return t == "pumped_lobe"  # the colour-keeping pumped metal, spectral by definition


def parse_spec(text: str) -> dict:
    """A model spec from its text: JSON (``'{"type": "phong", "n": 20}'``) or the short form
    ``"phong:n=20,c=1"`` (values are JSON numbers, ``true``/``false``, or else strings).

    Raises
    ------
    SpecError
        Invalid JSON, or a short-form item that is not ``name=value``.

    Examples
    --------
    >>> parse_spec("phong:n=20,c=1")
    {'type': 'phong', 'n': 20, 'c': 1}
    """
    if not isinstance(text, str):
        raise SpecError(f"a spec text must be a string, got {type(text).__name__}")
    text = text.strip()
    if text.startswith("{"):
        try:
            spec = json.loads(text)
        except json.JSONDecodeError as exc:
            raise SpecError(f"the spec is not valid JSON: {exc}") from None
        if not isinstance(spec, dict):
            raise SpecError(f"a spec must be a JSON object with a 'type' key, got {text!r}")
        return spec
    name, _, rest = text.partition(":")
    if not name.strip():
        raise SpecError(f"a spec needs a model type before ':' (e.g. 'phong:n=20'), got {text!r}")
    spec: dict = {"type": name.strip()}
    for item in filter(None, (i.strip() for i in _split_items(rest))):
        key, eq, value = item.partition("=")
        if not eq or not key.strip():
            raise SpecError(f"spec parameter {item!r} must look like name=value (e.g. 'phong:n=20')")
        try:
            spec[key.strip()] = json.loads(value)
        except json.JSONDecodeError:
            spec[key.strip()] = value.strip()
    return spec


def _split_items(text: str) -> list[str]:
    """``text`` cut at the commas outside brackets, so a short-form value may be a JSON list
    (``"metal:n=20,eta=[0.2,0.4],k=[3,2],wavelengths=[650,550]"``).
    """
    items, depth, start = [], 0, 0
    for i, ch in enumerate(text):
        if ch in "[{":
            depth += 1
        elif ch in "]}":
            depth = max(depth - 1, 0)
        elif ch == "," and depth == 0:
            items.append(text[start:i])
            start = i + 1
    items.append(text[start:])
    return items


# ----------------------------------------------------------------------------------------
# Checks of engine and table arguments (the same style as the model parameters)
# ----------------------------------------------------------------------------------------


def _show(value: Any) -> str:
    """The repr of a value, shortened to about 40 characters (an int of 400 digits names its length)."""
    r = repr(value)
    return r if len(r) <= 40 else f"{r[:20]}... ({len(r)} characters)"


def _as_real(func: str, name: str, value: Any, what: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise SpecError(f"{func}: {name} must be {what}, got {_show(value)}")
    try:
        v = float(value)
    except OverflowError:
        raise SpecError(f"{func}: {name} must be {what}, got an integer too large for a float") from None
    if not math.isfinite(v):
        raise SpecError(f"{func}: {name} must be {what}, got {_show(value)}")
    return v


def check_tolerance(func: str, name: str, value: Any, hi: float = 1.0, zero: bool = False) -> float:
    """A tolerance (``rtol``, ``atol``, ...): a finite number in (0, hi] (``zero``: [0, hi], for an
    absolute tolerance that may be switched off); else a SpecError naming it.
    """
    what = f"a finite number in {'[' if zero else '('}0, {hi:g}]"
    v = _as_real(func, name, value, what)
    if not (0 <= v if zero else 0 < v) or not v <= hi:
        raise SpecError(f"{func}: {name} must be {what}, got {_show(value)}")
    return v


def check_count(func: str, name: str, value: Any, lo: int = 1, hi: int = 10**9) -> int:
    """An integer count in [lo, hi] (``max_regions``, ``max_points``, ``levels``...); else a SpecError."""
    what = f"an integer in [{lo}, {hi}]"
    if isinstance(value, bool) or not isinstance(value, (int, np.integer, float, np.floating)):
        raise SpecError(f"{func}: {name} must be {what}, got {_show(value)}")
    if isinstance(value, (float, np.floating)) and not (math.isfinite(value) and value == int(value)):
        raise SpecError(f"{func}: {name} must be {what}, got {_show(value)}")
    v = int(value)
    if not lo <= v <= hi:
        raise SpecError(f"{func}: {name} must be {what}, got {_show(value)}")
    return v


def check_open_unit(func: str, name: str, value: Any) -> float:
    """A number strictly inside (0, 1) (``mu_min``); else a SpecError naming it."""
    what = "a number in (0, 1)"
    v = _as_real(func, name, value, what)
    if not 0 < v < 1:
        raise SpecError(f"{func}: {name} must be {what}, got {_show(value)}")
    return v


def check_pair(wi: np.ndarray, wo: np.ndarray) -> tuple:
    """The broadcast shape of the leading axes of wi and wo, or a ValueError naming both."""
    try:
        return np.broadcast_shapes(wi.shape[:-1], wo.shape[:-1])
    except ValueError:
        raise ValueError(f"wi and wo must broadcast against each other: wi has shape {wi.shape}, "
                         f"wo has shape {wo.shape} (leading axes {wi.shape[:-1]} and {wo.shape[:-1]})") from None


# ----------------------------------------------------------------------------------------
# User functions
# ----------------------------------------------------------------------------------------

_USER_FUNCTIONS: dict[str, Callable] = {}


@register("function")
class FunctionBRDF(BRDF):
    """Any callable ``fn(wi, wo) -> f_r`` as a BRDF (see :func:`from_function`).

    The spec ``{"type": "function", "name": name}`` refers to a function registered in
    this Python session by ``from_function``; a spec never carries code.
    """

    params = {"name": Param(kind="str", doc="name the function was registered under")}
    constant = None

    def __init__(self, **kwargs: Any) -> None:
        super().__init__(**kwargs)
        name = self.p["name"]
        if name not in _USER_FUNCTIONS:
            raise SpecError(
                f"function: no function named {name!r} is registered in this session; "
                "call pumpup.from_function(fn, name=...) first"
            )
        self.fn, self.reciprocal, self.isotropic = _USER_FUNCTIONS[name]

    def _eval(self, wi: np.ndarray, wo: np.ndarray) -> np.ndarray:
        shape = np.broadcast_shapes(wi.shape[:-1], wo.shape[:-1])
        out = self.fn(wi, wo)
        try:
            out = np.broadcast_to(np.asarray(out, dtype=np.float64), shape)
        except ValueError:
            raise ValueError(
                f"function {self.p['name']!r} returned shape {np.shape(out)}; expected {shape} "
                "(the broadcast of the leading axes of wi and wo)"
            ) from None
        bad = ~np.isfinite(out) | (out < 0)
        if np.any(bad):
            i = tuple(np.argwhere(bad)[0])
            wib = np.broadcast_to(wi, shape + (3,))[i]
            wob = np.broadcast_to(wo, shape + (3,))[i]
            raise ValueError(
                f"function {self.p['name']!r} returned {out[i]!r} at wi={wib.tolist()}, wo={wob.tolist()}: "
                "a BRDF must be finite and non-negative"
            )
        return np.where((wi[..., 2] > 0) & (wo[..., 2] > 0), out, 0.0)

    reference = BRDF.eval

    def kernel_args(self) -> tuple:
        return ()

    def azimuth_range(self) -> float | None:
        # nothing is known about a user function's symmetry, unless it was declared (and checked) isotropic
        return None if self.isotropic else 2.0 * math.pi


#: :func:`from_function`'s check of a claim of isotropy: pairs, and the relative change allowed under a rotation about N
ISOTROPY_PAIRS = 2000
ISOTROPY_RTOL = 1e-9


def from_function(fn: Callable[[np.ndarray, np.ndarray], ArrayLike], name: str = "function", reciprocal: bool = True,
                  isotropic: bool = False) -> BRDF:
    """Wrap a callable ``fn(wi, wo) -> f_r`` (numpy, broadcasting) as a BRDF.

    Parameters
    ----------
    fn : callable
        Takes arrays of unit vectors of shape (..., 3) and returns f_r in 1/sr, without
        the cosine factor.  Values below the horizon are replaced by 0.
    name : str
        Registers the function under this name for the session, so that the spec
        ``{"type": "function", "name": name}`` loads it again.
    reciprocal : bool
        What the caller claims; :func:`check_reciprocity` measures it.
    isotropic : bool
        The caller's claim that f does not change when wi and wo turn together about N (it depends on them through
        N.wi, N.wo and wi.wo only): the albedo then does not depend on the azimuth of wi, and pumping tabulates it once
        instead of bounding its supremum over that azimuth (:func:`pumpup.tables.azimuth.sup_albedo`: 16 tables or
        more).  Checked here: f at :data:`ISOTROPY_PAIRS` random pairs against the same pairs turned by random angles,
        which must agree within :data:`ISOTROPY_RTOL` (relative); a ValueError names the largest change otherwise.

    Examples
    --------
    >>> import numpy as np, pumpup
    >>> f = pumpup.from_function(lambda wi, wo: np.full(np.broadcast_shapes(wi.shape, wo.shape)[:-1], 0.5 / np.pi),
    ...                          name="half_white")
    >>> float(f.eval([0, 0, 1], [0.6, 0, 0.8])) * np.pi
    0.5
    """
    if not callable(fn):
        raise TypeError(f"from_function needs a callable fn(wi, wo), got {type(fn).__name__}")
    if not isinstance(name, str) or not name:
        raise SpecError("from_function: 'name' must be a non-empty string")
    old = _USER_FUNCTIONS.get(name)
    _USER_FUNCTIONS[name] = (fn, bool(reciprocal), bool(isotropic))
    f = FunctionBRDF(name=name)
    if isotropic:
        rng = np.random.default_rng(20261202)
        n = ISOTROPY_PAIRS
        z = rng.uniform(1e-3, 1.0, (2, n))  # (above the horizon, where f is not replaced by 0)
        ph = rng.uniform(0.0, 2.0 * math.pi, (2, n))
        turn = rng.uniform(0.0, 2.0 * math.pi, n)
        r = np.sqrt((1.0 - z) * (1.0 + z))
        wi, wo, wi2, wo2 = (np.stack([r[k] * np.cos(ph[k] + t), r[k] * np.sin(ph[k] + t), z[k]], axis=-1)
                            for t in (0.0, turn) for k in (0, 1))
        try:
            a, b = f._eval(wi, wo), f._eval(wi2, wo2)
        except Exception:
            _USER_FUNCTIONS.pop(name) if old is None else _USER_FUNCTIONS.__setitem__(name, old)
            raise
        change = np.abs(a - b) / np.maximum(np.maximum(np.abs(a), np.abs(b)), 1e-300)
        if change.max() > ISOTROPY_RTOL:
            i = int(np.argmax(change))
            _USER_FUNCTIONS.pop(name) if old is None else _USER_FUNCTIONS.__setitem__(name, old)
            raise ValueError(f"from_function: isotropic=True, but {name!r} changes by {change[i]:.3g} (relative, "
                             f"allowed {ISOTROPY_RTOL:g}) when wi={wi[i].tolist()}, wo={wo[i].tolist()} turn about N "
                             f"by {turn[i]:.6g} rad: {float(a[i])!r} against {float(b[i])!r}")
    return f


# ----------------------------------------------------------------------------------------
# Reciprocity
# ----------------------------------------------------------------------------------------


@dataclass
class ReciprocityResult:
    """Measured asymmetry max |f(wi, wo) - f(wo, wi)| / scale over a set of direction pairs.

    ``scale`` is max(|f(wi, wo)|, |f(wo, wi)|) per pair (pairs where both vanish are
    skipped).  ``reciprocal`` is ``max_rel_error <= tol``.
    """

    max_rel_error: float
    worst_wi: np.ndarray
    worst_wo: np.ndarray
    f_forward: float
    f_backward: float
    pairs: int
    tol: float
    reciprocal: bool = field(init=False)

    def __post_init__(self) -> None:
        self.reciprocal = bool(self.max_rel_error <= self.tol)

    def __bool__(self) -> bool:
        return self.reciprocal

    def __str__(self) -> str:
        verdict = "reciprocal" if self.reciprocal else "NOT reciprocal"
        return (
            f"{verdict}: max relative asymmetry {self.max_rel_error:.3g} (tol {self.tol:g}) over {self.pairs} pairs; "
            f"worst at wi={np.round(self.worst_wi, 6).tolist()}, wo={np.round(self.worst_wo, 6).tolist()}: "
            f"f(wi,wo)={self.f_forward:.6g}, f(wo,wi)={self.f_backward:.6g}"
        )


def direction_set(n_mu: int = 24, n_phi: int = 24) -> np.ndarray:
    """A well-spread set of upper-hemisphere directions, including near-grazing ones.

    mu = cos(theta) runs over a grid uniform in theta plus mu = 1e-3, 1e-6, 1e-8; phi
    is uniform and staggered per ring.  Returns shape (n, 3).
    """
    theta = (np.arange(n_mu) + 0.5) / n_mu * (np.pi / 2)
    mu = np.concatenate([np.cos(theta), [1.0, 1e-3, 1e-6, 1e-8]])
    dirs = []
    for k, m in enumerate(mu):
        phi = (np.arange(n_phi) + 0.5 * (k % 2)) / n_phi * 2 * np.pi
        s = math.sqrt((1 - m) * (1 + m))
        dirs.append(np.stack([s * np.cos(phi), s * np.sin(phi), np.full_like(phi, m)], axis=-1))
    return np.concatenate(dirs)


def check_reciprocity(brdf: BRDF, tol: float = 1e-12, n_mu: int = 24, n_phi: int = 24) -> ReciprocityResult:
    """Measure the asymmetry of ``brdf`` on all pairs of a well-spread direction set.

    Parameters
    ----------
    brdf : BRDF
    tol : float
        Relative asymmetry allowed for a reciprocal verdict (rounding error).
    n_mu, n_phi : int
        Size of the direction set (:func:`direction_set`); the check uses every pair.

    Returns
    -------
    ReciprocityResult
        With the worst pair; truthy when reciprocal.

    Examples
    --------
    >>> import pumpup
    >>> pumpup.check_reciprocity(pumpup.load({"type": "phong", "n": 20})).reciprocal
    True
    """
    d = direction_set(n_mu, n_phi)
    wi = d[:, None, :]
    wo = d[None, :, :]
    fwd = np.asarray(brdf._eval(wi, wo), dtype=np.float64)
    bwd = np.asarray(brdf._eval(wo, wi), dtype=np.float64)
    scale = np.maximum(np.abs(fwd), np.abs(bwd))
    with np.errstate(invalid="ignore", divide="ignore"):
        rel = np.where(scale > 0, np.abs(fwd - bwd) / scale, 0.0)
    if fwd.ndim > 2:  # multi-channel models: worst channel
        rel = rel.max(axis=tuple(range(2, rel.ndim)))
        fwd, bwd = fwd[..., 0], bwd[..., 0]
    i, j = np.unravel_index(np.argmax(rel), rel.shape)
    return ReciprocityResult(
        max_rel_error=float(rel[i, j]),
        worst_wi=d[i],
        worst_wo=d[j],
        f_forward=float(fwd[i, j]),
        f_backward=float(bwd[i, j]),
        pairs=int(rel.size),
        tol=tol,
    )


from .._lazy import submodules  # noqa: E402

__getattr__ = submodules(__name__)  # the package's modules on first use (pumpup.core.<module>)
