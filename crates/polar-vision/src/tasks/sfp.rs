//! `sfp`: shape from polarization (polar-shape) -> normal.exr, depth.exr,
//! normal_confidence.exr, reflection.png and pictures; with ground truth, the normal and
//! depth metrics, the index used and its source, the fitted light, and a picture of the
//! errors (S0 | estimate | truth | angular error).

use polar_eval::normal_metrics;
use polar_imgproc::angular_error_map;
use polar_io::RGB_CHANNELS;
use polar_io::files::vision::{self, pictures};
use polar_shape::global::Light;
use polar_shape::{Shape, ShapeOptions, estimate_shape_of};

use super::{
    Context, Failure, NOISY, Outcome, SPARSE, io, object_mask, picture_path, to_json, write_plane,
};
use crate::pictures::{REFLECTION_PALETTE, label_picture, normal_error_picture, normal_picture};
use crate::task_options::TaskArgs;
use crate::writes::Writes;

/// Names of the reflection types, index = value of reflection.png.
const REFLECTION_NAMES: [&str; 4] = ["none", "diffuse", "specular", "mixed"];

/// The shape estimate of the options in `args`, without writing anything (also for
/// `material` when sfp is not among the tasks).
pub fn estimate(ctx: &Context<'_>, args: &TaskArgs) -> Result<Shape, Failure> {
    estimate_shape_of(ctx.obs, &options(args), ctx.known_objects.as_ref())
        .map_err(|e| Failure::CannotRun(e.to_string()))
}

fn options(args: &TaskArgs) -> ShapeOptions {
    ShapeOptions {
        method: args.sfp_method,
        integrator: args.integrator,
        ior: args.ior.unwrap_or_default(),
        working_size: args.sfp_working_size,
    }
}

/// Runs the task; leaves the normals for `material`.
pub fn run(ctx: &mut Context<'_>, args: &TaskArgs) -> Result<Outcome, Failure> {
    let opts = options(args);
    let shape = estimate(ctx, args)?;
    write(ctx, &shape)?;
    let mut outcome = Outcome::default();
    let objects = shape
        .foreground
        .as_slice()
        .iter()
        .filter(|&&v| v != 0)
        .count();
    let given = if ctx.known_objects.is_some() {
        " (the mask of --objects)"
    } else {
        ""
    };
    outcome.messages.push(format!(
        "{} with index {:.3}, {}; {}; {objects} pixels on objects{given}",
        opts.method,
        shape.ior,
        shape.ior_source,
        light_message(shape.light.as_ref())
    ));
    if let (Some(gt_n), Some(objects)) = (&ctx.gt.normal, object_mask(ctx.gt)) {
        let types = Some((&shape.reflection, REFLECTION_NAMES.as_slice()));
        let depth = ctx.gt.depth.as_ref().map(|d| (&shape.depth, d));
        let m = normal_metrics(&shape.normal, gt_n, &objects, types, depth)
            .map_err(|e| Failure::CannotRun(e.to_string()))?;
        outcome.metrics = Some(to_json(&serde_json::json!({
            "normal": m,
            "ior": { "value": shape.ior, "source": shape.ior_source.name() },
            "light": shape.light.map(|l| serde_json::json!({
                "direction": l.direction().map(|d| [d.x, d.y, d.z]),
                "strength": l.strength(),
                "ambient": l.ambient,
            })),
        }))?);
        let error = angular_error_map(&shape.normal, gt_n, Some(&objects))
            .map_err(|e| Failure::CannotRun(e.to_string()))?;
        let picture = normal_error_picture(&ctx.obs.planes.s0, &shape.normal, gt_n, &error);
        polar_io::write_rgb8_png(
            picture_path(ctx.out, vision::pictures::NORMAL_ERROR),
            &picture,
        )
        .map_err(io)?;
    }
    ctx.normals = Some(shape.normal);
    ctx.objects = Some(shape.foreground);
    Ok(outcome)
}

/// The fitted light for the run's messages: direction toward the light in the camera
/// frame, strength (albedo × irradiance) and ambient, both in units of the frame's robust
/// S0 scale.
fn light_message(light: Option<&Light>) -> String {
    let Some(l) = light else {
        return "no light fitted (too few lit diffuse pixels)".into();
    };
    let d = l.direction().unwrap_or_default();
    format!(
        "light toward ({:.3}, {:.3}, {:.3}) in the camera frame, strength {:.3}, ambient {:.3} (units of the S0 scale)",
        d.x,
        d.y,
        d.z,
        l.strength(),
        l.ambient
    )
}

fn write(ctx: &Context<'_>, s: &Shape) -> Result<(), Failure> {
    let out = ctx.out;
    let mut files = Writes::default();
    files.push(vision::NORMAL, || {
        polar_io::write_exr_with(out.join(vision::NORMAL), &s.normal, RGB_CHANNELS, NOISY)
    });
    files.push(vision::DEPTH, || {
        write_plane(out.join(vision::DEPTH), &s.depth, SPARSE)
    });
    files.push(vision::NORMAL_CONFIDENCE, || {
        write_plane(out.join(vision::NORMAL_CONFIDENCE), &s.confidence, SPARSE)
    });
    files.push(vision::REFLECTION, || {
        polar_io::write_gray8_png(out.join(vision::REFLECTION), &s.reflection)
    });
    files.push(pictures::NORMAL, || {
        polar_io::write_rgb8_png(
            picture_path(out, pictures::NORMAL),
            &normal_picture(&s.normal),
        )
    });
    files.push(pictures::REFLECTION, || {
        let types = label_picture(&s.reflection, &REFLECTION_PALETTE);
        polar_io::write_rgb8_png(picture_path(out, pictures::REFLECTION), &types)
    });
    files.run().map_err(io)?;
    Ok(())
}
