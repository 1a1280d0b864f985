"""White-furnace renders of a metal sphere in Blender Cycles and Mitsuba 3, read along rings of constant view cosine.

A sphere of F = 1 metal (white base colour and edge tint) under a uniform white environment, seen by an
orthographic camera: every pixel's value is the furnace toward the viewer at the view cosine mu of its normal,
which :func:`pumpup.furnace_prediction` predicts.  The renders keep what the comparison needs: a box pixel filter
one pixel wide; no adaptive sampling, denoising or clamping; a transparent film (alpha is the pixel's coverage;
only fully covered pixels are used) and the shading-normal pass (a check of the geometry).  Cycles' default
blue-noise pattern correlates the errors of pixels whose integrands are alike, as a ring's are: the standard error
of a ring comes from renders with different seeds.

:func:`rings` bins the pixels by mu and gives, per ring, the render's mean, the prediction's mean at the same
pixels, and the Monte Carlo standard error of their difference (the scatter of the pixel residuals over the square
root of their number).

``bpy`` (the ``blender`` extra) and ``mitsuba`` (the ``render`` extra) are imported only by the functions that
render.
"""

from __future__ import annotations

import os
import tempfile

import numpy as np

__all__ = ["render_cycles", "render_mitsuba", "rings", "compare_rings"]


def _read_exr_layers(path: str) -> dict:
    import OpenEXR

    out = {}
    with OpenEXR.File(path) as f:
        for part in f.parts:
            for name, ch in part.channels.items():
                out[name] = np.asarray(ch.pixels, dtype=np.float64)
    return out


def render_cycles(roughness: float, distribution: str = "MULTI_GGX", *, resolution: int = 128, spp: int = 64,
                  seed: int = 1, threads: int = 2, pattern: str = "AUTOMATIC", keep: str | None = None) -> dict:
    """Render the furnace sphere with Cycles on the CPU (``bpy``).

    Parameters
    ----------
    roughness : float
        The Metallic BSDF's roughness r in [0, 1] (Cycles' alpha = r^2).
    distribution : {"MULTI_GGX", "GGX", "BECKMANN"}
        The Metallic BSDF's distribution: "MULTI_GGX" (the default in Blender) scales the GGX lobe by 1 / E of its
        shipped table (``microfacet_ggx_preserve_energy``); "GGX" is the single-scattering lobe.
    resolution, spp, seed, threads : int
        Square image size in pixels, samples per pixel, Cycles' seed, CPU threads.
    pattern : str
        Cycles' sampling pattern: "AUTOMATIC" (Blender's default, blue noise), or the debug options
        "TABULATED_SOBOL", "SOBOL_BURLEY", ... (Sobol-Burley renders this furnace with an offset that depends on
        the sample count and not on the seed).
    keep : str, optional
        Keep the rendered multilayer EXR at this path.

    Returns
    -------
    dict
        ``value`` (mean of R, G, B over coverage), ``alpha`` (coverage), ``mu`` (shading normal's z over coverage:
        the view cosine), each an array of shape (resolution, resolution); ``seconds``; ``version``.
    """
    import time

    from ._extras import MissingExtraError

    try:
        import bpy
    except ImportError as exc:
        raise MissingExtraError(
            "the Cycles furnace render needs bpy, which is not installed: pip install --no-deps \"bpy>=5,<6\" "
            "(the blender extra; bpy 5.0 declares numpy < 2, which pumpup's other dependencies exclude, and runs "
            "with numpy 2)") from exc
    if distribution not in ("MULTI_GGX", "GGX", "BECKMANN"):
        raise ValueError(f"distribution must be MULTI_GGX, GGX or BECKMANN; got {distribution!r}")
    if not 0.0 <= roughness <= 1.0:
        raise ValueError(f"roughness must be in [0, 1]; got {roughness!r}")
    bpy.ops.wm.read_factory_settings(use_empty=True)
    sc = bpy.context.scene
    sc.render.engine = "CYCLES"
    cy = sc.cycles
    cy.device = "CPU"
    cy.samples = int(spp)
    cy.use_adaptive_sampling = False
    cy.use_denoising = False
    cy.sample_clamp_direct = 0.0
    cy.sample_clamp_indirect = 0.0
    cy.max_bounces = 4
    cy.seed = int(seed)
    if pattern != "AUTOMATIC":  # the others are debug options
        bpy.context.preferences.experimental.use_cycles_debug = True
        bpy.context.preferences.view.show_developer_ui = True
    cy.sampling_pattern = pattern
    cy.pixel_filter_type = "BOX"
    cy.filter_width = 1.0  # each sample lands in one pixel: independent pixels
    sc.render.threads_mode = "FIXED"
    sc.render.threads = int(threads)
    sc.render.film_transparent = True
    sc.render.resolution_x = sc.render.resolution_y = int(resolution)
    sc.render.resolution_percentage = 100
    sc.view_settings.view_transform = "Standard"
    sc.view_settings.look = "None"
    world = bpy.data.worlds.new("furnace")
    sc.world = world
    world.use_nodes = True
    bg = world.node_tree.nodes.get("Background")
    bg.inputs[0].default_value = (1.0, 1.0, 1.0, 1.0)
    bg.inputs[1].default_value = 1.0
    # an exact sphere: one point of radius 1 (Cycles renders points as spheres, with analytic normals)
    me = bpy.data.meshes.new("point")
    me.from_pydata([(0.0, 0.0, 0.0)], [], [])
    ob = bpy.data.objects.new("sphere", me)
    sc.collection.objects.link(ob)
    ng = bpy.data.node_groups.new("to_point", "GeometryNodeTree")
    ng.interface.new_socket("Geometry", in_out="INPUT", socket_type="NodeSocketGeometry")
    ng.interface.new_socket("Geometry", in_out="OUTPUT", socket_type="NodeSocketGeometry")
    gi, go = ng.nodes.new("NodeGroupInput"), ng.nodes.new("NodeGroupOutput")
    m2p = ng.nodes.new("GeometryNodeMeshToPoints")
    m2p.inputs["Radius"].default_value = 1.0
    setmat = ng.nodes.new("GeometryNodeSetMaterial")
    mat = bpy.data.materials.new("white_metal")
    mat.use_nodes = True
    nt = mat.node_tree
    for node in list(nt.nodes):
        if node.type != "OUTPUT_MATERIAL":
            nt.nodes.remove(node)
    metal = nt.nodes.new("ShaderNodeBsdfMetallic")
    metal.distribution = distribution
    metal.fresnel_type = "F82"
    metal.inputs["Base Color"].default_value = (1.0, 1.0, 1.0, 1.0)  # F0 = 1
    metal.inputs["Edge Tint"].default_value = (1.0, 1.0, 1.0, 1.0)  # F82 = 1: F = 1 at every angle
    metal.inputs["Roughness"].default_value = float(roughness)
    nt.links.new(metal.outputs[0], nt.nodes.get("Material Output").inputs["Surface"])
    setmat.inputs["Material"].default_value = mat
    ng.links.new(gi.outputs[0], m2p.inputs["Mesh"])
    ng.links.new(m2p.outputs[0], setmat.inputs["Geometry"])
    ng.links.new(setmat.outputs[0], go.inputs[0])
    ob.modifiers.new("to_point", "NODES").node_group = ng
    cam = bpy.data.cameras.new("ortho")
    cam.type = "ORTHO"
    cam.ortho_scale = 2.05
    co = bpy.data.objects.new("camera", cam)
    co.location = (0.0, 0.0, 10.0)  # looking down -z: mu = N_z
    sc.collection.objects.link(co)
    sc.camera = co
    sc.view_layers[0].use_pass_normal = True
    ims = sc.render.image_settings
    if hasattr(ims, "media_type"):  # Blender 5
        ims.media_type = "MULTI_LAYER_IMAGE"
    ims.file_format = "OPEN_EXR_MULTILAYER"
    ims.color_depth = "32"
    with tempfile.TemporaryDirectory() as tmp:
        path = keep or os.path.join(tmp, "furnace.exr")
        sc.render.filepath = path
        t0 = time.perf_counter()
        bpy.ops.render.render(write_still=True)
        seconds = time.perf_counter() - t0
        ch = _read_exr_layers(path)
    comb = ch["ViewLayer.Combined"]
    a = comb[..., 3]
    cover = np.where(a > 0, a, np.nan)
    return {"value": comb[..., :3].mean(axis=-1) / cover, "alpha": a, "mu": ch["ViewLayer.Normal.Z"] / cover,
            "seconds": seconds, "version": bpy.app.version_string}


def render_mitsuba(alpha: float, *, resolution: int = 128, spp: int = 64, seed: int = 1,
                   variant: str | None = None) -> dict:
    """Render the furnace sphere with Mitsuba 3's ``roughconductor`` (GGX, ``material = "none"``: F = 1).

    Parameters
    ----------
    alpha : float
        Mitsuba's GGX alpha.
    resolution, spp, seed : int
        Square image size, samples per pixel, sampler seed.
    variant : str, optional
        The Mitsuba variant (default: :func:`pumpup.mitsuba.register`'s choice).

    Returns
    -------
    dict
        ``value``, ``alpha`` (coverage), ``mu`` as :func:`render_cycles`; ``seconds``; ``version``.
    """
    import time

    from ._extras import require

    mi = require("mitsuba", "the Mitsuba furnace render")
    from . import mitsuba as pm

    pm.register(variant)
    scene = mi.load_dict({
        "type": "scene",
        "integrator": {"type": "aov", "aovs": "nn:sh_normal", "image": {"type": "path", "max_depth": 4}},
        "sensor": {"type": "orthographic",
                   "to_world": mi.ScalarTransform4f().look_at(origin=[0, 0, 10], target=[0, 0, 0], up=[0, 1, 0])
                   @ mi.ScalarTransform4f().scale([1.025, 1.025, 1.0]),
                   "film": {"type": "hdrfilm", "width": int(resolution), "height": int(resolution),
                            "pixel_format": "rgba", "rfilter": {"type": "box"}},
                   "sampler": {"type": "independent", "sample_count": int(spp)}},
        "emitter": {"type": "constant", "radiance": {"type": "rgb", "value": 1.0}},
        "sphere": {"type": "sphere", "radius": 1.0,
                   "bsdf": {"type": "roughconductor", "distribution": "ggx", "alpha": float(alpha),
                            "material": "none"}},
    })
    t0 = time.perf_counter()
    img = np.asarray(mi.render(scene, spp=int(spp), seed=int(seed)), dtype=np.float64)
    seconds = time.perf_counter() - t0
    # the environment counts as a hit in Mitsuba's alpha: the coverage is the length of the pixel's mean shading
    # normal (1 where every sample hit the sphere, less at the rim, 0 on the background)
    nn = img[..., 4:7]
    cover = np.linalg.norm(nn, axis=-1)
    mu = nn[..., 2] / np.where(cover > 0, cover, np.nan)
    return {"value": img[..., :3].mean(axis=-1), "alpha": cover, "mu": mu, "seconds": seconds,
            "version": mi.__version__}


def rings(renders, predict, edges=None, *, extent: float | None = 1.025, subpixels: int = 8,
          min_alpha: float = 0.9999, min_pixels: int = 20) -> list[dict]:
    """The render against a prediction along rings of constant view cosine.

    Parameters
    ----------
    renders : dict or list of dict
        ``value``, ``alpha`` and ``mu`` arrays (:func:`render_cycles`, :func:`render_mitsuba`); a list holds
        renders of the same scene with different seeds.
    predict : callable
        ``predict(mu)`` -> the predicted furnace at each view cosine (a 1-D array in, the same shape out); it is
        evaluated on 4097 view cosines and interpolated.
    edges : array_like, optional
        Ring edges in mu (default 10 rings of width 0.1).
    extent : float or None
        Half the image's width in sphere radii (both renders frame the unit sphere in [-1.025, 1.025]^2): a pixel
        then belongs to the ring of its footprint's mean mu on the exact sphere, and its prediction is averaged
        over ``subpixels`` x ``subpixels`` points of that footprint (near the rim mu varies by 0.1 across a pixel,
        and the furnace is not linear in mu).  None uses the normal pass's mu for both.
    min_alpha : float
        The coverage from which a pixel counts as inside the sphere (in every render).

    Returns
    -------
    list of dict
        Per ring with at least ``min_pixels`` pixels: ``mu_lo``, ``mu_hi``, ``mu`` (mean), ``n`` (pixels),
        ``render``, ``predicted`` (means over the same pixels and renders), ``difference`` (render - predicted),
        ``se``, its Monte Carlo standard error, and ``geometry`` (largest |normal pass - footprint mean| of mu in
        the ring, with ``extent``).  With several renders, ``se`` is the scatter of the renders' ring differences
        over the square root of their number, which holds whatever the sampler correlates between pixels (Cycles'
        default blue-noise pattern does); with one, it is the scatter of the pixel residuals over the square root
        of their number, which assumes independent pixels.
    """
    renders = [renders] if isinstance(renders, dict) else list(renders)
    edges = np.linspace(0.0, 1.0, 11) if edges is None else np.asarray(edges, dtype=np.float64)
    full = np.ones(renders[0]["value"].shape, bool)
    for rd in renders:
        full &= (rd["alpha"] > min_alpha) & np.isfinite(rd["mu"]) & np.isfinite(rd["value"])
    mu = np.clip(renders[0]["mu"][full], 1e-6, 1.0)
    vals = np.stack([rd["value"][full] for rd in renders])
    grid = np.linspace(0.0, 1.0, 4097)
    grid[0] = 1e-6
    table = np.asarray(predict(grid), dtype=np.float64)
    if extent is None:
        pred = np.interp(mu, grid, table)
        mu_fp = mu
    else:
        n_rows, n_cols = renders[0]["value"].shape
        rows, cols = np.nonzero(full)
        sub = (np.arange(subpixels) + 0.5) / subpixels
        x = ((cols[:, None, None] + sub[None, None, :]) / n_cols * 2 - 1) * extent
        y = ((rows[:, None, None] + sub[None, :, None]) / n_rows * 2 - 1) * extent
        m = np.sqrt(np.clip(1.0 - x * x - y * y, 0.0, 1.0)).reshape(len(rows), -1)
        hit = m > 0
        pred = np.sum(np.where(hit, np.interp(m, grid, table), 0.0), axis=1) / np.maximum(hit.sum(axis=1), 1)
        mu_fp = np.sum(m, axis=1) / np.maximum(hit.sum(axis=1), 1)
    out = []
    for lo, hi in zip(edges[:-1], edges[1:]):
        # membership by the footprint's mu: the normal pass is a sample mean over the same sub-pixel positions as
        # the radiance, so choosing pixels by it would choose their radiance's noise too
        s = (mu_fp > lo) & (mu_fp <= hi)
        n = int(s.sum())
        if n < min_pixels:
            continue
        res = vals[:, s] - pred[s][None, :]
        per_render = res.mean(axis=1)
        if len(renders) > 1:
            se = float(per_render.std(ddof=1) / np.sqrt(len(renders)))
        else:
            se = float(res[0].std(ddof=1) / np.sqrt(n))
        out.append({"mu_lo": float(lo), "mu_hi": float(hi), "mu": float(mu_fp[s].mean()), "n": n,
                    "render": float(vals[:, s].mean()), "predicted": float(pred[s].mean()),
                    "difference": float(per_render.mean()), "se": se,
                    "geometry": float(np.max(np.abs(mu[s] - mu_fp[s])))})
    return out


def compare_rings(table: list[dict], k: float = 3.0) -> tuple[bool, float]:
    """(every ring within ``k`` standard errors, the largest |difference| / se)."""
    z = max(abs(r["difference"]) / r["se"] for r in table)
    return bool(z <= k), float(z)
