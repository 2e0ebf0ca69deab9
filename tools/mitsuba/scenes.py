"""The Mitsuba 3 cross-check scenes (described in scenes.md) and the shared
pieces of the tools in this directory: Mitsuba set-up, Stokes EXR I/O,
per-pixel camera rays and the comparison metrics.

Mitsuba must be imported through `setup_mitsuba()` so that the LLVM backend
finds Debian's libLLVM (DRJIT_LIBLLVM_PATH), the thread count is set
before the first kernel runs and the polarized Rayleigh phase function
(rayleigh_phase.py) is registered.
"""

import functools
import os
import tomllib
from pathlib import Path

import numpy as np

import rayleigh_phase

VARIANT = "llvm_ad_mono_polarized"
LIBLLVM = "/usr/lib/x86_64-linux-gnu/libLLVM-19.so"

REPO = Path(__file__).resolve().parents[2]
SCENE_DIR = REPO / "datasets-synth" / "scenes" / "crosscheck"

# Camera and lights common to the four surface scenes (scenes.md, "Common to all four").
WIDTH = HEIGHT = 128
FOV_DEG = 30.0
ORIGIN = np.array([0.0, 0.0, 5.0])
TARGET = np.array([0.0, 0.0, 0.0])
UP = np.array([0.0, 1.0, 0.0])
SPHERE_RADIUS = 1.0
ENV_RADIANCE = 0.5
SUN_IRRADIANCE = 4.0
SUN_TRAVEL = [-1.0, -1.0, -1.0]  # direction the sun's light travels (Mitsuba `direction`)
MAX_DEPTH = 16  # Mitsuba counting: at most 15 scattering events

MATERIALS = {
    "conductor": {"type": "conductor", "eta": 0.2, "k": 3.0},
    "roughconductor": {
        "type": "roughconductor",
        "distribution": "ggx",
        "alpha": 0.2,
        "eta": 0.2,
        "k": 3.0,
    },
    "pplastic": {
        "type": "pplastic",
        "distribution": "ggx",
        "diffuse_reflectance": 0.5,
        "alpha": 0.1,
        "int_ior": 1.5,
        "ext_ior": 1.0,
    },
    "dielectric": {"type": "dielectric", "int_ior": 1.5, "ext_ior": 1.0},
}
SURFACE_SCENES = list(MATERIALS)

# The hazy scene (scenes.md, "haze"): a box of Rayleigh medium lit by the sun
# from the side, a Lambertian sphere inside it, no environment (black behind).
# Its one source is our scene file, read by haze() below.
SCENES = SURFACE_SCENES + ["haze"]

# Reference spp per scene: enough for the reference's own S0 error (one render
# against the truth) to stay near or below 1% over the sphere pixels, as
# measured between two independent Mitsuba renders (docs/performance-notes.md). Mitsuba picks
# one of the two emitters per next-event estimate, so the sun's highlight on
# the rough sphere is what needs most samples.
REFERENCE_SPP = {"conductor": 1024, "roughconductor": 32768, "pplastic": 16384, "dielectric": 4096, "haze": 16384}
# Our renderer's spp in the cross-check: its own S0 noise about 1% where the
# reference leaves room (measured: no bias above 0.1%, README.md).
OURS_SPP = {"conductor": 256, "roughconductor": 16384, "pplastic": 4096, "dielectric": 1024, "haze": 16384}


def setup_mitsuba(threads=None):
    """Imports Mitsuba with the LLVM polarized variant and registers the
    polarized Rayleigh phase function; returns (mi, dr)."""
    os.environ.setdefault("DRJIT_LIBLLVM_PATH", LIBLLVM)
    import drjit as dr
    import mitsuba as mi

    mi.set_variant(VARIANT)
    mi.set_log_level(mi.LogLevel.Error)
    if threads is not None:
        dr.set_thread_count(threads)
    rayleigh_phase.register(mi, dr)
    return mi, dr


@functools.cache
def haze():
    """The `haze` scene's parameters, read from SCENE_DIR/haze.toml (our
    renderer's scene file, the one source of the scene): camera size, medium
    box, sigma_s, sigma_a, the sphere and its albedo, the sun. Everything else
    in the file must be what the Mitsuba translation assumes (the common camera,
    max_depth, a Rayleigh phase function, one Lambertian sphere, one sun),
    else ValueError names the key."""
    path = SCENE_DIR / "haze.toml"
    doc = tomllib.loads(path.read_text())

    def need(ok, what):
        if not ok:
            raise ValueError(f"{path}: {what} (the Mitsuba translation in scenes.py assumes it)")

    cam, med = doc["camera"], doc["medium"]
    need(cam["position"] == ORIGIN.tolist() and cam["look_at"] == TARGET.tolist() and cam["up"] == UP.tolist()
         and cam["fov_deg"] == FOV_DEG, "camera must be the common cross-check camera")
    need(doc["render"]["max_depth"] == MAX_DEPTH - 1, f"render.max_depth must be {MAX_DEPTH - 1}")
    need(med["phase"] == {"type": "rayleigh"}, "medium.phase must be rayleigh")
    (shape,), (light,) = doc["shapes"], doc["lights"]
    material = doc["materials"][shape["material"]]
    need(shape["type"] == "sphere" and set(material) == {"type", "albedo"} and material["type"] == "lambertian",
         "the one shape must be a sphere with a lambertian material")
    need(light["type"] == "sun" and "polarization" not in light, "the one light must be an unpolarized sun")
    lo, hi, c = (np.array(v, float) for v in (med["bounds_min"], med["bounds_max"], shape["center"]))
    need(np.all(lo + shape["radius"] <= c) and np.all(c + shape["radius"] <= hi), "the sphere must lie inside the medium box")
    return {
        "size": (cam["width"], cam["height"]),
        "bounds_min": med["bounds_min"],
        "bounds_max": med["bounds_max"],
        "sigma_s": med["sigma_s"],
        "sigma_a": med["sigma_a"],
        "center": shape["center"],
        "radius": shape["radius"],
        "albedo": material["albedo"],
        "sun_toward": light["direction"],  # toward the sun: the light travels along -sun_toward
        "sun_irradiance": light["irradiance"],
    }


def image_size(name):
    """(width, height) of cross-check scene `name`."""
    return haze()["size"] if name == "haze" else (WIDTH, HEIGHT)


def look_at(mi):
    """The camera-to-world transform of the cross-check camera."""
    return mi.ScalarTransform4f().look_at(
        origin=ORIGIN.tolist(), target=TARGET.tolist(), up=UP.tolist()
    )


# Mitsuba's samplers (bench.py compares them; the cross-check uses `independent`).
# `orthogonal` rounds the sample count up to the square of a prime (16 -> 25,
# 64 -> 121, 256 -> 289, 1024 -> 1369): read the count back, do not assume it.
SAMPLERS = ["independent", "stratified", "multijitter", "orthogonal", "ldsampler"]


def sensor_dict(mi, spp, width=WIDTH, height=HEIGHT, sampler="independent"):
    """Perspective sensor with a box filter and the given sampler (default independent)."""
    return {
        "type": "perspective",
        "fov": FOV_DEG,
        "fov_axis": "x",
        "to_world": look_at(mi),
        "film": {
            "type": "hdrfilm",
            "width": width,
            "height": height,
            "rfilter": {"type": "box"},
        },
        "sampler": {"type": sampler, "sample_count": spp},
    }


def stokes_integrator(max_depth=MAX_DEPTH, inner="path"):
    """Mitsuba's `stokes` integrator around a path tracer (`volpath` with media)."""
    return {"type": "stokes", "integrator": {"type": inner, "max_depth": max_depth}}


def haze_dict(mi, spp, sampler="independent"):
    """The Mitsuba scene of `haze`: the medium fills a null-BSDF cube (its
    `interior`); the sphere inside declares it as its `exterior` (volpath
    keeps the current medium at a surface that is no medium transition, so
    this only makes the nesting explicit: same image, README.md)."""
    h = haze()
    lo, hi = np.array(h["bounds_min"]), np.array(h["bounds_max"])
    sigma_t = h["sigma_s"] + h["sigma_a"]
    medium = {
        "type": "homogeneous",
        "sigma_t": sigma_t,
        "albedo": h["sigma_s"] / sigma_t,
        "phase": {"type": rayleigh_phase.PLUGIN},
    }
    return {
        "type": "scene",
        "integrator": stokes_integrator(inner="volpath"),
        "sensor": sensor_dict(mi, spp, *h["size"], sampler=sampler),
        "haze": medium,
        "box": {
            "type": "cube",
            "to_world": mi.ScalarTransform4f().translate(((lo + hi) / 2).tolist()).scale(((hi - lo) / 2).tolist()),
            "bsdf": {"type": "null"},
            "interior": {"type": "ref", "id": "haze"},
        },
        "sphere": {
            "type": "sphere",
            "center": h["center"],
            "radius": h["radius"],
            "bsdf": {"type": "diffuse", "reflectance": h["albedo"]},
            "exterior": {"type": "ref", "id": "haze"},
        },
        "sun": {"type": "directional", "direction": (-np.array(h["sun_toward"], float)).tolist(),
                "irradiance": h["sun_irradiance"]},
    }


def scene_dict(mi, name, spp, sampler="independent"):
    """The Mitsuba scene dictionary of cross-check scene `name` (sampler: one of SAMPLERS)."""
    if name == "haze":
        return haze_dict(mi, spp, sampler)
    return {
        "type": "scene",
        "integrator": stokes_integrator(),
        "sensor": sensor_dict(mi, spp, sampler=sampler),
        "sphere": {
            "type": "sphere",
            "center": [0.0, 0.0, 0.0],
            "radius": SPHERE_RADIUS,
            "bsdf": MATERIALS[name],
        },
        "sun": {"type": "directional", "direction": SUN_TRAVEL, "irradiance": SUN_IRRADIANCE},
        "env": {"type": "constant", "radiance": ENV_RADIANCE},
    }


def render_stokes(mi, scene, spp, seed=0):
    """Renders `scene` and returns an (H, W, 4) float32 array S0..S3.

    The `stokes` integrator writes AOVs after the film's own channel:
    [Y, S0.R, S0.G, S0.B, S1.R, ..., S3.B]; in a mono variant R = G = B, so
    S_k is channel 1 + 3k. The channel names are checked, not assumed.
    """
    img = np.asarray(mi.render(scene, spp=spp, seed=seed), dtype=np.float32)
    names = ["Y"] + list(scene.integrator().aov_names())
    if img.shape[2] != len(names):
        raise RuntimeError(f"expected channels {names}, got {img.shape[2]} channels")
    return np.stack([img[..., names.index(f"S{k}.R")] for k in range(4)], axis=-1)


def write_stokes_exr(mi, path, stokes):
    """Writes float32 channels S0, S1, S2, S3 (the conventions' stokes.exr)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    bmp = mi.Bitmap(
        np.ascontiguousarray(stokes, dtype=np.float32),
        pixel_format=mi.Bitmap.PixelFormat.MultiChannel,
        channel_names=["S0", "S1", "S2", "S3"],
    )
    bmp.write(str(path))


def read_stokes_exr(mi, path):
    """Reads S0..S3 from an EXR by channel name; a missing S3 reads as zero."""
    bmp = mi.Bitmap(str(path))
    names = [bmp.struct_()[i].name for i in range(bmp.channel_count())]
    if not {"S0", "S1", "S2"} <= set(names):
        raise RuntimeError(f"{path}: needs channels S0, S1, S2; has {names}")
    data = np.asarray(bmp, dtype=np.float32).reshape(bmp.height(), bmp.width(), len(names))
    zero = np.zeros(data.shape[:2], np.float32)
    return np.stack([data[..., names.index(c)] if c in names else zero for c in ("S0", "S1", "S2", "S3")], axis=-1)


def camera_basis():
    """Orthonormal camera axes (right, up, forward) in world space."""
    forward = (TARGET - ORIGIN) / np.linalg.norm(TARGET - ORIGIN)
    right = np.cross(forward, UP)
    right /= np.linalg.norm(right)
    return right, np.cross(right, forward), forward


def pixel_rays(width=WIDTH, height=HEIGHT, fov_deg=FOV_DEG):
    """Unit world directions d (H, W, 3) through the pixel centres."""
    right, up, forward = camera_basis()
    t = np.tan(np.radians(fov_deg) / 2)
    x = ((np.arange(width) + 0.5) / width * 2 - 1) * t
    y = (1 - (np.arange(height) + 0.5) / height * 2) * t * height / width
    d = forward + x[None, :, None] * right + y[:, None, None] * up
    return d / np.linalg.norm(d, axis=-1, keepdims=True)


def reference_frame(d, up=UP):
    """The conventions' per-pixel frame: x_ref = normalize(d x u), y_ref = x_ref x d."""
    x_ref = np.cross(d, up)
    x_ref /= np.linalg.norm(x_ref, axis=-1, keepdims=True)
    return x_ref, np.cross(x_ref, d)


def sphere_mask():
    """Pixels whose centre ray hits the sphere (the cross-check's object pixels)."""
    d = pixel_rays()
    oc = ORIGIN - 0.0
    b = d @ oc
    disc = b**2 - (oc @ oc - SPHERE_RADIUS**2)
    return (disc > 0) & (-b - np.sqrt(np.maximum(disc, 0)) > 0)


def box_mask(lo, hi, width, height):
    """Pixels whose centre ray crosses the box [lo, hi] (slab test)."""
    d = pixel_rays(width, height)
    with np.errstate(divide="ignore", invalid="ignore"):
        t1, t2 = (np.array(lo) - ORIGIN) / d, (np.array(hi) - ORIGIN) / d
    near = np.nanmax(np.minimum(t1, t2), axis=-1)
    far = np.nanmin(np.maximum(t1, t2), axis=-1)
    return (far > np.maximum(near, 0.0))


def object_mask(name):
    """The pixels the figures are taken over: the sphere's, or for `haze` the medium box's."""
    if name == "haze":
        return box_mask(haze()["bounds_min"], haze()["bounds_max"], *image_size(name))
    return sphere_mask()


def dolp(s):
    """sqrt(S1^2 + S2^2) / S0; NaN where S0 <= 0 or not finite."""
    s0 = s[..., 0]
    ok = np.isfinite(s0) & (s0 > 0)
    out = np.full(s0.shape, np.nan)
    out[ok] = np.hypot(s[..., 1], s[..., 2])[ok] / s0[ok]
    return out


def aolp(s):
    """0.5 atan2(S2, S1) wrapped to [0, pi)."""
    return np.mod(0.5 * np.arctan2(s[..., 2], s[..., 1]), np.pi)


def angle_diff(a, b):
    """a - b for axial angles (period pi), in [-pi/2, pi/2)."""
    return np.mod(a - b + np.pi / 2, np.pi) - np.pi / 2


def compare(ours, ref, mask, dolp_min=0.05):
    """The cross-check figures of `ours` against `ref` over `mask` (scenes.md)."""
    d_ours, d_ref = dolp(ours), dolp(ref)
    pol = mask & (d_ref > dolp_min)
    s0o, s0r = ours[..., 0][mask], ref[..., 0][mask]
    daolp = np.abs(angle_diff(aolp(ours), aolp(ref)))[pol]
    return {
        "dolp_mae": float(np.nanmean(np.abs(d_ours - d_ref)[mask])),
        "aolp_mae_deg": float(np.degrees(daolp.mean())) if pol.any() else 0.0,
        "aolp_pixels": int(pol.sum()),
        "s0_rel_rmse": float(np.sqrt(np.mean((s0o - s0r) ** 2)) / np.mean(s0r)),
    }


LIMITS = {"dolp_mae": 0.01, "aolp_mae_deg": 2.0, "s0_rel_rmse": 0.02}


def passes(figures):
    """True when every figure is within LIMITS (NaN fails)."""
    return all(figures[k] <= v for k, v in LIMITS.items())
