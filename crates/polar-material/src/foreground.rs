//! Object pixels without ground truth.
//!
//! Heuristic (documented limits): floors, walls and sky are diffuse (Lambertian-like)
//! scatterers, whose light is depolarized, while every object surface polarizes the light
//! it sends at grazing view (specular Fresnel reflection, or the exit refraction of
//! diffuse light), so each object carries a polarized rim at its silhouette, and most
//! silhouettes are intensity edges. Object pixels are therefore: pixels whose windowed
//! DoLP is clearly above the sensor noise or whose relative intensity gradient marks an
//! edge, closed and
//! opened to bridge gaps and drop specks, with holes filled (an unpolarized object centre
//! enclosed by its rim is object), and small components dropped. Fails where the
//! background itself polarizes (water, glossy floors, the sky far from the sun) and for
//! nearly unpolarizing objects such as smooth silver; pass a mask then.

use polar_image::Gray;
use polar_imgproc::sobel;

use crate::MaterialError;
use crate::features::Features;
use polar_imgproc::mask::clean;

/// DoLP below this is never called polarized: diffuse backgrounds reach a percent or two
/// (polarizer extinction, demosaicing of fine intensity detail, light the objects reflect
/// onto them).
pub const DOLP_FLOOR: f32 = 0.02;
/// Multiple of the windowed DoLP noise a pixel must exceed.
const NOISE_SIGMAS: f32 = 4.0;

/// The DoLP threshold separating polarized object pixels from depolarizing background.
pub fn threshold(f: &Features) -> f32 {
    DOLP_FLOOR.max(NOISE_SIGMAS * f.window_noise())
}

/// `true` on estimated object pixels.
pub fn estimate(f: &Features) -> Result<Vec<bool>, MaterialError> {
    let (w, h) = (f.width, f.height);
    let t = threshold(f);
    let g = relative_gradient(f)?;
    let seed: Vec<bool> = (0..w * h)
        .map(|k| f.valid[k] && (f.dolp[k] > t || g[k] > EDGE))
        .collect();
    Ok(clean(&seed, w, h)?)
}

/// Relative intensity edge strength that marks a silhouette: `|∇S0| / S0` per pixel of the
/// windowed S0 (Sobel, divided by its gain 8).
pub const EDGE: f32 = 0.05;

fn relative_gradient(f: &Features) -> Result<Vec<f32>, MaterialError> {
    let (w, h) = (f.width, f.height);
    let s0 = Gray::from_vec(w, h, f.s0.clone()).expect("size");
    let (mut gx, mut gy) = (Gray::new(w, h), Gray::new(w, h));
    sobel(&s0, &mut gx, 1, 0, 3)?;
    sobel(&s0, &mut gy, 0, 1, 3)?;
    Ok((0..w * h)
        .map(|k| {
            let m = gx.as_slice()[k].hypot(gy.as_slice()[k]) / 8.0;
            if f.s0[k] > 0.0 { m / f.s0[k] } else { 0.0 }
        })
        .collect())
}
