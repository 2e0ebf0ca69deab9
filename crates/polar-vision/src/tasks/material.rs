//! `material`: material classification (polar-material) -> material.png,
//! material_confidence.exr and a colour picture; material metrics.

use polar_eval::material_metrics;
use polar_io::files::vision::{self, pictures};
use polar_material::{Classifier, MaterialOptions, classify};

use super::{
    Context, Failure, Outcome, SPARSE, io, knn_message, picture_path, to_json, write_plane,
};
use crate::pictures::{MATERIAL_PALETTE, label_error_picture, label_picture};
use crate::task_options::TaskArgs;
use crate::writes::Writes;

/// Runs the task with the normals, object mask and transparency mask of earlier tasks,
/// where they ran (one foreground for both tasks: sfp's follows the occluding contours).
/// Without `sfp` in the run its estimate is made here and not written: the classifier's
/// cues (and a kNN model's features) are those of sfp's normals.
pub fn run(ctx: &mut Context<'_>, args: &TaskArgs) -> Result<Outcome, Failure> {
    let clf = args.material_classifier()?;
    let mut outcome = Outcome::default();
    if ctx.normals.is_none() {
        match super::sfp::estimate(ctx, args) {
            Ok(shape) => {
                ctx.normals = Some(shape.normal);
                ctx.objects = Some(shape.foreground);
                outcome
                    .messages
                    .push("normals and objects from sfp, made for this task and not written (add sfp to --tasks to keep them)".into());
            }
            Err(e) => outcome
                .messages
                .push(format!("sfp {e}: azimuths from the silhouettes instead")),
        }
    }
    let map = classify(
        ctx.obs,
        ctx.normals.as_ref(),
        ctx.objects.as_ref(),
        ctx.transparent.as_ref(),
        &clf,
        &MaterialOptions::default(),
    )
    .map_err(|e| Failure::CannotRun(e.to_string()))?;
    let out = ctx.out;
    let mut files = Writes::default();
    files.push(vision::MATERIAL, || {
        polar_io::write_gray8_png(out.join(vision::MATERIAL), &map.labels)
    });
    files.push(vision::MATERIAL_CONFIDENCE, || {
        write_plane(
            out.join(vision::MATERIAL_CONFIDENCE),
            &map.confidence,
            SPARSE,
        )
    });
    files.push(pictures::MATERIAL, || {
        let picture = label_picture(&map.labels, &MATERIAL_PALETTE);
        polar_io::write_rgb8_png(picture_path(out, pictures::MATERIAL), &picture)
    });
    files.run().map_err(io)?;
    if let Classifier::Knn(m) = &clf {
        outcome.messages.push(knn_message(m.model()));
    }
    if let Some(gt) = &ctx.gt.material {
        let m = material_metrics(&map.labels, gt).map_err(|e| Failure::CannotRun(e.to_string()))?;
        outcome.metrics = Some(to_json(&m)?);
        let s0 = &ctx.obs.planes.s0;
        let picture = label_error_picture(s0, &map.labels, gt, &MATERIAL_PALETTE);
        polar_io::write_rgb8_png(
            picture_path(out, vision::pictures::MATERIAL_ERROR),
            &picture,
        )
        .map_err(io)?;
    }
    Ok(outcome)
}
