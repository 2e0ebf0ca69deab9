#!/usr/bin/env python3
"""Vision-task scenes rendered by Mitsuba 3 itself, written as sample
directories in our format (docs/conventions.md).

Why: the vision tasks (shape from polarization, material classification,
transparent-object detection, dehazing) will be scored by outside people on
scenes made by a renderer that is not ours. Everything our datagen makes
shares our renderer's BSDF models, light models and scene recipes, so a
method can fit our renderer's quirks and still look good on our own data.
These scenes close that loop a little: Mitsuba's own BSDFs (`pplastic`,
`conductor` / `roughconductor` with Mitsuba's spectral material names Au, Ag,
Al, Cu, `dielectric`, `diffuse`), Mitsuba's own lights
(`constant` environment, `directional` sun, `sphere` area lights) and
camera (`perspective`, fov_axis x), and scene layouts written here from
scratch (deliberately not our datagen's recipes). The generalization gap is
then what `polar-vision eval` measures on them.

What it makes, under --out (default /work/data/mitsuba-tasks), one folder per
scene and noise level, named `mts-<kind>-<noise>-<k>` so that the eval's
family (the folder name without its trailing -digits) is `mts-<kind>-<noise>`;
the noisy family holds --noise-draws draws of the sensor noise per scene, draw d
of scene k numbered k + 10 d (`mts-shape-noisy-13` is draw 1 of scene 3):

  kind      scenes  content
  shape     4       pplastic / diffuse spheres, ellipsoids, a torus, a rounded
                    cube (meshes generated here as PLY with analytic normals)
                    on a floor under an environment plus a sun or a sphere light
  material  3       Mitsuba conductors (Au, Ag, Al, Cu; smooth and rough) next
                    to pplastic and diffuse objects
  glass     3       dielectric spheres, a slab and an ellipsoid
                    in front of a checkerboard backdrop, plus a shiny opaque
                    distractor (pplastic or silver)
  glasshard 4       the hard cases of transparency, one per scene: glass in
                    front of an opaque object, glass seen against glass, thin
                    walls (a drinking glass, a blown bulb), glass in front of
                    a plain wall. Frosted glass is not among them: Mitsuba's
                    roughdielectric returns unpolarized light (DoLP 0 over
                    it), so our datagen's rough glass stands for it
  haze      2       opaque objects at increasing distance in a homogeneous
                    medium with the project's polarized Rayleigh phase
                    function (rayleigh_phase.py) in `volpath`, sun from the side

  and a second set, written after the methods' last change and measured once
  (held out: not for tuning), with shapes, lights and layouts the first lacks:
  shape2    4       a vase with a concave neck, a boxier superquadric, a
                    cylinder with sharp rims, a flattened and a lying ellipsoid,
                    touching spheres; sky alone, a grazing sun, a lamp overhead,
                    the sun behind the camera
  material2 3       rough gold, smooth aluminium, a copper vase, a rough silver
                    torus, a silver and a plastic cylinder of one shape, white
                    and black glossy plastic, a matte cube
  glass2    3       a glass cylinder, a glass superquadric and torus, a glass
                    egg lying on the floor; a glossy white and a gold distractor
  haze2     2       cylinders, a vase, boxy blocks; thin haze with the sun at
                    right angles, dense haze with the sun behind the camera

  noise: `clean` (noiseless 12-bit quantization) and `noisy` (Poisson shot
  noise, full well FULL_WELL_E, Gaussian read noise READ_NOISE_E); all share
  the same Stokes image and ground truth. One draw of four small noisy frames
  moves a task's mean by several degrees or points, so the noisy figure is a
  mean over draws; and each pixel's noise is the Poisson quantile of its own
  uniform draw, so a render that differs in its last bits on another machine
  keeps the same noise (`sensor_noise`; `--check-noise` tests both).

Each sample directory holds
  stokes.exr         float32 S0..S3 from Mitsuba's `stokes` integrator: its
                     frame is the conventions' per-pixel frame (docs/performance-notes.md),
                     so no conversion
  polarizers.exr     I0, I45, I90, I135 = 1/2 (S0 + S1 cos 2t + S2 sin 2t)
  raw.png            16-bit PNG holding right-aligned 12-bit DN, mosaic
                     row 0 = [90, 45], row 1 = [135, 0]; the 99th percentile of
                     S0 maps to P99_FRACTION of 4095 DN
  meta.json          our own keys; `camera.fov_deg` with `fov_axis` "x" is the
                     one documented key the tools read
  gt/normal.exr      R, G, B unit camera-frame normal (x right, y up, z toward
                     the viewer), 0 where no surface
  gt/depth.exr       Y = distance along -z (camera axis), 0 where no surface
  gt/material.png    0 background (floor, walls, sky, lights), 1 opaque
                     dielectric, 2 metal, 3 transparent
  gt/transparent.png 255 on transparent objects
  haze only:
  gt/clear.exr       Y = S0 of the same scene without the medium
  gt/transmission.exr Y = exp(-sigma_t * L), L = length of the pixel's central
                     ray inside the medium up to the first surface (the
                     medium's far side where there is none), analytic
  gt/dehazed.exr     Y = S0 with the camera segment free of the medium but the
                     objects still lit through it: each camera ray is restarted
                     just in front of its first surface (or the medium's far
                     side) and traced there by `volpath` inside the medium

The ground truth is taken along the pixel-centre rays (Mitsuba's own
`sensor.sample_ray` and `scene.ray_intersect`); the Stokes images are
box-filtered pixel means.

    tools/.venv/bin/python tools/mitsuba/task_scenes.py [--out DIR] [--spp 1024]
        [--haze-spp 512] [--size 128] [--threads 2] [--only PREFIX,..] [--no-dehazed]
        [--noise-draws 5] [--redraw-noise] [--check-noise]

Defaults take about 9.5 minutes on 2 cores for the first set (each surface scene 16 to 47 s, each
haze scene 2 to 2.5 minutes: volpath with free-flight shadow rays is slow
and noisy). Results of `polar-vision eval` on them: task_scenes.md.
"""

import argparse
import json
import shutil
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from PIL import Image

sys.path.insert(0, str(Path(__file__).resolve().parent))
import rayleigh_phase  # noqa: E402
import scenes as common  # noqa: E402

DEFAULT_OUT = Path("/work/data/mitsuba-tasks")
BITS = 12
FULL_SCALE = (1 << BITS) - 1
P99_FRACTION = 0.8
FULL_WELL_E = 10500.0
READ_NOISE_E = 2.3
MAX_DEPTH = 12
HAZE_MAX_DEPTH = 8
UP = [0.0, 1.0, 0.0]
# Mosaic: the polarizer angle (degrees) of pixel (row % 2, column % 2).
MOSAIC = np.array([[90.0, 45.0], [135.0, 0.0]])
# Noise draw d of scene k is sample `mts-<kind>-noisy-<k + SCENES_PER_DRAW d>`.
SCENES_PER_DRAW = 10
MAX_DRAWS = 100
LABEL_BACKGROUND, LABEL_DIELECTRIC, LABEL_METAL, LABEL_TRANSPARENT = 0, 1, 2, 3


# --------------------------------------------------------------------------- meshes
def sphere_directions(nu, nv):
    """Unit directions on a (nv + 1) x nu latitude-longitude grid (poles
    repeated, longitude wrapping) and its triangles."""
    th = np.linspace(0.0, np.pi, nv + 1)
    ph = np.linspace(0.0, 2 * np.pi, nu, endpoint=False)
    t, p = np.meshgrid(th, ph, indexing="ij")
    d = np.stack([np.sin(t) * np.cos(p), np.cos(t), np.sin(t) * np.sin(p)], -1).reshape(-1, 3)
    return d, grid_faces(nv + 1, nu, wrap_rows=False)


def grid_faces(rows, cols, wrap_rows):
    """Triangles of a rows x cols vertex grid, columns wrapping (and rows if asked),
    wound counterclockwise seen from outside for the parametrizations below."""
    faces = []
    for i in range(rows if wrap_rows else rows - 1):
        for j in range(cols):
            a, b = i * cols + j, i * cols + (j + 1) % cols
            c, e = ((i + 1) % rows) * cols + j, ((i + 1) % rows) * cols + (j + 1) % cols
            faces += [(a, c, b), (b, c, e)]
    return np.array(faces, np.int32)


def ellipsoid_mesh(a, b, c, nu=96, nv=48):
    """Ellipsoid with semi-axes a, b, c (x, y, z): positions, analytic normals, faces."""
    d, f = sphere_directions(nu, nv)
    p = d * [a, b, c]
    n = d / [a, b, c]
    return p, n / np.linalg.norm(n, axis=1, keepdims=True), f


def rounded_cube_mesh(half, power=4.0, nu=128, nv=64):
    """The superquadric |x|^p + |y|^p + |z|^p = half^p (a cube with rounded
    edges for p = 4): sphere directions projected radially onto it; the
    normal is the gradient (sign(x)|x|^(p-1), ...)."""
    d, f = sphere_directions(nu, nv)
    p = d / (np.sum(np.abs(d) ** power, axis=1, keepdims=True) ** (1 / power)) * half
    n = np.sign(p) * np.abs(p) ** (power - 1)
    return p, n / np.linalg.norm(n, axis=1, keepdims=True), f


def torus_mesh(major, minor, nu=128, nv=48):
    """Torus around the y axis: ring radius `major`, tube radius `minor`."""
    u = np.linspace(0.0, 2 * np.pi, nu, endpoint=False)
    v = np.linspace(0.0, 2 * np.pi, nv, endpoint=False)
    vv, uu = np.meshgrid(v, u, indexing="ij")
    n = np.stack([np.cos(vv) * np.cos(uu), np.sin(vv), np.cos(vv) * np.sin(uu)], -1).reshape(-1, 3)
    centre = np.stack([major * np.cos(uu), 0 * uu, major * np.sin(uu)], -1).reshape(-1, 3)
    faces = grid_faces(nv, nu, wrap_rows=True)[:, [0, 2, 1]]
    return centre + minor * n, n, faces


def revolved(profile, nu=128):
    """Surface of revolution about the y axis of a profile polyline [(r, y, nr, ny), ...],
    traversed so that its outward normal (nr, ny) is the tangent turned by +90 degrees."""
    prof = np.asarray(profile, float)
    ph = np.linspace(0.0, 2 * np.pi, nu, endpoint=False)
    c, s = np.cos(ph)[None, :], np.sin(ph)[None, :]
    r, y, nr, ny = (prof[:, k, None] for k in range(4))
    p = np.stack([r * c, y + 0 * c, r * s], -1).reshape(-1, 3)
    n = np.stack([nr * c, ny + 0 * c, nr * s], -1).reshape(-1, 3)
    return p, n, grid_faces(len(prof), nu, wrap_rows=False)


def cup_mesh(radius, wall, height, base):
    """A closed thin-walled cup standing on y = 0: outer wall, bottom, inner bottom,
    inner wall and rim, each its own strip (sharp edges keep their normals)."""
    ri = radius - wall
    strips = [
        [(radius, height, 1, 0), (radius, 0.0, 1, 0)],
        [(radius, 0.0, 0, -1), (0.0, 0.0, 0, -1)],
        [(0.0, base, 0, 1), (ri, base, 0, 1)],
        [(ri, base, -1, 0), (ri, height, -1, 0)],
        [(ri, height, 0, 1), (radius, height, 0, 1)],
    ]
    parts = [revolved(strip) for strip in strips]
    offsets = np.cumsum([0] + [len(p) for p, _, _ in parts[:-1]])
    return (np.vstack([p for p, _, _ in parts]), np.vstack([n for _, n, _ in parts]),
            np.vstack([f + o for (_, _, f), o in zip(parts, offsets)]))


def solid_of_revolution(radius, slope, height, nv=64):
    """A closed solid of revolution standing on y = 0: the side r = radius(y) for y in
    [0, height] (outward normal (1, -slope(y)) in the (r, y) plane) and flat caps, each
    its own strip (the caps' edges keep their normals)."""
    y = np.linspace(height, 0.0, nv)
    r, dr = radius(y), slope(y)
    n = np.stack([np.ones_like(y), -dr], -1) / np.hypot(1.0, dr)[:, None]
    strips = [
        [(0.0, height, 0, 1), (r[0], height, 0, 1)],
        [(ri, yi, nr, ny) for ri, yi, (nr, ny) in zip(r, y, n)],
        [(r[-1], 0.0, 0, -1), (0.0, 0.0, 0, -1)],
    ]
    parts = [revolved(strip) for strip in strips]
    offsets = np.cumsum([0] + [len(p) for p, _, _ in parts[:-1]])
    return (np.vstack([p for p, _, _ in parts]), np.vstack([n for _, n, _ in parts]),
            np.vstack([f + o for (_, _, f), o in zip(parts, offsets)]))


def vase_mesh(height, base, bulge, neck):
    """A vase: radius base + bulge sin(pi y / height) - neck sin^2(pi y / height)^4
    toward the top, so that its side is convex low down and concave at the neck."""
    k = np.pi / height

    def radius(y):
        u = k * y
        return base + bulge * np.sin(u) - neck * np.sin(0.5 * u) ** 8

    def slope(y):
        u = k * y
        return k * (bulge * np.cos(u) - neck * 4.0 * np.sin(0.5 * u) ** 7 * np.cos(0.5 * u))

    return solid_of_revolution(radius, slope, height)


def cylinder_mesh(radius, height):
    """A closed cylinder standing on y = 0 (sharp edges at its caps)."""
    return solid_of_revolution(lambda y: radius + 0 * y, lambda y: 0 * y, height, nv=2)


def write_ply(path, positions, normals, faces):
    """Binary little-endian PLY with vertex positions, normals and triangles."""
    header = (
        "ply\nformat binary_little_endian 1.0\n"
        f"element vertex {len(positions)}\n"
        "property float x\nproperty float y\nproperty float z\n"
        "property float nx\nproperty float ny\nproperty float nz\n"
        f"element face {len(faces)}\nproperty list uchar int vertex_indices\nend_header\n"
    )
    verts = np.hstack([positions, normals]).astype("<f4")
    tri = np.zeros(len(faces), dtype=[("n", "u1"), ("i", "<i4", 3)])
    tri["n"], tri["i"] = 3, faces
    with open(path, "wb") as fh:
        fh.write(header.encode())
        fh.write(verts.tobytes())
        fh.write(tri.tobytes())


class Meshes:
    """Generated PLY files in a temporary folder, made once per shape key."""

    def __init__(self, folder):
        self.folder = Path(folder)
        self.made = {}

    def get(self, key, make):
        if key not in self.made:
            path = self.folder / f"{len(self.made)}.ply"
            write_ply(path, *make())
            self.made[key] = str(path)
        return self.made[key]


# --------------------------------------------------------------------------- scene pieces
def T(mi):
    return mi.ScalarTransform4f()


def sphere(center, radius, bsdf):
    return {"type": "sphere", "center": list(center), "radius": radius, "bsdf": bsdf}


def mesh(mi, meshes, key, make, bsdf, translate, rotate=(), scale=1.0):
    """A generated mesh placed by translate . rotations (axis, degrees) . scale."""
    tf = T(mi).translate(list(translate))
    for axis, deg in rotate:
        tf = tf @ T(mi).rotate(list(axis), deg)
    return {"type": "ply", "filename": meshes.get(key, make), "face_normals": False,
            "to_world": tf @ T(mi).scale(scale), "bsdf": bsdf}


def floor(mi, y=0.0, half=(12.0, 12.0), z=0.0, bsdf=None):
    """Horizontal rectangle (normal +y) at height y."""
    return {"type": "rectangle",
            "to_world": T(mi).translate([0.0, y, z]) @ T(mi).rotate([1, 0, 0], -90) @ T(mi).scale([half[0], half[1], 1.0]),
            "bsdf": bsdf or {"type": "diffuse", "reflectance": 0.35}}


def checker_bsdf(mi, c0, c1, tiles):
    return {"type": "diffuse", "reflectance": {
        "type": "checkerboard", "color0": c0, "color1": c1, "to_uv": T(mi).scale([tiles, tiles, 1.0])}}


def backdrop(mi, z, width, height, y0, bsdf):
    """Vertical rectangle facing +z, bottom edge at y0."""
    return {"type": "rectangle",
            "to_world": T(mi).translate([0.0, y0 + height / 2, z]) @ T(mi).scale([width / 2, height / 2, 1.0]),
            "bsdf": bsdf}


def pplastic(refl, alpha, ior=1.5):
    return {"type": "pplastic", "diffuse_reflectance": refl, "alpha": alpha, "int_ior": ior, "ext_ior": 1.0,
            "distribution": "ggx"}


def metal(name, alpha=None):
    if alpha is None:
        return {"type": "conductor", "material": name}
    return {"type": "roughconductor", "material": name, "alpha": alpha, "distribution": "ggx"}


def glass(ior=1.5, outside=1.0):
    """A smooth glass interface; `outside` is the index on the side the normals face."""
    return {"type": "dielectric", "int_ior": ior, "ext_ior": outside}


def sun(toward, irradiance):
    """Directional light; `toward` points from the scene to the sun."""
    d = -np.asarray(toward, float)
    return {"type": "directional", "direction": (d / np.linalg.norm(d)).tolist(), "irradiance": irradiance}


def sphere_light(center, radius, radiance):
    return {"type": "sphere", "center": list(center), "radius": radius,
            "emitter": {"type": "area", "radiance": radiance}}


# --------------------------------------------------------------------------- the scenes
# Each returns a dict: camera (origin, target, fov_deg), objects {name: (shape, label)},
# background {name: shape} (label 0), emitters {name: emitter}, and for haze `medium`.

def shape_scenes(mi, m):
    return [
        {  # a glossy sphere and a tilted ellipsoid under sky + sun
            "camera": ([0.0, 2.2, 5.2], [0.0, 0.6, 0.0], 34.0),
            "objects": {
                "ball": (sphere([-0.85, 0.6, 0.1], 0.6, pplastic(0.55, 0.06)), LABEL_DIELECTRIC),
                "egg": (mesh(mi, m, "ell-a", lambda: ellipsoid_mesh(0.45, 0.8, 0.5), pplastic(0.3, 0.15, 1.55),
                             [0.8, 0.85, -0.2], rotate=[([0, 0, 1], -25), ([0, 1, 0], 30)]), LABEL_DIELECTRIC),
            },
            "background": {"floor": floor(mi)},
            "emitters": {"sky": {"type": "constant", "radiance": 0.45}, "sun": sun([-0.6, 1.0, 0.5], 3.0)},
        },
        {  # a tilted torus and a small sphere, sun from the left and behind
            "camera": ([0.3, 2.6, 4.6], [0.0, 0.55, 0.0], 32.0),
            "objects": {
                "torus": (mesh(mi, m, "torus", lambda: torus_mesh(0.75, 0.3), pplastic(0.25, 0.08),
                               [0.0, 0.75, 0.0], rotate=[([1, 0, 0], 50), ([0, 0, 1], 15)]), LABEL_DIELECTRIC),
                "bead": (sphere([1.25, 0.35, 0.7], 0.35, pplastic(0.7, 0.2, 1.45)), LABEL_DIELECTRIC),
            },
            "background": {"floor": floor(mi, bsdf={"type": "diffuse", "reflectance": 0.5})},
            "emitters": {"sky": {"type": "constant", "radiance": 0.6}, "sun": sun([-1.0, 0.8, -0.7], 2.5)},
        },
        {  # a rounded cube and an upright ellipsoid, lit by a sphere light and a dim sky
            "camera": ([-1.5, 2.4, 4.8], [0.0, 0.6, 0.0], 36.0),
            "objects": {
                "cube": (mesh(mi, m, "rcube", lambda: rounded_cube_mesh(0.55), pplastic(0.4, 0.1),
                              [-0.4, 0.55, 0.0], rotate=[([0, 1, 0], 35)]), LABEL_DIELECTRIC),
                "pill": (mesh(mi, m, "ell-b", lambda: ellipsoid_mesh(0.35, 0.7, 0.35), pplastic(0.15, 0.05, 1.6),
                              [0.95, 0.7, 0.6], rotate=[([1, 0, 0], 20)]), LABEL_DIELECTRIC),
            },
            "background": {"floor": floor(mi, bsdf=checker_bsdf(mi, 0.2, 0.45, 10.0))},
            "emitters": {"sky": {"type": "constant", "radiance": 0.25},
                         "lamp": sphere_light([2.5, 4.0, 3.0], 0.6, 25.0)},
        },
        {  # three spheres: dark and bright pplastic, and Mitsuba's (depolarizing) diffuse
            "camera": ([0.0, 1.8, 5.5], [0.0, 0.5, 0.0], 38.0),
            "objects": {
                "dark": (sphere([-1.3, 0.5, 0.0], 0.5, pplastic(0.08, 0.04)), LABEL_DIELECTRIC),
                "bright": (sphere([0.0, 0.55, -0.3], 0.55, pplastic(0.8, 0.12)), LABEL_DIELECTRIC),
                "matte": (sphere([1.3, 0.5, 0.0], 0.5, {"type": "diffuse", "reflectance": 0.6}), LABEL_DIELECTRIC),
            },
            "background": {"floor": floor(mi)},
            "emitters": {"sky": {"type": "constant", "radiance": 0.5}, "sun": sun([0.4, 1.0, 0.8], 2.0)},
        },
    ]


def material_scenes(mi, m):
    return [
        {  # smooth gold and silver next to plastics
            "camera": ([0.0, 2.3, 5.4], [0.0, 0.55, 0.0], 40.0),
            "objects": {
                "gold": (sphere([-1.4, 0.5, 0.0], 0.5, metal("Au")), LABEL_METAL),
                "silver": (mesh(mi, m, "ell-c", lambda: ellipsoid_mesh(0.5, 0.65, 0.4), metal("Ag"),
                                [-0.1, 0.65, -0.6], rotate=[([0, 1, 0], -20)]), LABEL_METAL),
                "red": (sphere([1.2, 0.5, 0.2], 0.5, pplastic(0.35, 0.05)), LABEL_DIELECTRIC),
                "ring": (mesh(mi, m, "torus-s", lambda: torus_mesh(0.45, 0.16), pplastic(0.6, 0.2),
                              [0.2, 0.16, 0.9], rotate=[([1, 0, 0], 0)]), LABEL_DIELECTRIC),
            },
            "background": {"floor": floor(mi)},
            "emitters": {"sky": {"type": "constant", "radiance": 0.5}, "sun": sun([0.5, 1.0, 0.6], 3.0)},
        },
        {  # rough aluminium and copper, a rough plastic and a matte sphere
            "camera": ([0.5, 2.0, 5.6], [0.0, 0.5, 0.0], 38.0),
            "objects": {
                "alu": (sphere([-1.3, 0.55, 0.0], 0.55, metal("Al", 0.15)), LABEL_METAL),
                "copper": (sphere([0.0, 0.5, -0.5], 0.5, metal("Cu", 0.3)), LABEL_METAL),
                "plastic": (sphere([1.25, 0.5, 0.2], 0.5, pplastic(0.5, 0.3)), LABEL_DIELECTRIC),
                "chalk": (sphere([0.3, 0.3, 1.0], 0.3, {"type": "diffuse", "reflectance": 0.7}), LABEL_DIELECTRIC),
            },
            "background": {"floor": floor(mi, bsdf=checker_bsdf(mi, 0.25, 0.4, 8.0))},
            "emitters": {"sky": {"type": "constant", "radiance": 0.4}, "sun": sun([-0.7, 1.0, 0.3], 3.0)},
        },
        {  # a copper rounded cube, a gold torus and a plastic ellipsoid under a sphere light
            "camera": ([1.2, 2.5, 4.8], [0.0, 0.55, 0.0], 38.0),
            "objects": {
                "block": (mesh(mi, m, "rcube", lambda: rounded_cube_mesh(0.55), metal("Cu", 0.08),
                               [-0.7, 0.55, -0.2], rotate=[([0, 1, 0], 20)]), LABEL_METAL),
                "band": (mesh(mi, m, "torus", lambda: torus_mesh(0.75, 0.3), metal("Au", 0.05),
                              [0.9, 0.3, 0.6], rotate=[([0, 1, 0], 10)], scale=0.8), LABEL_METAL),
                "egg": (mesh(mi, m, "ell-a", lambda: ellipsoid_mesh(0.45, 0.8, 0.5), pplastic(0.2, 0.1),
                             [0.6, 0.8, -0.9]), LABEL_DIELECTRIC),
            },
            "background": {"floor": floor(mi, bsdf={"type": "diffuse", "reflectance": 0.45})},
            "emitters": {"sky": {"type": "constant", "radiance": 0.3},
                         "lamp": sphere_light([-2.0, 4.0, 3.5], 0.7, 20.0)},
        },
    ]


def glass_scenes(mi, m):
    board = checker_bsdf(mi, 0.1, 0.75, 12.0)
    return [
        {  # a glass ball in front of a checkerboard wall and a glossy plastic distractor
            "camera": ([0.0, 1.3, 5.0], [0.0, 0.7, 0.0], 36.0),
            "objects": {
                "ball": (sphere([-0.55, 0.65, 0.3], 0.65, glass(1.5)), LABEL_TRANSPARENT),
                "shiny": (sphere([0.95, 0.5, -0.2], 0.5, pplastic(0.1, 0.02)), LABEL_DIELECTRIC),
            },
            "background": {"floor": floor(mi), "wall": backdrop(mi, -1.6, 8.0, 5.0, 0.0, board)},
            "emitters": {"sky": {"type": "constant", "radiance": 0.6}, "sun": sun([0.5, 1.0, 1.0], 2.5)},
        },
        {  # a tilted glass slab and a silver ball
            "camera": ([0.8, 1.5, 4.8], [0.0, 0.75, 0.0], 36.0),
            "objects": {
                "slab": ({"type": "cube", "bsdf": glass(1.52),
                          "to_world": T(mi).translate([-0.3, 0.8, 0.2]) @ T(mi).rotate([0, 1, 0], 30)
                          @ T(mi).rotate([0, 0, 1], 8) @ T(mi).scale([0.6, 0.75, 0.06])}, LABEL_TRANSPARENT),
                "mirrorball": (sphere([1.0, 0.45, -0.4], 0.45, metal("Ag")), LABEL_METAL),
            },
            "background": {"floor": floor(mi), "wall": backdrop(mi, -1.5, 8.0, 5.0, 0.0, board)},
            "emitters": {"sky": {"type": "constant", "radiance": 0.6}, "sun": sun([-0.6, 1.0, 0.8], 2.5)},
        },
        {  # a glass ball, a glass ellipsoid and a glossy plastic cube (the ball is smooth:
           # Mitsuba's roughdielectric returns unpolarized light, which no glass does)
            "camera": ([-0.4, 1.6, 5.2], [0.0, 0.6, 0.0], 38.0),
            "objects": {
                "ball": (sphere([-1.1, 0.55, 0.2], 0.55, glass(1.45)), LABEL_TRANSPARENT),
                "drop": (mesh(mi, m, "ell-b", lambda: ellipsoid_mesh(0.35, 0.7, 0.35), glass(1.5),
                              [0.2, 0.7, 0.5], rotate=[([0, 0, 1], -15)]), LABEL_TRANSPARENT),
                "cube": (mesh(mi, m, "rcube", lambda: rounded_cube_mesh(0.55), pplastic(0.2, 0.03),
                              [1.25, 0.45, -0.5], rotate=[([0, 1, 0], 25)], scale=0.8), LABEL_DIELECTRIC),
            },
            "background": {"floor": floor(mi, bsdf={"type": "diffuse", "reflectance": 0.5}),
                           "wall": backdrop(mi, -1.8, 9.0, 5.0, 0.0, checker_bsdf(mi, 0.15, 0.6, 9.0))},
            "emitters": {"sky": {"type": "constant", "radiance": 0.5},
                         "lamp": sphere_light([2.0, 3.5, 3.0], 0.5, 30.0)},
        },
    ]


def glass_hard_scenes(mi, m):
    """The hard cases of transparent-object detection, one per scene."""
    board = checker_bsdf(mi, 0.1, 0.75, 12.0)
    sky_sun = {"sky": {"type": "constant", "radiance": 0.6}, "sun": sun([0.4, 1.0, 0.9], 2.5)}
    return [
        {  # glass in front of an opaque object: a ball half over a glossy plastic sphere
            "camera": ([0.0, 1.3, 5.0], [0.0, 0.6, 0.0], 34.0),
            "objects": {
                "ball": (sphere([-0.2, 0.55, 0.8], 0.55, glass(1.5)), LABEL_TRANSPARENT),
                "behind": (sphere([0.45, 0.6, -0.5], 0.6, pplastic(0.45, 0.05)), LABEL_DIELECTRIC),
            },
            "background": {"floor": floor(mi), "wall": backdrop(mi, -1.6, 8.0, 5.0, 0.0, board)},
            "emitters": sky_sun,
        },
        {  # glass seen against glass: two balls and an ellipsoid overlapping in the view
            "camera": ([0.6, 1.4, 5.0], [0.0, 0.6, 0.0], 34.0),
            "objects": {
                "front": (sphere([-0.3, 0.45, 0.9], 0.45, glass(1.5)), LABEL_TRANSPARENT),
                "back": (sphere([0.3, 0.6, -0.2], 0.6, glass(1.52)), LABEL_TRANSPARENT),
                "drop": (mesh(mi, m, "ell-b", lambda: ellipsoid_mesh(0.35, 0.7, 0.35), glass(1.5),
                              [-0.9, 0.7, -0.6]), LABEL_TRANSPARENT),
            },
            "background": {"floor": floor(mi), "wall": backdrop(mi, -1.8, 8.0, 5.0, 0.0, board)},
            "emitters": sky_sun,
        },
        {  # thin walls: a drinking glass (1.5 cm wall) and a blown bulb (1 cm shell)
            "camera": ([0.0, 1.8, 4.8], [0.0, 0.55, 0.0], 34.0),
            "objects": {
                "cup": (mesh(mi, m, "cup", lambda: cup_mesh(0.4, 0.015, 1.0, 0.04), glass(1.5),
                             [-0.6, 0.0, 0.2]), LABEL_TRANSPARENT),
                "bulb": (sphere([0.75, 0.5, 0.0], 0.5, glass(1.5)), LABEL_TRANSPARENT),
                "bulb-inside": (sphere([0.75, 0.5, 0.0], 0.49, glass(1.0, outside=1.5)), LABEL_TRANSPARENT),
            },
            "background": {"floor": floor(mi), "wall": backdrop(mi, -1.5, 8.0, 5.0, 0.0, board)},
            "emitters": sky_sun,
        },
        {  # a ball and a pane in front of a plain wall (no texture seen through the glass)
            "camera": ([0.0, 1.3, 5.0], [0.0, 0.6, 0.0], 34.0),
            "objects": {
                "ball": (sphere([-0.6, 0.6, 0.3], 0.6, glass(1.5)), LABEL_TRANSPARENT),
                "pane": ({"type": "cube", "bsdf": glass(1.52),
                          "to_world": T(mi).translate([0.8, 0.7, -0.1]) @ T(mi).rotate([0, 1, 0], -25)
                          @ T(mi).scale([0.45, 0.7, 0.05])}, LABEL_TRANSPARENT),
            },
            "background": {"floor": floor(mi),
                           "wall": backdrop(mi, -1.6, 8.0, 5.0, 0.0, {"type": "diffuse", "reflectance": 0.55})},
            "emitters": {"sky": {"type": "constant", "radiance": 0.5}, "lamp": sphere_light([2.0, 3.5, 3.0], 0.5, 30.0)},
        },
    ]


def haze_scenes(mi, m):
    box = ([-20.0, -0.5, -45.0], [20.0, 12.0, 9.0])
    ground = floor(mi, half=(19.0, 26.0), z=-17.0, bsdf={"type": "diffuse", "reflectance": 0.3})
    return [
        {  # spheres and a rounded cube receding into the haze, sun from the right
            "camera": ([0.0, 1.4, 6.0], [0.0, 1.0, -10.0], 50.0),
            "objects": {
                "near": (sphere([-1.6, 0.7, 1.5], 0.7, pplastic(0.5, 0.1)), LABEL_DIELECTRIC),
                "mid": (mesh(mi, m, "rcube", lambda: rounded_cube_mesh(1.0), pplastic(0.35, 0.15),
                             [1.8, 1.0, -6.0], rotate=[([0, 1, 0], 30)]), LABEL_DIELECTRIC),
                "far": (sphere([-2.5, 1.8, -16.0], 1.8, pplastic(0.6, 0.1)), LABEL_DIELECTRIC),
                "farthest": (mesh(mi, m, "rcube-big", lambda: rounded_cube_mesh(3.0), pplastic(0.4, 0.2),
                                  [-9.0, 3.0, -28.0], rotate=[([0, 1, 0], 10)]), LABEL_DIELECTRIC),
            },
            "background": {"floor": ground},
            "emitters": {"sky": {"type": "constant", "radiance": 0.3}, "sun": sun([1.0, 0.35, -0.1], 3.0)},
            "medium": {"box": box, "sigma_t": 0.06, "albedo": 1.0},
        },
        {  # a row of pillars (ellipsoids) and a torus, denser haze, sun from the left and behind
            "camera": ([0.5, 1.6, 6.0], [-0.5, 1.2, -10.0], 46.0),
            "objects": {
                "p1": (mesh(mi, m, "pillar", lambda: ellipsoid_mesh(0.6, 2.0, 0.6), pplastic(0.45, 0.1),
                            [-2.5, 2.0, 0.0]), LABEL_DIELECTRIC),
                "p2": (mesh(mi, m, "pillar", lambda: ellipsoid_mesh(0.6, 2.0, 0.6), pplastic(0.45, 0.1),
                            [-3.0, 2.0, -7.0]), LABEL_DIELECTRIC),
                "p3": (mesh(mi, m, "pillar", lambda: ellipsoid_mesh(0.6, 2.0, 0.6), pplastic(0.45, 0.1),
                            [-3.5, 2.0, -15.0]), LABEL_DIELECTRIC),
                "ring": (mesh(mi, m, "torus", lambda: torus_mesh(0.75, 0.3), pplastic(0.3, 0.1),
                              [1.8, 1.6, -3.0], rotate=[([1, 0, 0], 80)], scale=1.4), LABEL_DIELECTRIC),
                "dome": (sphere([9.0, 0.0, -22.0], 4.0, pplastic(0.55, 0.15)), LABEL_DIELECTRIC),
            },
            "background": {"floor": ground},
            "emitters": {"sky": {"type": "constant", "radiance": 0.25}, "sun": sun([-1.0, 0.5, 0.4], 3.0)},
            "medium": {"box": box, "sigma_t": 0.09, "albedo": 1.0},
        },
    ]


# The second set: scenes written after the methods' last change and measured once, with
# shapes, lights and layouts the first set does not have (a vase with a concave neck,
# cylinders with sharp rims, a boxier superquadric, flattened and lying ellipsoids; sky
# alone, a grazing sun, light from behind the camera, two lamps). Not for tuning.
def shape_scenes_2(mi, m):
    return [
        {  # a vase with a concave neck and a boxy superquadric under the sky alone
            "camera": ([0.4, 2.8, 4.6], [0.0, 0.6, 0.0], 36.0),
            "objects": {
                "vase": (mesh(mi, m, "vase", lambda: vase_mesh(1.3, 0.3, 0.25, 0.18), pplastic(0.5, 0.08),
                              [-0.7, 0.0, 0.0]), LABEL_DIELECTRIC),
                "box": (mesh(mi, m, "rcube8", lambda: rounded_cube_mesh(0.4, power=8.0), pplastic(0.35, 0.12, 1.6),
                             [0.85, 0.4, 0.3], rotate=[([0, 1, 0], 40)]), LABEL_DIELECTRIC),
            },
            "background": {"floor": floor(mi, bsdf={"type": "diffuse", "reflectance": 0.4})},
            "emitters": {"sky": {"type": "constant", "radiance": 0.9}},
        },
        {  # a flattened disc-like ellipsoid and a lying capsule, sun low from the right
            "camera": ([-0.5, 1.7, 5.0], [0.0, 0.4, 0.0], 34.0),
            "objects": {
                "disc": (mesh(mi, m, "ell-disc", lambda: ellipsoid_mesh(0.7, 0.25, 0.7), pplastic(0.6, 0.1, 1.45),
                              [-0.7, 0.45, 0.2], rotate=[([1, 0, 0], 35), ([0, 0, 1], 10)]), LABEL_DIELECTRIC),
                "capsule": (mesh(mi, m, "ell-caps", lambda: ellipsoid_mesh(0.8, 0.28, 0.28), pplastic(0.25, 0.05),
                                 [0.9, 0.28, -0.1], rotate=[([0, 1, 0], -30)]), LABEL_DIELECTRIC),
            },
            "background": {"floor": floor(mi, bsdf={"type": "diffuse", "reflectance": 0.15})},
            "emitters": {"sky": {"type": "constant", "radiance": 0.3}, "sun": sun([1.0, 0.25, 0.2], 4.0)},
        },
        {  # a cylinder with sharp rims and a sphere under one lamp overhead and a dim sky
            "camera": ([0.0, 2.5, 4.9], [0.0, 0.5, 0.0], 36.0),
            "objects": {
                "drum": (mesh(mi, m, "cyl", lambda: cylinder_mesh(0.45, 0.7), pplastic(0.45, 0.1),
                              [-0.6, 0.0, -0.1], rotate=[([0, 0, 1], 0)]), LABEL_DIELECTRIC),
                "ball": (sphere([0.85, 0.5, 0.4], 0.5, pplastic(0.7, 0.25, 1.55)), LABEL_DIELECTRIC),
            },
            "background": {"floor": floor(mi, bsdf=checker_bsdf(mi, 0.3, 0.5, 6.0))},
            "emitters": {"sky": {"type": "constant", "radiance": 0.1},
                         "lamp": sphere_light([0.0, 4.5, 0.5], 0.8, 18.0)},
        },
        {  # three touching spheres, rough and smooth, the sun behind the camera
            "camera": ([0.2, 1.6, 5.2], [0.0, 0.55, 0.0], 32.0),
            "objects": {
                "big": (sphere([-0.4, 0.7, -0.3], 0.7, pplastic(0.4, 0.3)), LABEL_DIELECTRIC),
                "small": (sphere([0.55, 0.4, 0.3], 0.4, pplastic(0.2, 0.02, 1.7)), LABEL_DIELECTRIC),
                "matte": (sphere([-0.95, 0.35, 0.65], 0.35, {"type": "diffuse", "reflectance": 0.5}), LABEL_DIELECTRIC),
            },
            "background": {"floor": floor(mi)},
            "emitters": {"sky": {"type": "constant", "radiance": 0.35}, "sun": sun([0.1, 0.7, 1.0], 3.0)},
        },
    ]


def material_scenes_2(mi, m):
    return [
        {  # rough gold, smooth aluminium, a white and a black glossy plastic
            "camera": ([-0.3, 2.2, 5.3], [0.0, 0.5, 0.0], 40.0),
            "objects": {
                "gold": (mesh(mi, m, "ell-g", lambda: ellipsoid_mesh(0.5, 0.4, 0.6), metal("Au", 0.2),
                              [-1.3, 0.4, 0.0], rotate=[([0, 1, 0], 25)]), LABEL_METAL),
                "alu": (mesh(mi, m, "rcube", lambda: rounded_cube_mesh(0.55), metal("Al"),
                             [-0.1, 0.45, -0.5], rotate=[([0, 1, 0], 15)], scale=0.8), LABEL_METAL),
                "white": (sphere([1.0, 0.45, 0.1], 0.45, pplastic(0.8, 0.02)), LABEL_DIELECTRIC),
                "black": (sphere([0.3, 0.3, 0.9], 0.3, pplastic(0.03, 0.1)), LABEL_DIELECTRIC),
            },
            "background": {"floor": floor(mi, bsdf={"type": "diffuse", "reflectance": 0.5})},
            "emitters": {"sky": {"type": "constant", "radiance": 0.6}, "sun": sun([-1.0, 0.7, 0.2], 2.5)},
        },
        {  # a copper vase, a rough silver torus and a matte cube, lamp and dim sky
            "camera": ([0.6, 2.6, 4.8], [0.0, 0.5, 0.0], 38.0),
            "objects": {
                "vase": (mesh(mi, m, "vase", lambda: vase_mesh(1.3, 0.3, 0.25, 0.18), metal("Cu", 0.05),
                              [-0.9, 0.0, -0.2]), LABEL_METAL),
                "ring": (mesh(mi, m, "torus", lambda: torus_mesh(0.75, 0.3), metal("Ag", 0.1),
                              [0.7, 0.3, 0.4], scale=0.7), LABEL_METAL),
                "cube": (mesh(mi, m, "rcube8", lambda: rounded_cube_mesh(0.4, power=8.0),
                              {"type": "diffuse", "reflectance": 0.3}, [0.5, 0.4, -0.8],
                              rotate=[([0, 1, 0], 20)]), LABEL_DIELECTRIC),
            },
            "background": {"floor": floor(mi, bsdf=checker_bsdf(mi, 0.2, 0.4, 8.0))},
            "emitters": {"sky": {"type": "constant", "radiance": 0.2},
                         "lamp": sphere_light([2.5, 3.5, 2.5], 0.6, 25.0)},
        },
        {  # a silver and a plastic cylinder alike in shape, a small gold ball, sun from the back
            "camera": ([0.0, 2.0, 5.4], [0.0, 0.5, 0.0], 36.0),
            "objects": {
                "chrome": (mesh(mi, m, "cyl", lambda: cylinder_mesh(0.45, 0.7), metal("Ag"),
                                [-0.8, 0.0, 0.0]), LABEL_METAL),
                "plastic": (mesh(mi, m, "cyl", lambda: cylinder_mesh(0.45, 0.7), pplastic(0.3, 0.06),
                                 [0.6, 0.0, -0.3]), LABEL_DIELECTRIC),
                "bead": (sphere([0.0, 0.25, 0.9], 0.25, metal("Au")), LABEL_METAL),
            },
            "background": {"floor": floor(mi)},
            "emitters": {"sky": {"type": "constant", "radiance": 0.45}, "sun": sun([-0.5, 0.9, -0.8], 3.0)},
        },
    ]


def glass_scenes_2(mi, m):
    board = checker_bsdf(mi, 0.15, 0.7, 10.0)
    return [
        {  # a glass cylinder beside a white glossy ball, checkerboard wall
            "camera": ([0.3, 1.4, 5.0], [0.0, 0.6, 0.0], 34.0),
            "objects": {
                "rod": (mesh(mi, m, "cyl", lambda: cylinder_mesh(0.45, 0.7), glass(1.5),
                             [-0.5, 0.0, 0.3], scale=[1.0, 1.4, 1.0]), LABEL_TRANSPARENT),
                "white": (sphere([0.9, 0.45, -0.2], 0.45, pplastic(0.85, 0.05)), LABEL_DIELECTRIC),
            },
            "background": {"floor": floor(mi), "wall": backdrop(mi, -1.6, 8.0, 5.0, 0.0, board)},
            "emitters": {"sky": {"type": "constant", "radiance": 0.6}, "sun": sun([0.7, 1.0, 0.6], 2.5)},
        },
        {  # a glass superquadric and a glass torus under a lamp, checkerboard wall
            "camera": ([-0.4, 1.5, 5.0], [0.0, 0.6, 0.0], 36.0),
            "objects": {
                "block": (mesh(mi, m, "rcube", lambda: rounded_cube_mesh(0.55), glass(1.5),
                               [-0.7, 0.55, 0.0], rotate=[([0, 1, 0], 30)], scale=0.9), LABEL_TRANSPARENT),
                "ring": (mesh(mi, m, "torus", lambda: torus_mesh(0.75, 0.3), glass(1.5),
                              [0.9, 0.8, 0.2], rotate=[([1, 0, 0], 70)], scale=0.7), LABEL_TRANSPARENT),
            },
            "background": {"floor": floor(mi, bsdf={"type": "diffuse", "reflectance": 0.45}),
                           "wall": backdrop(mi, -1.7, 8.0, 5.0, 0.0, board)},
            "emitters": {"sky": {"type": "constant", "radiance": 0.4},
                         "lamp": sphere_light([-2.0, 3.5, 3.0], 0.5, 30.0)},
        },
        {  # a glass egg lying on the floor in front of a plain wall, a gold distractor
            "camera": ([0.0, 1.8, 4.8], [0.0, 0.4, 0.0], 34.0),
            "objects": {
                "egg": (mesh(mi, m, "ell-lie", lambda: ellipsoid_mesh(0.7, 0.35, 0.45), glass(1.5),
                             [-0.5, 0.35, 0.3], rotate=[([0, 1, 0], 20)]), LABEL_TRANSPARENT),
                "gold": (sphere([1.0, 0.4, -0.3], 0.4, metal("Au", 0.05)), LABEL_METAL),
            },
            "background": {"floor": floor(mi, bsdf=checker_bsdf(mi, 0.3, 0.5, 8.0)),
                           "wall": backdrop(mi, -1.5, 8.0, 5.0, 0.0, {"type": "diffuse", "reflectance": 0.6})},
            "emitters": {"sky": {"type": "constant", "radiance": 0.5}, "sun": sun([-0.6, 1.0, 0.7], 2.5)},
        },
    ]


def haze_scenes_2(mi, m):
    box = ([-20.0, -0.5, -45.0], [20.0, 12.0, 9.0])
    ground = floor(mi, half=(19.0, 26.0), z=-17.0, bsdf={"type": "diffuse", "reflectance": 0.25})
    return [
        {  # cylinders and a vase receding into thin haze, sun from the left at right angles
            "camera": ([0.0, 1.5, 6.0], [0.0, 1.2, -10.0], 48.0),
            "objects": {
                "drum": (mesh(mi, m, "cyl", lambda: cylinder_mesh(0.45, 0.7), pplastic(0.5, 0.1),
                              [1.2, 0.0, 2.0], scale=1.5), LABEL_DIELECTRIC),
                "vase": (mesh(mi, m, "vase", lambda: vase_mesh(1.3, 0.3, 0.25, 0.18), pplastic(0.4, 0.15),
                              [-2.0, 0.0, -5.0], scale=2.0), LABEL_DIELECTRIC),
                "tower": (mesh(mi, m, "cyl", lambda: cylinder_mesh(0.45, 0.7), pplastic(0.6, 0.1),
                               [3.0, 0.0, -14.0], scale=[4.0, 8.0, 4.0]), LABEL_DIELECTRIC),
                "hill": (sphere([-8.0, -1.0, -26.0], 5.0, pplastic(0.35, 0.2)), LABEL_DIELECTRIC),
            },
            "background": {"floor": ground},
            "emitters": {"sky": {"type": "constant", "radiance": 0.35}, "sun": sun([-1.0, 0.4, 0.0], 3.0)},
            "medium": {"box": box, "sigma_t": 0.045, "albedo": 1.0},
        },
        {  # boxy blocks in dense haze, sun high and behind the camera's right shoulder
            "camera": ([-0.5, 1.4, 6.0], [0.5, 1.1, -10.0], 50.0),
            "objects": {
                "b1": (mesh(mi, m, "rcube8", lambda: rounded_cube_mesh(0.4, power=8.0), pplastic(0.5, 0.1),
                            [-1.5, 1.0, 0.5], rotate=[([0, 1, 0], 25)], scale=2.5), LABEL_DIELECTRIC),
                "b2": (mesh(mi, m, "rcube8", lambda: rounded_cube_mesh(0.4, power=8.0), pplastic(0.4, 0.1),
                            [2.5, 1.6, -6.0], rotate=[([0, 1, 0], -15)], scale=4.0), LABEL_DIELECTRIC),
                "ball": (sphere([-3.5, 2.0, -13.0], 2.0, pplastic(0.55, 0.15)), LABEL_DIELECTRIC),
                "far": (mesh(mi, m, "rcube8", lambda: rounded_cube_mesh(0.4, power=8.0), pplastic(0.45, 0.2),
                             [6.0, 4.0, -30.0], scale=10.0), LABEL_DIELECTRIC),
            },
            "background": {"floor": ground},
            "emitters": {"sky": {"type": "constant", "radiance": 0.3}, "sun": sun([0.5, 0.8, 0.6], 3.0)},
            "medium": {"box": box, "sigma_t": 0.11, "albedo": 1.0},
        },
    ]


KINDS = {"shape": shape_scenes, "material": material_scenes, "glass": glass_scenes, "haze": haze_scenes,
         "glasshard": glass_hard_scenes, "shape2": shape_scenes_2, "material2": material_scenes_2,
         "glass2": glass_scenes_2, "haze2": haze_scenes_2}


# --------------------------------------------------------------------------- building and rendering
def camera_transform(mi, cam):
    origin, target, _ = cam
    return T(mi).look_at(origin=list(origin), target=list(target), up=UP)


def scene_dict(mi, desc, size, spp, with_medium):
    """The Mitsuba scene dictionary; with_medium adds the medium box around
    camera and scene (only for scenes that have one)."""
    medium = desc.get("medium") if with_medium else None
    sensor = {
        "type": "perspective", "fov": desc["camera"][2], "fov_axis": "x",
        "to_world": camera_transform(mi, desc["camera"]),
        "film": {"type": "hdrfilm", "width": size, "height": size, "rfilter": {"type": "box"}},
        "sampler": {"type": "independent", "sample_count": spp},
    }
    d = {"type": "scene"}
    if medium:
        lo, hi = np.array(medium["box"][0]), np.array(medium["box"][1])
        d["haze"] = {"type": "homogeneous", "sigma_t": medium["sigma_t"], "albedo": medium["albedo"],
                     "phase": {"type": rayleigh_phase.PLUGIN}}
        d["haze_box"] = {"type": "cube", "bsdf": {"type": "null"}, "interior": {"type": "ref", "id": "haze"},
                         "to_world": T(mi).translate(((lo + hi) / 2).tolist()) @ T(mi).scale(((hi - lo) / 2).tolist())}
        sensor["medium"] = {"type": "ref", "id": "haze"}
        d["integrator"] = common.stokes_integrator(HAZE_MAX_DEPTH, "volpath")
    else:
        d["integrator"] = common.stokes_integrator(MAX_DEPTH, "path")
    d["sensor"] = sensor
    for name, (shape, _) in desc["objects"].items():
        d[name] = shape
    d.update(desc["background"])
    d.update(desc["emitters"])
    return d


def film_positions(size):
    """Normalized film positions of the pixel centres (row-major; y = 0 is the top row)."""
    ys, xs = np.mgrid[0:size, 0:size]
    return (xs.ravel() + 0.5) / size, (ys.ravel() + 0.5) / size


def camera_rays(mi, scene, fx, fy):
    sensor = scene.sensors()[0]
    pos = mi.Point2f(np.asarray(fx, np.float32), np.asarray(fy, np.float32))
    ray, _ = sensor.sample_ray(0.0, 0.5, pos, mi.Point2f(0.5, 0.5))
    return ray


def camera_axes(mi, scene):
    """World-space (right, up, toward viewer) of the camera. Mitsuba's
    look_at puts the camera's local +x to the image's left and +z forward."""
    m = np.array(scene.sensors()[0].world_transform().matrix).reshape(4, 4)
    return -m[:3, 0], m[:3, 1], -m[:3, 2]


def ground_truth(mi, dr, scene, desc, size):
    """Normal (camera frame), depth along -z, material labels, transparency mask
    and per-pixel ray distance t (inf on a miss), along the pixel-centre rays."""
    ray = camera_rays(mi, scene, *film_positions(size))
    si = scene.ray_intersect(ray)
    hit = np.array(si.is_valid())
    t = np.where(hit, np.array(si.t), np.inf)
    d = np.array(ray.d).T
    n = np.array(si.sh_frame.n).T
    n = np.where((np.sum(n * d, axis=1) > 0)[:, None], -n, n)  # face the viewer
    right, up, toward = camera_axes(mi, scene)
    n_cam = np.stack([n @ right, n @ up, n @ toward], -1)
    n_cam /= np.maximum(np.linalg.norm(n_cam, axis=1, keepdims=True), 1e-12)
    n_cam[~hit] = 0.0
    depth = np.where(hit, t * (d @ -toward), 0.0)
    shape_id = np.array(dr.reinterpret_array(mi.UInt32, si.shape))
    labels = np.zeros(size * size, np.uint8)
    for shape in scene.shapes():
        entry = desc["objects"].get(shape.id())
        if entry is not None:
            sid = int(np.array(dr.reinterpret_array(mi.UInt32, mi.ShapePtr(shape)))[0])
            labels[hit & (shape_id == sid)] = entry[1]
    shp = (size, size)
    return {
        "normal": n_cam.reshape(size, size, 3).astype(np.float32),
        "depth": depth.reshape(shp).astype(np.float32),
        "material": labels.reshape(shp),
        "transparent": np.where(labels == LABEL_TRANSPARENT, 255, 0).astype(np.uint8).reshape(shp),
        "t": t,
        "ray_o": np.array(ray.o).T,
        "ray_d": d,
    }


def box_span(o, d, lo, hi):
    """Ray parameters (near, far) of the box [lo, hi] (slab test; far < near: miss)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        t1, t2 = (np.asarray(lo) - o) / d, (np.asarray(hi) - o) / d
    return np.nanmax(np.minimum(t1, t2), axis=1), np.nanmin(np.maximum(t1, t2), axis=1)


def transmission(gt, medium, size):
    """exp(-sigma_t L), L = length of the central ray inside the box up to the first surface."""
    near, far = box_span(gt["ray_o"], gt["ray_d"], *medium["box"])
    end = np.minimum(gt["t"], far)
    length = np.clip(end - np.maximum(near, 0.0), 0.0, None)
    return np.exp(-medium["sigma_t"] * length).reshape(size, size).astype(np.float32)


def render_dehazed(mi, dr, hazy, clear, desc, size, spp, seed, chunk=32):
    """S0 with the camera segment free of the medium: each jittered camera ray
    is found in the clear scene, restarted EPS before its first surface (or just
    inside the medium's far side) in the medium, and traced by volpath."""
    eps = 1e-3
    medium = next(s for s in hazy.shapes() if s.id() == "haze_box").interior_medium()
    integ = mi.load_dict({"type": "volpath", "max_depth": HAZE_MAX_DEPTH})
    lo, hi = desc["medium"]["box"]
    total = np.zeros(size * size)
    done = 0
    while done < spp:
        k = min(chunk, spp - done)
        n = size * size * k
        sampler = mi.load_dict({"type": "independent"})
        sampler.seed(seed * 1000 + done, n)
        rng = np.random.default_rng(seed * 7919 + done)
        jx = (np.repeat(np.arange(size * size) % size, k) + rng.random(n)) / size
        jy = (np.repeat(np.arange(size * size) // size, k) + rng.random(n)) / size
        ray = camera_rays(mi, clear, jx, jy)
        si = clear.ray_intersect(ray)
        o, d = np.array(ray.o).T, np.array(ray.d).T
        t = np.where(np.array(si.is_valid()), np.array(si.t), np.inf)
        _, far = box_span(o, d, lo, hi)
        start = np.maximum(np.minimum(t, far) - eps, 0.0)
        p = o + start[:, None] * d
        ray2 = mi.RayDifferential3f(mi.Point3f(*[p[:, i].astype(np.float32) for i in range(3)]),
                        mi.Vector3f(*[d[:, i].astype(np.float32) for i in range(3)]))
        spec, _, _ = integ.sample(hazy, sampler, ray2, medium, True)
        s0 = np.array(spec).reshape(4, 4, -1)[0, 0]
        total += s0.reshape(size * size, k).sum(axis=1)
        done += k
    return (total / spp).reshape(size, size).astype(np.float32)


# --------------------------------------------------------------------------- sensor simulation
def polarizer_images(stokes):
    """I(theta) = 1/2 (S0 + S1 cos 2 theta + S2 sin 2 theta) for 0, 45, 90, 135 degrees."""
    s0, s1, s2 = stokes[..., 0], stokes[..., 1], stokes[..., 2]
    return {a: 0.5 * (s0 + s1 * np.cos(2 * np.radians(a)) + s2 * np.sin(2 * np.radians(a))) for a in (0, 45, 90, 135)}


def mosaic(stokes):
    """Full-resolution mosaic image: each pixel's I(theta) at its micro-polarizer angle."""
    h, w = stokes.shape[:2]
    imgs = polarizer_images(stokes)
    out = np.zeros((h, w))
    for r in range(2):
        for c in range(2):
            out[r::2, c::2] = imgs[int(MOSAIC[r, c])][r::2, c::2]
    return out


def raw_dn(stokes, noisy, seed):
    """12-bit DN: the 99th percentile of S0 -> P99_FRACTION of full scale;
    noisy adds Poisson shot noise (FULL_WELL_E electrons at full scale) and
    Gaussian read noise READ_NOISE_E (`sensor_noise`), then quantizes and clips."""
    s0 = stokes[..., 0]
    p99 = float(np.percentile(s0[np.isfinite(s0)], 99))
    k = P99_FRACTION * FULL_SCALE / max(p99, 1e-30)
    dn = np.clip(mosaic(stokes) * k, 0.0, None)
    gain = FULL_WELL_E / FULL_SCALE  # electrons per DN
    if noisy:
        dn = sensor_noise(np.minimum(dn * gain, 1e9), seed) / gain
    return np.clip(np.rint(dn), 0, FULL_SCALE).astype(np.uint16), k, gain


def sensor_noise(electrons, seed):
    """Poisson shot noise and Gaussian read noise on mean electron counts. Every pixel
    takes one uniform and one normal draw from the seeded stream whatever its mean,
    and its shot noise is the Poisson quantile of its uniform (inverse transform), so a
    render that differs in its last bits (another machine, another Mitsuba build)
    keeps the same noise instead of drawing new noise, as a sampler whose use of the
    stream depends on the means would."""
    from scipy.stats import poisson

    rng = np.random.default_rng(seed)
    u = np.clip(rng.random(electrons.shape), 1e-12, 1.0 - 1e-12)
    read = rng.normal(0.0, READ_NOISE_E, electrons.shape)
    return poisson.ppf(u, electrons) + read


def check_noise():
    """The noise's two promises, checked without Mitsuba: its statistics (mean and
    variance of the electrons at several means) and its stability (means changed by
    one part in 10^6 keep the noise of nearly every pixel)."""
    seed = 7
    for mean in (0.5, 20.0, 3000.0):
        e = sensor_noise(np.full((256, 256), mean), seed)
        var = mean + READ_NOISE_E**2
        # 65,536 samples: the sample mean's standard error is sqrt(var / n), the
        # variance's about var * sqrt(2 / n) (0.6 %); 5 standard errors each.
        se_mean, se_var = np.sqrt(var / e.size), var * np.sqrt(2.0 / e.size)
        assert abs(e.mean() - mean) < 5 * se_mean, (mean, e.mean())
        assert abs(e.var() - var) < 5 * se_var, (mean, e.var())
    rng = np.random.default_rng(1)
    means = rng.uniform(0.0, FULL_WELL_E, (256, 256))
    changed = means * (1.0 + 1e-6)
    a, b = sensor_noise(means, seed), sensor_noise(changed, seed)
    # A pixel's quantile moves, by one electron, when its uniform lies within the CDF's
    # change of a step: with probability about the change of its mean in electrons
    # (0.005 on average here; a fresh draw would move nearly every pixel).
    moved, expected = np.mean(a != b), np.mean(changed - means)
    assert moved < 2 * expected and np.abs(a - b).max() <= 1, (moved, expected)
    print(f"sensor noise: statistics within 5 standard errors; means changed by 1e-6 move "
          f"{moved:.4f} of the pixels by one electron (expected about {expected:.4f})")


# --------------------------------------------------------------------------- writing
def write_exr(mi, path, array, names):
    """Float32 EXR with the given channel names. Mitsuba's Bitmap.write deadlocks
    with a single Dr.Jit worker thread (3.9.1 / 1.5.0), so it is given two."""
    import drjit as dr

    threads = dr.thread_count()
    if threads < 2:
        dr.set_thread_count(2)
    try:
        write_exr_unguarded(mi, path, array, names)
    finally:
        if threads < 2:
            dr.set_thread_count(threads)


def write_exr_unguarded(mi, path, array, names):
    array = np.ascontiguousarray(array, dtype=np.float32)
    if array.ndim == 2:
        array = array[..., None]
    bmp = mi.Bitmap(array, pixel_format=mi.Bitmap.PixelFormat.MultiChannel, channel_names=names)
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    bmp.write(str(path))


def write_png(path, array):
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    Image.fromarray(array).save(path)


def write_sample(mi, out, name, stokes, gt, extra, meta, draws):
    """Writes one scene's clean sample folder and its `draws` noisy ones."""
    kind, k = name.rsplit("-", 1)
    d = out / f"{kind}-clean-{k}"
    if d.exists():
        shutil.rmtree(d)
    (d / "gt").mkdir(parents=True)
    write_exr(mi, d / "stokes.exr", stokes, ["S0", "S1", "S2", "S3"])
    imgs = polarizer_images(stokes)
    write_exr(mi, d / "polarizers.exr", np.stack([imgs[a] for a in (0, 45, 90, 135)], -1),
              ["I0", "I45", "I90", "I135"])
    write_exr(mi, d / "gt" / "normal.exr", gt["normal"], ["R", "G", "B"])
    write_exr(mi, d / "gt" / "depth.exr", gt["depth"], ["Y"])
    write_png(d / "gt" / "material.png", gt["material"])
    write_png(d / "gt" / "transparent.png", gt["transparent"])
    for key, img in extra.items():
        write_exr(mi, d / "gt" / f"{key}.exr", img, ["Y"])
    write_raw(d, stokes, meta, None)
    write_noisy_draws(out, d, stokes, meta, draws)


def noisy_name(clean, draw):
    """The folder of noise draw `draw` of a clean sample folder `mts-<kind>-clean-<k>`:
    `mts-<kind>-noisy-<k + 10 draw>`, one family for all draws."""
    kind, k = clean.name.rsplit("-", 1)
    return f"{kind.removesuffix('-clean')}-noisy-{int(k) + SCENES_PER_DRAW * draw}"


def write_noisy_draws(out, clean, stokes, meta, draws):
    """Copies the clean sample folder to each noise draw's and writes its raw and meta;
    draws left from an earlier run with more of them are removed."""
    for draw in range(MAX_DRAWS):
        d = out / noisy_name(clean, draw)
        if d.exists():
            shutil.rmtree(d)
        if draw < draws:
            shutil.copytree(clean, d)
            write_raw(d, stokes, meta, draw)


def write_raw(d, stokes, meta, draw):
    """raw.png and meta.json of sample folder `d`: noiseless for `draw` None, else that
    noise draw (its own seed)."""
    noisy = draw is not None
    seed = meta["seed"] * 2 + noisy + 1000 * (draw or 0)
    raw, k_dn, gain = raw_dn(stokes, noisy, seed)
    write_png(d / "raw.png", raw)
    m = dict(meta)
    m["sample"] = d.name
    m["sensor"] = {
        "noise": "noisy" if noisy else "clean", "noise_draw": draw,
        "bits": BITS, "container_bits": 16, "alignment": "right",
        "mosaic": {"row0": [90, 45], "row1": [135, 0]},
        "dn_per_radiance": k_dn, "p99_s0_dn": P99_FRACTION * FULL_SCALE,
        "full_well_e": FULL_WELL_E, "gain_e_per_dn": gain,
        "read_noise_e": READ_NOISE_E if noisy else 0.0,
        "shot_noise": noisy,
        "saturated_pixels": int(np.sum(raw >= FULL_SCALE)), "seed": seed,
    }
    (d / "meta.json").write_text(json.dumps(m, indent=2) + "\n")


def redraw_noise(mi, out, only, draws):
    """Writes the noisy draws again from the clean sample folders under `out` (their
    stokes.exr and meta.json), without rendering."""
    cleans = sorted(p for p in out.glob("mts-*-clean-*") if p.is_dir())
    cleans = [p for p in cleans if not only or any(p.name.startswith(o) for o in only)]
    if not cleans:
        sys.exit(f"--redraw-noise: no clean sample folders (mts-*-clean-*) under {out}"
                 + (f" matching --only {','.join(only)}" if only else ""))
    for clean in cleans:
        stokes = np.array(mi.Bitmap(str(clean / "stokes.exr")), dtype=np.float64)
        meta = json.loads((clean / "meta.json").read_text())
        meta.pop("sample", None)
        meta.pop("sensor", None)
        write_noisy_draws(out, clean, stokes, meta, draws)
        print(f"{clean.name}: {draws} noise draws", flush=True)


def jsonable(desc):
    """The scene description without Mitsuba objects, for meta.json."""
    def clean(v):
        if isinstance(v, dict):
            return {k: clean(x) for k, x in v.items() if k not in ("to_world", "filename", "to_uv")}
        if isinstance(v, (list, tuple)):
            return [clean(x) for x in v]
        if isinstance(v, (int, float, str, bool)) or v is None:
            return v
        if isinstance(v, np.ndarray):
            return v.tolist()
        return str(v)
    return {
        "objects": {k: {"shape": clean(s), "label": lab} for k, (s, lab) in desc["objects"].items()},
        "background": clean(desc["background"]),
        "emitters": clean(desc["emitters"]),
        "medium": clean(desc.get("medium")),
    }


def render_one(mi, dr, out, name, desc, args, seed):
    import mitsuba

    size = args.size
    has_medium = "medium" in desc
    spp = args.haze_spp if has_medium else args.spp
    t0 = time.perf_counter()
    scene = mi.load_dict(scene_dict(mi, desc, size, spp, True), optimize=False)
    stokes = common.render_stokes(mi, scene, spp, seed)
    extra, meta_extra = {}, {}
    clear = scene
    if has_medium:
        clear = mi.load_dict(scene_dict(mi, desc, size, args.spp, False), optimize=False)
        extra["clear"] = common.render_stokes(mi, clear, args.spp, seed + 1)[..., 0]
        meta_extra["clear_spp"] = args.spp
    gt = ground_truth(mi, dr, clear, desc, size)
    if has_medium:
        extra["transmission"] = transmission(gt, desc["medium"], size)
        if not args.no_dehazed:
            extra["dehazed"] = render_dehazed(mi, dr, scene, clear, desc, size, spp, seed + 2)
    seconds = time.perf_counter() - t0
    origin, target, fov = desc["camera"]
    meta = {
        "renderer": f"mitsuba {mitsuba.__version__}",
        "variant": common.VARIANT,
        "generator": "tools/mitsuba/task_scenes.py",
        "width": size, "height": size,
        "camera": {"fov_deg": fov, "fov_axis": "x", "position": list(origin), "look_at": list(target), "up": UP,
                   "projection": "perspective"},
        "integrator": "stokes(volpath)" if has_medium else "stokes(path)",
        "max_depth": HAZE_MAX_DEPTH if has_medium else MAX_DEPTH,
        "spp": spp, **meta_extra, "seed": seed, "seconds": round(seconds, 3),
        "stokes_frame": "Mitsuba stokes integrator = conventions' per-pixel frame (x_ref = d x up)",
        "scene": {"name": name, **jsonable(desc)},
        "ground_truth": {"rays": "pixel centres", "dehazed": "camera segment without medium" if "dehazed" in extra else None},
    }
    write_sample(mi, out, name, stokes, gt, extra, meta, args.noise_draws)
    return seconds, stokes, gt


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", type=Path, default=DEFAULT_OUT)
    ap.add_argument("--spp", type=int, default=1024,
                    help="samples per pixel of the surface scenes and of the haze scenes' gt/clear.exr")
    ap.add_argument("--haze-spp", type=int, default=512,
                    help="samples per pixel of the hazy images and gt/dehazed.exr (volpath; the slow part)")
    ap.add_argument("--size", type=int, default=128, help="image width = height (even)")
    ap.add_argument("--threads", type=int, default=None, help="Dr.Jit threads (default: all cores)")
    ap.add_argument("--only", default="", help="comma-separated scene-name prefixes, e.g. mts-haze,mts-shape-1")
    ap.add_argument("--no-dehazed", action="store_true", help="skip gt/dehazed.exr (saves ~1/3 of a haze scene's time)")
    ap.add_argument("--noise-draws", type=int, default=5,
                    help="noisy samples per scene, each with its own sensor-noise draw (one family)")
    ap.add_argument("--redraw-noise", action="store_true",
                    help="only write the noisy draws again from the clean samples under --out (no rendering)")
    ap.add_argument("--check-noise", action="store_true",
                    help="check the sensor noise's statistics and stability and exit (no Mitsuba)")
    args = ap.parse_args()
    if args.check_noise:
        check_noise()
        return
    if min(args.spp, args.haze_spp) < 1 or args.size < 2 or args.size % 2:
        ap.error("--spp and --haze-spp must be >= 1 and --size even and >= 2")
    if not 1 <= args.noise_draws <= MAX_DRAWS:
        ap.error(f"--noise-draws must be in 1..{MAX_DRAWS}")
    mi, dr = common.setup_mitsuba(args.threads)
    args.out.mkdir(parents=True, exist_ok=True)
    only = [p for p in args.only.split(",") if p]
    if args.redraw_noise:
        redraw_noise(mi, args.out, only, args.noise_draws)
        return
    t_all = time.perf_counter()
    with tempfile.TemporaryDirectory() as tmp:
        meshes = Meshes(tmp)
        seed = 0
        for kind, make in KINDS.items():
            descs = make(mi, meshes)
            assert len(descs) <= SCENES_PER_DRAW, f"{kind}: noisy sample numbers would collide"
            for k, desc in enumerate(descs):
                name = f"mts-{kind}-{k}"
                seed += 1
                if only and not any(name.startswith(p) for p in only):
                    continue
                seconds, stokes, gt = render_one(mi, dr, args.out, name, desc, args, seed)
                obj = gt["material"] > 0
                s0 = stokes[..., 0]
                dolp = np.hypot(stokes[..., 1], stokes[..., 2]) / np.where(s0 > 0, s0, np.nan)
                print(f"{name}: {seconds:6.1f} s, object pixels {int(obj.sum())}, "
                      f"mean DoLP objects {np.nanmean(dolp[obj]):.3f} background {np.nanmean(dolp[~obj]):.3f}",
                      flush=True)
    print(f"total {time.perf_counter() - t_all:.1f} s -> {args.out}")


if __name__ == "__main__":
    main()
