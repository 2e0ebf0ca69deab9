//! The objects' pixels, found without ground truth or scene knowledge.
//!
//! Two cues, united:
//!
//! **A. Regions enclosed by edges.** Objects are regions enclosed by strong edges of
//! brightness or polarization that do not reach the image border, where the background
//! (floor, walls, sky) does:
//! 1. edge strength `g = √(|∇ ln s|² + k² (|∇ s₁/s₀|² + |∇ s₂/s₀|²))` (Sobel, on the
//!    normalised brightness `s` and the normalised Stokes vector; `k = 4` weighs a DoLP
//!    step of 0.25 like a brightness ratio of e), invariant to the global scale;
//! 2. edges are `g` above half of Otsu's threshold of `g` (Otsu alone follows the
//!    strongest edges, e.g. cast shadows, and leaves gaps in a silhouette against a floor
//!    of similar brightness), and above a floor so a flat frame has none; the edge map is
//!    dilated by a 3×3 square to close one-pixel gaps;
//! 3. the edge-free 4-connected regions touching the border are background; the rest
//!    (enclosed regions, the edges around them, invalid pixels such as saturated
//!    highlights inside an object) is the foreground, eroded by 3×3 (undoing the
//!    dilation) and opened by 3×3 to drop thin edge lines;
//! 4. of the edge-free interiors only object faces count (`object_faces`): those B
//!    holds (a tenth of the ring around them is B: a face inside its coherent rim),
//!    and those polarized above the background (median DoLP twice the background's: a
//!    glossy face whose AoLP varies too fast for B), raised as noise grows on faces
//!    darker than half the background, by `√(background / (2 face))`; with the edges
//!    near them or near B. Edges also enclose cast shadows and floor texture: they are
//!    no more polarized than the floor, and B touches a shadow only along its contact
//!    line with the object. A deep shadow's DoLP does rise above the lit floor's, by the
//!    noise and demosaicing residue of its fewer photons (shot noise in DoLP goes as
//!    `1/√S0`), while a dark glossy object polarizes far more than that (Umov's effect;
//!    the bundled real frame's black camera body). The
//!    occluding-contour signature below is no test of a face: a floor tile whose edges
//!    run along and across the floor's AoLP shows it too. A weakly polarized object
//!    that neither cue holds is lost.
//!
//! **B. Coherently polarized regions** (for silhouettes too weak
//! to be enclosed by A, e.g. a bright object on a bright floor):
//! 1. the Rayleigh statistic of the AoLP in a Gaussian window, `z = |Σ g e^{2iα}|² / Σ g²`
//!    (Mardia & Jupp, *Directional Statistics*, §6.3.1, on the doubled angle): about 1 where
//!    the AoLP is random (a depolarizing floor, its shadows and texture; only noise and
//!    demosaicing residue), up to `Σg²⁻¹·(Σg)²` where it is one smooth field (an object).
//!    Regions are `z` above Otsu's threshold of `z`, opened by 3×3, without components
//!    smaller than the window (`π (2σ)²` pixels) and without those polarized no more
//!    than the background and without an occluding-contour signature, or reaching the
//!    frame's border (`object_like`): a floor's AoLP can be coherent where its DoLP is
//!    only noise and demosaicing residue, and where the objects are few and small
//!    Otsu's threshold falls inside that floor's coherence;
//! 2. holes are filled unless an occluding contour bounds them: the diffuse DoLP peaks
//!    at grazing, so around a hole seen through an object (a torus) the DoLP is highest
//!    next to the hole, while around a patch facing the camera (low DoLP) it rises away
//!    from it, and around a highlight it is the same on both sides, the difference within
//!    the noise (`fill_object_holes`);
//! 3. a hole is also left open when its median log brightness is closer to the
//!    background's around the regions than to the region's around it
//!    (`looks_through`): background seen through the object;
//! 4. a region that reaches the image border (a glossy floor or wall may be coherent)
//!    is kept only if its boundary shows the occluding-contour signature: the AoLP
//!    parallel (diffuse) or perpendicular (specular) to the boundary's 2-D normal, i.e.
//!    the DoLP-weighted mean of `cos 4Δ` (Δ = AoLP − normal direction) more than three
//!    standard deviations above 0, its value for a random AoLP (`has_contour`).
//!
//! **The union**: B's regions, and A's outside the holes B left open. A's edge-free
//! interiors that B does not touch and that the rest of the foreground encloses are
//! opened by the same brightness test (`open_see_through_holes`): edges also enclose
//! the hole of a torus. Components without any pixel of B or of an object face are
//! dropped (specks; every object polarizes somewhere). Regions inside the frame are
//! not held to the contour signature: on glossy objects the diffuse and specular parts
//! cancel along stretches of the rim, and the shape prior checks it per boundary pixel
//! instead (`crate::local`). Last, the gaps between a component and its convex hull that
//! the component mostly borders and that are as bright as it, or whose stretch of the
//! hull's outline shows the occluding-contour signature, are filled (`fill_hull_gaps`;
//! two large blobs joined by a narrow neck are hulled apart, the arcs of one rim share a
//! hull where it runs along them or shows the signature across their breaks,
//! `hull_per_blob`): a white object on a light floor is found as the open arcs of its
//! rim, its face toward the camera too weakly polarized and edged for either cue, and its
//! shaded side may be as dark as the floor, but the rim between the arcs still polarizes
//! as a rim does. Then the boundary pixels as bright as the background beside them rather
//! than the object are given back to the background, twice (`trim_boundary`): the edges
//! of A straddle the silhouette.
//!
//! Invalid pixels (saturated highlights) are foreground only where it mostly surrounds
//! them (`with_enclosed_invalid`): a hole there would be a silhouette to the shape prior.
//! If neither cue finds anything (a surface filling the view, a tiny image), every valid
//! pixel is foreground: the frame shows one surface and no occluding contour. A fails on
//! an object that is neither coherently polarized nor shows a contour signature (a bright
//! diffuse object on a bright floor: it is dropped with the shadows); B fails on objects
//! whose polarization is too weak or broken up to form a coherent field at the window's
//! scale.

use std::collections::VecDeque;
use std::ops::RangeInclusive;

use polar_image::{Gray, quantile};
use polar_imgproc::mask::{components, fill_holes, remove_small};
use polar_imgproc::{
    Border, MorphShape, dilate, erode, gaussian_blur, gaussian_kernel, open, sep_filter, sobel,
    threshold_otsu,
};

use rayon::prelude::*;

use crate::ShapeError;
use crate::cues::{Cues, image_direction_angle};

/// Weight of a polarization step against a log-brightness step.
const POLARIZATION_WEIGHT: f32 = 4.0;
/// Gaussian pre-smoothing (pixels) of the edge features, against sensor noise.
const EDGE_SIGMA: f64 = 1.0;
/// Lowest edge strength counted as an edge (a log-brightness change of 0.1 per pixel).
const MIN_EDGE: f32 = 0.1;
/// Fraction of Otsu's threshold used.
const OTSU_FRACTION: f32 = 0.3;
/// Brightness floor (normalised) inside the logarithm, so dark noise is not an edge.
const DARK_FLOOR: f32 = 0.02;
/// Sigma (pixels) of the smoothed region mask whose gradient gives the boundary normal.
const BOUNDARY_SIGMA: f64 = 1.5;
/// Smoothed-mask gradient (per pixel) above which a region pixel is on its boundary.
const BOUNDARY_GRADIENT: f64 = 0.05;
/// Gaussian window sigma (pixels) of the Rayleigh statistic: wider than the few pixels
/// over which demosaicing correlates the AoLP of noise, narrower than small objects.
const COHERENCE_SIGMA: f64 = 3.0;
/// Significance (standard deviations) of the occluding-contour signature.
const CONTOUR_SIGNIFICANCE: f64 = 3.0;
/// Distances (4-connected steps) from a hole of the near ring (`< RING_NEAR`) and of the
/// far ring (`RING_NEAR..RING_FAR`) whose DoLP [`fill_object_holes`] compares.
const RING_NEAR: u32 = 2;
const RING_FAR: u32 = 6;
/// Width (4-connected steps) of the dilated edges between an edge-free interior and
/// the object around it.
const EDGE_BAND: u32 = 4;
/// Fraction of the pixels next to a gap between a component and its convex hull that must
/// be the component for the gap to be filled ([`fill_hull_gaps`]): a face between the
/// arcs of its rim is mostly bordered by them, the floor between two objects by the hull's
/// chords as well.
const HULL_ENCLOSURE: f64 = 0.7;
/// Fraction of the ring around an interior region that must be foreground for the
/// region to be a hole.
const HOLE_ENCLOSURE: f64 = 0.9;
/// Fraction of the ring around an edge-free interior that must be cue B for the interior
/// to be an object face: a face inside a coherent rim has far more, floor texture none;
/// a cast shadow touches B along its contact line with the object, a few percent of its
/// ring (0.05-0.3 scored the same on the dev and Mitsuba sets).
const HELD_BY_B: f64 = 0.1;
/// Share of an edge-free interior that must be polarized (cue B or a polarized face) for
/// the see-through test to leave it alone: cue B's window spills coherence from a
/// torus's rim a few pixels into its depolarized hole, so a touch is not enough (0.1-0.3
/// scored the same on the dev and Mitsuba shape sets, 0.3 better on Mitsuba's material
/// scenes, 0.5 worse on its noisy shape scenes).
const POLARIZED_INTERIOR: f64 = 0.3;
/// Median DoLP, in units of the background's median DoLP (the depolarizing floor's noise
/// and demosaicing residue), above which an interior is a polarized object face: a glossy
/// or dark dielectric whose AoLP varies too fast for cue B (the real camera's body).
const FACE_DOLP_FACTOR: f32 = 2.0;
/// Brightness, in units of the background's, below which the face bar is raised as an
/// interior's DoLP noise grows ([`noise_growth`]). Above it the bar's factor 2 leaves the
/// noise a margin of at least `√2`, and below it the raised bar keeps that margin; keeping
/// the whole factor 2 everywhere also drops faces polarized barely above their noise
/// (metal spheres under sensor noise), which the rule's material labels need.
const NOISE_COVERED: f32 = 0.5;
/// Lowest background DoLP [`FACE_DOLP_FACTOR`] multiplies: a camera's DoLP noise floor
/// (photon noise at mid-scale of an IMX250MZR-class sensor, about 5000 e⁻ per pixel,
/// gives DoLP noise near 1/√5000 ≈ 0.014). Against a noise-free render's near-zero
/// background, light reflected onto the floor by the objects counted as polarized and
/// made faces of the floor in a torus's hole.
const MIN_BACKGROUND_DOLP: f32 = 0.01;
/// DoLP ([`DOLP_QUANTILE`]), in units of the background's, above which a coherent region
/// (cue B) without a contour signature is an object's: the floor's AoLP can be coherent
/// where its DoLP is no more than the background's noise and demosaicing residue (a
/// brightness gradient polarizes a division-of-focal-plane mosaic along one angle). On the
/// dev, full-size, Mitsuba and hard-case sets the floor's coherent regions sit near 1,
/// objects' mostly far above.
const COHERENT_DOLP_FACTOR: f32 = 1.2;
/// The quantile of the DoLP that [`COHERENT_DOLP_FACTOR`] compares.
const DOLP_QUANTILE: f64 = 0.75;
/// Blobs a short way apart share one hull in [`fill_hull_gaps`] where their joint hull's
/// outline runs within this many pixels of them and they leave part of it empty
/// ([`polar_imgproc::mask::ArcJoin::rim_arcs`]): the arcs of one rim, broken where the
/// diffuse and specular phases cancel.
const ARC_NEAR: usize = 2;
/// The outline coverage down to which [`hull_per_blob`] also joins blobs whose joint
/// hull's outline, away from them, shows the occluding-contour signature: the signature
/// decides, the bar only keeps such joins to blobs that outline most of their hull
/// (docs/benchmarks.md, "a face as dark as the floor inside its rim").
const SIGNED_ARC_COVERAGE: f32 = 0.6;
/// Steps from the blobs beyond which [`hull_per_blob`] reads the joint hull's outline: the
/// outline's pixels next to the blobs are the blobs' own rims, which carry the signature
/// even where the outline crosses the floor between two objects.
const OUTLINE_AWAY: u32 = 2;
/// Share of the pixels around a region of invalid pixels that must be foreground for the
/// region to join it ([`with_enclosed_invalid`]): a highlight inside an object is
/// surrounded by it, a light source or sky beside the objects mostly by background.
const INVALID_ENCLOSURE: f64 = 0.5;
/// Passes of [`trim_boundary`] (each peels at most one pixel).
const TRIM_PASSES: usize = 2;
/// Half-width (pixels) of the window [`trim_boundary`] compares a boundary pixel in.
const TRIM_RADIUS: usize = 2;

/// Foreground mask (`true` on objects) of the cues (module doc).
pub fn foreground(cues: &Cues) -> Result<Vec<bool>, ShapeError> {
    let (w, h) = (cues.width, cues.height);
    let any_valid = cues.valid.iter().any(|&v| v);
    if !any_valid {
        return Ok(vec![false; w * h]);
    }
    if w < 3 || h < 3 {
        return Ok(cues.valid.clone());
    }
    let coherent = coherent_with_holes(cues)?;
    let faces = object_faces(cues, enclosed_by_edges(cues)?, &coherent.regions)?;
    let enclosed = &faces.enclosed;
    let fg: Vec<bool> = (0..w * h)
        .into_par_iter()
        .map(|k| {
            cues.valid[k]
                && (coherent.regions[k] || (enclosed.regions[k] && !coherent.open_holes[k]))
        })
        .collect();
    let polarized: Vec<bool> = (0..w * h)
        .into_par_iter()
        .map(|k| coherent.regions[k] || faces.polarized[k])
        .collect();
    let fg = open_see_through_holes(cues, fg, enclosed, &polarized)?;
    let evidence: Vec<bool> = (0..w * h)
        .into_par_iter()
        .map(|k| coherent.regions[k] || enclosed.interiors[k])
        .collect();
    let fg = with_evidence(fg, &evidence, w, h)?;
    let fg = fill_hull_gaps(cues, fg)?;
    let fg = (0..TRIM_PASSES).try_fold(fg, |fg, _| trim_boundary(cues, &fg))?;
    let fg = with_enclosed_invalid(&cues.valid, w, h, fg)?;
    if fg.iter().any(|&v| v) {
        Ok(fg)
    } else {
        Ok(cues.valid.clone())
    }
}

/// The foreground of a given object mask `objects` (`w × h`): its valid pixels, with the
/// invalid regions it mostly surrounds ([`with_enclosed_invalid`]).
pub(crate) fn given(
    valid: &[bool],
    w: usize,
    h: usize,
    objects: &[bool],
) -> Result<Vec<bool>, ShapeError> {
    let fg = valid.iter().zip(objects).map(|(&v, &o)| v && o).collect();
    with_enclosed_invalid(valid, w, h, fg)
}

/// `fg` with the regions of invalid pixels (saturated highlights) inside the frame of
/// which at least [`INVALID_ENCLOSURE`] of the 4-neighbours around them are `fg`: a
/// highlight on an object is part of it, and a hole there would be an occluding contour to
/// the shape prior (`crate::local`), its normals turned away from the highlight. Their
/// polarization is not measured: the methods give them their neighbours' shape. A region
/// reaching the frame's border (a saturated sky, a dark frame's unlit pixels) stays out.
/// `valid` and `fg` are `w × h` masks.
pub(crate) fn with_enclosed_invalid(
    valid: &[bool],
    w: usize,
    h: usize,
    mut fg: Vec<bool>,
) -> Result<Vec<bool>, ShapeError> {
    let invalid: Vec<bool> = valid.iter().map(|&v| !v).collect();
    let (id, n) = components(&invalid, w, h)?;
    if n == 0 {
        return Ok(fg);
    }
    // Per region: the pixels one step outside it, and those of them in `fg`.
    let (owner, dist) = grow_labels(&id, w, h, 1, |_| true);
    let mut around = vec![[0usize; 2]; n + 1];
    for k in (0..w * h).filter(|&k| dist[k] == 1) {
        around[owner[k] as usize][0] += 1;
        around[owner[k] as usize][1] += usize::from(fg[k]);
    }
    let at_border = touching_border(&id, n, w, h);
    for k in (0..w * h).filter(|&k| id[k] != 0) {
        let c = id[k] as usize;
        let [all, object] = around[c];
        fg[k] = !at_border[c] && all > 0 && object as f64 >= INVALID_ENCLOSURE * all as f64;
    }
    Ok(fg)
}

/// Cue A of the module doc (at least 3×3 pixels).
/// Cue A's regions and, inside them, the edge-free regions the edges enclose (object
/// faces, or the background seen through a hole).
pub(crate) struct Enclosed {
    pub(crate) regions: Vec<bool>,
    pub(crate) interiors: Vec<bool>,
}

pub(crate) fn enclosed_by_edges(cues: &Cues) -> Result<Enclosed, ShapeError> {
    let (w, h) = (cues.width, cues.height);
    let g = edge_strength(cues)?;
    let t = (OTSU_FRACTION * threshold_otsu(&g)?).max(MIN_EDGE);
    let edges: Vec<bool> = g
        .as_slice()
        .iter()
        .zip(&cues.valid)
        .map(|(&v, &ok)| !ok || v > t)
        .collect();
    let edges = morph_mask(&edges, w, h, Morph::Dilate)?;
    let background = border_regions(&edges, w, h)?;
    let interiors = (0..w * h).map(|k| !edges[k] && !background[k]).collect();
    let raw: Vec<bool> = background.iter().map(|&b| !b).collect();
    let raw = morph_mask(&raw, w, h, Morph::Erode)?;
    Ok(Enclosed {
        regions: morph_mask(&raw, w, h, Morph::Open)?,
        interiors,
    })
}

/// Cue A kept to its object faces ([`object_faces`]).
pub(crate) struct Faces {
    pub(crate) enclosed: Enclosed,
    /// Pixels of faces polarized above the background ([`FACE_DOLP_FACTOR`]).
    pub(crate) polarized: Vec<bool>,
}

/// Cue A restricted to its object faces (module doc, A.4) and to the edges that go with
/// them ([`face_edges`]); all of A when B is empty.
pub(crate) fn object_faces(
    cues: &Cues,
    enclosed: Enclosed,
    coherent: &[bool],
) -> Result<Faces, ShapeError> {
    let (w, h) = (cues.width, cues.height);
    if !coherent.iter().any(|&v| v) {
        return Ok(Faces {
            enclosed,
            polarized: vec![false; w * h],
        });
    }
    let (id, n) = components(&enclosed.interiors, w, h)?;
    let verdicts = face_interiors(cues, &enclosed, coherent, &id, n)?;
    let face: Vec<bool> = id.iter().map(|&i| verdicts[i as usize].face).collect();
    let edges = face_edges(&enclosed, coherent, &id, &face, w, h)?;
    Ok(Faces {
        polarized: id.iter().map(|&i| verdicts[i as usize].polarized).collect(),
        enclosed: Enclosed {
            regions: (0..w * h)
                .map(|k| enclosed.regions[k] && edges[k] && (id[k] == 0 || face[k]))
                .collect(),
            interiors: (0..w * h)
                .map(|k| enclosed.interiors[k] && face[k])
                .collect(),
        },
    })
}

/// The edge pixels of cue A that go with the object faces (`face`, per pixel) and B:
/// those within [`EDGE_BAND`] steps of them, those nearer to them than to any other
/// edge-free region (wide edges of a blurred or high-resolution image), and those the
/// two enclose.
fn face_edges(
    enclosed: &Enclosed,
    coherent: &[bool],
    id: &[u32],
    face: &[bool],
    w: usize,
    h: usize,
) -> Result<Vec<bool>, ShapeError> {
    let object = |k: usize| coherent[k] || face[k];
    let seeds: Vec<u32> = (0..w * h).map(|k| u32::from(object(k))).collect();
    let (_, near) = grow_labels(&seeds, w, h, EDGE_BAND, |_| true);
    // Edge-free regions: objects (1), other interiors (2), the background (3).
    let regions: Vec<u32> = (0..w * h)
        .map(|k| match (object(k), id[k] > 0, enclosed.regions[k]) {
            (true, _, _) => 1,
            (false, true, _) => 2,
            (false, false, false) => 3,
            (false, false, true) => 0,
        })
        .collect();
    let (nearest, _) = grow_labels(&regions, w, h, u32::MAX - 1, |_| true);
    let kept: Vec<bool> = (0..w * h)
        .map(|k| near[k] != u32::MAX || nearest[k] == 1)
        .collect();
    Ok(fill_holes(&kept, w, h)?)
}

/// What [`face_interiors`] finds of one interior.
#[derive(Clone, Copy, Default)]
struct Verdict {
    face: bool,
    polarized: bool,
}

/// Per interior label of `id` (`n` labels; index 0 outside them): it is an object face
/// when at least [`HELD_BY_B`] of the pixels within [`RING_FAR`] steps around it are B,
/// or when its median DoLP is above [`FACE_DOLP_FACTOR`] times the background's, taken as
/// at least [`MIN_BACKGROUND_DOLP`] and multiplied by [`noise_growth`] of their median
/// brightnesses (then it is also `polarized`). The occluding-contour signature of its rim
/// does not count: floor texture whose edges run along and across the floor's one AoLP
/// shows it too.
fn face_interiors(
    cues: &Cues,
    enclosed: &Enclosed,
    coherent: &[bool],
    id: &[u32],
    n: usize,
) -> Result<Vec<Verdict>, ShapeError> {
    let (w, h) = (cues.width, cues.height);
    let (owner, dist) = grow_labels(id, w, h, RING_FAR, |_| true);
    // Per interior: ring pixels, ring pixels in B.
    let mut counts = vec![[0usize; 2]; n + 1];
    for k in (0..w * h).filter(|&k| dist[k] != u32::MAX && dist[k] > 0) {
        let c = &mut counts[owner[k] as usize];
        c[0] += 1;
        c[1] += usize::from(coherent[k]);
    }
    let background: Vec<u32> = (0..w * h)
        .map(|k| u32::from(!enclosed.regions[k] && !enclosed.interiors[k]))
        .collect();
    let [bg_dolp, bg_brightness] = median_dolp_and_brightness(cues, &background, 1)[1];
    let bg_dolp = bg_dolp.map(|b| b.max(MIN_BACKGROUND_DOLP));
    let interiors = median_dolp_and_brightness(cues, id, n);
    Ok((0..=n)
        .map(|c| {
            if c == 0 {
                return Verdict::default();
            }
            let [dolp, brightness] = interiors[c];
            let polarized = matches!(
                (dolp, bg_dolp, brightness, bg_brightness),
                (Some(d), Some(b), Some(v), Some(bv)) if d > FACE_DOLP_FACTOR * b * noise_growth(v, bv)
            );
            let held = counts[c][1] as f64 >= HELD_BY_B * counts[c][0] as f64;
            Verdict {
                face: held || polarized,
                polarized,
            }
        })
        .collect())
}

/// The factor by which the face bar grows on an interior of median brightness `v` against
/// a background of median brightness `bv`: shot noise's DoLP goes as `1/√S0`, so
/// `√(NOISE_COVERED · bv / v)` below [`NOISE_COVERED`] of the background's brightness, 1
/// above it.
fn noise_growth(v: f32, bv: f32) -> f32 {
    (NOISE_COVERED * bv / v.max(f32::MIN_POSITIVE))
        .sqrt()
        .max(1.0)
}

/// Per label of `id` (`n` labels; 0 unlabelled): the median DoLP and the median normalised
/// brightness of its valid pixels.
fn median_dolp_and_brightness(cues: &Cues, id: &[u32], n: usize) -> Vec<[Option<f32>; 2]> {
    let mut values: Vec<[Vec<f32>; 2]> = vec![[Vec::new(), Vec::new()]; n + 1];
    for k in (0..id.len()).filter(|&k| id[k] > 0 && cues.valid[k]) {
        let v = &mut values[id[k] as usize];
        v[0].push(cues.dolp[k]);
        v[1].push(cues.s0n[k]);
    }
    values
        .into_iter()
        .map(|[d, b]| [median(d), median(b)])
        .collect()
}

/// `fg` without the edge-free interiors that are holes of the rest of `fg` and look like
/// the background seen through them (see [`looks_through`]); interiors of which at least
/// [`POLARIZED_INTERIOR`] is `polarized` (cue B, or a face polarized above the
/// background) show no depolarizing background and stay.
pub(crate) fn open_see_through_holes(
    cues: &Cues,
    fg: Vec<bool>,
    enclosed: &Enclosed,
    polarized: &[bool],
) -> Result<Vec<bool>, ShapeError> {
    let (w, h) = (cues.width, cues.height);
    let (id, n) = components(&enclosed.interiors, w, h)?;
    let mut tally = vec![[0usize; 2]; n + 1];
    for k in 0..w * h {
        tally[id[k] as usize][0] += 1;
        tally[id[k] as usize][1] += usize::from(polarized[k]);
    }
    let holds_polarization: Vec<bool> = tally
        .iter()
        .map(|&[all, pol]| pol as f64 >= POLARIZED_INTERIOR * all as f64 && pol > 0)
        .collect();
    let outside = brightness_around(cues, &fg);
    let candidates: Vec<u32> = id
        .iter()
        .map(|&i| if holds_polarization[i as usize] { 0 } else { i })
        .collect();
    let (owner, dist) = grow_labels(&candidates, w, h, EDGE_BAND + RING_FAR, |_| true);
    // Per interior: ring pixels, ring pixels in fg; brightness of the interior and of
    // the object beyond the edge band around it.
    let mut counts = vec![[0usize; 2]; n + 1];
    let mut hole: Vec<Vec<f32>> = vec![Vec::new(); n + 1];
    let mut object: Vec<Vec<f32>> = vec![Vec::new(); n + 1];
    for k in (0..w * h).filter(|&k| dist[k] != u32::MAX) {
        let (o, d) = (owner[k] as usize, dist[k]);
        if (1..=RING_FAR).contains(&d) {
            counts[o][0] += 1;
            counts[o][1] += usize::from(fg[k]);
        }
        if !cues.valid[k] {
            continue;
        }
        if d == 0 {
            hole[o].push(log_brightness(cues, k));
        } else if d > EDGE_BAND && fg[k] {
            object[o].push(log_brightness(cues, k));
        }
    }
    let open: Vec<bool> = (0..=n)
        .map(|c| {
            c > 0
                && counts[c][1] as f64 >= HOLE_ENCLOSURE * counts[c][0] as f64
                && looks_through(
                    median(std::mem::take(&mut hole[c])),
                    median(std::mem::take(&mut object[c])),
                    outside,
                )
        })
        .collect();
    let out = (0..w * h)
        .map(|k| fg[k] && !open[candidates[k] as usize])
        .collect();
    Ok(out)
}

/// The 8-connected components of `fg` that hold a pixel of `evidence` (cue B or an
/// object face of A), or all of `fg` when there is none: every object polarizes
/// somewhere, so a region without either is floor texture or a speck.
fn with_evidence(
    fg: Vec<bool>,
    evidence: &[bool],
    w: usize,
    h: usize,
) -> Result<Vec<bool>, ShapeError> {
    if !evidence.iter().any(|&v| v) {
        return Ok(fg);
    }
    let (id, n) = components(&fg, w, h)?;
    let mut has = vec![false; n + 1];
    for k in (0..w * h).filter(|&k| evidence[k]) {
        has[id[k] as usize] = true;
    }
    Ok((0..w * h).map(|k| fg[k] && has[id[k] as usize]).collect())
}

/// `fg` with the gaps between each component and its convex hull that the component
/// borders on at least [`HULL_ENCLOSURE`] of the pixels next to them and that do not look
/// like the background ([`looks_through`]): an object's face between the coherent arcs of
/// its rim, as bright as the rim, rather than the floor seen between two objects. A gap
/// that looks like the background is filled all the same where the hull's outline along
/// it shows the occluding-contour signature ([`has_contour`]): the shaded side of a white
/// ball, as dark as the floor, bounded by its rim; a hole seen through an object lies
/// inside the hull, off its outline, and the floor between two objects meets the outline
/// along chords over the floor.
pub(crate) fn fill_hull_gaps(cues: &Cues, fg: Vec<bool>) -> Result<Vec<bool>, ShapeError> {
    let (w, h) = (cues.width, cues.height);
    let hull = hull_per_blob(cues, &fg)?;
    let gaps: Vec<bool> = (0..w * h)
        .map(|k| hull[k] && !fg[k] && cues.valid[k])
        .collect();
    let (id, n) = components(&gaps, w, h)?;
    if n == 0 {
        return Ok(fg);
    }
    let outside = brightness_around(cues, &hull);
    let rims = contour_sums(cues, &hull, &id, n)?;
    let (owner, dist) = grow_labels(&id, w, h, RING_FAR, |_| true);
    let mut gap: Vec<Vec<f32>> = vec![Vec::new(); n + 1];
    let mut object: Vec<Vec<f32>> = vec![Vec::new(); n + 1];
    // Pixels next to the gap (2 steps): all, and those of the object.
    let mut near = vec![[0usize; 2]; n + 1];
    for k in (0..w * h).filter(|&k| (1..=2).contains(&dist[k])) {
        near[owner[k] as usize][0] += 1;
        near[owner[k] as usize][1] += usize::from(fg[k]);
    }
    for k in (0..w * h).filter(|&k| dist[k] != u32::MAX && cues.valid[k]) {
        match (dist[k], fg[k]) {
            (0, _) => gap[owner[k] as usize].push(log_brightness(cues, k)),
            (_, true) => object[owner[k] as usize].push(log_brightness(cues, k)),
            _ => {}
        }
    }
    let fill: Vec<bool> = (0..=n)
        .map(|c| {
            c > 0
                && near[c][1] as f64 >= HULL_ENCLOSURE * near[c][0] as f64
                && (has_contour(rims[c][0], rims[c][1], rims[c][2])
                    || !looks_through(
                        median(std::mem::take(&mut gap[c])),
                        median(std::mem::take(&mut object[c])),
                        outside,
                    ))
        })
        .collect();
    Ok((0..w * h).map(|k| fg[k] || fill[id[k] as usize]).collect())
}

/// The union of the convex hulls of `fg`'s blobs ([`polar_imgproc::mask::blobs_apart`]: the
/// floor seen between two objects whose regions touch through a shared shadow is a gap of
/// neither), blobs that are the arcs of one rim under one hull ([`ARC_NEAR`]). Where a
/// join down to [`SIGNED_ARC_COVERAGE`] hulls more blobs together, its hull is taken when
/// its outline more than [`OUTLINE_AWAY`] steps from them shows the occluding-contour
/// signature ([`has_contour`]): the rim runs on between the arcs, broken only in the mask;
/// between two objects the outline crosses the floor.
pub(crate) fn hull_per_blob(cues: &Cues, fg: &[bool]) -> Result<Vec<bool>, ShapeError> {
    let (w, h) = (cues.width, cues.height);
    let apart = polar_imgproc::mask::blobs_apart(fg, w, h)?;
    let join = polar_imgproc::mask::ArcJoin::rim_arcs(w, h, ARC_NEAR);
    let mut hull = polar_imgproc::mask::convex_hulls_joined(&apart, w, h, &join)?;
    let signed = polar_imgproc::mask::ArcJoin {
        min_coverage: SIGNED_ARC_COVERAGE,
        ..join
    };
    let wider = polar_imgproc::mask::convex_hulls_joined(&apart, w, h, &signed)?;
    let (id, n) = components(&wider, w, h)?;
    let mut joins_more = vec![false; n + 1];
    for k in (0..w * h).filter(|&k| wider[k] && !hull[k]) {
        joins_more[id[k] as usize] = true;
    }
    if !joins_more.contains(&true) {
        return Ok(hull);
    }
    let blobs: Vec<u32> = fg.iter().map(|&v| u32::from(v)).collect();
    let (_, dist) = grow_labels(&blobs, w, h, OUTLINE_AWAY, |_| true);
    let away: Vec<u32> = (0..w * h)
        .map(|k| if dist[k] == u32::MAX { id[k] } else { 0 })
        .collect();
    let sums = contour_sums(cues, &wider, &away, n)?;
    let take: Vec<bool> = (0..=n)
        .map(|c| joins_more[c] && has_contour(sums[c][0], sums[c][1], sums[c][2]))
        .collect();
    for (k, v) in hull.iter_mut().enumerate() {
        *v |= take[id[k] as usize];
    }
    Ok(hull)
}

/// `fg` without the boundary pixels (those with a 4-neighbour outside `fg`) whose log
/// brightness is closer to the mean of the background's pixels than to the mean of the
/// object's inner pixels in the (2 [`TRIM_RADIUS`] + 1)² window around them. Cue A's
/// edges are a gradient response that straddles the silhouette and its regions include
/// them, so the mask reaches about a pixel into the background; every such pixel moves
/// the occluding contour outward and lowers the zeniths of the shape prior
/// (`crate::local`). A pixel without valid neighbours on either side stays.
pub(crate) fn trim_boundary(cues: &Cues, fg: &[bool]) -> Result<Vec<bool>, ShapeError> {
    let (w, h) = (cues.width, cues.height);
    let inner = morph_mask(fg, w, h, Morph::ErodeCross)?;
    Ok((0..w * h)
        .into_par_iter()
        .map(|k| {
            if !fg[k] || inner[k] || !cues.valid[k] {
                return fg[k];
            }
            let (x, y) = (k % w, k / w);
            // Sums and counts of log brightness: inner object pixels, background pixels.
            let mut sums = [[0.0f32; 2]; 2];
            for b in y.saturating_sub(TRIM_RADIUS)..(y + TRIM_RADIUS + 1).min(h) {
                for a in x.saturating_sub(TRIM_RADIUS)..(x + TRIM_RADIUS + 1).min(w) {
                    let j = b * w + a;
                    if cues.valid[j] && (inner[j] || !fg[j]) {
                        let side = &mut sums[usize::from(!fg[j])];
                        side[0] += log_brightness(cues, j);
                        side[1] += 1.0;
                    }
                }
            }
            let [[object, n_object], [background, n_background]] = sums;
            if n_object == 0.0 || n_background == 0.0 {
                return true;
            }
            let v = log_brightness(cues, k);
            (v - object / n_object).abs() <= (v - background / n_background).abs()
        })
        .collect())
}

/// The median log brightness of the valid pixels within [`RING_FAR`] steps outside `mask`:
/// the background around the objects.
fn brightness_around(cues: &Cues, mask: &[bool]) -> Option<f32> {
    let ring = ring(mask, cues.width, cues.height, 1..=RING_FAR);
    let valid = ring.into_iter().filter(|&k| cues.valid[k]);
    median(valid.map(|k| log_brightness(cues, k)).collect())
}

/// A hole whose median log brightness is closer to the background's around the objects
/// than to the object's around it shows the background through the object (a torus).
fn looks_through(hole: Option<f32>, object: Option<f32>, background: Option<f32>) -> bool {
    match (hole, object, background) {
        (Some(hole), Some(object), Some(bg)) => (hole - bg).abs() < (hole - object).abs(),
        _ => false,
    }
}

/// The edge strength `g` of the module doc.
pub fn edge_strength(cues: &Cues) -> Result<Gray<f32>, ShapeError> {
    let (w, h) = (cues.width, cues.height);
    let plane = |f: &(dyn Fn(usize) -> f32 + Sync)| -> Gray<f32> {
        Gray::from_vec(w, h, (0..w * h).into_par_iter().map(f).collect()).expect("sized")
    };
    let log_s = plane(&|k| (cues.s0n[k].max(0.0) + DARK_FLOOR).ln());
    let (c, s) = (
        plane(&|k| cues.dolp[k] * (2.0 * cues.aolp[k]).cos()),
        plane(&|k| cues.dolp[k] * (2.0 * cues.aolp[k]).sin()),
    );
    let mut g = vec![0.0f32; w * h];
    for (src, weight) in [
        (&log_s, 1.0f32),
        (&c, POLARIZATION_WEIGHT),
        (&s, POLARIZATION_WEIGHT),
    ] {
        let mut smooth = Gray::new(w, h);
        gaussian_blur(src, &mut smooth, 0, EDGE_SIGMA)?;
        for (dx, dy) in [(1, 0), (0, 1)] {
            let mut d = Gray::new(w, h);
            sobel(&smooth, &mut d, dx, dy, 3)?;
            // A unit ramp gives a 3x3 Sobel response of 8.
            g.par_iter_mut().zip(d.as_slice()).for_each(|(acc, v)| {
                let v = v / 8.0 * weight;
                *acc += v * v;
            });
        }
    }
    g.par_iter_mut().for_each(|v| *v = v.sqrt());
    Ok(Gray::from_vec(w, h, g).expect("sized"))
}

/// Pixels of the edge-free 4-connected regions that touch the image border: the
/// complement of the edge mask with its holes filled.
fn border_regions(edges: &[bool], w: usize, h: usize) -> Result<Vec<bool>, ShapeError> {
    Ok(fill_holes(edges, w, h)?.into_iter().map(|v| !v).collect())
}

/// A 3x3 morphological operation on a mask: with a square, or erosion with a cross (the
/// pixels whose 4-neighbours are all in the mask).
#[derive(Clone, Copy)]
enum Morph {
    Dilate,
    Erode,
    ErodeCross,
    Open,
}

/// Applies `op` (3x3) to a mask.
fn morph_mask(mask: &[bool], w: usize, h: usize, op: Morph) -> Result<Vec<bool>, ShapeError> {
    let src = Gray::from_vec(
        w,
        h,
        mask.par_iter().map(|&m| f32::from(u8::from(m))).collect(),
    )
    .expect("sized");
    let mut dst = Gray::new(w, h);
    match op {
        Morph::Dilate => dilate(&src, &mut dst, MorphShape::Rect, 3, 3)?,
        Morph::Erode => erode(&src, &mut dst, MorphShape::Rect, 3, 3)?,
        Morph::ErodeCross => erode(&src, &mut dst, MorphShape::Cross, 3, 3)?,
        Morph::Open => open(&src, &mut dst, MorphShape::Rect, 3, 3)?,
    }
    Ok(dst.as_slice().par_iter().map(|&v| v > 0.5).collect())
}

/// Cue B of the module doc (at least 3×3 pixels).
#[cfg(test)]
pub(crate) fn coherent_regions(cues: &Cues) -> Result<Vec<bool>, ShapeError> {
    Ok(coherent_with_holes(cues)?.regions)
}

/// Cue B's regions and the holes in them that it left open (a torus's hole).
struct Coherent {
    regions: Vec<bool>,
    open_holes: Vec<bool>,
}

/// Cue B of the module doc, with the holes it leaves open.
fn coherent_with_holes(cues: &Cues) -> Result<Coherent, ShapeError> {
    let (w, h) = (cues.width, cues.height);
    let z = rayleigh_statistic(cues)?;
    let t = threshold_otsu(&z)?;
    let raw: Vec<bool> = z.as_slice().iter().map(|&v| v > t).collect();
    let opened = morph_mask(&raw, w, h, Morph::Open)?;
    let window = std::f64::consts::PI * (2.0 * COHERENCE_SIGMA).powi(2);
    let regions = remove_small(&opened, w, h, window as usize)?;
    let regions = object_like(cues, regions)?;
    let filled = fill_object_holes(cues, &regions)?;
    let regions = inner_or_with_contour(cues, &filled)?;
    let all_holes = fill_holes(&regions, w, h)?;
    let open_holes = (0..w * h).map(|k| all_holes[k] && !regions[k]).collect();
    Ok(Coherent {
        regions,
        open_holes,
    })
}

/// The components of cue B's `regions` that are an object's: polarized above the
/// background (their [`DOLP_QUANTILE`] of the DoLP above [`COHERENT_DOLP_FACTOR`] times that
/// of the valid pixels outside them, at least [`MIN_BACKGROUND_DOLP`]; a quantile above
/// the median, as an object is polarized mostly toward its rim), or inside the frame with
/// the occluding-contour signature along their boundary ([`has_contour`]: a smooth metal is
/// polarized no more than the floor, but across its silhouette's normal). A region that
/// reaches the frame's border polarized no more than the background is background: a
/// floor seen obliquely is weakly polarized along one angle, and its boundary shows the
/// signature wherever it runs along or across that angle (the edge of an object lying on
/// it, a tile's edge).
fn object_like(cues: &Cues, regions: Vec<bool>) -> Result<Vec<bool>, ShapeError> {
    let (w, h) = (cues.width, cues.height);
    let (id, n) = components(&regions, w, h)?;
    let outside = (0..w * h).filter(|&k| cues.valid[k] && id[k] == 0);
    let Some(background) = quantile(outside.map(|k| cues.dolp[k]), DOLP_QUANTILE) else {
        return Ok(regions);
    };
    let bar = COHERENT_DOLP_FACTOR * background.max(MIN_BACKGROUND_DOLP);
    let mut dolp: Vec<Vec<f32>> = vec![Vec::new(); n + 1];
    for k in (0..w * h).filter(|&k| id[k] > 0 && cues.valid[k]) {
        dolp[id[k] as usize].push(cues.dolp[k]);
    }
    let contour = contour_sums(cues, &regions, &id, n)?;
    let at_border = touching_border(&id, n, w, h);
    let keep: Vec<bool> = dolp
        .into_iter()
        .enumerate()
        .map(|(c, d)| {
            let [cos, weight, weight_sq] = contour[c];
            c > 0
                && (quantile(d, DOLP_QUANTILE).is_some_and(|q| q > bar)
                    || (!at_border[c] && has_contour(cos, weight, weight_sq)))
        })
        .collect();
    Ok(id.iter().map(|&i| keep[i as usize]).collect())
}

/// Rayleigh statistic `z = |Σ g e^{2iα}|² / Σ g²` of the AoLP over a Gaussian window `g`
/// (`COHERENCE_SIGMA`) of the valid pixels with a DoLP; 0 elsewhere. Its expectation
/// is 1 for independent uniformly random angles.
pub fn rayleigh_statistic(cues: &Cues) -> Result<Gray<f32>, ShapeError> {
    let (w, h) = (cues.width, cues.height);
    let used = |k: usize| cues.valid[k] && cues.dolp[k] > 0.0;
    let plane = |f: &(dyn Fn(usize) -> f32 + Sync)| -> Gray<f32> {
        Gray::from_vec(w, h, (0..w * h).into_par_iter().map(f).collect()).expect("sized")
    };
    let angle = |k: usize| 2.0 * cues.aolp[k];
    let cos = plane(&|k| if used(k) { angle(k).cos() } else { 0.0 });
    let sin = plane(&|k| if used(k) { angle(k).sin() } else { 0.0 });
    let count = plane(&|k| f32::from(u8::from(used(k))));
    let g = gaussian_kernel(
        (COHERENCE_SIGMA * 8.0 + 1.0).round() as usize | 1,
        COHERENCE_SIGMA,
    )?;
    let g2: Vec<f32> = g.iter().map(|v| v * v).collect();
    let filter = |src: &Gray<f32>, k: &[f32]| -> Result<Gray<f32>, ShapeError> {
        let mut dst = Gray::new(w, h);
        sep_filter(src, &mut dst, k, k, Border::Reflect101)?;
        Ok(dst)
    };
    let (c, s, q) = (filter(&cos, &g)?, filter(&sin, &g)?, filter(&count, &g2)?);
    let (c, s, q) = (c.as_slice(), s.as_slice(), q.as_slice());
    Ok(plane(&|k| {
        if used(k) && q[k] > 0.0 {
            (c[k] * c[k] + s[k] * s[k]) / q[k]
        } else {
            0.0
        }
    }))
}

/// `m` with its enclosed holes filled, except holes bounded by an occluding contour: the
/// mean DoLP of the object pixels within [`RING_NEAR`] steps of the hole above that of
/// the pixels [`RING_NEAR`] to [`RING_FAR`] steps away ([`dolp_rises_toward`]; module
/// doc, B.2).
fn fill_object_holes(cues: &Cues, m: &[bool]) -> Result<Vec<bool>, ShapeError> {
    let (w, h) = (cues.width, cues.height);
    let filled = fill_holes(m, w, h)?;
    let holes: Vec<bool> = filled.iter().zip(m).map(|(&f, &o)| f && !o).collect();
    let (hole_id, n) = components(&holes, w, h)?;
    if n == 0 {
        return Ok(filled);
    }
    // Breadth-first from all holes at once over the region: each pixel joins the ring
    // sums of the hole that reaches it first.
    let (owner, dist) = grow_labels(&hole_id, w, h, RING_FAR, |j| m[j]);
    // Per hole: [near DoLP sum, near count, far DoLP sum, far count, near DoLP² sum,
    // far DoLP² sum].
    let mut rings = vec![[0.0f64; 6]; n + 1];
    // Per hole: log brightness of the hole and of the region around it.
    let mut inside: Vec<Vec<f32>> = vec![Vec::new(); n + 1];
    let mut around: Vec<Vec<f32>> = vec![Vec::new(); n + 1];
    for k in (0..w * h).filter(|&k| cues.valid[k] && dist[k] != u32::MAX) {
        let o = owner[k] as usize;
        if dist[k] == 0 {
            inside[o].push(log_brightness(cues, k));
            continue;
        }
        around[o].push(log_brightness(cues, k));
        let slot = if dist[k] <= RING_NEAR { 0 } else { 2 };
        let d = f64::from(cues.dolp[k]);
        rings[o][slot] += d;
        rings[o][slot + 1] += 1.0;
        rings[o][4 + slot / 2] += d * d;
    }
    let outside = ring(&filled, w, h, 1..=RING_FAR)
        .into_iter()
        .filter(|&k| cues.valid[k])
        .map(|k| log_brightness(cues, k))
        .collect::<Vec<_>>();
    let outside = median(outside);
    let open_hole: Vec<bool> = (0..=n)
        .map(|i| {
            let contour = dolp_rises_toward(&rings[i]);
            contour
                || looks_through(
                    median(std::mem::take(&mut inside[i])),
                    median(std::mem::take(&mut around[i])),
                    outside,
                )
        })
        .collect();
    Ok((0..w * h)
        .map(|k| m[k] || (holes[k] && !open_hole[hole_id[k] as usize]))
        .collect())
}

/// Whether the mean DoLP of a hole's near ring is above its far ring's by more than
/// [`CONTOUR_SIGNIFICANCE`] standard errors of the difference (Welch's statistic;
/// `r`: near sum, count, far sum, count, near sum of squares, far sum of squares): on a
/// highlight's edge the two rings are alike and the difference only noise.
pub(crate) fn dolp_rises_toward(r: &[f64; 6]) -> bool {
    let [near, n_near, far, n_far, near_sq, far_sq] = *r;
    if n_near < 2.0 || n_far < 2.0 {
        return false;
    }
    let (m_near, m_far) = (near / n_near, far / n_far);
    let var = |sq: f64, m: f64, n: f64| (sq / n - m * m).max(0.0) / (n - 1.0);
    let se = (var(near_sq, m_near, n_near) + var(far_sq, m_far, n_far)).sqrt();
    m_near - m_far > CONTOUR_SIGNIFICANCE * se
}

/// `ln(S0 + floor)` of pixel `k` (normalised S0, [`DARK_FLOOR`]).
fn log_brightness(cues: &Cues, k: usize) -> f32 {
    (cues.s0n[k].max(0.0) + DARK_FLOOR).ln()
}

/// The median of `v`, `None` if empty.
fn median(mut v: Vec<f32>) -> Option<f32> {
    if v.is_empty() {
        return None;
    }
    let mid = v.len() / 2;
    Some(*v.select_nth_unstable_by(mid, f32::total_cmp).1)
}

/// The pixels outside `m` at a number of 4-connected steps from it in `steps`.
fn ring(m: &[bool], w: usize, h: usize, steps: RangeInclusive<u32>) -> Vec<usize> {
    let id: Vec<u32> = m.iter().map(|&v| u32::from(v)).collect();
    let (_, dist) = grow_labels(&id, w, h, *steps.end(), |_| true);
    (0..w * h).filter(|&k| steps.contains(&dist[k])).collect()
}

/// Grows the labelled pixels (`id > 0`) breadth-first, 4-connected, through the pixels
/// where `passable` holds, for at most `steps` steps: per pixel the label that reached
/// it first and its number of steps (0 on the labelled pixels, `u32::MAX` unreached).
fn grow_labels(
    id: &[u32],
    w: usize,
    h: usize,
    steps: u32,
    passable: impl Fn(usize) -> bool,
) -> (Vec<u32>, Vec<u32>) {
    let mut owner = id.to_vec();
    let mut dist: Vec<u32> = id
        .iter()
        .map(|&i| if i > 0 { 0 } else { u32::MAX })
        .collect();
    let mut queue: VecDeque<usize> = (0..w * h).filter(|&k| id[k] > 0).collect();
    while let Some(k) = queue.pop_front() {
        if dist[k] >= steps {
            continue;
        }
        let (x, y) = (k % w, k / w);
        let neighbours = [
            (x > 0).then(|| k - 1),
            (x + 1 < w).then(|| k + 1),
            (y > 0).then(|| k - w),
            (y + 1 < h).then(|| k + w),
        ];
        for j in neighbours.into_iter().flatten() {
            if dist[j] == u32::MAX && passable(j) {
                dist[j] = dist[k] + 1;
                owner[j] = owner[k];
                queue.push_back(j);
            }
        }
    }
    (owner, dist)
}

/// The 8-connected components of `m` that do not touch the image border or that pass
/// [`has_contour`]: a coherent region reaching the border may be a glossy floor or wall,
/// and is kept only with an occluding contour (an object the frame cuts).
fn inner_or_with_contour(cues: &Cues, m: &[bool]) -> Result<Vec<bool>, ShapeError> {
    let (w, h) = (cues.width, cues.height);
    let (id, n) = components(m, w, h)?;
    if n == 0 {
        return Ok(m.to_vec());
    }
    let sums = contour_sums(cues, m, &id, n)?;
    let at_border = touching_border(&id, n, w, h);
    let keep: Vec<bool> = (0..=n)
        .map(|c| !at_border[c] || has_contour(sums[c][0], sums[c][1], sums[c][2]))
        .collect();
    Ok((0..w * h).map(|k| m[k] && keep[id[k] as usize]).collect())
}

/// Per label of `id` (`n` labels, 0 = none), whether one of its pixels lies on the frame's
/// border.
fn touching_border(id: &[u32], n: usize, w: usize, h: usize) -> Vec<bool> {
    let mut at_border = vec![false; n + 1];
    for (k, &i) in id.iter().enumerate().filter(|(_, i)| **i > 0) {
        let (x, y) = (k % w, k / w);
        at_border[i as usize] |= x == 0 || y == 0 || x + 1 == w || y + 1 == h;
    }
    at_border
}

/// Per label of `id` (`n` labels on pixels of `m`, 0 unlabelled), the sums [`has_contour`]
/// tests over the label's pixels on `m`'s boundary: `Σ ρ cos 4Δ`, `Σ ρ`, `Σ ρ²`, with `Δ`
/// the AoLP against the outward normal of `m`'s smoothed boundary.
fn contour_sums(
    cues: &Cues,
    m: &[bool],
    id: &[u32],
    n: usize,
) -> Result<Vec<[f64; 3]>, ShapeError> {
    let (w, h) = (cues.width, cues.height);
    let mask =
        Gray::from_vec(w, h, m.iter().map(|&b| f32::from(u8::from(b))).collect()).expect("sized");
    let mut smooth = Gray::new(w, h);
    gaussian_blur(&mask, &mut smooth, 0, BOUNDARY_SIGMA)?;
    let (mut gx, mut gy) = (Gray::new(w, h), Gray::new(w, h));
    sobel(&smooth, &mut gx, 1, 0, 3)?;
    sobel(&smooth, &mut gy, 0, 1, 3)?;
    let mut sums = vec![[0.0f64; 3]; n + 1];
    for k in (0..w * h).filter(|&k| m[k] && cues.valid[k]) {
        // Outward normal = −∇(smoothed mask); a unit ramp gives a Sobel response of 8.
        let (dx, dy) = (-f64::from(gx.as_slice()[k]), -f64::from(gy.as_slice()[k]));
        if dx.hypot(dy) / 8.0 < BOUNDARY_GRADIENT {
            continue;
        }
        let normal = image_direction_angle(&cues.frame(k), dx, dy);
        let rho = f64::from(cues.dolp[k]);
        let s = &mut sums[id[k] as usize];
        s[0] += rho * (4.0 * (f64::from(cues.aolp[k]) - normal)).cos();
        s[1] += rho;
        s[2] += rho * rho;
    }
    Ok(sums)
}

/// The occluding-contour test of a boundary from `Σ ρ cos 4Δ`, `Σ ρ` and `Σ ρ²` over its
/// pixels: the weighted mean of `cos 4Δ` exceeds [`CONTOUR_SIGNIFICANCE`] standard
/// deviations of its value for independent random AoLP (`cos 4Δ` has mean 0 and
/// variance ½, so the standard deviation is `√(Σρ²/2) / Σρ`).
pub(crate) fn has_contour(weighted_cos: f64, weight: f64, weight_sq: f64) -> bool {
    weight > 0.0 && weighted_cos > CONTOUR_SIGNIFICANCE * (0.5 * weight_sq).sqrt()
}
