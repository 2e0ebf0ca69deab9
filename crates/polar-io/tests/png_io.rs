//! PNG round trips (exact), the bundled real frame, and one test per error case.

use std::path::{Path, PathBuf};

use polar_image::{Gray, Image};
use polar_io::{
    BitDepth, Error, GrayPng, MosaicPng, read_gray_png, read_gray8_png, read_mask_png, read_mosaic,
    read_rgb8_png, write_gray_png, write_gray8_png, write_gray16_png, write_indexed8_png_rows,
    write_rgb8_png, write_rgb8_png_rows,
};

fn ramp8(width: usize, height: usize) -> Gray<u8> {
    let data = (0..width * height).map(|i| (i * 37 % 256) as u8).collect();
    Gray::from_vec(width, height, data).unwrap()
}

fn ramp16(width: usize, height: usize) -> Gray<u16> {
    // Multiplier coprime to 65536 so extremes 0 and 65535 and odd values all occur.
    let mut data: Vec<u16> = (0..width * height)
        .map(|i| (i as u32 * 40503 % 65536) as u16)
        .collect();
    data[0] = u16::MAX;
    data[1] = 0;
    Gray::from_vec(width, height, data).unwrap()
}

/// Writes a grayscale PNG at any bit depth / colour type with the `png` crate directly.
fn write_raw_png(
    path: &Path,
    width: u32,
    height: u32,
    color: png::ColorType,
    depth: png::BitDepth,
    data: &[u8],
) {
    let file = std::fs::File::create(path).unwrap();
    let mut enc = png::Encoder::new(std::io::BufWriter::new(file), width, height);
    enc.set_color(color);
    enc.set_depth(depth);
    enc.write_header().unwrap().write_image_data(data).unwrap();
}

fn real_frame() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/data/real/camera_IMX250MZR.png")
}

#[test]
fn gray8_round_trip_is_exact() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("a.png");
    let img = ramp8(33, 17);
    write_gray8_png(&path, &img).unwrap();
    assert_eq!(read_gray8_png(&path).unwrap(), img);
    let wide = read_gray_png(&path).unwrap();
    assert_eq!(wide.bit_depth, BitDepth::Eight);
    assert!(
        wide.image
            .as_slice()
            .iter()
            .zip(img.as_slice())
            .all(|(&w, &n)| w == u16::from(n))
    );
}

#[test]
fn gray16_round_trip_is_exact() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("a.png");
    let img = ramp16(64, 30);
    write_gray16_png(&path, &img).unwrap();
    let back = read_mosaic(&path).unwrap();
    assert_eq!(
        back,
        MosaicPng {
            image: img.into_kind(),
            bit_depth: BitDepth::Sixteen
        }
    );
}

#[test]
fn gray_png_writes_at_its_bit_depth() {
    let dir = tempfile::tempdir().unwrap();
    for depth in [BitDepth::Eight, BitDepth::Sixteen] {
        let path = dir.path().join(format!("{depth:?}.png"));
        let data = ramp8(6, 4)
            .as_slice()
            .iter()
            .map(|&v| u16::from(v))
            .collect();
        let png = GrayPng {
            image: Gray::from_vec(6, 4, data).unwrap(),
            bit_depth: depth,
        };
        write_gray_png(&path, &png).unwrap();
        assert_eq!(read_gray_png(&path).unwrap(), png);
    }
}

#[test]
fn gray8_write_of_a_value_above_255_is_a_range_error() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("a.png");
    let mut image = Gray::<u16>::new(4, 2);
    image.as_mut_slice()[5] = 256;
    let err = write_gray_png(
        &path,
        &GrayPng {
            image,
            bit_depth: BitDepth::Eight,
        },
    )
    .unwrap_err();
    assert!(
        matches!(
            err,
            Error::ValueRange {
                x: 1,
                y: 1,
                value: 256,
                bits: 8,
                ..
            }
        ),
        "{err}"
    );
    assert!(!path.exists(), "a failed write must not leave a file");
}

#[test]
fn rgb8_round_trip_is_exact() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("rgb.png");
    let data = (0..5 * 3 * 3).map(|i| (i * 29 % 256) as u8).collect();
    let img = Image::<u8, 3>::from_vec(5, 3, data).unwrap();
    write_rgb8_png(&path, &img).unwrap();
    assert_eq!(read_rgb8_png(&path).unwrap(), img);
}

/// A palette image (indices streamed in blocks, every one of 256 entries used) reads back as
/// the RGB of its palette, byte for byte.
#[test]
fn palette_image_reads_back_as_its_colours() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("indexed.png");
    let (w, h) = (16, 100);
    let palette: Vec<[u8; 3]> = (0..=255u8)
        .map(|i| [i, 255 - i, i.wrapping_mul(7)])
        .collect();
    let index = |k: usize| (k * 11 % 256) as u8;
    write_indexed8_png_rows(&path, (w, h), &palette, |y, rows| {
        rows.iter_mut()
            .enumerate()
            .for_each(|(i, b)| *b = index(y * w + i));
    })
    .unwrap();
    let rgb = (0..w * h)
        .flat_map(|k| palette[usize::from(index(k))])
        .collect();
    assert_eq!(
        read_rgb8_png(&path).unwrap(),
        Image::<u8, 3>::from_vec(w, h, rgb).unwrap()
    );
}

/// No palette or one over 256 colours is refused before a file exists; an index that names
/// no colour of the file's palette is a corrupt file, not a panic or a black pixel.
#[test]
fn palette_out_of_range_is_an_error() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("indexed.png");
    for n in [0, 257] {
        let err = write_indexed8_png_rows(&path, (2, 2), &vec![[0; 3]; n], |_, _| {}).unwrap_err();
        assert!(
            matches!(err, Error::Palette { entries, .. } if entries == n),
            "{err}"
        );
        assert!(!path.exists());
    }
    write_indexed8_png_rows(&path, (2, 2), &[[1, 2, 3], [4, 5, 6]], |_, rows| {
        rows.copy_from_slice(&[0, 1, 1, 2]);
    })
    .unwrap();
    let err = read_rgb8_png(&path).unwrap_err();
    assert!(
        matches!(err, Error::Corrupt { .. }) && err.to_string().contains("palette index 2"),
        "{err}"
    );
}

/// Rows streamed in blocks (150 rows: whole blocks and a partial last one) arrive once
/// each, in order, and read back exactly; so do 16-bit and 8-bit gray images of that height.
#[test]
fn rows_streamed_in_blocks_round_trip_exactly() {
    let dir = tempfile::tempdir().unwrap();
    let (w, h) = (7, 150);
    let value = |i: usize| (i * 29 % 251) as u8;
    let mut next_row = 0;
    write_rgb8_png_rows(dir.path().join("rows.png"), (w, h), |y, rows| {
        assert_eq!((y, rows.len() % (3 * w)), (next_row, 0));
        rows.iter_mut()
            .enumerate()
            .for_each(|(i, b)| *b = value(y * 3 * w + i));
        next_row += rows.len() / (3 * w);
    })
    .unwrap();
    assert_eq!(next_row, h);
    let expected = Image::<u8, 3>::from_vec(w, h, (0..w * h * 3).map(value).collect()).unwrap();
    assert_eq!(
        read_rgb8_png(dir.path().join("rows.png")).unwrap(),
        expected
    );
    let (g8, g16) = (ramp8(w, h), ramp16(w, h));
    write_gray8_png(dir.path().join("g8.png"), &g8).unwrap();
    write_gray16_png(dir.path().join("g16.png"), &g16).unwrap();
    assert_eq!(read_gray8_png(dir.path().join("g8.png")).unwrap(), g8);
    assert_eq!(
        read_gray_png(dir.path().join("g16.png")).unwrap().image,
        g16
    );
}

#[test]
fn real_imx250mzr_frame_is_2448x2048_at_8_bits() {
    let png = read_mosaic(real_frame()).unwrap();
    assert_eq!(png.image.size(), (2448, 2048));
    assert_eq!(png.bit_depth, BitDepth::Eight);
    // A real exposure is neither black nor constant.
    let max = png.image.as_slice().iter().max().copied().unwrap();
    let min = png.image.as_slice().iter().min().copied().unwrap();
    assert!(max > min && max <= 255, "min {min} max {max}");
}

#[test]
fn missing_file_is_not_found() {
    let err = read_gray_png("/nonexistent/dir/raw.png").unwrap_err();
    assert!(
        matches!(&err, Error::NotFound { path } if path.ends_with("raw.png")),
        "{err}"
    );
    assert!(err.to_string().contains("/nonexistent/dir/raw.png"));
}

#[test]
fn write_into_missing_directory_is_not_found() {
    let err = write_gray8_png("/nonexistent/dir/out.png", &ramp8(2, 2)).unwrap_err();
    assert!(matches!(err, Error::NotFound { .. }), "{err}");
}

#[test]
fn truncated_png_is_corrupt() {
    let dir = tempfile::tempdir().unwrap();
    let good = dir.path().join("good.png");
    write_gray16_png(&good, &ramp16(40, 40)).unwrap();
    let bytes = std::fs::read(&good).unwrap();
    // Empty, inside the signature, inside IHDR, inside IDAT, just before IEND.
    for cut in [0, 5, 20, bytes.len() / 2, bytes.len() - 12] {
        let path = dir.path().join(format!("cut{cut}.png"));
        std::fs::write(&path, &bytes[..cut]).unwrap();
        let err = read_gray_png(&path).unwrap_err();
        assert!(
            matches!(&err, Error::Corrupt { format: "PNG", path: p, .. } if *p == path),
            "cut {cut}: {err}"
        );
    }
}

#[test]
fn png_with_flipped_bytes_is_corrupt() {
    let dir = tempfile::tempdir().unwrap();
    let good = dir.path().join("good.png");
    write_gray8_png(&good, &ramp8(40, 40)).unwrap();
    let bytes = std::fs::read(&good).unwrap();
    // Byte 0 is the signature; 20 is in IHDR's width; the middle is in IDAT (CRC-checked).
    for pos in [0, 20, bytes.len() / 2] {
        let mut bad = bytes.clone();
        bad[pos] ^= 0x5a;
        let path = dir.path().join(format!("flip{pos}.png"));
        std::fs::write(&path, &bad).unwrap();
        let err = read_gray_png(&path).unwrap_err();
        assert!(matches!(err, Error::Corrupt { .. }), "flip at {pos}: {err}");
    }
}

#[test]
fn colour_png_as_mosaic_names_file_and_colour_type() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("colour.png");
    write_rgb8_png(&path, &Image::<u8, 3>::new(4, 4)).unwrap();
    let err = read_mosaic(&path).unwrap_err();
    assert!(
        matches!(&err, Error::ColorType { found, .. } if found == "Rgb, 8-bit"),
        "{err}"
    );
    let msg = err.to_string();
    assert!(
        msg.contains("colour.png") && msg.contains("Rgb, 8-bit"),
        "{msg}"
    );
}

#[test]
fn gray_with_alpha_is_a_colour_type_error() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("la.png");
    write_raw_png(
        &path,
        2,
        2,
        png::ColorType::GrayscaleAlpha,
        png::BitDepth::Eight,
        &[0; 8],
    );
    let err = read_gray_png(&path).unwrap_err();
    assert!(
        matches!(&err, Error::ColorType { found, .. } if found == "GrayscaleAlpha, 8-bit"),
        "{err}"
    );
}

#[test]
fn palette_png_is_a_colour_type_error() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("pal.png");
    let file = std::fs::File::create(&path).unwrap();
    let mut enc = png::Encoder::new(std::io::BufWriter::new(file), 2, 2);
    enc.set_color(png::ColorType::Indexed);
    enc.set_palette(vec![0, 0, 0, 255, 255, 255]);
    enc.write_header()
        .unwrap()
        .write_image_data(&[0, 1, 1, 0])
        .unwrap();
    let err = read_mosaic(&path).unwrap_err();
    assert!(
        matches!(&err, Error::ColorType { found, .. } if found.starts_with("Indexed")),
        "{err}"
    );
}

#[test]
fn four_bit_and_one_bit_gray_are_bit_depth_errors() {
    let dir = tempfile::tempdir().unwrap();
    for (depth, bits) in [(png::BitDepth::Four, 4), (png::BitDepth::One, 1)] {
        let path = dir.path().join(format!("d{bits}.png"));
        write_raw_png(
            &path,
            8,
            2,
            png::ColorType::Grayscale,
            depth,
            &vec![0x3c; 8 * bits as usize / 8 * 2],
        );
        let err = read_mosaic(&path).unwrap_err();
        assert!(
            matches!(err, Error::BitDepth { found, .. } if found == bits),
            "{bits}: {err}"
        );
    }
}

#[test]
fn sixteen_bit_label_map_is_a_bit_depth_error() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("material.png");
    write_gray16_png(&path, &ramp16(4, 4)).unwrap();
    let err = read_gray8_png(&path).unwrap_err();
    assert!(matches!(err, Error::BitDepth { found: 16, .. }), "{err}");
}

#[test]
fn odd_or_tiny_mosaics_are_size_errors() {
    let dir = tempfile::tempdir().unwrap();
    for (w, h) in [(3, 4), (4, 5), (1, 1), (1, 2)] {
        let path = dir.path().join(format!("m{w}x{h}.png"));
        write_gray8_png(&path, &ramp8(w, h)).unwrap();
        let err = read_mosaic(&path).unwrap_err();
        assert!(
            matches!(err, Error::MosaicSize { width, height, .. } if (width, height) == (w, h)),
            "{err}"
        );
        // The same file is fine as a plain grayscale image.
        assert_eq!(read_gray_png(&path).unwrap().image.size(), (w, h));
    }
}

#[test]
fn zero_sized_image_cannot_be_written() {
    let dir = tempfile::tempdir().unwrap();
    let err = write_gray8_png(dir.path().join("z.png"), &Gray::new(0, 3)).unwrap_err();
    assert!(
        matches!(
            err,
            Error::Dimensions {
                width: 0,
                height: 3,
                ..
            }
        ),
        "{err}"
    );
}

/// An object mask reads the same from every layout a segmenter may write: the object is
/// where a colour sample is non-zero (a 16-bit label 1, a blue-only pixel, a palette
/// entry that is not black) and the pixel is not transparent; a truncated mask is a
/// corrupt file.
#[test]
fn object_masks_read_alike_from_every_png_layout() {
    let dir = tempfile::tempdir().unwrap();
    let (w, h) = (8u32, 4u32);
    let object = |k: usize| k.is_multiple_of(3);
    let expected = Gray::from_vec(
        w as usize,
        h as usize,
        (0..(w * h) as usize)
            .map(|k| if object(k) { 255 } else { 0 })
            .collect(),
    )
    .unwrap();
    let per_pixel = |on: &[u8], off: &[u8]| -> Vec<u8> {
        (0..(w * h) as usize)
            .flat_map(|k| if object(k) { on.to_vec() } else { off.to_vec() })
            .collect()
    };
    let one_bit: Vec<u8> = (0..h as usize)
        .flat_map(|y| {
            let mut row = [0u8; 1];
            for x in 0..w as usize {
                row[0] |= u8::from(object(y * w as usize + x)) << (7 - x);
            }
            row
        })
        .collect();
    use png::{BitDepth as D, ColorType as C};
    let layouts: [(&str, C, D, Vec<u8>); 6] = [
        ("gray8", C::Grayscale, D::Eight, per_pixel(&[1], &[0])),
        (
            "gray16",
            C::Grayscale,
            D::Sixteen,
            per_pixel(&[0, 1], &[0, 0]),
        ),
        ("gray1", C::Grayscale, D::One, one_bit),
        ("rgb", C::Rgb, D::Eight, per_pixel(&[0, 0, 9], &[0, 0, 0])),
        (
            "gray-alpha",
            C::GrayscaleAlpha,
            D::Eight,
            per_pixel(&[200, 255], &[200, 0]),
        ),
        (
            "rgba",
            C::Rgba,
            D::Eight,
            per_pixel(&[255, 255, 255, 1], &[255, 255, 255, 0]),
        ),
    ];
    let frame = (w as usize, h as usize);
    for (name, color, depth, data) in layouts {
        let path = dir.path().join(format!("{name}.png"));
        write_raw_png(&path, w, h, color, depth, &data);
        assert_eq!(read_mask_png(&path, frame).unwrap(), expected, "{name}");
    }
    let path = dir.path().join("palette.png");
    let palette = [[0, 0, 0], [128, 0, 0], [0, 0, 0]];
    write_indexed8_png_rows(&path, (w as usize, h as usize), &palette, |y, row| {
        for (x, b) in row.iter_mut().enumerate() {
            *b = if object(y * w as usize + x) {
                1
            } else {
                2 * (x % 2) as u8
            };
        }
    })
    .unwrap();
    assert_eq!(read_mask_png(&path, frame).unwrap(), expected, "palette");
    let bytes = std::fs::read(&path).unwrap();
    let cut = dir.path().join("cut.png");
    std::fs::write(&cut, &bytes[..bytes.len() / 2]).unwrap();
    let err = read_mask_png(&cut, frame).unwrap_err();
    assert!(
        matches!(&err, Error::Corrupt { format: "PNG", .. }),
        "{err}"
    );
}
