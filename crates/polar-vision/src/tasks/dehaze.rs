//! `dehaze`: polarization dehazing (polar-dehaze) -> dehazed.exr, transmission.exr,
//! haze_depth.exr and a hazy / dehazed / transmission picture; image and transmission
//! metrics against the haze-free view.

use polar_dehaze::{DehazeOptions, dehaze};
use polar_eval::dehaze_metrics;
use polar_image::Gray;
use polar_io::files::vision::{self, pictures};

use super::{Context, Failure, NOISY, Outcome, SPARSE, io, picture_path, to_json, write_plane};
use crate::pictures::side_by_side;
use crate::task_options::TaskArgs;
use crate::writes::Writes;

/// Runs the task.
pub fn run(ctx: &mut Context<'_>, args: &TaskArgs) -> Result<Outcome, Failure> {
    let opts = DehazeOptions {
        method: args.dehaze_method,
        min_airlight_share: args.dehaze_min_airlight,
        ..DehazeOptions::default()
    };
    let d = dehaze(ctx.obs, &opts).map_err(|e| Failure::CannotRun(e.to_string()))?;
    let (out, s0) = (ctx.out, &ctx.obs.planes.s0);
    let mut files = Writes::default();
    for (name, plane, compression) in [
        (vision::DEHAZED, &d.radiance, NOISY),
        (vision::TRANSMISSION, &d.transmission, SPARSE),
        (vision::HAZE_DEPTH, &d.depth, SPARSE),
    ] {
        files.push(name, move || {
            write_plane(out.join(name), plane, compression)
        });
    }
    files.push(pictures::DEHAZE, || {
        let picture = side_by_side(&[s0, &d.radiance], Some(&d.transmission));
        polar_io::write_rgb8_png(picture_path(out, pictures::DEHAZE), &picture)
    });
    files.run().map_err(io)?;
    let mut outcome = Outcome {
        metrics: None,
        messages: d.warnings.clone(),
    };
    outcome.messages.push(format!(
        "{}: airlight at infinity {:.4} of the S0 scale, its DoLP {:.3}",
        d.method, d.airlight_inf, d.airlight_dolp
    ));
    if let Some(k) = ctx.radiance_per_unit {
        let (hazy, dehazed) = (scaled(s0, k), scaled(&d.radiance, k));
        let t = ctx.gt.transmission.as_ref().map(|gt| (&d.transmission, gt));
        let mut metrics = serde_json::Map::new();
        // gt/dehazed.exr removes what a dehazer can (attenuation and airlight along the
        // camera rays); gt/clear.exr also removes the haze's effect on the lighting.
        for (key, reference) in [
            ("against_dehazed", &ctx.gt.dehazed),
            ("against_clear", &ctx.gt.clear),
        ] {
            if let Some(reference) = reference {
                let labels = ctx.gt.material.as_ref();
                let m = dehaze_metrics(&hazy, &dehazed, reference, t, labels)
                    .map_err(|e| Failure::CannotRun(e.to_string()))?;
                metrics.insert(key.to_owned(), to_json(&m)?);
            }
        }
        outcome.metrics = (!metrics.is_empty()).then_some(serde_json::Value::Object(metrics));
    }
    Ok(outcome)
}

/// `img · k` (into the ground truth's radiance unit).
fn scaled(img: &Gray<f32>, k: f64) -> Gray<f32> {
    let mut out = img.clone();
    out.as_mut_slice()
        .iter_mut()
        .for_each(|v| *v = (f64::from(*v) * k) as f32);
    out
}
