//! Suite files: a versioned TOML description of a dataset (families, sizes, parameter ranges,
//! sensor noise levels), parsed and validated before any rendering starts.
//!
//! The format is documented in `datasets-synth/suites/README.md`; [`param_specs`] is the
//! single table of parameter names, default ranges and physical limits.

use std::collections::BTreeMap;
use std::path::Path;

use polar_render::scene::MAX_SPP;
use polar_sensor::SensorSettings;
use serde::{Deserialize, Serialize};

use crate::Error;

/// The suite file format version this crate reads.
pub const SUITE_VERSION: u32 = 1;

/// Most samples a suite may plan at one size, per family and over all families: far above
/// real datasets, low enough that the plan (about 1 KB per sample) fits in memory.
pub const MAX_COUNT: u32 = 1_000_000;

/// A whole dataset description.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Suite {
    /// Format version, must be [`SUITE_VERSION`].
    pub version: u32,
    /// Short name, used in the run record.
    pub name: String,
    /// Free text for people.
    #[serde(default)]
    pub description: String,
    /// Master seed: every sample seed derives from it, the family name and the sample index.
    pub seed: u64,
    /// Sensor noise levels, cycled over the samples of each family.
    #[serde(rename = "noise")]
    pub noise: Vec<NoiseLevel>,
    /// The families of samples, in order.
    #[serde(rename = "family")]
    pub families: Vec<Family>,
}

/// One sensor noise level (photon shot noise, read noise, quantisation), as in EMVA 1288.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NoiseLevel {
    /// Name referred to by families, e.g. `clean` or `realistic`.
    pub name: String,
    /// Full-well capacity, electrons; auto-exposure puts the 99th percentile of S0 at 80 % of it.
    pub full_well_e: f64,
    /// Gaussian read noise, electrons RMS.
    pub read_noise_e: f64,
    /// ADC bit depth of the raw mosaic (8..=16); the gain maps the full well to the ADC range.
    pub bits: u8,
    /// Poisson photon shot noise on or off.
    pub shot_noise: bool,
    /// Micro-polarizer extinction ratio T_max / T_min; absent = ideal polarizers.
    #[serde(default)]
    pub extinction_ratio: Option<f64>,
    /// Fraction of the full well the 99th percentile of S0 reaches (auto-exposure); absent =
    /// 0.8. Above 1 over-exposes (the brightest objects saturate), small values under-expose.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub exposure: Option<f64>,
}

/// What a family of samples is for; decides its parameters and scene layout.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FamilyKind {
    /// Shape from polarization: procedural shapes of varied index, roughness and albedo.
    Shape,
    /// Material classification: metals and dielectrics, rough and smooth, textured.
    Material,
    /// Transparent objects: glass of several shapes and thicknesses over textured backgrounds.
    Transparent,
    /// Haze: objects spread in depth in a slab of polarizing haze, for dehazing.
    Haze,
}

impl FamilyKind {
    /// The snake_case name used in suite files.
    pub fn name(self) -> &'static str {
        match self {
            FamilyKind::Shape => "shape",
            FamilyKind::Material => "material",
            FamilyKind::Transparent => "transparent",
            FamilyKind::Haze => "haze",
        }
    }
}

/// Which of a family's two sizes to make.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, clap::ValueEnum)]
#[serde(rename_all = "snake_case")]
pub enum SizeName {
    /// A few tiny samples: seconds on a laptop, for CI.
    Ci,
    /// The real dataset.
    Full,
}

impl SizeName {
    /// The key of this size in a family (`ci` or `full`).
    pub fn key(self) -> &'static str {
        match self {
            SizeName::Ci => "ci",
            SizeName::Full => "full",
        }
    }
}

/// Image size, sample count and samples per pixel for one size of a family.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SizeSpec {
    /// Number of samples.
    pub count: u32,
    /// Image width in pixels (even: the mosaic has 2x2 super-pixels).
    pub width: u32,
    /// Image height in pixels (even).
    pub height: u32,
    /// Path-tracing samples per pixel.
    pub spp: u32,
}

/// A family: one kind of sample with its sizes, ranges and choices.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Family {
    /// Unique name, the prefix of its sample ids.
    pub name: String,
    /// What the family is for.
    pub kind: FamilyKind,
    /// Names of the noise levels to cycle through (at least one); absent means all of the suite's.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub noise: Option<Vec<String>>,
    /// The CI size.
    pub ci: SizeSpec,
    /// The full size.
    pub full: SizeSpec,
    /// Overrides of numeric ranges, `key = [min, max]`; see [`param_specs`].
    #[serde(default)]
    pub ranges: BTreeMap<String, [f64; 2]>,
    /// Overrides of choice lists, `key = ["a", "b"]`; see [`choice_specs`].
    #[serde(default)]
    pub choices: BTreeMap<String, Vec<String>>,
}

impl Family {
    /// The size spec for `size`.
    pub fn size(&self, size: SizeName) -> SizeSpec {
        match size {
            SizeName::Ci => self.ci,
            SizeName::Full => self.full,
        }
    }

    /// The effective `[min, max]` for `key`: the suite's override or the documented default.
    pub fn range(&self, key: &str) -> [f64; 2] {
        if let Some(r) = self.ranges.get(key) {
            return *r;
        }
        param_specs(self.kind)
            .iter()
            .find(|s| s.key == key)
            .map_or([0.0, 0.0], |s| s.default)
    }

    /// The effective choice list for `key`: the suite's override or the documented default.
    pub fn choices(&self, key: &str) -> Vec<String> {
        if let Some(c) = self.choices.get(key) {
            return c.clone();
        }
        choice_specs(self.kind)
            .iter()
            .find(|s| s.key == key)
            .map_or_else(Vec::new, |s| {
                s.default.iter().map(|v| v.to_string()).collect()
            })
    }
}

/// A numeric parameter: name, default range, physical limits and meaning.
#[derive(Clone, Copy, Debug)]
pub struct ParamSpec {
    /// Key in `[family.ranges]` and in the recorded parameters.
    pub key: &'static str,
    /// Default `[min, max]` drawn uniformly.
    pub default: [f64; 2],
    /// Hard limits: a range outside is rejected as physically implausible.
    pub limits: [f64; 2],
    /// A count drawn as a whole number: its range must be whole numbers too.
    pub integer: bool,
    /// What it means, with unit.
    pub doc: &'static str,
}

/// A categorical parameter: name, allowed values and default list.
#[derive(Clone, Copy, Debug)]
pub struct ChoiceSpec {
    /// Key in `[family.choices]`.
    pub key: &'static str,
    /// Values a suite may list.
    pub allowed: &'static [&'static str],
    /// Default list, drawn uniformly.
    pub default: &'static [&'static str],
    /// What it means.
    pub doc: &'static str,
}

const fn p(key: &'static str, default: [f64; 2], limits: [f64; 2], doc: &'static str) -> ParamSpec {
    ParamSpec {
        key,
        default,
        limits,
        integer: false,
        doc,
    }
}

/// An integer parameter (a count), drawn with both ends inclusive.
const fn int(
    key: &'static str,
    default: [f64; 2],
    limits: [f64; 2],
    doc: &'static str,
) -> ParamSpec {
    ParamSpec {
        integer: true,
        ..p(key, default, limits, doc)
    }
}

const COMMON: &[ParamSpec] = &[
    p(
        "camera_distance",
        [3.0, 4.5],
        [0.5, 100.0],
        "camera distance to the scene centre, m",
    ),
    p(
        "camera_elevation_deg",
        [5.0, 35.0],
        [-80.0, 80.0],
        "camera elevation above the ground plane, degrees",
    ),
    p(
        "fov_deg",
        [30.0, 40.0],
        [5.0, 120.0],
        "horizontal field of view, degrees",
    ),
    p(
        "light_elevation_deg",
        [20.0, 75.0],
        [0.0, 90.0],
        "key light elevation, degrees",
    ),
    p(
        "light_azimuth_deg",
        [0.0, 360.0],
        [0.0, 360.0],
        "key light azimuth, degrees",
    ),
    p(
        "light_intensity",
        [2.0, 5.0],
        [0.01, 1000.0],
        "key light radiance scale, relative",
    ),
    p(
        "ambient",
        [0.05, 0.3],
        [0.0, 10.0],
        "uniform environment radiance, relative",
    ),
];

const SHAPE: &[ParamSpec] = &[
    int(
        "objects",
        [1.0, 3.0],
        [1.0, 8.0],
        "number of objects (integer)",
    ),
    p(
        "ior",
        [1.3, 1.8],
        [1.0, 3.0],
        "dielectric index of refraction (plastics 1.45-1.6, gems up to 2.4)",
    ),
    p("roughness", [0.0, 0.35], [0.0, 1.0], "GGX roughness alpha"),
    p(
        "albedo",
        [0.05, 0.9],
        [0.0, 1.0],
        "diffuse albedo under the specular coat",
    ),
    p("object_size", [0.5, 0.9], [0.05, 5.0], "object radius, m"),
];

/// Shape parameters, shared by every kind with objects.
const GEOMETRY: &[ParamSpec] = &[
    p(
        "superquadric_exponent",
        [0.3, 1.9],
        [0.1, 1.95],
        "superquadric exponents e1, e2 (1 = sphere; < 2 keeps normals finite)",
    ),
    p(
        "blob_amplitude",
        [0.05, 0.25],
        [0.0, 0.5],
        "radial bump amplitude of blobs, fraction of radius",
    ),
    p(
        "blob_frequency",
        [2.0, 5.0],
        [1.0, 12.0],
        "angular frequency of blob bumps",
    ),
    p(
        "torus_minor_ratio",
        [0.2, 0.45],
        [0.05, 0.9],
        "torus tube radius / ring radius",
    ),
    int(
        "extrusion_sides",
        [3.0, 8.0],
        [3.0, 32.0],
        "sides of the extruded star/polygon (integer)",
    ),
    p(
        "extrusion_depth",
        [0.3, 1.2],
        [0.05, 4.0],
        "extrusion depth, fraction of size",
    ),
];

const MATERIAL: &[ParamSpec] = &[
    int(
        "objects",
        [2.0, 4.0],
        [1.0, 8.0],
        "number of objects (integer)",
    ),
    p(
        "ior",
        [1.3, 1.8],
        [1.0, 3.0],
        "dielectric index of refraction",
    ),
    p("roughness", [0.0, 0.5], [0.0, 1.0], "GGX roughness alpha"),
    p("albedo", [0.05, 0.9], [0.0, 1.0], "diffuse albedo"),
    p(
        "texture_scale",
        [2.0, 12.0],
        [1.0, 64.0],
        "checker/stripe repetitions across an object",
    ),
    p("object_size", [0.4, 0.7], [0.05, 5.0], "object radius, m"),
];

const TRANSPARENT: &[ParamSpec] = &[
    int(
        "objects",
        [1.0, 2.0],
        [1.0, 8.0],
        "number of glass objects (integer)",
    ),
    p(
        "glass_ior",
        [1.45, 1.6],
        [1.0, 2.5],
        "glass index of refraction (fused silica 1.46, crown 1.52, flint 1.6)",
    ),
    p(
        "glass_roughness",
        [0.0, 0.0],
        [0.0, 1.0],
        "GGX roughness of the glass surface (0: polished)",
    ),
    p(
        "thickness",
        [0.05, 0.4],
        [0.005, 2.0],
        "slab thickness, m (the other glass shapes are solid)",
    ),
    p(
        "texture_scale",
        [4.0, 16.0],
        [1.0, 64.0],
        "background pattern repetitions",
    ),
    p("object_size", [0.5, 0.9], [0.05, 5.0], "object radius, m"),
];

/// Haze: objects spread in depth from `camera_distance` to `scene_depth` in a slab of haze,
/// seen by a camera looking along the ground; the sun is the key light.
const HAZE: &[ParamSpec] = &[
    p(
        "camera_distance",
        [3.0, 40.0],
        [0.5, 100.0],
        "depth of the nearest object, m",
    ),
    p(
        "camera_elevation_deg",
        [0.0, 8.0],
        [-10.0, 45.0],
        "downward pitch of the view, degrees",
    ),
    p(
        "light_elevation_deg",
        [5.0, 60.0],
        [0.0, 90.0],
        "sun elevation, degrees",
    ),
    p(
        "density",
        [0.005, 0.04],
        [0.0, 10.0],
        "haze extinction coefficient sigma_t, 1/m (0.04: visibility ~100 m)",
    ),
    p(
        "haze_albedo",
        [0.85, 1.0],
        [0.0, 1.0],
        "single-scattering albedo sigma_s / sigma_t of the haze",
    ),
    p(
        "haze_asymmetry",
        [0.0, 0.6],
        [-0.95, 0.95],
        "Henyey-Greenstein g of the haze (0 isotropic, aerosols 0.6-0.8)",
    ),
    p(
        "haze_depolarization",
        [0.0, 0.5],
        [0.0, 1.0],
        "depolarization of the haze phase matrix (0: Rayleigh-like, 1: none)",
    ),
    p(
        "scene_depth",
        [60.0, 200.0],
        [1.0, 10000.0],
        "distance of the farthest object, m",
    ),
    int(
        "objects",
        [3.0, 6.0],
        [1.0, 16.0],
        "number of objects (integer)",
    ),
    p(
        "ior",
        [1.4, 1.7],
        [1.0, 3.0],
        "object coat index of refraction",
    ),
    p(
        "roughness",
        [0.05, 0.5],
        [0.0, 1.0],
        "object GGX roughness alpha",
    ),
    p("albedo", [0.1, 0.8], [0.0, 1.0], "object diffuse albedo"),
];

/// The numeric parameters of a kind: common camera/light ones, the kind's own, then shape ones.
/// A kind may redefine a common key (default range, limits and meaning): its own spec wins.
pub fn param_specs(kind: FamilyKind) -> Vec<ParamSpec> {
    let (own, geometry) = match kind {
        FamilyKind::Shape => (SHAPE, GEOMETRY),
        FamilyKind::Material => (MATERIAL, GEOMETRY),
        FamilyKind::Transparent => (TRANSPARENT, GEOMETRY),
        FamilyKind::Haze => (HAZE, GEOMETRY),
    };
    let common = COMMON
        .iter()
        .filter(|c| !own.iter().any(|o| o.key == c.key));
    common.chain(own).chain(geometry).copied().collect()
}

const SHAPES: &[&str] = &["sphere", "superquadric", "blob", "torus", "extrusion"];
const GLASS_SHAPES: &[&str] = &["sphere", "slab", "torus", "extrusion"];
const MATERIALS: &[&str] = &["dielectric", "metal", "textured"];
const METALS: &[&str] = &["gold", "silver", "aluminium", "copper"];
const BACKGROUNDS: &[&str] = &["checker", "plain"];

/// The categorical parameters of a kind.
pub fn choice_specs(kind: FamilyKind) -> &'static [ChoiceSpec] {
    const fn c(
        key: &'static str,
        allowed: &'static [&'static str],
        doc: &'static str,
    ) -> ChoiceSpec {
        ChoiceSpec {
            key,
            allowed,
            default: allowed,
            doc,
        }
    }
    const SHAPE_C: &[ChoiceSpec] = &[c("shape", SHAPES, "procedural shape of each object")];
    const MATERIAL_C: &[ChoiceSpec] = &[
        c("shape", SHAPES, "procedural shape of each object"),
        c("material", MATERIALS, "material class of each object"),
        c(
            "metal",
            METALS,
            "metal of `metal` objects (complex index at 550 nm)",
        ),
    ];
    const HAZE_C: &[ChoiceSpec] = &[c("shape", SHAPES, "procedural shape of each object")];
    const TRANSPARENT_C: &[ChoiceSpec] = &[
        c("shape", GLASS_SHAPES, "shape of each glass object"),
        c(
            "background",
            BACKGROUNDS,
            "pattern of the backdrop behind the glass",
        ),
    ];
    match kind {
        FamilyKind::Shape => SHAPE_C,
        FamilyKind::Material => MATERIAL_C,
        FamilyKind::Transparent => TRANSPARENT_C,
        FamilyKind::Haze => HAZE_C,
    }
}

impl Suite {
    /// Reads and validates a suite file; all errors name the file.
    pub fn load(path: &Path) -> Result<Suite, Error> {
        let text = std::fs::read_to_string(path).map_err(Error::io(path))?;
        Suite::parse(&text).map_err(|message| Error::Suite {
            path: path.to_owned(),
            message,
        })
    }

    /// Parses and validates suite text; the error message says what is wrong and where.
    pub fn parse(text: &str) -> Result<Suite, String> {
        let suite: Suite = toml::from_str(text).map_err(|e| e.to_string())?;
        suite.validate()?;
        Ok(suite)
    }

    /// Checks every rule the TOML types cannot express.
    pub fn validate(&self) -> Result<(), String> {
        if self.version != SUITE_VERSION {
            return Err(format!(
                "version = {} is not supported (expected {SUITE_VERSION})",
                self.version
            ));
        }
        if self.noise.is_empty() {
            return Err("needs at least one [[noise]] level".into());
        }
        for (i, n) in self.noise.iter().enumerate() {
            validate_noise(n).map_err(|m| format!("[[noise]] #{} '{}': {m}", i + 1, n.name))?;
            if self.noise[..i].iter().any(|o| o.name == n.name) {
                return Err(format!("noise level '{}' is defined twice", n.name));
            }
        }
        if self.families.is_empty() {
            return Err("needs at least one [[family]]".into());
        }
        for (i, f) in self.families.iter().enumerate() {
            self.validate_family(f)
                .map_err(|m| format!("family '{}': {m}", f.name))?;
            if self.families[..i].iter().any(|o| o.name == f.name) {
                return Err(format!("family name '{}' is used twice", f.name));
            }
        }
        for size in [SizeName::Ci, SizeName::Full] {
            let total: u64 = self
                .families
                .iter()
                .map(|f| u64::from(f.size(size).count))
                .sum();
            if total > u64::from(MAX_COUNT) {
                return Err(format!(
                    "the families' {}.count add up to {total} samples, more than {MAX_COUNT}",
                    size.key()
                ));
            }
        }
        Ok(())
    }

    fn validate_family(&self, f: &Family) -> Result<(), String> {
        let name_ok = !f.name.is_empty()
            && f.name
                .chars()
                .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-');
        if !name_ok {
            return Err("name must be non-empty ASCII letters, digits, '_' or '-'".into());
        }
        for (label, s) in [("ci", f.ci), ("full", f.full)] {
            validate_size(s).map_err(|m| format!("{label}.{m}"))?;
        }
        if f.noise.as_ref().is_some_and(Vec::is_empty) {
            return Err(
                "noise = [] names no level; list at least one, or leave the key out for all".into(),
            );
        }
        for n in f.noise.iter().flatten() {
            if !self.noise.iter().any(|l| &l.name == n) {
                return Err(format!("noise level '{n}' is not defined in [[noise]]"));
            }
        }
        let specs = param_specs(f.kind);
        for (key, [lo, hi]) in &f.ranges {
            let Some(spec) = specs.iter().find(|s| s.key == key) else {
                let known: Vec<_> = specs.iter().map(|s| s.key).collect();
                return Err(format!(
                    "unknown range '{key}' for kind {}; known: {}",
                    f.kind.name(),
                    known.join(", ")
                ));
            };
            if !(lo.is_finite() && hi.is_finite() && lo <= hi) {
                return Err(format!(
                    "range {key} = [{lo}, {hi}] must be finite with min <= max"
                ));
            }
            if spec.integer && (lo.fract() != 0.0 || hi.fract() != 0.0) {
                return Err(format!(
                    "range {key} = [{lo}, {hi}] must be whole numbers ({})",
                    spec.doc
                ));
            }
            let [a, b] = spec.limits;
            if *lo < a || *hi > b {
                return Err(format!(
                    "range {key} = [{lo}, {hi}] leaves the physically plausible limits [{a}, {b}] ({})",
                    spec.doc
                ));
            }
        }
        let cspecs = choice_specs(f.kind);
        for (key, values) in &f.choices {
            let Some(spec) = cspecs.iter().find(|s| s.key == key) else {
                let known: Vec<_> = cspecs.iter().map(|s| s.key).collect();
                return Err(format!(
                    "unknown choice '{key}' for kind {}; known: {}",
                    f.kind.name(),
                    known.join(", ")
                ));
            };
            if values.is_empty() {
                return Err(format!("choice {key} must list at least one value"));
            }
            if let Some(bad) = values.iter().find(|v| !spec.allowed.contains(&v.as_str())) {
                return Err(format!(
                    "choice {key} has unknown value '{bad}'; allowed: {}",
                    spec.allowed.join(", ")
                ));
            }
        }
        Ok(())
    }

    /// The noise levels a family cycles through, in suite order.
    pub fn noise_for(&self, family: &Family) -> Vec<&NoiseLevel> {
        self.noise
            .iter()
            .filter(|l| family.noise.as_ref().is_none_or(|n| n.contains(&l.name)))
            .collect()
    }
}

/// Bounds of [`NoiseLevel::exposure`]: from a frame a few electrons deep to one saturated
/// almost everywhere.
const MIN_EXPOSURE: f64 = 1e-3;
/// See [`MIN_EXPOSURE`].
const MAX_EXPOSURE: f64 = 20.0;

/// Checks a noise level with the bounds of the sensor settings (`polar_sensor`); the
/// message starts with the key.
fn validate_noise(n: &NoiseLevel) -> Result<(), String> {
    if let Some(e) = n.exposure
        && !(MIN_EXPOSURE..=MAX_EXPOSURE).contains(&e)
    {
        return Err(format!(
            "exposure = {e} must be in {MIN_EXPOSURE}..={MAX_EXPOSURE} \
             (fraction of the full well at the 99th percentile of S0)"
        ));
    }
    SensorSettings {
        full_well_e: Some(n.full_well_e),
        read_noise_e: Some(n.read_noise_e),
        bits: Some(n.bits),
        shot_noise: Some(n.shot_noise),
        extinction_ratio: n.extinction_ratio,
    }
    .check()
}

/// Checks one size spec; the message starts with the key (`width`, `spp`, ...).
fn validate_size(s: SizeSpec) -> Result<(), String> {
    polar_render::scene::check_image_size(s.width as usize, s.height as usize)
        .map_err(|(key, reason)| format!("{key}: {reason}"))?;
    for (key, v) in [("width", s.width), ("height", s.height)] {
        if v < 2 || !v.is_multiple_of(2) {
            return Err(format!(
                "{key} = {v} must be even and >= 2 (2x2 polarizer super-pixels)"
            ));
        }
    }
    if !(1..=MAX_SPP).contains(&s.spp) {
        return Err(format!("spp = {} must be in 1..={MAX_SPP}", s.spp));
    }
    if s.count > MAX_COUNT {
        return Err(format!("count = {} exceeds {MAX_COUNT}", s.count));
    }
    Ok(())
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    pub(crate) const MINI: &str = r#"
version = 1
name = "mini"
seed = 7
[[noise]]
name = "clean"
full_well_e = 60000
read_noise_e = 0
bits = 16
shot_noise = false
[[family]]
name = "sfp"
kind = "shape"
ci = { count = 3, width = 8, height = 8, spp = 1 }
full = { count = 10, width = 64, height = 64, spp = 16 }
ranges = { ior = [1.4, 1.6] }
"#;

    #[test]
    fn mini_suite_parses_with_overrides_and_defaults() {
        let s = Suite::parse(MINI).unwrap();
        let f = &s.families[0];
        assert_eq!(f.range("ior"), [1.4, 1.6]);
        assert_eq!(f.range("roughness"), [0.0, 0.35]);
        assert_eq!(f.choices("shape").len(), SHAPES.len());
    }

    fn err_of(text: &str) -> String {
        Suite::parse(text).unwrap_err()
    }

    #[test]
    fn ior_below_one_is_rejected_with_limits() {
        let e = err_of(&MINI.replace("[1.4, 1.6]", "[0.5, 1.6]"));
        assert!(
            e.contains("family 'sfp'") && e.contains("ior") && e.contains("[1, 3]"),
            "{e}"
        );
    }

    #[test]
    fn unknown_range_key_lists_known_keys() {
        let e = err_of(&MINI.replace("ior = [1.4, 1.6]", "iorr = [1.4, 1.6]"));
        assert!(
            e.contains("unknown range 'iorr'") && e.contains("roughness"),
            "{e}"
        );
    }

    #[test]
    fn odd_width_is_rejected() {
        let e = err_of(&MINI.replace("width = 8", "width = 7"));
        assert!(e.contains("ci.width = 7") && e.contains("even"), "{e}");
    }

    /// Issue #22: counts, sizes and spp that would exhaust memory or run for years are
    /// refused naming the key and the bound.
    #[test]
    fn size_like_keys_have_upper_bounds() {
        let cases = [
            (
                "count = 3",
                "count = 1000000000",
                "ci.count = 1000000000 exceeds 1000000",
            ),
            (
                "width = 8, height = 8",
                "width = 100000, height = 100000",
                "ci.width: 100000 must be in 1..=16384",
            ),
            (
                "width = 8, height = 8",
                "width = 16384, height = 16384",
                "exceeds the limit of 100000000 pixels",
            ),
            (
                "spp = 1 }",
                "spp = 4294967295 }",
                "ci.spp = 4294967295 must be in 1..=1048576",
            ),
        ];
        for (from, to, message) in cases {
            let e = err_of(&MINI.replace(from, to));
            assert!(e.contains("family 'sfp'") && e.contains(message), "{e}");
        }
        let two = format!(
            "{MINI}{}",
            &MINI[MINI.find("[[family]]").unwrap()..].replace("\"sfp\"", "\"b\"")
        );
        let big = two.replace("count = 3", "count = 600000");
        let e = err_of(&big);
        assert!(
            e.contains("ci.count add up to 1200000 samples, more than 1000000"),
            "{e}"
        );
        assert!(Suite::parse(&two.replace("count = 3", "count = 500000")).is_ok());
    }

    /// Issue #22: a fractional range of a count and an empty noise list are refused.
    #[test]
    fn fractional_counts_and_empty_noise_lists_are_rejected() {
        let e = err_of(&MINI.replace("ior = [1.4, 1.6]", "objects = [1.5, 2.5]"));
        assert!(
            e.contains("range objects = [1.5, 2.5] must be whole numbers"),
            "{e}"
        );
        let e = err_of(&MINI.replace("ior = [1.4, 1.6]", "extrusion_sides = [3, 4.5]"));
        assert!(e.contains("range extrusion_sides"), "{e}");
        assert!(Suite::parse(&MINI.replace("ior = [1.4, 1.6]", "objects = [2, 3]")).is_ok());
        let e = err_of(&MINI.replace("kind = \"shape\"", "kind = \"shape\"\nnoise = []"));
        assert!(
            e.contains("family 'sfp'") && e.contains("noise = []"),
            "{e}"
        );
    }

    /// A noise level's exposure is read, absent by default, and refused outside its bounds
    /// (0, NaN, a hundredfold over-exposure) naming the key.
    #[test]
    fn exposure_is_read_and_bounded() {
        assert_eq!(Suite::parse(MINI).unwrap().noise[0].exposure, None);
        let with = |v: &str| {
            MINI.replace(
                "shot_noise = false",
                &format!("shot_noise = false\nexposure = {v}"),
            )
        };
        assert_eq!(
            Suite::parse(&with("2.5")).unwrap().noise[0].exposure,
            Some(2.5)
        );
        for bad in ["0", "nan", "100"] {
            let e = err_of(&with(bad));
            assert!(
                e.contains("exposure") && e.contains("must be in"),
                "{bad}: {e}"
            );
        }
    }

    /// Every suite file shipped in `datasets-synth/suites` is valid (a suite with a typo
    /// would otherwise fail only when someone renders it).
    #[test]
    fn every_shipped_suite_parses() {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../datasets-synth/suites");
        let mut names = Vec::new();
        for entry in std::fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            if path.extension().is_some_and(|e| e == "toml") {
                let suite =
                    Suite::load(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
                assert!(!suite.families.is_empty(), "{}", path.display());
                names.push(suite.name);
            }
        }
        assert!(names.iter().any(|n| n == "material-hard"), "{names:?}");
        assert!(names.len() >= 10, "{names:?}");
    }

    #[test]
    fn unknown_field_and_bad_version_are_rejected() {
        assert!(err_of(&MINI.replace("seed = 7", "seed = 7\ncolour = 3")).contains("colour"));
        assert!(err_of(&MINI.replace("version = 1", "version = 2")).contains("version = 2"));
    }

    #[test]
    fn undefined_noise_level_and_bad_choice_are_rejected() {
        let with_noise = MINI.replace("kind = \"shape\"", "kind = \"shape\"\nnoise = [\"loud\"]");
        assert!(err_of(&with_noise).contains("'loud'"));
        let with_choice = MINI.replace(
            "kind = \"shape\"",
            "kind = \"shape\"\nchoices = { shape = [\"cube\"] }",
        );
        assert!(err_of(&with_choice).contains("'cube'"));
    }
}
