//! Polarized path tracer: scene description (TOML file or Rust API), geometry in
//! an obvhs BVH, a pinhole camera, lights (area, environment, sun), a
//! unidirectional Mueller/Stokes path tracer with NEE + MIS, and the film with
//! first-hit ground truth (an option of the render call), following `docs/conventions.md`.
//!
//! ```no_run
//! let scene = polar_render::load_scene(std::path::Path::new("scene.toml"))?;
//! let out = polar_render::render(&scene, &Default::default(), &|_done, _total| {})?;
//! println!("{:?} transport, {} s", out.model, out.seconds);
//! # Ok::<(), polar_render::Error>(())
//! ```

mod camera;
mod geometry;
mod integrator;
pub mod math;
pub mod medium;
mod render;
pub mod sampler;
pub mod scene;
pub mod scene_file;
pub mod settings;
pub mod shapes;
mod tracking;
pub mod transport;
mod world;

pub use math::Vec3;
pub use medium::{DensityGrid, Medium};
pub use polar_bsdf::Material;
pub use polar_optics::Polarization;
pub use render::{FirstHit, RenderOptions, RenderOutput, render, required_model};
pub use sampler::SamplerKind;
pub use scene::{Camera, Emission, Geometry, Light, NamedMaterial, Scene, Shape};
pub use scene_file::{load_scene, parse_scene};
pub use settings::{MAX_SPLIT_DEPTH, RenderSettings};
pub use shapes::TriangleMesh;

use std::path::PathBuf;

/// Errors of scene loading and rendering.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// The scene file cannot be read.
    #[error("{file}: cannot read: {reason}")]
    Io {
        /// The scene file.
        file: PathBuf,
        /// The OS error.
        reason: String,
    },
    /// The scene file is not valid TOML or does not match the schema
    /// (the message names the key, its line and the reason, e.g. an unknown key).
    #[error("{file}: {message}")]
    Parse {
        /// The scene file.
        file: PathBuf,
        /// The parser's message.
        message: String,
    },
    /// A value is out of range or inconsistent.
    #[error("{file}: `{key}`: {reason}")]
    Invalid {
        /// The scene file (or `<scene built in code>`).
        file: PathBuf,
        /// Dotted key, e.g. `shapes[2].radius` or `materials.glass.ior`.
        key: String,
        /// Why the value is rejected.
        reason: String,
    },
    /// A mesh file cannot be loaded.
    #[error("mesh {path}: {reason}")]
    Mesh {
        /// The mesh file.
        path: PathBuf,
        /// What went wrong.
        reason: String,
    },
    /// A forced transport model is cheaper than the scene needs.
    #[error(
        "transport model {requested:?} cannot render this scene exactly; it needs {required:?}"
    )]
    ModelTooCheap {
        /// The model asked for.
        requested: Polarization,
        /// The cheapest exact model.
        required: Polarization,
    },
}
