//! Scene-file parsing: every example scene loads, meshes load from PLY and OBJ,
//! and each kind of bad input gives an error naming the file, the key and the reason.

use polar_render::{Error, Geometry, SamplerKind, load_scene, parse_scene};
use std::path::{Path, PathBuf};

const HEADER: &str = r#"
version = 1
[camera]
position = [0.0, 0.0, 5.0]
look_at = [0.0, 0.0, 0.0]
up = [0.0, 1.0, 0.0]
fov_deg = 30.0
width = 16
height = 16
"#;

fn parse(body: &str) -> Result<polar_render::Scene, Error> {
    parse_scene(&format!("{HEADER}{body}"), Path::new("/scenes/bad.toml"))
}

/// The error message must name the file, the key and contain the reason.
fn assert_names(err: Error, key: &str, reason: &str) {
    let msg = err.to_string();
    assert!(msg.contains("bad.toml"), "no file in: {msg}");
    assert!(msg.contains(key), "no key `{key}` in: {msg}");
    assert!(msg.contains(reason), "no reason `{reason}` in: {msg}");
}

#[test]
fn unknown_key_is_named() {
    let err = parse("[[shapes]]\ntype = \"sphere\"\nradius = 1.0\nradiuss = 2.0\n").unwrap_err();
    assert_names(err, "radiuss", "unknown field");
    let err = parse("[render]\nsamples = 4\n").unwrap_err();
    assert_names(err, "samples", "unknown field");
}

#[test]
fn sampler_key_is_read_and_checked() {
    assert_eq!(parse("").unwrap().settings.sampler, SamplerKind::Sobol);
    let scene = parse("[render]\nsampler = \"independent\"\n").unwrap();
    assert_eq!(scene.settings.sampler, SamplerKind::Independent);
    let err = parse("[render]\nsampler = \"halton\"\n").unwrap_err();
    assert_names(err, "sampler", "unknown variant `halton`");
}

#[test]
fn split_depth_is_read_and_checked() {
    let default = parse("").unwrap().settings.split_depth;
    assert_eq!(default, polar_render::MAX_SPLIT_DEPTH);
    assert_eq!(
        parse("[render]\nsplit_depth = 0\n")
            .unwrap()
            .settings
            .split_depth,
        0
    );
    let err = parse("[render]\nsplit_depth = 6\n").unwrap_err();
    assert_names(err, "render.split_depth", "must be at most 5");
}

#[test]
fn key_of_another_shape_type_is_rejected() {
    let err = parse("[[shapes]]\ntype = \"cube\"\nradius = 1.0\n").unwrap_err();
    assert_names(err, "shapes[0].radius", "not used by shape type");
}

#[test]
fn missing_mesh_file_is_named() {
    let err = parse("[[shapes]]\ntype = \"mesh\"\nfile = \"nowhere.ply\"\n").unwrap_err();
    assert_names(err, "shapes[0].file", "nowhere.ply");
}

#[test]
fn negative_roughness_is_rejected() {
    let err = parse("[materials.m]\ntype = \"conductor\"\nmetal = \"au\"\nroughness = -0.1\n")
        .unwrap_err();
    assert_names(err, "materials.m.roughness", "-0.1");
}

#[test]
fn non_positive_ior_is_rejected() {
    let err = parse("[materials.glass]\ntype = \"dielectric\"\nior = 0.0\n").unwrap_err();
    assert_names(err, "materials.glass.ior", "> 0");
}

#[test]
fn nan_values_are_rejected() {
    let err = parse("[[shapes]]\ntype = \"sphere\"\nradius = nan\n").unwrap_err();
    assert_names(err, "shapes[0].radius", "positive and finite");
    let err = parse("[[lights]]\ntype = \"environment\"\nradiance = nan\n").unwrap_err();
    assert_names(err, "lights[0].radiance", "finite");
}

#[test]
fn unknown_material_and_bad_version_are_named() {
    let err =
        parse("[[shapes]]\ntype = \"sphere\"\nradius = 1.0\nmaterial = \"gold\"\n").unwrap_err();
    assert_names(err, "shapes[0].material", "no material named `gold`");
    let err = parse_scene(
        &HEADER.replace("version = 1", "version = 2"),
        Path::new("bad.toml"),
    )
    .unwrap_err();
    assert_names(err, "version", "unsupported version 2");
}

#[test]
fn meshes_load_from_ply_and_obj() {
    let dir = tempfile::tempdir().expect("tempdir");
    let ply = "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n\
               element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n";
    std::fs::write(dir.path().join("quad.ply"), ply).expect("write");
    std::fs::write(
        dir.path().join("tri.obj"),
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nvn 0 0 1\nvn 0 0 1\nf 1//1 2//2 3//3\n",
    )
    .expect("write");
    let body = "[[shapes]]\ntype = \"mesh\"\nfile = \"quad.ply\"\nscale = 2.0\n[[shapes]]\ntype = \"mesh\"\nfile = \"tri.obj\"\n";
    let path = dir.path().join("scene.toml");
    std::fs::write(&path, format!("{HEADER}{body}")).expect("write");
    let scene = load_scene(&path).expect("scene");
    let Geometry::Mesh(quad) = &scene.shapes[0].geometry else {
        panic!("not a mesh")
    };
    assert_eq!(quad.triangles.len(), 2, "the quad is fan-triangulated");
    assert_eq!(
        quad.positions[2],
        nalgebra::Vector3::new(2.0, 2.0, 0.0),
        "scale applied"
    );
    let Geometry::Mesh(tri) = &scene.shapes[1].geometry else {
        panic!("not a mesh")
    };
    assert_eq!((tri.triangles.len(), tri.normals.len()), (1, 3));
}

fn scene_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).expect("scenes dir").flatten() {
        let p = entry.path();
        if p.is_dir() {
            scene_files(&p, out);
        } else if p.extension().is_some_and(|e| e == "toml") {
            out.push(p);
        }
    }
}

#[test]
fn every_example_scene_loads() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../datasets-synth/scenes");
    let mut files = Vec::new();
    scene_files(&root, &mut files);
    assert!(files.len() >= 8, "only {} example scenes", files.len());
    for f in files {
        let scene = load_scene(&f).unwrap_or_else(|e| panic!("{e}"));
        assert!(!scene.shapes.is_empty(), "{} has no shapes", f.display());
    }
}

const MEDIUM: &str = "[medium]\nbounds_min = [-1.0, -1.0, -1.0]\nbounds_max = [1.0, 1.0, 1.0]\n";

#[test]
fn medium_keys_are_read() {
    let scene = parse(&format!(
        "{MEDIUM}sigma_s = 0.5\nphase = {{ type = \"hg\", g = 0.6, depolarization = 0.5 }}\n\
         density = {{ resolution = [2, 1, 1], values = [0.0, 2.0] }}\n"
    ))
    .expect("scene");
    let m = scene.medium.expect("medium");
    assert_eq!((m.sigma_s, m.sigma_a), (0.5, 0.0));
    assert_eq!(m.density.expect("grid").values, vec![0.0, 2.0]);
    let fog = parse(&format!(
        "{MEDIUM}sigma_s = 0.5\nphase = {{ type = \"rayleigh\" }}\n\
         density = {{ height_falloff = 0.5, up = [0.0, 0.0, 1.0] }}\n"
    ))
    .expect("fog")
    .medium
    .expect("medium")
    .density
    .expect("grid");
    // Along z only; density 1 at the bottom centre, e^{-h/H} above.
    assert_eq!(fog.resolution, [1, 1, 64]);
    let first = (-(1.0 / 64.0) / 0.5_f64).exp();
    assert!((fog.values[0] - first).abs() < 1e-12 && fog.values[63] < fog.values[0]);
}

/// Issue #22: sizes that would exhaust memory or run for years are refused before any work,
/// naming the key and the bound.
#[test]
fn size_like_keys_have_upper_bounds() {
    let sized = |w: u32, h: u32| {
        HEADER
            .replace("width = 16", &format!("width = {w}"))
            .replace("height = 16", &format!("height = {h}"))
    };
    let big = parse_scene(&sized(100_000, 100_000), Path::new("/scenes/bad.toml")).unwrap_err();
    assert_names(big, "camera.width", "1..=16384");
    let area = parse_scene(&sized(16_384, 16_384), Path::new("/scenes/bad.toml")).unwrap_err();
    assert_names(
        area,
        "camera.width",
        "exceeds the limit of 100000000 pixels",
    );
    assert!(parse_scene(&sized(10_000, 10_000), Path::new("/scenes/bad.toml")).is_ok());
    let err = parse("[render]\nspp = 4294967295\n").unwrap_err();
    assert_names(err, "render.spp", "1..=1048576");
    let err = parse("[render]\nmax_depth = 4294967295\n").unwrap_err();
    assert_names(err, "render.max_depth", "1..=1024");
    // `segments`: segments_above_the_limit_are_rejected.
}

/// Issue #22: a torus tube of negative radius, or one reaching the axis, is refused.
#[test]
fn torus_minor_radius_must_be_inside_the_ring() {
    for r in ["-0.5", "0.0", "1.0", "3.0", "nan"] {
        let err = parse(&format!(
            "[[shapes]]\ntype = \"torus\"\nminor_radius = {r}\n"
        ))
        .unwrap_err();
        assert_names(err, "shapes[0].minor_radius", "must be in (0, 1)");
    }
    assert!(parse("[[shapes]]\ntype = \"torus\"\nminor_radius = 0.9\n").is_ok());
}

#[test]
fn bad_medium_values_are_named() {
    let rayleigh = "phase = { type = \"rayleigh\" }\n";
    let cases = [
        (
            format!("{MEDIUM}sigma_s = -0.5\n{rayleigh}"),
            "medium.sigma_s",
            ">= 0",
        ),
        (
            format!("{MEDIUM}sigma_s = 0.5\nsigma_a = nan\n{rayleigh}"),
            "medium.sigma_a",
            "finite",
        ),
        (
            format!(
                "[medium]\nbounds_min = [0.0, 0.0, 0.0]\nbounds_max = [1.0, 0.0, 1.0]\nsigma_s = 1.0\n{rayleigh}"
            ),
            "medium.bounds_max",
            "must exceed bounds_min",
        ),
        (
            format!("{MEDIUM}sigma_s = 1.0\nphase = {{ type = \"hg\", g = 1.0 }}\n"),
            "medium.phase.g",
            "(-1, 1)",
        ),
        (
            format!(
                "{MEDIUM}sigma_s = 1.0\n{rayleigh}density = {{ resolution = [2, 2, 2], values = [1.0] }}\n"
            ),
            "medium.density.values",
            "1 values for resolution [2, 2, 2]",
        ),
        (
            format!(
                "{MEDIUM}sigma_s = 1.0\n{rayleigh}density = {{ resolution = [2, 1, 1], values = [1.0, -1.0] }}\n"
            ),
            "medium.density.values",
            "values[1] = -1",
        ),
        (
            format!(
                "{MEDIUM}sigma_s = 1.0\n{rayleigh}density = {{ resolution = [0, 1, 1], values = [] }}\n"
            ),
            "medium.density.resolution",
            "at least 1 cell",
        ),
        (
            format!("{MEDIUM}sigma_s = 1.0\n{rayleigh}density = {{ height_falloff = 0.0 }}\n"),
            "medium.density.height_falloff",
            "positive",
        ),
        (
            format!(
                "{MEDIUM}sigma_s = 1.0\n{rayleigh}density = {{ height_falloff = 1.0, values = [1.0] }}\n"
            ),
            "medium.density.values",
            "not both",
        ),
        (
            format!(
                "{MEDIUM}sigma_s = 1.0\n{rayleigh}density = {{ height_falloff = 1.0, resolution = [100000, 100000, 1] }}\n"
            ),
            "medium.density.resolution",
            "cells",
        ),
        (
            format!(
                "{MEDIUM}sigma_s = 1.0\n{rayleigh}density = {{ resolution = [4294967296, 4294967296, 2], values = [1.0] }}\n"
            ),
            "medium.density.resolution",
            "more than 16777216 cells",
        ),
        (
            format!("{MEDIUM}sigma_s = 1.0\n{rayleigh}sigma_t = 2.0\n"),
            "sigma_t",
            "unknown field",
        ),
        (
            format!(
                "{MEDIUM}sigma_s = 1.0\nphase = {{ type = \"mie\", size_parameter = 1e9, ior = [1.33, 0.0] }}\n"
            ),
            "medium.phase.size_parameter",
            "exceeds 1000",
        ),
        (
            format!(
                "{MEDIUM}sigma_s = 1.0\nphase = {{ type = \"mie\", size_parameter = 2.0, ior = [1.33, -0.1] }}\n"
            ),
            "medium.phase.ior",
            "-0.1",
        ),
        (
            format!(
                "{MEDIUM}sigma_s = 1.0\nphase = {{ type = \"mie\", size_parameter = 0.0, ior = [1.33, 0.0] }}\n"
            ),
            "medium.phase.size_parameter",
            "0",
        ),
        (
            format!("{MEDIUM}sigma_s = 1.0\nphase = {{ type = \"rayleigh\", g = 0.5 }}\n"),
            "g",
            "unknown field",
        ),
    ];
    for (body, key, reason) in cases {
        assert_names(parse(&body).unwrap_err(), key, reason);
    }
}

#[test]
fn sky_light_is_read_and_checked() {
    let sky = "[[lights]]\ntype = \"sky\"\nsun_direction = [1.0, 1.0, 0.0]\noptical_depth = 0.1\nsun_irradiance = 2.0\n";
    let scene = parse(sky).expect("sky");
    let polar_render::Light::Sky(s) = &scene.lights[0] else {
        panic!("not a sky")
    };
    assert!((s.sun_direction.norm() - 1.0).abs() < 1e-12 && s.up == nalgebra::Vector3::y());
    let below = sky.replace("[1.0, 1.0, 0.0]", "[1.0, -1.0, 0.0]");
    assert_names(
        parse(&below).unwrap_err(),
        "lights[0].sun_direction",
        "horizon",
    );
    let negative = sky.replace("optical_depth = 0.1", "optical_depth = -1.0");
    assert_names(
        parse(&negative).unwrap_err(),
        "lights[0].optical_depth",
        "-1",
    );
    let zero = sky.replace("[1.0, 1.0, 0.0]", "[0.0, 0.0, 0.0]");
    assert_names(parse(&zero).unwrap_err(), "lights[0].sun_direction", "unit");
}

/// Hostile input (issue #22, seen writing the `scene` fuzz target): `segments` near `u32::MAX` overflowed `2 * segments`
/// and asked for far more memory than exists; above `MAX_SEGMENTS` it is now refused.
#[test]
fn segments_above_the_limit_are_rejected() {
    let max = polar_render::shapes::MAX_SEGMENTS;
    for segments in [max + 1, u32::MAX] {
        let body =
            format!("[[shapes]]\ntype = \"torus\"\nminor_radius = 0.3\nsegments = {segments}\n");
        let err = parse(&body).unwrap_err();
        assert_names(err, "shapes[0].segments", &format!("more than {max}"));
    }
    assert!(parse("[[shapes]]\ntype = \"disk\"\nsegments = 3\n").is_ok());
}
