//! Task metrics of the vision pipeline, one function per task, each over the pixels
//! docs/conventions.md names (object pixels: `gt/material.png` label != 0, unless stated).
//! The per-pixel primitives (angular error, confusion matrix, IoU, PSNR, SSIM) come from
//! `polar-imgproc`, where they are checked against numpy / scikit-image; what is composed
//! here (depth after a scale-and-offset fit, precision/recall, correlation) is checked
//! against numpy by `tools/eval_goldens.py`. Results serialize to `metrics.json`.

mod aggregate;
mod depth;
mod tasks;

pub use aggregate::{Aggregate, Summary, aggregate, family_of};
pub use depth::{DepthFit, depth_fit};
pub use tasks::{
    DehazeMetrics, ImageScore, MaskMetrics, MaterialMetrics, NormalMetrics, REACHABLE_TRANSMISSION,
    ReachableScore, dehaze_metrics, gain_to, mask_metrics, material_metrics, normal_metrics,
    pearson,
};

use thiserror::Error;

/// Version of the `metrics.json` layout; raised when a key changes meaning.
pub const SCHEMA_VERSION: u32 = 1;

/// Errors of the metrics.
#[derive(Debug, Error)]
pub enum EvalError {
    /// A primitive rejected its inputs (sizes differ, labels out of range, ...).
    #[error(transparent)]
    Imgproc(#[from] polar_imgproc::Error),
    /// An estimate and its ground truth differ in size.
    #[error("{what}: estimate is {est_w}x{est_h}, ground truth {gt_w}x{gt_h}")]
    Size {
        /// What was compared.
        what: &'static str,
        /// Estimate width.
        est_w: usize,
        /// Estimate height.
        est_h: usize,
        /// Ground-truth width.
        gt_w: usize,
        /// Ground-truth height.
        gt_h: usize,
    },
}

/// Checks that two images have one size, naming `what` otherwise.
pub(crate) fn check_size(
    what: &'static str,
    est: (usize, usize),
    gt: (usize, usize),
) -> Result<(), EvalError> {
    if est == gt {
        return Ok(());
    }
    Err(EvalError::Size {
        what,
        est_w: est.0,
        est_h: est.1,
        gt_w: gt.0,
        gt_h: gt.1,
    })
}
