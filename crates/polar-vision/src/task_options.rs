//! The options of the tasks (shared by `run` and `eval`) and the dispatch to each task.

use clap::Args;

use crate::tasks::{Context, Failure, Outcome, Task};

/// Options of the analysis tasks.
#[derive(Clone, Debug, Args)]
pub struct TaskArgs {
    /// Horizontal field of view of the camera in degrees, for the per-pixel Stokes frame.
    /// Default: `camera.fov_deg` of the sample's meta.json, else an orthographic camera
    /// (the image axes as the Stokes frame: exact at the centre, off by a few degrees in
    /// the corners of a wide-angle view).
    #[arg(long, value_name = "DEG", value_parser = parse_fov)]
    pub fov: Option<f64>,
    /// Refractive index of the objects (sfp, material). Default: estimated where the image
    /// allows, else 1.5.
    #[arg(long, value_name = "N", value_parser = parse_ior)]
    pub ior: Option<f64>,
}

fn parse_fov(s: &str) -> Result<f64, String> {
    let v: f64 = s.parse().map_err(|_| format!("{s:?} is not a number"))?;
    if v > 0.0 && v < 180.0 {
        Ok(v)
    } else {
        Err(format!("{v} is not a field of view in (0, 180) degrees"))
    }
}

fn parse_ior(s: &str) -> Result<f64, String> {
    let v: f64 = s.parse().map_err(|_| format!("{s:?} is not a number"))?;
    if (1.0..=4.0).contains(&v) && v > 1.0 {
        Ok(v)
    } else {
        Err(format!("{v} is not a refractive index in (1, 4]"))
    }
}

/// Runs one task on the context.
pub fn execute(task: Task, _ctx: &mut Context<'_>, _args: &TaskArgs) -> Result<Outcome, Failure> {
    Err(Failure::CannotRun(format!(
        "{task} is not available in this build"
    )))
}
