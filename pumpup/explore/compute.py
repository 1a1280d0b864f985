"""What the explorer's page shows, computed with pumpup's own API: one function per view, all plain numpy.

Nothing here knows about the web server: :func:`compute` takes the page's state (a JSON-like dict) and returns the
numbers of every view, so the tests and the benchmark call the same code as the page.

Only registry specs are accepted (:func:`check_spec`): a spec is data (:func:`pumpup.load` never imports or runs
code); the ``function`` type (:func:`pumpup.from_function`) and the spectral models (whose loader reads measured
optical constants) are refused, and every string value is checked against the parameter's choices by the model.
"""

from __future__ import annotations

import base64
import json
import math
import time
import warnings
from collections.abc import Callable
from typing import Any

import numpy as np

from .. import render
from ..core import BRDF, REQUIRED, SpecError, is_spectral_spec, load, parse_spec, registry

__all__ = [
    "Cancelled",
    "TimeLimit",
    "check_spec",
    "check_state",
    "model_catalog",
    "compute",
    "lobe_curve",
    "albedo_curve",
    "slice_image",
    "reproduce_lines",
]

#: the longest spec text the page may send (a 5-level pumped nested spec is under 1 kB)
MAX_SPEC_CHARS = 4000
#: model types the explorer refuses: ``function`` wraps Python code (from_function), and ``transposed`` is internal
REFUSED_TYPES = ("function",)
#: the most BRDFs compared side by side
MAX_COMPARE = 4
#: pumping levels offered by the page
MAX_LEVELS = 5
#: parameters shown on a log slider: lobe exponents and widths (roughness)
LOG_PARAMS = ("n", "nu", "nv", "m", "alpha", "ax", "ay", "s", "sigma", "sigma_0", "k")
#: the lobe widths among them (slopes and roughness): their sliders span 1e-3 to 2, the exponents' 0.1 to 1e4 (the
#: field beside a slider takes any value in the registry's range)
WIDTH_PARAMS = ("m", "alpha", "ax", "ay", "sigma", "sigma_0")
#: incidence angles of the albedo plot [degrees]: 0 to 89.9 (theta, so that the plot reads in degrees); near grazing
#: the points follow mu down to 1e-3
ALBEDO_THETA = np.concatenate([np.linspace(0.0, 85.0, 86), np.degrees(np.arccos(np.geomspace(0.087, 1e-3, 24)))])
#: sizes of the images (pixels per side)
FURNACE_SIZE = 64
SPHERE_SIZE = 128
SLICE_SIZE = 64


class Cancelled(Exception):
    """A newer request from the same tab superseded this computation."""


class TimeLimit(Exception):
    """The computation ran past its time bound."""


# --------------------------------------------------------------------------------------------
# Specs
# --------------------------------------------------------------------------------------------


def _walk_types(spec: Any) -> list[str]:
    """The model types named anywhere in a (nested) spec dict."""
    out, stack = [], [spec]
    while stack:
        node = stack.pop()
        if isinstance(node, dict):
            if "type" in node:
                out.append(node["type"])
            stack.extend(node.values())
        elif isinstance(node, (list, tuple)):
            stack.extend(node)
    return out


def _refuse(spec: dict) -> None:
    """A SpecError for a spec dict that names a type outside the registry or in :data:`REFUSED_TYPES`, or that is
    spectral (nothing is built).
    """
    known = registry()
    for t in _walk_types(spec):
        if not isinstance(t, str) or t not in known:
            raise SpecError(f"spec: unknown model type {t!r}; known types: "
                            f"{', '.join(k for k in known if k not in REFUSED_TYPES)}")
        if t in REFUSED_TYPES:
            raise SpecError(f"spec: type {t!r} wraps Python code and is not accepted here; use a registered model")
    if is_spectral_spec(spec):
        raise SpecError("spec: spectral specs (a 'material', 'wavelengths' or per-wavelength lists) are not shown "
                        "here; give one channel (eta, k numbers)")


def check_spec(spec: Any) -> BRDF:
    """A registry model from the page's spec (its short form, JSON text or a dict); a SpecError otherwise.

    Refused, before anything is built: text over :data:`MAX_SPEC_CHARS` characters, a type that is not in
    :func:`pumpup.registry` or is in :data:`REFUSED_TYPES` (wrapped Python code), spectral specs (a ``material``,
    ``wavelengths`` or per-wavelength lists: the views are single-channel).
    """
    if isinstance(spec, str):
        if len(spec) > MAX_SPEC_CHARS:
            raise SpecError(f"spec: at most {MAX_SPEC_CHARS} characters, got {len(spec)}")
        if not spec.strip():
            raise SpecError("spec: empty; type a model such as phong:n=20 or {\"type\": \"ggx\", \"alpha\": 0.2}")
        spec = parse_spec(spec)
    if not isinstance(spec, dict):
        raise SpecError(f"spec: must be a model spec (a dict with a 'type'), got {type(spec).__name__}")
    if len(json.dumps(spec, default=str)) > MAX_SPEC_CHARS:
        raise SpecError(f"spec: at most {MAX_SPEC_CHARS} characters of JSON")
    _refuse(spec)
    f = load(spec)
    if getattr(f, "is_spectral", False):
        raise SpecError("spec: spectral models are not shown here; give one channel")
    return f


def parse_spec_any(spec: Any) -> dict:
    """The spec as the user gave it, as a dict (its text parsed); call :func:`check_spec` first."""
    return parse_spec(spec) if isinstance(spec, str) else dict(spec)


def _number(value: Any, name: str, lo: float, hi: float) -> float:
    """``value`` as a float in [lo, hi]; a SpecError naming ``name`` otherwise."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise SpecError(f"{name} must be a number in [{lo:g}, {hi:g}], got {value!r}")
    v = float(value)
    if not (math.isfinite(v) and lo <= v <= hi):
        raise SpecError(f"{name} = {value!r} is outside its allowed range [{lo:g}, {hi:g}]")
    return v


def check_state(state: Any) -> dict:
    """The page's state, checked and completed with defaults (a SpecError naming the bad entry).

    Keys: ``specs`` (1 to 4 specs), ``theta_i`` (degrees, [0, 89.9]), ``phi`` (azimuth of the plane of incidence,
    degrees, [-180, 180]), ``pump`` ({"on", "g": g1|g2, "levels": 1-5}), ``kulla_conty`` and ``scaled`` (bool),
    ``light`` (degrees from the view, [0, 179]) and ``light_azimuth`` (degrees), ``server_sphere`` (bool: send the
    server-rendered sphere image too), ``lobe3d`` (bool: the lobe over the whole hemisphere too).
    """
    if not isinstance(state, dict):
        raise SpecError("state: must be a JSON object")
    specs = state.get("specs")
    if not isinstance(specs, list) or not 1 <= len(specs) <= MAX_COMPARE:
        raise SpecError(f"specs: give 1 to {MAX_COMPARE} model specs")
    pump = state.get("pump") or {}
    if not isinstance(pump, dict):
        raise SpecError("pump: must be an object {on, g, levels}")
    g = pump.get("g", "g2")
    if g not in ("g1", "g2"):
        raise SpecError(f"pump g must be 'g1' or 'g2', got {g!r}")
    levels = _number(pump.get("levels", 1), "pump levels", 1, MAX_LEVELS)
    if levels != int(levels):
        raise SpecError(f"pump levels must be an integer in [1, {MAX_LEVELS}], got {pump.get('levels')!r}")
    return {
        "specs": specs,
        "theta_i": _number(state.get("theta_i", 30.0), "theta_i (incidence angle, degrees)", 0.0, 89.9),
        "phi": _number(state.get("phi", 0.0), "phi (azimuth, degrees)", -180.0, 180.0),
        "pump": {"on": bool(pump.get("on", False)), "g": g, "levels": int(levels)},
        "kulla_conty": bool(state.get("kulla_conty", False)),
        "scaled": bool(state.get("scaled", False)),
        "light": _number(state.get("light", 30.0), "light (degrees from the view)", 0.0, 179.0),
        "light_azimuth": _number(state.get("light_azimuth", 0.0), "light azimuth (degrees)", -360.0, 360.0),
        "server_sphere": bool(state.get("server_sphere", False)),
        "lobe3d": bool(state.get("lobe3d", False)),
    }


# --------------------------------------------------------------------------------------------
# The model list for the page
# --------------------------------------------------------------------------------------------


def _default(cls: type, name: str, p) -> Any:
    """A parameter's default as plain JSON: its value, None (computed from the others, or unset), or the first
    example's value for a required one.
    """
    if p.default is REQUIRED:
        for ex in cls.examples:
            if name in ex:
                return ex[name]
        return None
    if callable(p.default) or p.default is None:
        return None
    return p.default


def _slider(name: str, p, default: Any) -> dict:
    """The slider of a numeric parameter: its range (inside the registry's), and whether it is logarithmic."""
    lo, hi = float(p.lo), float(p.hi)
    log = name in LOG_PARAMS and lo >= 0.0
    if log and name in WIDTH_PARAMS:  # roughness: 1e-3 (a mirror on screen) to 2 (rougher than any surface)
        s_lo, s_hi = max(lo, 1e-3), min(hi, 2.0)
    elif log:  # exponents: 0.1 (nearly diffuse) to 1e4 (a sharp highlight)
        s_lo, s_hi = max(lo, 0.1), min(hi, 1e4)
    else:
        s_lo = lo if math.isfinite(lo) else -10.0
        ref = abs(default) if isinstance(default, (int, float)) and not isinstance(default, bool) else 1.0
        s_hi = hi if math.isfinite(hi) else max(2.0, 4.0 * ref)
    return {"lo": s_lo, "hi": s_hi, "log": log}


def model_catalog() -> list[dict]:
    """Every registered model the page offers: type, parameters (kind, range, default, slider, doc) and a first
    example spec that loads.
    """
    out = []
    for name, cls in registry().items():
        if name in REFUSED_TYPES:
            continue
        params = []
        for pname, p in cls.params.items():
            d = _default(cls, pname, p)
            entry = {"name": pname, "kind": p.kind, "range": p.range_text(), "doc": p.doc,
                     "required": p.default is REQUIRED, "default": d,
                     "lo": p.lo if math.isfinite(p.lo) else None, "hi": p.hi if math.isfinite(p.hi) else None,
                     "lo_open": p.lo_open, "hi_open": p.hi_open, "choices": list(p.choices)}
            if p.kind in ("float", "int"):
                entry["slider"] = _slider(pname, p, d)
            params.append(entry)
        example = {"type": name, **(cls.examples[0] if cls.examples else {})}
        for pname, p in cls.params.items():  # an operator without an example (pumped): over Phong
            if p.kind == "spec" and p.default is REQUIRED and pname not in example:
                example[pname] = {"type": "phong", "n": 20}
        try:
            _refuse(example)
        except SpecError:
            continue  # a model whose example is a spec kind the page refuses
        out.append({"type": name, "params": params, "example": example,
                    "doc": (cls.__doc__ or "").strip().split("\n")[0]})
    return out


# --------------------------------------------------------------------------------------------
# Views
# --------------------------------------------------------------------------------------------


def _b64(a: np.ndarray) -> str:
    """A little-endian float64 array as base64 (a JavaScript ``Float64Array`` reads it back exactly)."""
    return base64.b64encode(np.ascontiguousarray(a, dtype="<f8").tobytes()).decode("ascii")


def _floats(a) -> list:
    """A list of Python floats (JSON numbers that round-trip exactly)."""
    return [float(x) for x in np.asarray(a, dtype=np.float64).ravel()]


def incidence(theta_deg: float, phi_deg: float) -> np.ndarray:
    """The incidence direction wi at polar angle theta and azimuth phi [degrees], N = (0, 0, 1)."""
    t, p = math.radians(theta_deg), math.radians(phi_deg)
    return np.array([math.sin(t) * math.cos(p), math.sin(t) * math.sin(p), math.cos(t)])


def lobe_angles(theta_i: float) -> np.ndarray:
    """Signed angles theta_o [degrees] in the plane of incidence: every half degree in (-90, 90), and points packed
    geometrically around the mirror direction (+theta_i), so that a sharp lobe is drawn.
    """
    base = np.linspace(-89.75, 89.75, 360)
    off = np.geomspace(1e-4, 10.0, 60)
    near = np.concatenate([theta_i - off, [theta_i], theta_i + off])
    t = np.unique(np.concatenate([base, near]))
    return t[(t > -90.0) & (t < 90.0)]


def lobe_curve(f: BRDF, theta_i: float, phi: float = 0.0) -> dict:
    """f_r(wi, wo) cos(theta_o) for wo in the plane of incidence.

    wi is at ``theta_i`` and azimuth ``phi``; wo at the signed angle t has the direction
    (-sin t cos phi, -sin t sin phi, cos t), so t = +theta_i is the mirror direction and t = -theta_i the light.
    """
    t = lobe_angles(theta_i)
    tr, p = np.radians(t), math.radians(phi)
    wo = np.stack([-np.sin(tr) * math.cos(p), -np.sin(tr) * math.sin(p), np.cos(tr)], axis=-1)
    # wi repeated on every row: the model's row kernel, not its broadcasting ufunc (whose first call builds a
    # wrapper; the values are the same)
    wi = np.ascontiguousarray(np.broadcast_to(incidence(theta_i, phi), wo.shape))
    fr = np.asarray(f.eval(wi, wo), dtype=np.float64)
    return {"theta_o": _floats(t), "value": _floats(fr * np.cos(tr))}  # f_r cos(theta_o), 000 eq. 2's integrand


def lobe_surface(f: BRDF, theta_i: float, phi: float = 0.0, n_theta: int = 31, n_phi: int = 61) -> dict:
    """f_r(wi, wo) cos(theta_o) over the hemisphere of wo, for the 3-D lobe: rows theta_o (0 to 90 degrees, the
    last row at 89.9), columns phi_o (-180 to 180 degrees), wi at ``theta_i`` and azimuth ``phi``.
    """
    t = np.radians(np.linspace(0.0, 89.9, n_theta))[:, None]
    p = np.radians(np.linspace(-180.0, 180.0, n_phi))[None, :]
    wo = np.stack([np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), np.cos(t) + 0.0 * p], axis=-1)
    fr = np.asarray(f.eval(incidence(theta_i, phi), wo), dtype=np.float64)
    return {"theta": _floats(np.degrees(t)), "phi": _floats(np.degrees(p)),
            "data": _b64(fr * np.cos(t))}  # f_r cos(theta_o)


def albedo_curve(f: BRDF, phi: float = 0.0) -> dict:
    """Directional albedo a(theta_i) with its error estimate (``pumpup.albedo(f, mu, return_error=True)``) at
    :data:`ALBEDO_THETA`, and the intervals where a - error > 1 (more light out than in).
    """
    theta = ALBEDO_THETA
    mu = np.cos(np.radians(theta))
    mu[0] = 1.0
    import pumpup

    a, err = pumpup.albedo(f, mu, return_error=True, phi=math.radians(phi))
    a, err = np.asarray(a, dtype=np.float64), np.asarray(err, dtype=np.float64)
    over = a - err > 1.0
    spans = []
    i = 0
    while i < len(theta):
        if over[i]:
            j = i
            while j + 1 < len(theta) and over[j + 1]:
                j += 1
            spans.append([float(theta[i]), float(theta[j])])
            i = j + 1
        else:
            i += 1
    return {"theta": _floats(theta), "mu": _floats(mu), "a": _floats(a), "err": _floats(err), "above_one": spans,
            "max": float(a.max())}


def slice_image(f: BRDF, phi: float = 0.0, n: int = SLICE_SIZE) -> dict:
    """f_r over (theta_h, theta_d) at phi_d = 90 degrees, as BRDF Explorer's image slice (Rusinkiewicz's
    half/difference angles): rows theta_d, columns theta_h, both from 0 to 90 degrees (pixel centres).
    """
    c = (np.arange(n) + 0.5) * (90.0 / n)
    th = np.radians(c)[None, :]
    td = np.radians(c)[:, None]
    ph = math.radians(phi)

    def direction(phi_d):
        x = np.sin(td) * math.cos(phi_d) + 0.0 * th
        y = np.sin(td) * math.sin(phi_d) + 0.0 * th
        z = np.cos(td) + 0.0 * th
        # rotate about y by theta_h (z -> h), then about z by phi_h
        x1 = x * np.cos(th) + z * np.sin(th)
        z1 = -x * np.sin(th) + z * np.cos(th)
        return np.stack([x1 * math.cos(ph) - y * math.sin(ph), x1 * math.sin(ph) + y * math.cos(ph), z1], axis=-1)

    wi = direction(math.pi / 2)
    wo = direction(-math.pi / 2)
    for w in (wi, wo):
        w /= np.linalg.norm(w, axis=-1, keepdims=True)
    fr = np.asarray(f.eval(wi, wo), dtype=np.float64)
    return {"n": n, "axis": _floats(c), "data": _b64(fr), "max": float(fr.max())}


def furnace_image(f: BRDF, size: int = FURNACE_SIZE) -> dict:
    """The white-furnace sphere in ``pumpup.render``'s geometry: pixel = a(mu_V), mu_V = N.V (000 eq. 2).

    For a reciprocal isotropic model every pixel is ``pumpup.albedo(f, mu_V, return_error=True)`` at its own mu_V
    (one call over the distinct values: 296 at 64 pixels), and ``bound`` is the largest error estimate; otherwise
    (a non-reciprocal model, whose furnace integrates over the incidence direction, or an anisotropic one, which
    pumpup refuses) it is ``pumpup.render.furnace``'s image and bound.  ``method`` says which.
    """
    import pumpup

    g = render.geometry(size)
    if f.reciprocal and render._anisotropy(f) <= render.ISOTROPY_TOL:
        mu, inverse = np.unique(g.view[:, 2], return_inverse=True)
        a, err = pumpup.albedo(f, mu, return_error=True)
        rad = np.zeros(g.mask.shape)
        rad[g.mask] = np.asarray(a, dtype=np.float64)[inverse]
        return {"size": size, "data": _b64(rad), "bound": float(np.max(err)), "max": float(rad.max()),
                "method": "pumpup.albedo per pixel"}
    im = render.furnace(f, size=size)
    return {"size": size, "data": _b64(im.radiance), "bound": float(im.error), "max": float(im.radiance.max()),
            "method": "pumpup.render.furnace"}


def sphere_image(f: BRDF, light: float, azimuth: float, size: int = SPHERE_SIZE) -> dict:
    """The lit sphere rendered by pumpup on the server (``pumpup.render.sphere``)."""
    im = render.sphere(f, light_deg=light, size=size, azimuth_deg=azimuth)
    return {"size": size, "data": _b64(im.radiance), "max": float(im.radiance.max())}


def shader_source(f: BRDF) -> dict | None:
    """The GLSL ES library of ``pumpup.shader(spec, target="glsl-es")`` and its uniforms
    (``pumpup.shaders.uniforms``), ``{"error": message}`` for a model the export does not translate, or None where
    pumpup has no shader export.
    """
    import importlib.util

    if importlib.util.find_spec("pumpup.shaders") is None:
        return None
    import pumpup
    from pumpup import shaders

    try:
        return {"glsl": pumpup.shader(f.spec, target="glsl-es"), "uniforms": shaders.uniforms(f.spec)}
    except (SpecError, ValueError, NotImplementedError) as exc:
        return {"error": str(exc)}


def _has_shader(spec: dict) -> bool:
    """Whether ``pumpup shader`` translates the model."""
    import importlib.util

    if importlib.util.find_spec("pumpup.shaders") is None:
        return False
    from pumpup import shaders

    try:
        shaders.uniforms(spec)
    except (SpecError, ValueError):
        return False
    return True


def reproduce_lines(state: dict, spec: dict) -> dict:
    """The Python and command lines that compute what the page shows for the model ``spec``."""
    short = short_spec(spec)
    spec = json.dumps(spec)
    q = "'"
    theta = state["theta_i"]
    py = [
        "import numpy as np, pumpup, pumpup.render",
        f"f = pumpup.load({spec})",
        f"a, err = pumpup.albedo(f, np.cos(np.radians({theta:g})), return_error=True)  # at the page's theta_i",
        "theta = np.linspace(0, 89, 90)  # the albedo plot",
        "a, err = pumpup.albedo(f, np.cos(np.radians(theta)), return_error=True)",
        "pumpup.mean_albedo(f), pumpup.max_constant(f)",
    ]
    cli = [f"pumpup explore {q}{short}{q}", f"pumpup albedo {q}{short}{q} --theta {theta:g}",
           f"pumpup check {q}{short}{q}"]
    if state["pump"]["on"]:
        g, lv = state["pump"]["g"], state["pump"]["levels"]
        py.append(f"p = pumpup.pump(f, g={g!r}, levels={lv})")
        cli.append(f"pumpup pump {q}{short}{q} --g {g} --levels {lv}")
    if state["kulla_conty"]:
        py.append("kc = pumpup.compensate(f, method='kulla_conty')")
    if state["scaled"]:
        py.append("sc = pumpup.compensate(f, method='scale')")
    py.append(f"pumpup.render.sphere(f, light_deg={state['light']:g}, azimuth_deg={state['light_azimuth']:g}, "
              f"size={SPHERE_SIZE})")
    py.append(f"pumpup.render.furnace(f, size={FURNACE_SIZE})")
    cli.append(f"pumpup render sphere {q}{short}{q} --light {state['light']:g} --size {SPHERE_SIZE} --out spheres")
    cli.append(f"pumpup render furnace {q}{short}{q} --size {FURNACE_SIZE} --out spheres")
    if _has_shader(json.loads(spec)):
        py.append("glsl = pumpup.shader(f, target='glsl-es')")
        cli.append(f"pumpup shader {q}{short}{q} --target glsl-es --out {json.loads(spec)['type']}.glsl")
    return {"python": "\n".join(py), "cli": "\n".join(cli)}


def short_spec(spec: dict) -> str:
    """The short form ``type:k=v,...`` of a flat spec, or its JSON when a value is nested."""
    if any(isinstance(v, (dict, list)) for v in spec.values()):
        return json.dumps(spec)
    items = [f"{k}={json.dumps(v) if not isinstance(v, str) else v}" for k, v in spec.items() if k != "type"]
    return spec["type"] + (":" + ",".join(items) if items else "")


# --------------------------------------------------------------------------------------------
# One request
# --------------------------------------------------------------------------------------------


def _scalar_views(f: BRDF) -> dict:
    """Mean albedo (``pumpup.mean_albedo``) and maximum constant (``pumpup.max_constant``, for models with one)."""
    import pumpup

    out: dict[str, Any] = {"mean_albedo": float(pumpup.mean_albedo(f))}
    if getattr(f, "constant", None):
        c, theta = pumpup.max_constant(f)
        out["max_constant"] = {"name": f.constant, "value": float(c), "theta": float(theta)}
    else:
        out["max_constant"] = None
    return out


def _one(f: BRDF, st: dict, check: Callable[[], None], with_images: bool) -> dict:
    """Every view of one model; a view that pumpup refuses (an anisotropic model's furnace) holds its message."""
    out: dict[str, Any] = {"spec": f.spec, "short": short_spec(f.spec)}
    steps: list[tuple[str, Callable[[], Any]]] = [
        ("lobe", lambda: lobe_curve(f, st["theta_i"], st["phi"])),
        ("albedo", lambda: albedo_curve(f, st["phi"])),
        ("scalars", lambda: _scalar_views(f)),
    ]
    if st["lobe3d"]:
        steps.append(("lobe3d", lambda: lobe_surface(f, st["theta_i"], st["phi"])))
    if with_images:
        steps += [("slice", lambda: slice_image(f, st["phi"])), ("furnace", lambda: furnace_image(f))]
        if st["server_sphere"]:
            steps.append(("sphere", lambda: sphere_image(f, st["light"], st["light_azimuth"])))
    notes: list[str] = []
    for key, step in steps:
        check()
        # pumpup's warnings (an unbounded albedo, a tolerance not met) go to the page, not to the server's terminal;
        # catch_warnings changes process-wide state, so the server runs one computation at a time
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            try:
                value = step()
            except (SpecError, ValueError, ArithmeticError) as exc:
                value = {"error": str(exc)}
        notes.extend(f"{key}: {w.message}" for w in caught if f"{key}: {w.message}" not in notes)
        if key == "scalars" and "error" not in value:
            out.update(value)
        else:
            out[key] = value
    out["notes"] = notes
    return out


def compute(state: Any, *, cancel: Callable[[], bool] | None = None, deadline: float | None = None) -> dict:
    """Every view of the page's ``state`` (:func:`check_state`).

    Parameters
    ----------
    state : dict
        The page's state.
    cancel : callable, optional
        Returns True once a newer request supersedes this one: checked between views, it ends the work with
        :class:`Cancelled`.
    deadline : float, optional
        A ``time.monotonic()`` time past which the work ends with :class:`TimeLimit` (checked between views).

    Returns
    -------
    dict
        ``models``: one entry per spec with its views (lobe, albedo with error and where a > 1, mean albedo,
        maximum constant, image slice, furnace sphere, shader source) and its overlays (``pumped``, ``kulla_conty``,
        ``scaled``: the same views of ``pumpup.pump`` / ``pumpup.compensate`` of it); ``lines``: Python and command
        lines for the first model.  A bad spec raises SpecError before any work.
    """
    st = check_state(state)
    models, inputs = [], []
    for i, s in enumerate(st["specs"]):
        try:
            models.append(check_spec(s))
            inputs.append(parse_spec(s) if isinstance(s, str) else s)
        except SpecError as exc:
            if len(st["specs"]) > 1:
                raise SpecError(f"model {i + 1}: {exc}") from None
            raise

    def check() -> None:
        if cancel is not None and cancel():
            raise Cancelled()
        if deadline is not None and time.monotonic() > deadline:
            raise TimeLimit("pumpup explore: past the time limit")

    from ..core.budget import BudgetExceeded, time_budget

    seconds = None if deadline is None else max(deadline - time.monotonic(), 1e-9)
    try:
        # the budget holds inside pumpup's own work too (the engine checks it between pieces of work)
        with time_budget("pumpup explore", seconds, option="time limit"):
            out = _models(st, models, inputs, check)
    except BudgetExceeded as exc:
        raise TimeLimit(str(exc)) from None
    return {"state": st, "models": out, "lines": reproduce_lines(st, inputs[0])}


def _models(st: dict, models: list, inputs: list, check: Callable[[], None]) -> list:
    """The views of every model and of its overlays."""
    import pumpup

    out = []
    for f, given in zip(models, inputs):
        shader = shader_source(f)
        # the page draws the lit sphere with the shader's GLSL; without one, pumpup renders it here
        entry = _one(f, {**st, "server_sphere": st["server_sphere"] or shader is None or "error" in shader}, check,
                     True)
        entry["input"] = given
        entry["short"] = short_spec(given)
        entry["shader"] = shader
        overlays = []
        if st["pump"]["on"]:
            overlays.append(("pumped", lambda f=f: pumpup.pump(f, g=st["pump"]["g"], levels=st["pump"]["levels"])))
        if st["kulla_conty"]:
            overlays.append(("kulla_conty", lambda f=f: pumpup.compensate(f, method="kulla_conty")))
        if st["scaled"]:
            overlays.append(("scaled", lambda f=f: pumpup.compensate(f, method="scale")))
        entry["overlays"] = {}
        for name, make in overlays:
            check()
            try:
                g = make()
                entry["overlays"][name] = _one(g, {**st, "server_sphere": False}, check, False)
            except (SpecError, ValueError, ArithmeticError) as exc:
                entry["overlays"][name] = {"error": str(exc)}
        out.append(entry)
    return out
