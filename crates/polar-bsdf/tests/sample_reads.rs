//! A renderer leaves uncomputed the numbers a BSDF sample does not read: `u[0]`
//! (the lobe choice) unless [`Bsdf::chooses_lobes`], `u[1]` and `u[2]` (the 2-D
//! point) if [`Bsdf::is_delta`]. Those numbers must not change the sample,
//! whatever they are (NaN included).

mod common;

use common::*;
use polar_bsdf::Bsdf;
use polar_optics::Stokes;

/// The entries of `u` that `bsdf` may read.
fn readable(bsdf: &Bsdf) -> [bool; 3] {
    let point = !bsdf.is_delta();
    [bsdf.chooses_lobes(), point, point]
}

/// Whether sampling at `wo` with `u` gives the same result when the entries not
/// in `read` are replaced by NaN, 0 or a number just below 1.
fn reads_only(bsdf: &Bsdf, wo: &V3, u: [f64; 3], read: [bool; 3]) -> bool {
    let reference = bsdf.sample(wo, u);
    [f64::NAN, 0.0, 1.0 - f64::EPSILON]
        .into_iter()
        .all(|other| {
            let changed = std::array::from_fn(|i| if read[i] { u[i] } else { other });
            bsdf.sample(wo, changed) == reference
        })
}

/// The shared fixture named `wanted`.
fn by_name(wanted: &str) -> Bsdf {
    all_bsdfs()
        .into_iter()
        .find(|(n, _)| *n == wanted)
        .unwrap_or_else(|| panic!("no fixture {wanted}"))
        .1
}

/// The BSDFs of the shared fixtures, and again with a camera row (glass and
/// plastic then choose their lobes by it).
fn bsdfs_with_importance() -> Vec<(String, Bsdf)> {
    let row = Stokes::new(1.0, 0.4, -0.3, 0.1);
    all_bsdfs()
        .into_iter()
        .flat_map(|(name, b)| {
            let aimed = b.with_importance(&dir(30.0, 20.0), &row);
            [(name.to_string(), b), (format!("{name} aimed"), aimed)]
        })
        .collect()
}

#[test]
fn bsdfs_read_only_the_numbers_they_need() {
    let mut r = rng(17);
    for (name, bsdf) in bsdfs_with_importance() {
        let read = readable(&bsdf);
        for _ in 0..200 {
            let wo = if two_sided(&bsdf) {
                sphere(&mut r)
            } else {
                hemisphere(&mut r)
            };
            let u = u3(&mut r);
            assert!(
                reads_only(&bsdf, &wo, u, read),
                "{name}: wo {wo:?}, u {u:?}"
            );
        }
    }
}

#[test]
fn a_smooth_mirror_reads_nothing_and_smooth_glass_its_choice() {
    assert_eq!(readable(&by_name("smooth_conductor")), [false; 3]);
    assert_eq!(readable(&by_name("polarizer")), [false; 3]);
    assert_eq!(
        readable(&by_name("smooth_dielectric")),
        [true, false, false]
    );
}

#[test]
fn the_check_sees_a_number_that_is_read() {
    // The test above can fail: a rough conductor reads u[1] and u[2], and glass
    // reads u[0] (at 45°, reflectance ~5 %: u = 0.01 reflects, 1 − ε refracts).
    let rough = by_name("rough_conductor_iso");
    assert!(!reads_only(
        &rough,
        &dir(40.0, 10.0),
        [0.3, 0.6, 0.2],
        [true, false, false]
    ));
    let glass = by_name("smooth_dielectric");
    assert!(!reads_only(
        &glass,
        &dir(45.0, 0.0),
        [0.01, 0.5, 0.5],
        [false, true, true]
    ));
}
