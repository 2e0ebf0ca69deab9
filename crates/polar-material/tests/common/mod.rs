//! The analytic scene shared by the material tests: two spheres seen orthographically
//! over an unpolarized floor, with the DoLP and AoLP of Fresnel's equations.

#![allow(dead_code)]

use polar_image::{Gray, NormalImage};
use polar_material::fresnel_cues::specular_dolp;
use polar_optics::pixel_frame::CameraModel;
use polar_sensor::{Observation, StokesPlanes};

pub const W: usize = 96;
pub const H: usize = 48;

/// How a sphere sends light: specular reflection with index `n + ik`, or diffuse.
#[derive(Clone, Copy)]
pub enum Surface {
    Specular(f64, f64),
    Diffuse(f64),
}

/// DoLP of light leaving a dielectric of index `n` after subsurface scattering, at
/// emission zenith `t` (Atkinson & Hancock 2006).
pub fn diffuse_dolp(t: f64, n: f64) -> f64 {
    let s2 = t.sin().powi(2);
    let num = (n - 1.0 / n).powi(2) * s2;
    let den = 2.0 + 2.0 * n * n - (n + 1.0 / n).powi(2) * s2 + 4.0 * t.cos() * (n * n - s2).sqrt();
    num / den
}

/// Two spheres of radius 20 px centred at x = 24 and x = 72, and the pixel's
/// `(sphere index, zenith, azimuth)`; azimuth measured counterclockwise from image +x.
pub fn sphere_at(x: usize, y: usize) -> Option<(usize, f64, f64)> {
    for (i, cx) in [24.0, 72.0].into_iter().enumerate() {
        let (dx, dy) = (x as f64 + 0.5 - cx, -(y as f64 + 0.5 - 24.0));
        let r = dx.hypot(dy) / 20.0;
        if r < 1.0 {
            return Some((i, r.asin(), dy.atan2(dx)));
        }
    }
    None
}

/// The observation of the two spheres (`surfaces[i]`) over a floor of S0 0.4.
pub fn scene(surfaces: [Surface; 2]) -> (Observation, NormalImage, Gray<u8>) {
    let mut p = StokesPlanes::new(W, H);
    let mut normals = NormalImage::new(W, H);
    let mut fg = Gray::<u8>::new(W, H);
    for y in 0..H {
        for x in 0..W {
            let k = y * W + x;
            let (s0, dolp, aolp) = match sphere_at(x, y) {
                None => (0.4, 0.0, 0.0),
                Some((i, ze, az)) => {
                    normals.pixels_mut()[k] = [
                        (ze.sin() * az.cos()) as f32,
                        (ze.sin() * az.sin()) as f32,
                        ze.cos() as f32,
                    ];
                    fg.as_mut_slice()[k] = 1;
                    match surfaces[i] {
                        Surface::Specular(n, kk) => (
                            0.6,
                            specular_dolp(ze, n, kk),
                            az + std::f64::consts::FRAC_PI_2,
                        ),
                        Surface::Diffuse(n) => (0.7, diffuse_dolp(ze, n), az),
                    }
                }
            };
            p.s0.as_mut_slice()[k] = s0 as f32;
            p.s1.as_mut_slice()[k] = (s0 * dolp * (2.0 * aolp).cos()) as f32;
            p.s2.as_mut_slice()[k] = (s0 * dolp * (2.0 * aolp).sin()) as f32;
        }
    }
    let planes = StokesPlanes::from_linear_stokes(&p.linear_stokes());
    (
        Observation::new(planes, CameraModel::Orthographic),
        normals,
        fg,
    )
}

/// Share of sphere `i`'s pixels labelled `label`.
pub fn share(labels: &Gray<u8>, i: usize, label: u8) -> f64 {
    let (mut n, mut hit) = (0, 0);
    for y in 0..H {
        for x in 0..W {
            if let Some((j, _, _)) = sphere_at(x, y)
                && j == i
            {
                n += 1;
                hit += usize::from(labels.as_slice()[y * W + x] == label);
            }
        }
    }
    hit as f64 / n as f64
}
