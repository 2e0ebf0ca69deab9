//! Synthetic ground truth and error measures for demosaicing, shared by the
//! `demosaic_error` example (the README table) and the `demosaic_ordering` test.
//!
//! The field is a linear Stokes field (S3 = 0) in DN of a 16-bit sensor, laid out on a
//! 1024-pixel-wide design scaled to the requested width: a bright, strongly polarized
//! disc and a dark, weakly polarized rectangle whose S0, DoLP and AoLP differ from the
//! background (edges), a zone-plate chirp in S0 whose local frequency grows to the
//! mosaic's Nyquist frequency, 2-pixel stripes every 9 pixels that change S0 and AoLP
//! (fine texture), a smooth AoLP rotation and a DoLP gradient.

use std::f32::consts::PI;

use polar_image::{PolarizerStack, StokesImage};
use polar_sensor::products::StokesPlanes;

/// Which parts of the synthetic field are present.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Field {
    /// Edges and fine texture.
    Full,
    /// The disc and the rectangle only (no zone plate, no stripes).
    EdgesOnly,
    /// The zone plate and the stripes only (no disc, no rectangle).
    TextureOnly,
}

impl Field {
    /// Every field, in table order.
    pub const ALL: [Field; 3] = [Field::Full, Field::EdgesOnly, Field::TextureOnly];

    /// A short description for table headings.
    pub fn label(self) -> &'static str {
        match self {
            Field::Full => "edges + fine texture",
            Field::EdgesOnly => "edges only",
            Field::TextureOnly => "fine texture only",
        }
    }
}

/// The synthetic Stokes field of size `w x h` (`w` scales the 1024-wide design).
pub fn truth_stokes(w: usize, h: usize, field: Field) -> StokesImage {
    let (edges, texture) = (field != Field::TextureOnly, field != Field::EdgesOnly);
    let s = w as f32 / 1024.0;
    let zone_r = 190.0 * s;
    let mut out = StokesImage::new(w, h);
    for (k, px) in out.pixels_mut().iter_mut().enumerate() {
        let (x, y) = ((k % w) as f32, (k / w) as f32);
        let mut s0 = 30000.0;
        let mut dolp = 0.1 + 0.4 * x / w as f32;
        let mut aolp = PI * (x + 0.5 * y) / w as f32;
        // Zone plate: local frequency r / (2 zone_r) grows to 0.5 cycles/pixel at its rim.
        let r2 = (x - 200.0 * s).powi(2) + (y - 560.0 * s).powi(2);
        if texture && r2 < zone_r * zone_r {
            s0 += 12000.0 * (PI * r2 / (2.0 * zone_r)).cos();
        }
        if edges && (x - 650.0 * s).powi(2) + (y - 250.0 * s).powi(2) < (140.0 * s).powi(2) {
            s0 = 50000.0;
            dolp = 0.8;
            aolp = 30f32.to_radians();
        }
        if edges && (300.0 * s..520.0 * s).contains(&x) && (80.0 * s..300.0 * s).contains(&y) {
            s0 = 8000.0;
            dolp = 0.15;
            aolp = 120f32.to_radians();
        }
        if texture && x > 850.0 * s && (y as usize) % 9 < 2 {
            s0 *= 0.5;
            aolp += PI / 3.0;
        }
        *px = [
            s0,
            s0 * dolp * (2.0 * aolp).cos(),
            s0 * dolp * (2.0 * aolp).sin(),
            0.0,
        ];
    }
    out
}

/// Errors of one demosaiced stack against the truth.
#[derive(Clone, Copy, Debug)]
pub struct Errors {
    /// PSNR of I0, I45, I90, I135 in dB, peak 65535.
    pub psnr: [f64; 4],
    /// Mean |DoLP error| over pixels where both are defined.
    pub dolp: f64,
    /// Mean circular |AoLP error| in degrees (mod 180°) where the true DoLP >= 0.05.
    pub aolp_deg: f64,
}

/// PSNR per channel and DoLP / AoLP mean absolute errors of `got` against `truth`.
pub fn errors(got: &PolarizerStack, truth: &PolarizerStack, truth_planes: &StokesPlanes) -> Errors {
    let psnr = std::array::from_fn(|c| {
        let mse = got
            .pixels()
            .iter()
            .zip(truth.pixels())
            .map(|(p, q)| f64::from(p[c] - q[c]).powi(2))
            .sum::<f64>()
            / got.pixels().len() as f64;
        10.0 * (65535.0f64.powi(2) / mse).log10()
    });
    let planes = StokesPlanes::from_stack(got);
    let (mut sd, mut nd, mut sa, mut na) = (0.0, 0usize, 0.0, 0usize);
    for k in 0..truth_planes.dolp.as_slice().len() {
        let (dt, dg) = (truth_planes.dolp.as_slice()[k], planes.dolp.as_slice()[k]);
        if !(dt.is_finite() && dg.is_finite()) {
            continue;
        }
        sd += f64::from((dg - dt).abs());
        nd += 1;
        if dt >= 0.05 {
            let d = f64::from((planes.aolp.as_slice()[k] - truth_planes.aolp.as_slice()[k]).abs())
                % std::f64::consts::PI;
            sa += d.min(std::f64::consts::PI - d).to_degrees();
            na += 1;
        }
    }
    Errors {
        psnr,
        dolp: sd / nd.max(1) as f64,
        aolp_deg: sa / na.max(1) as f64,
    }
}
