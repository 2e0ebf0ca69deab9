//! Colour polarization mosaics: synthesized from known per-colour Stokes fields in the
//! IMX250MYR layout of docs/conventions.md, then demosaiced back (round trip).

use polar_optics::stokes::intensity_through_polarizer;
use polar_sensor::layout::{CHANNEL_ANGLES_DEG, channel_at, color_at};
use polar_sensor::products::LUMA_REC709;
use polar_sensor::{
    ColorStokesPlanes, DemosaicMethod, Mosaic, SensorError, demosaic_rgb, stokes_planes_rgb,
};

/// The colour mosaic of a per-colour linear Stokes field `stokes(colour, x, y)`, rounded to DN.
fn colour_mosaic(w: usize, h: usize, stokes: impl Fn(usize, f32, f32) -> [f32; 3]) -> Mosaic<u16> {
    let data = (0..w * h)
        .map(|k| {
            let (x, y) = (k % w, k / w);
            let [s0, s1, s2] = stokes(color_at(x, y), x as f32, y as f32);
            let theta = (CHANNEL_ANGLES_DEG[channel_at(x, y)] as f32).to_radians();
            intensity_through_polarizer(s0, s1, s2, theta).round() as u16
        })
        .collect();
    Mosaic::from_vec(w, h, data).unwrap()
}

/// Per colour a different constant field whose four intensities are whole DN:
/// I0 = (S0 + S1)/2, I45 = (S0 + S2)/2, ... all integers.
const FLAT: [[f32; 3]; 3] = [
    [200.0, 40.0, -60.0],
    [1000.0, -300.0, 100.0],
    [3000.0, 0.0, 2000.0],
];

/// Constant fields come back exactly (tolerance 0 for S0..S2: every interpolation of equal
/// integers returns them, and the Stokes sums are exact in f32), for every method, also at
/// the smallest sizes and at the borders; a swap of colours or angles would fail.
#[test]
fn flat_colour_fields_round_trip_exactly() {
    for (w, h) in [(24, 16), (8, 8), (4, 4)] {
        let raw = colour_mosaic(w, h, |c, _, _| FLAT[c]);
        for method in DemosaicMethod::ALL {
            let planes = stokes_planes_rgb(&raw, method).unwrap();
            for (c, p) in planes.colors.iter().enumerate() {
                for (k, plane) in [&p.s0, &p.s1, &p.s2].into_iter().enumerate() {
                    assert!(
                        plane.as_slice().iter().all(|&v| v == FLAT[c][k]),
                        "{w}x{h} {method} colour {c} S{k}"
                    );
                }
            }
        }
    }
}

/// Smoothly varying fields (S0, DoLP and AoLP differ per colour and drift across the
/// frame): bilinear recovers them away from the border within what 1-DN rounding and
/// the curvature of the field allow: S0 within 0.5 % of its value, DoLP within 0.01,
/// AoLP within 0.01 rad.
#[test]
fn smooth_colour_fields_round_trip() {
    let (w, h) = (64, 48);
    let truth = |c: usize, x: f32, y: f32| {
        let s0 = 4000.0 + 1000.0 * c as f32 + 20.0 * x - 10.0 * y;
        let dolp = 0.1 + 0.2 * c as f32 + 0.002 * x;
        let aolp = 0.3 + 0.8 * c as f32 + 0.005 * y;
        [
            s0,
            s0 * dolp * (2.0 * aolp).cos(),
            s0 * dolp * (2.0 * aolp).sin(),
        ]
    };
    let raw = colour_mosaic(w, h, truth);
    let planes = stokes_planes_rgb(&raw, DemosaicMethod::Bilinear).unwrap();
    for (c, p) in planes.colors.iter().enumerate() {
        for y in 4..h - 4 {
            for x in 4..w - 4 {
                let k = y * w + x;
                let [s0, s1, s2] = truth(c, x as f32, y as f32);
                let (dolp, aolp) = ((s1.hypot(s2)) / s0, 0.5 * s2.atan2(s1));
                let got_aolp = p.aolp.as_slice()[k];
                let da = (got_aolp - aolp).rem_euclid(std::f32::consts::PI);
                assert!(
                    (p.s0.as_slice()[k] - s0).abs() <= 5e-3 * s0,
                    "colour {c} S0 at ({x},{y})"
                );
                assert!(
                    (p.dolp.as_slice()[k] - dolp).abs() <= 0.01,
                    "colour {c} DoLP at ({x},{y}): {} vs {dolp}",
                    p.dolp.as_slice()[k]
                );
                assert!(
                    da.min(std::f32::consts::PI - da) <= 0.01,
                    "colour {c} AoLP at ({x},{y}): {got_aolp} vs {aolp}"
                );
            }
        }
    }
}

/// The luminance Stokes vector is the Rec. 709 mix of the colours' (exact to f32 rounding
/// of three products, 1e-6 relative), and its DoLP is that of the mix, not a mix of DoLPs.
#[test]
fn luminance_mixes_stokes_vectors() {
    let raw = colour_mosaic(16, 16, |c, _, _| FLAT[c]);
    let lum = stokes_planes_rgb(&raw, DemosaicMethod::Bilinear)
        .unwrap()
        .luminance();
    let want: [f32; 3] = std::array::from_fn(|k| (0..3).map(|c| LUMA_REC709[c] * FLAT[c][k]).sum());
    let dolp = want[1].hypot(want[2]) / want[0];
    for (k, plane) in [&lum.s0, &lum.s1, &lum.s2].into_iter().enumerate() {
        assert!(
            plane
                .as_slice()
                .iter()
                .all(|v| (v - want[k]).abs() <= 1e-6 * want[0]),
            "S{k}"
        );
    }
    assert!(lum.dolp.as_slice().iter().all(|v| (v - dolp).abs() <= 1e-6));
}

#[test]
fn demosaic_rgb_gives_each_colours_polarizer_images() {
    let raw = colour_mosaic(8, 8, |c, _, _| FLAT[c]);
    let stacks = demosaic_rgb(&raw, DemosaicMethod::Superpixel).unwrap();
    for (c, stack) in stacks.iter().enumerate() {
        let [s0, s1, s2] = FLAT[c];
        let want = [
            (s0 + s1) / 2.0,
            (s0 + s2) / 2.0,
            (s0 - s1) / 2.0,
            (s0 - s2) / 2.0,
        ];
        assert_eq!(stack.size(), (4, 4));
        assert!(stack.pixels().iter().all(|&p| p == want), "colour {c}");
    }
}

#[test]
fn colour_mosaic_not_of_whole_tiles_is_an_error() {
    let raw = Mosaic::<u8>::new(10, 8);
    assert_eq!(
        stokes_planes_rgb(&raw, DemosaicMethod::Bilinear).unwrap_err(),
        SensorError::ColorSize {
            width: 10,
            height: 8
        }
    );
}

/// A colour Stokes image in `stokes.exr`'s channel order (`S0.R, S0.G, S0.B, S1.R, ...`)
/// gives back each colour's planes exactly: the products are the same f32 formulas on the
/// same values, so any swap of colours or parameters fails the equality.
#[test]
fn colour_stokes_image_gives_each_colours_planes() {
    let raw = colour_mosaic(24, 16, |c, x, y| {
        let [s0, s1, s2] = FLAT[c];
        [s0 + 8.0 * x, s1 - 2.0 * y, s2 + x]
    });
    let planes = stokes_planes_rgb(&raw, DemosaicMethod::Bilinear).unwrap();
    let (w, h) = planes.size();
    let channels: Vec<&[f32]> = [0, 1, 2]
        .iter()
        .flat_map(|&k| {
            planes
                .colors
                .iter()
                .map(move |p| [&p.s0, &p.s1, &p.s2][k].as_slice())
        })
        .collect();
    let data = (0..w * h)
        .flat_map(|i| channels.iter().map(move |c| c[i]))
        .collect();
    let image = polar_image::Image::<f32, 9>::from_vec(w, h, data).unwrap();
    assert_eq!(ColorStokesPlanes::from_rgb_linear_stokes(&image), planes);
}
