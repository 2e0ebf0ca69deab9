//! The training-free physics rule.
//!
//! - Fresnel cue (Wolff 1990): a DoLP above the largest specular DoLP a metal of
//!   [`crate::fresnel_cues::METAL_INDICES`] reaches at that zenith cannot come from a
//!   metal. The envelope is read [`MEASURED_MARGIN_DEG`] further toward grazing where
//!   the zenith is the shape task's (never less than the silhouette's sphere prior,
//!   [`crate::cues::Cues::with_prior_floor`]), [`PRIOR_MARGIN_DEG`] where it is the
//!   prior alone (the envelope is a running maximum over the zenith), trading missed
//!   dielectrics for fewer false ones.
//! - Phase cue: light polarized along the surface azimuth (phase `> 0`) is diffuse light
//!   leaving a dielectric; metals have no diffuse lobe, so their light is polarized
//!   across the azimuth. Polarization across the azimuth decides nothing by itself: a
//!   dielectric's specular reflection is polarized the same way.
//!
//! A region is dielectric when enough of its pixels pass the Fresnel cue or when its
//! DoLP-weighted phase leans toward the azimuth, or when enough of its pixels see either
//! in their own window (a mask may merge a dielectric with other objects); else metal (a
//! metal never shows either). A metal merged into a region voted dielectric is outvoted:
//! the regions are split at narrow necks into blobs, and a blob that by itself shows no
//! Fresnel evidence and light polarized clearly across the azimuth is metal.

use crate::cues::Cues;
use crate::features::Features;
use crate::fresnel_cues::FresnelTable;
use crate::{MaterialError, Prepared, Regions};
use polar_image::{Gray, par_map};
use polar_imgproc::mask::split_at_necks;
use polar_imgproc::{Border, box_filter};

/// DoLP margin above the metal envelope before the Fresnel cue fires (rendering or
/// sensor deviations of a few percent), added to three windowed noise sigmas.
pub const FRESNEL_MARGIN: f32 = 0.03;
/// Widening of the zenith of the sphere prior toward grazing, degrees (0: the prior as
/// is, which on the dev set classified more pixels right than 15°).
pub const PRIOR_MARGIN_DEG: f32 = 0.0;
/// Widening of a measured zenith (the shape task's normals) toward grazing, degrees. That
/// zenith comes from a dielectric's polarization model and a smoothness field, and a
/// rough metal's light leaves facets tilted beyond the mean surface; read at too small a
/// zenith, the envelope is too low and a metal's own DoLP passes the Fresnel cue. With
/// the margin, the cue fires only on DoLP no metal reaches within the shape task's
/// typical zenith error (docs/benchmarks.md).
pub const MEASURED_MARGIN_DEG: f32 = 20.0;
/// Fraction of a region's pixels above the metal envelope at which the Fresnel cue
/// changes its vote (isolated pixels are noise or demosaicing edges).
const OVER_FRACTION: f32 = 0.06;
/// DoLP-weighted phase at which the phase cue changes its vote (a metal's is negative).
const PHASE_LEAN: f32 = 0.0;
/// Phase change that moves the phase cue by one unit of score.
const PHASE_SCALE: f32 = 0.2;
/// Share of a region's pixels with a dielectric in their own window at which a region the
/// region-wide tallies vote metal is dielectric after all. An object mask can merge a
/// dielectric with other objects and background, whose pixels dilute its cues in the
/// region's sums; a metal shows the cues in a window only where noise or a normal error
/// puts them, on a smaller share (Mitsuba 3's rough metals reach about a tenth).
pub const LOCAL_EVIDENCE_SHARE: f32 = 0.15;
/// Windowed dielectric score that counts as a dielectric seen in the window (a
/// probability of metal of 0.2).
pub const LOCAL_EVIDENCE_SCORE: f32 = 0.7;
/// A region is split into blobs where two meet at a neck narrower than this fraction of
/// the smaller blob's inscribed radius (two touching objects; a bent one keeps a waist
/// wider than that).
const NECK_RATIO: f32 = 0.5;
/// Inscribed radius (pixels) below which a blob is a bump of the outline, not an object.
const MIN_BLOB_RADIUS: f32 = 3.0;
/// Largest share of a blob's pixels above the metal envelope for it to show no Fresnel
/// evidence.
const BLOB_MAX_OVER: f32 = 0.01;
/// DoLP-weighted phase below which a blob's light is clearly polarized across the
/// azimuth, as a metal's (a specular-dominated dielectric's also leans that way, less).
const BLOB_METAL_PHASE: f32 = -0.55;
/// With measured normals, the phase cue uses only pixels seen beyond this zenith: nearer
/// normal incidence diffuse polarization vanishes (it grows as `sin² θ`) and any
/// specular reflection, a dielectric's included, sets the phase.
const PHASE_MIN_ZENITH_DEG: f32 = 50.0;

/// The metal envelope at pixel `k`: the largest metal specular DoLP at its zenith.
fn envelope(cues: &Cues, table: &FresnelTable, k: usize) -> f32 {
    let z = cues.zenith[k];
    if !z.is_finite() {
        return table.metal_ceiling();
    }
    let margin = if cues.prior {
        PRIOR_MARGIN_DEG
    } else {
        MEASURED_MARGIN_DEG
    };
    let z = (z + margin.to_radians()).min(std::f32::consts::FRAC_PI_2);
    table.metal_max(z)
}

/// `true` where the pixel's DoLP is above the metal envelope with margin.
fn over_envelope(f: &Features, cues: &Cues, table: &FresnelTable, k: usize) -> bool {
    f.valid[k] && f.dolp[k] > envelope(cues, table, k) + FRESNEL_MARGIN + 3.0 * f.window_noise()
}

/// Running sums of one region.
#[derive(Clone, Copy, Default)]
struct Tally {
    valid: f32,
    over: f32,
    rho_phase: f32,
    rho: f32,
}

impl Tally {
    fn add(&mut self, f: &Features, cues: &Cues, table: &FresnelTable, k: usize) {
        if !f.valid[k] {
            return;
        }
        self.valid += 1.0;
        self.over += f32::from(u8::from(over_envelope(f, cues, table, k)));
        let ph = cues.phase[k];
        let grazing = cues.prior || cues.zenith[k] > PHASE_MIN_ZENITH_DEG.to_radians();
        if ph.is_finite() && grazing && f.dolp[k] > 3.0 * f.window_noise() {
            self.rho_phase += f.dolp[k] * ph;
            self.rho += f.dolp[k];
        }
    }

    /// Dielectric score: `> 0` dielectric, `< 0` metal, in units of the cues' scales.
    fn score(&self) -> f32 {
        let over = self.over / self.valid.max(1.0);
        let fresnel = (over - OVER_FRACTION) / OVER_FRACTION;
        let phase = if self.rho > 0.0 {
            (self.rho_phase / self.rho - PHASE_LEAN) / PHASE_SCALE
        } else {
            -1.0
        };
        fresnel.max(phase)
    }
}

impl Tally {
    /// The rule's two region cues: the fraction of valid pixels above the metal envelope
    /// and the DoLP-weighted phase (0 where no pixel qualifies).
    fn region_cues(&self) -> [f32; 2] {
        let phase = if self.rho > 0.0 {
            self.rho_phase / self.rho
        } else {
            0.0
        };
        [self.over / self.valid.max(1.0), phase]
    }
}

/// Per region id of `regions` (index 0, outside the mask: [0, 0]), the rule's cues of
/// the region: the fraction of its valid pixels above the metal envelope and its
/// DoLP-weighted phase, the evidence the rule votes on.
pub fn region_cues(f: &Features, cues: &Cues, regions: &Regions) -> Vec<[f32; 2]> {
    tallies(f, cues, regions)
        .iter()
        .map(Tally::region_cues)
        .collect()
}

/// The tallies of every region (index 0, outside the mask, stays empty), summed in raster
/// order.
fn tallies(f: &Features, cues: &Cues, regions: &Regions) -> Vec<Tally> {
    let table = FresnelTable::new();
    let mut t = vec![Tally::default(); regions.count + 1];
    for (k, &l) in regions.labels.iter().enumerate() {
        if l != 0 {
            t[l as usize].add(f, cues, &table, k);
        }
    }
    t
}

/// Probability of metal from a dielectric score.
fn metal_from(score: f32) -> f32 {
    1.0 / (1.0 + (2.0 * score.clamp(-10.0, 10.0)).exp())
}

/// Probability of metal per pixel (0.5 outside the object mask). With `smooth`, each
/// region gets one value from its tallies, and a region voted metal is still dielectric
/// when at least [`LOCAL_EVIDENCE_SHARE`] of its pixels see a dielectric in their own
/// window ([`LOCAL_EVIDENCE_SCORE`]); without, each pixel gets the value of the tallies of
/// the object pixels in a [`crate::features::WINDOW`]² window around it.
pub fn metal_probability(p: &Prepared, smooth: bool) -> Result<Vec<f32>, MaterialError> {
    let fg = &p.fg;
    let local = windowed_scores(p)?;
    if !smooth {
        return Ok(par_map(fg.len(), |k| {
            if fg[k] { metal_from(local[k]) } else { 0.5 }
        }));
    }
    let regions = &p.regions;
    let mut evidence = vec![[0.0f32; 2]; regions.count + 1];
    for (k, &l) in regions.labels.iter().enumerate() {
        if l != 0 {
            let e = &mut evidence[l as usize];
            e[0] += 1.0;
            e[1] += f32::from(u8::from(local[k] >= LOCAL_EVIDENCE_SCORE));
        }
    }
    let metal: Vec<f32> = tallies(&p.features, &p.cues, regions)
        .iter()
        .zip(&evidence)
        .map(|(t, &[n, strong])| {
            let score = t.score();
            if score < 0.0 && strong >= LOCAL_EVIDENCE_SHARE * n {
                metal_from(LOCAL_EVIDENCE_SCORE)
            } else {
                metal_from(score)
            }
        })
        .collect();
    let merged = merged_metal(p, &metal)?;
    let lab = &regions.labels;
    Ok(par_map(fg.len(), |k| match (fg[k], merged[k]) {
        (false, _) => 0.5,
        (true, m) if m.is_finite() => m,
        (true, _) => metal[lab[k] as usize],
    }))
}

/// Probability of metal per pixel of the blobs (the object regions split at necks,
/// [`split_at_necks`]) that lie in a region voted dielectric (`region_metal < 0.5`) and
/// show a metal by themselves: at most [`BLOB_MAX_OVER`] of their pixels above the metal
/// envelope and a DoLP-weighted phase below [`BLOB_METAL_PHASE`]. NaN elsewhere.
fn merged_metal(p: &Prepared, region_metal: &[f32]) -> Result<Vec<f32>, MaterialError> {
    let (w, h) = (p.features.width, p.features.height);
    let region = &p.regions.labels;
    // Only the regions voted dielectric. Whole 8-connected regions, so the distance to
    // the outside of these is the distance to the outside of the mask.
    let voted_dielectric = |k: usize| region_metal[region[k] as usize] < 0.5;
    let m: Vec<bool> = (0..w * h).map(|k| p.fg[k] && voted_dielectric(k)).collect();
    let (labels, count) = split_at_necks(&m, &p.distance, w, h, NECK_RATIO, MIN_BLOB_RADIUS)?;
    let blobs = Regions { labels, count };
    let metal: Vec<f32> = tallies(&p.features, &p.cues, &blobs)
        .iter()
        .map(|t| {
            let [over, phase] = t.region_cues();
            if t.rho > 0.0 && over < BLOB_MAX_OVER && phase < BLOB_METAL_PHASE {
                metal_from(t.score())
            } else {
                f32::NAN
            }
        })
        .collect();
    Ok(par_map(w * h, |k| {
        if m[k] {
            metal[blobs.labels[k] as usize]
        } else {
            f32::NAN
        }
    }))
}

/// Per pixel, the dielectric score of the tallies of the object pixels in a
/// [`crate::features::WINDOW`]² window around it (meaningless off the object mask).
fn windowed_scores(p: &Prepared) -> Result<Vec<f32>, MaterialError> {
    let (f, cues, fg) = (&p.features, &p.cues, &p.fg);
    let table = FresnelTable::new();
    let (w, h) = (f.width, f.height);
    let tally: Vec<Tally> = par_map(w * h, |j| {
        let mut t = Tally::default();
        if fg[j] {
            t.add(f, cues, &table, j);
        }
        t
    });
    let plane = |v: fn(&Tally) -> f32| -> Result<Vec<f32>, MaterialError> {
        let src = Gray::from_vec(w, h, par_map(w * h, |j| v(&tally[j]))).expect("size");
        let mut dst = Gray::new(w, h);
        let k = crate::features::WINDOW;
        box_filter(&src, &mut dst, k, k, Border::Reflect101)?;
        Ok(dst.into_vec())
    };
    let sums = [
        plane(|t| t.valid)?,
        plane(|t| t.over)?,
        plane(|t| t.rho_phase)?,
        plane(|t| t.rho)?,
    ];
    Ok(par_map(w * h, |j| {
        Tally {
            valid: sums[0][j],
            over: sums[1][j],
            rho_phase: sums[2][j],
            rho: sums[3][j],
        }
        .score()
    }))
}
