//! Shape from polarization: unit camera-frame surface normals, relative depth, a
//! confidence map and a per-pixel reflection type from one linear-polarization
//! observation ([`polar_sensor::Observation`]).
//!
//! Pipeline ([`estimate_shape`]), at the working scale ([`scale`]: a frame much larger
//! than [`scale::WORKING_SIZE`] is binned, the steps run there and their results are
//! interpolated back to the frame's pixels):
//! 1. Per-pixel cues ([`cues`]): S0 normalised by [`Observation::s0_scale`], DoLP,
//!    AoLP, a confidence from the DoLP's signal-to-noise ratio and the validity flags.
//! 2. Foreground ([`foreground`]): objects are the regions enclosed by strong
//!    intensity / polarization edges that do not touch the image border.
//! 3. Candidate normals per pixel from the reflection models of
//!    [`polar_optics::reflection_dolp`] (diffuse: azimuth = AoLP; specular: AoLP + 90°),
//!    built in the per-pixel Stokes frame ([`polar_optics::pixel_frame::PixelFrame`]).
//! 4. Disambiguation: [`Method::Local`] (occluding-boundary prior + convexity +
//!    smoothness, [`local`]) or [`Method::Global`] (shading and polarization in one
//!    sparse linear least-squares problem for the height, [`global`]).
//! 5. Depth from the normals ([`integrate`]): Frankot–Chellappa or a masked Poisson solve.
//!
//! Alongside: the refractive index, given, estimated from the DoLP profile at the
//! occluding contours ([`ior`], with [`IorOption::Estimate`]) or [`DEFAULT_IOR`]
//! ([`IorSource`] says which and why), and the Lambertian light and ambient fitted to the
//! shading over the local method's normals ([`global::Light`]).
//!
//! Output conventions follow `gt/normal.exr`: `(x, y, z)` in the camera frame (x right,
//! y up, z toward the camera), `0, 0, 0` where there is no estimate. Depth is relative
//! (see [`integrate`]): NaN outside the foreground.

pub mod cues;
pub mod foreground;
pub mod global;
pub mod integrate;
pub mod ior;
pub mod local;
pub mod scale;
pub mod zenith;

#[cfg(test)]
mod synth;
#[cfg(test)]
mod tests;

use std::fmt;
use std::str::FromStr;

use nalgebra::Vector3;
use polar_image::{Gray, Image, NormalImage};
use polar_sensor::Observation;
use thiserror::Error;

use crate::local::Outline;

/// The refractive index used when none is given (and where [`IorOption::Estimate`] finds
/// too little evidence): typical plastics and glass (1.45–1.6). It is the default rather
/// than the estimate because on rendered glossy objects the contour DoLP is diluted by
/// specular light and the estimate strays further from the truth (docs/benchmarks.md).
pub const DEFAULT_IOR: f64 = 1.5;

/// Errors of shape from polarization.
#[derive(Debug, Error, PartialEq)]
pub enum ShapeError {
    /// The observation has no pixels.
    #[error("empty observation ({0}x{1})")]
    Empty(usize, usize),
    /// The refractive index is not a finite number above 1.
    #[error("refractive index {0} is not a finite number > 1")]
    InvalidIor(f64),
    /// A given object mask is not of the observation's size.
    #[error("the object mask is {0:?}, the observation {1:?}")]
    ObjectsSize((usize, usize), (usize, usize)),
    /// A method or integrator name that is not known.
    #[error("unknown {kind} `{name}` (known: {known})")]
    UnknownName {
        /// What was being parsed.
        kind: &'static str,
        /// The name given.
        name: String,
        /// The accepted names.
        known: &'static str,
    },
    /// An image-processing primitive failed.
    #[error("image processing: {0}")]
    Imgproc(#[from] polar_imgproc::Error),
    /// The sparse solver failed.
    #[error("sparse solver: {0}")]
    Solver(String),
}

/// How the azimuth ambiguity is resolved.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Method {
    /// Occluding-boundary propagation with a convexity prior and smoothness (fast).
    #[default]
    Local,
    /// Height from polarization and shading, one sparse least-squares solve.
    Global,
}

impl FromStr for Method {
    type Err = ShapeError;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s {
            "local" => Ok(Method::Local),
            "global" => Ok(Method::Global),
            _ => Err(ShapeError::UnknownName {
                kind: "method",
                name: s.into(),
                known: "local, global",
            }),
        }
    }
}

impl fmt::Display for Method {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Method::Local => "local",
            Method::Global => "global",
        })
    }
}

/// How depth is obtained from the normals.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Integrator {
    /// Frankot–Chellappa: least squares in the Fourier domain over the whole image.
    FrankotChellappa,
    /// Weighted least squares (screened Poisson) over the foreground only.
    #[default]
    Poisson,
}

impl FromStr for Integrator {
    type Err = ShapeError;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s {
            "fc" => Ok(Integrator::FrankotChellappa),
            "poisson" => Ok(Integrator::Poisson),
            _ => Err(ShapeError::UnknownName {
                kind: "integrator",
                name: s.into(),
                known: "fc, poisson",
            }),
        }
    }
}

impl fmt::Display for Integrator {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Integrator::FrankotChellappa => "fc",
            Integrator::Poisson => "poisson",
        })
    }
}

/// Options of [`estimate_shape`]; the default is local, Poisson, index [`DEFAULT_IOR`],
/// working scale [`scale::WORKING_SIZE`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShapeOptions {
    /// Disambiguation method.
    pub method: Method,
    /// Depth integrator of the local method (the global method's depth is its own
    /// least-squares solution, so it ignores this).
    pub integrator: Integrator,
    /// How the relative refractive index of the objects is chosen.
    pub ior: IorOption,
    /// Long side (pixels) of the working scale ([`scale`]); larger images are binned.
    pub working_size: usize,
}

impl Default for ShapeOptions {
    fn default() -> Self {
        Self {
            method: Method::Local,
            integrator: Integrator::Poisson,
            ior: IorOption::Default,
            working_size: scale::WORKING_SIZE,
        }
    }
}

/// How the refractive index is chosen.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum IorOption {
    /// [`DEFAULT_IOR`].
    #[default]
    Default,
    /// This index (a finite number above 1).
    Given(f64),
    /// Estimated from the image ([`ior::estimate_ior`]), else [`DEFAULT_IOR`].
    Estimate,
}

impl FromStr for IorOption {
    type Err = ShapeError;
    /// `auto` or a number.
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        if s == "auto" {
            return Ok(IorOption::Estimate);
        }
        match s.parse::<f64>() {
            Ok(n) if n.is_finite() && n > 1.0 => Ok(IorOption::Given(n)),
            Ok(n) => Err(ShapeError::InvalidIor(n)),
            Err(_) => Err(ShapeError::UnknownName {
                kind: "refractive index",
                name: s.into(),
                known: "a number > 1, auto",
            }),
        }
    }
}

/// Where the index of a [`Shape`] came from.
#[derive(Clone, Debug, PartialEq)]
pub enum IorSource {
    /// Given by the caller.
    Given,
    /// Estimated from the image.
    Estimated(ior::IorEstimate),
    /// [`DEFAULT_IOR`], with the reason (not asked for, or too little evidence).
    Default(String),
}

impl fmt::Display for IorSource {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            IorSource::Given => f.write_str("given"),
            IorSource::Estimated(e) => write!(
                f,
                "estimated from {} contour pixels (fit {:.3})",
                e.pixels, e.unclamped
            ),
            IorSource::Default(why) => write!(f, "default ({why})"),
        }
    }
}

impl IorSource {
    /// `given`, `estimated` or `default`.
    pub fn name(&self) -> &'static str {
        match self {
            IorSource::Given => "given",
            IorSource::Estimated(_) => "estimated",
            IorSource::Default(_) => "default",
        }
    }
}

/// The reflection that explains a pixel's polarization.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u8)]
pub enum ReflectionType {
    /// No estimate (background, invalid pixel).
    None = 0,
    /// Diffuse: AoLP parallel to the plane of incidence.
    Diffuse = 1,
    /// Specular: AoLP perpendicular to the plane of incidence.
    Specular = 2,
    /// Both contribute comparably; the polarization is not explained by one model alone.
    Mixed = 3,
}

/// Result of [`estimate_shape`].
#[derive(Clone, Debug)]
pub struct Shape {
    /// Unit camera-frame normals (R, G, B = x, y, z; z > 0 faces the camera), `0,0,0`
    /// where there is no estimate.
    pub normal: NormalImage,
    /// Relative depth (larger = farther), NaN outside the foreground.
    pub depth: Gray<f32>,
    /// Confidence in `[0, 1]` of each normal (0 where there is none).
    pub confidence: Gray<f32>,
    /// [`ReflectionType`] as `u8` per pixel.
    pub reflection: Gray<u8>,
    /// 255 on the estimated objects, 0 elsewhere.
    pub foreground: Gray<u8>,
    /// The refractive index used.
    pub ior: f64,
    /// Where [`Shape::ior`] came from.
    pub ior_source: IorSource,
    /// The light fitted to the shading ([`global::fit_light`]), `None` without enough
    /// lit diffuse pixels.
    pub light: Option<global::Light>,
}

/// Normals, depth, confidence and reflection types of one observation.
///
/// Errors: an empty observation, an invalid `opts.ior`, or a solver failure. An all-dark
/// or all-invalid frame is not an error: it gives no foreground, zero normals and NaN depth.
pub fn estimate_shape(obs: &Observation, opts: &ShapeOptions) -> Result<Shape, ShapeError> {
    estimate_shape_of(obs, opts, None)
}

/// [`estimate_shape`] with the object pixels given (`objects`, non-zero on objects, the
/// observation's size) in place of the foreground [`foreground::foreground`] finds: for a
/// mask from elsewhere, or to evaluate the rest of the method with a known mask, as
/// shape-from-polarization benchmarks give one. Its valid pixels are the foreground, with
/// the invalid regions it mostly surrounds; at a working scale a block is foreground
/// where at least half of its pixels are.
pub fn estimate_shape_of(
    obs: &Observation,
    opts: &ShapeOptions,
    objects: Option<&Gray<u8>>,
) -> Result<Shape, ShapeError> {
    let (w, h) = obs.size();
    if w == 0 || h == 0 {
        return Err(ShapeError::Empty(w, h));
    }
    if let Some(m) = objects.filter(|m| m.size() != (w, h)) {
        return Err(ShapeError::ObjectsSize(m.size(), (w, h)));
    }
    let objects: Option<Vec<bool>> =
        objects.map(|m| m.as_slice().iter().map(|&v| v != 0).collect());
    let given = match opts.ior {
        IorOption::Given(n) => n,
        IorOption::Default | IorOption::Estimate => DEFAULT_IOR,
    };
    if !(given.is_finite() && given > 1.0) {
        return Err(ShapeError::InvalidIor(given));
    }
    match scale::working_factor(w, h, opts.working_size) {
        1 => estimate_at_scale(obs, opts, given, objects.as_deref()),
        f => {
            let grid = scale::Grid { w, h, f };
            let coarse_objects = objects.as_deref().map(|m| grid.majority(m));
            let coarse = estimate_at_scale(&obs.binned(f), opts, given, coarse_objects.as_deref())?;
            grid.upsample(coarse, obs, objects.as_deref())
        }
    }
}

/// [`estimate_shape`] in the observation's own pixels, `given` the starting index.
fn estimate_at_scale(
    obs: &Observation,
    opts: &ShapeOptions,
    given: f64,
    objects: Option<&[bool]>,
) -> Result<Shape, ShapeError> {
    let (w, h) = obs.size();
    // The foreground does not depend on the index, so the index can be estimated on it.
    let mut cues = cues::Cues::new(obs, given)?;
    let (fg, outline) = match objects {
        Some(m) => (foreground::given(&cues.valid, w, h, m)?, Outline::Given(m)),
        None => (foreground::foreground(&cues)?, Outline::Found),
    };
    let (ior, ior_source) = choose_ior(&cues, &fg, opts.ior)?;
    if ior != given {
        cues.models = zenith::ZenithModels::new(ior);
    }
    let local = local::disambiguate(&cues, &fg, outline)?;
    let light = global::fit_light(&cues, &fg, &local);
    let est = match opts.method {
        Method::Local => local,
        Method::Global => global::solve(&cues, &fg, local, light.as_ref())?,
    };
    let depth = match (opts.method, &est.depth) {
        (Method::Global, Some(d)) => d.clone(),
        _ => integrate::depth_from_normals(
            &est.normals,
            &est.confidence,
            &fg,
            opts.integrator,
            w,
            h,
        )?,
    };
    Ok(Shape {
        normal: normal_image(w, h, &est.normals),
        depth,
        confidence: Gray::from_vec(w, h, est.confidence.clone()).expect("sized"),
        reflection: Gray::from_vec(w, h, est.reflection.iter().map(|&r| r as u8).collect())
            .expect("sized"),
        foreground: Gray::from_vec(w, h, fg.iter().map(|&f| if f { 255 } else { 0 }).collect())
            .expect("sized"),
        ior,
        ior_source,
        light,
    })
}

/// The index and its source for `option`.
fn choose_ior(
    cues: &cues::Cues,
    fg: &[bool],
    option: IorOption,
) -> Result<(f64, IorSource), ShapeError> {
    Ok(match option {
        IorOption::Given(n) => (n, IorSource::Given),
        IorOption::Default => (DEFAULT_IOR, IorSource::Default("no index given".into())),
        IorOption::Estimate => match ior::estimate_ior(cues, fg)? {
            Ok(e) => (e.ior, IorSource::Estimated(e)),
            Err(why) => (DEFAULT_IOR, IorSource::Default(why)),
        },
    })
}

/// Per-pixel result of a disambiguation method.
#[derive(Clone, Debug)]
pub struct Estimate {
    /// Unit normals (zero vector where none).
    pub normals: Vec<Vector3<f64>>,
    /// Confidence in `[0, 1]`.
    pub confidence: Vec<f32>,
    /// Reflection type per pixel.
    pub reflection: Vec<ReflectionType>,
    /// Depth, when the method produces it directly (the global method).
    pub depth: Option<Gray<f32>>,
}

/// Interleaved `f32` normal image from per-pixel vectors.
fn normal_image(w: usize, h: usize, normals: &[Vector3<f64>]) -> NormalImage {
    let data = normals
        .iter()
        .flat_map(|n| [n.x as f32, n.y as f32, n.z as f32])
        .collect();
    Image::from_vec(w, h, data).expect("sized")
}
