//! `transparent`: transparent-object detection (polar-transparency) -> transparent.png,
//! transparent_score.exr and an overlay picture; mask metrics with the false positives on
//! opaque objects.

use polar_eval::mask_metrics;
use polar_image::Gray;
use polar_io::MaterialLabel;
use polar_io::files::vision::{self, pictures};
use polar_transparency::{Segmenter, TransparencyOptions, detect};

use super::{
    Context, Failure, NOISY, Outcome, io, knn_message, picture_path, to_json, write_plane,
};
use crate::pictures::{mask_error_picture, overlay_picture};
use crate::task_options::TaskArgs;
use crate::writes::Writes;

/// Runs the task; leaves the mask for `material`.
pub fn run(ctx: &mut Context<'_>, args: &TaskArgs) -> Result<Outcome, Failure> {
    let segmenter = args.transparent_segmenter()?;
    let map = detect(ctx.obs, &segmenter, &TransparencyOptions::default())
        .map_err(|e| Failure::CannotRun(e.to_string()))?;
    let (out, s0) = (ctx.out, &ctx.obs.planes.s0);
    let mut files = Writes::default();
    files.push(vision::TRANSPARENT, || {
        polar_io::write_gray8_png(out.join(vision::TRANSPARENT), &map.mask)
    });
    files.push(vision::TRANSPARENT_SCORE, || {
        write_plane(out.join(vision::TRANSPARENT_SCORE), &map.score, NOISY)
    });
    files.push(pictures::TRANSPARENT, || {
        let picture = overlay_picture(s0, &map.mask);
        polar_io::write_rgb8_png(picture_path(out, pictures::TRANSPARENT), &picture)
    });
    files.run().map_err(io)?;
    let mut outcome = Outcome::default();
    if let Segmenter::Knn(m) = &segmenter {
        outcome.messages.push(knn_message(m.model()));
    }
    if let Some(bar) = map.noise_floor {
        outcome.messages.push(format!(
            "cue score threshold raised to {bar:.2} by the noise: the frame's background \
             scores high (a dim or noisy frame), so weakly polarized glass may be missed"
        ));
    }
    if let Some(gt) = &ctx.gt.transparent {
        let opaque = ctx.gt.material.as_ref().map(opaque_objects);
        let m = mask_metrics(&map.mask, gt, opaque.as_ref())
            .map_err(|e| Failure::CannotRun(e.to_string()))?;
        outcome.metrics = Some(to_json(&m)?);
        let picture = mask_error_picture(&ctx.obs.planes.s0, &map.mask, gt);
        polar_io::write_rgb8_png(
            picture_path(out, vision::pictures::TRANSPARENT_ERROR),
            &picture,
        )
        .map_err(io)?;
    }
    ctx.transparent = Some(map.mask);
    Ok(outcome)
}

/// Opaque objects (dielectric or metal labels): where a transparency mask must stay off.
fn opaque_objects(labels: &Gray<u8>) -> Gray<u8> {
    let mut m = labels.clone();
    for v in m.as_mut_slice() {
        let label = MaterialLabel::from_value(*v);
        *v = u8::from(matches!(
            label,
            Some(MaterialLabel::Dielectric | MaterialLabel::Metal)
        ));
    }
    m
}
