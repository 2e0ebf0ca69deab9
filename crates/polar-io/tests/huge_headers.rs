//! Regressions of the hostile-input issue: tiny files whose headers claim huge images
//! aborted the process on allocation, and a malformed palette panicked the PNG decoder.
//! The readers must refuse them from the header.

use std::path::Path;

use polar_image::Gray;
use polar_io::{Error, MAX_PIXELS};

/// CRC-32 (IEEE) as PNG chunks use it.
fn crc32(bytes: &[u8]) -> u32 {
    let mut crc = 0xFFFF_FFFFu32;
    for &b in bytes {
        crc ^= u32::from(b);
        for _ in 0..8 {
            crc = if crc & 1 != 0 {
                (crc >> 1) ^ 0xEDB8_8320
            } else {
                crc >> 1
            };
        }
    }
    !crc
}

fn chunk(kind: &[u8; 4], data: &[u8]) -> Vec<u8> {
    let mut body = kind.to_vec();
    body.extend_from_slice(data);
    let mut out = (data.len() as u32).to_be_bytes().to_vec();
    out.extend_from_slice(&body);
    out.extend_from_slice(&crc32(&body).to_be_bytes());
    out
}

/// PNG colour types (IHDR byte 9).
const GREY: u8 = 0;
const RGBA: u8 = 6;
const INDEXED: u8 = 3;

/// A PNG of a few dozen bytes whose header says `w x h`, 16 bits of colour type `color`,
/// with no pixel data.
fn png_claiming(path: &Path, w: u32, h: u32, color: u8) {
    let mut ihdr = w.to_be_bytes().to_vec();
    ihdr.extend_from_slice(&h.to_be_bytes());
    ihdr.extend_from_slice(&[16, color, 0, 0, 0]);
    let mut file = b"\x89PNG\r\n\x1a\n".to_vec();
    file.extend(chunk(b"IHDR", &ihdr));
    // An empty zlib stream: the decoder reads the header up to the first IDAT.
    file.extend(chunk(
        b"IDAT",
        &[0x78, 0x9c, 0x03, 0x00, 0x00, 0x00, 0x00, 0x01],
    ));
    file.extend(chunk(b"IEND", &[]));
    std::fs::write(path, file).unwrap();
}

fn assert_too_large(result: Result<impl std::fmt::Debug, Error>) {
    match result {
        Err(Error::TooLarge { max, .. }) => assert_eq!(max, MAX_PIXELS),
        other => panic!("expected TooLarge, got {other:?}"),
    }
}

#[test]
fn tiny_png_claiming_200000_squared_pixels_is_refused_from_its_header() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("huge.png");
    png_claiming(&path, 200_000, 200_000, GREY);
    assert!(std::fs::metadata(&path).unwrap().len() < 100);
    // Without the header check this aborted the process (a 40 GB allocation).
    assert_too_large(polar_io::read_mosaic(&path));
    assert_too_large(polar_io::read_gray8_png(&path));
}

#[test]
fn tiny_exr_claiming_100000_squared_pixels_is_refused_from_its_header() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("huge.exr");
    exr_claiming(&path, ["Y"], 100_000, 100_000);
    let result = polar_io::read_exr_channel(&path, "Y");
    // The exr crate may reject the inconsistent file itself; it must never allocate 40 GB.
    assert!(
        matches!(result, Err(Error::TooLarge { .. } | Error::Corrupt { .. })),
        "{result:?}"
    );
}

/// A colour PNG is refused from its header's colour type, before any pixel buffer is
/// allocated (a tiny file can claim 100 MP of 16-bit RGBA).
#[test]
fn tiny_colour_png_is_refused_from_its_header() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("rgba.png");
    png_claiming(&path, 10_000, 10_000, RGBA);
    for result in [
        polar_io::read_mosaic(&path).map(|_| ()),
        polar_io::read_gray8_png(&path).map(|_| ()),
        polar_io::read_rgb8_png(&path).map(|_| ()),
    ] {
        match result {
            Err(Error::ColorType { found, .. }) => assert_eq!(found, "Rgba, 16-bit"),
            other => panic!("expected ColorType, got {other:?}"),
        }
    }
}

/// An object mask may be of any colour type, so a tiny file claiming 100 MP of 16-bit RGBA
/// is refused from its header's size against the frame's, before the 800 MB its pixels
/// would take exist.
#[test]
fn tiny_mask_claiming_another_size_than_the_frame_is_refused_from_its_header() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("objects.png");
    png_claiming(&path, 10_000, 10_000, RGBA);
    match polar_io::read_mask_png(&path, (40, 30)) {
        Err(Error::FrameSize { found, frame, .. }) => {
            assert_eq!((found, frame), ((10_000, 10_000), (40, 30)))
        }
        other => panic!("expected FrameSize, got {other:?}"),
    }
}

/// A PLTE chunk whose length is not a whole number of RGB entries (4 bytes) made the `png`
/// crate (0.18.1) panic while expanding the palette (image-rs/image-png#694); an object
/// mask is read with that expansion, so the reader refuses such a palette from the header.
#[test]
fn palette_of_partial_entries_is_corrupt_not_a_panic() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("objects.png");
    let mut file = b"\x89PNG\r\n\x1a\n".to_vec();
    file.extend(chunk(
        b"IHDR",
        &[0, 0, 0, 1, 0, 0, 0, 1, 8, INDEXED, 0, 0, 0],
    ));
    file.extend(chunk(b"PLTE", &[255, 0, 0, 7]));
    // zlib of the one row: filter byte 0, palette index 0.
    let row = [0x78, 0x9c, 0x63, 0x60, 0x00, 0x00, 0x00, 0x02, 0x00, 0x01];
    file.extend(chunk(b"IDAT", &row));
    file.extend(chunk(b"IEND", &[]));
    std::fs::write(&path, file).unwrap();
    match polar_io::read_mask_png(&path, (1, 1)) {
        Err(Error::Corrupt { detail, .. }) => assert!(detail.contains("PLTE"), "{detail}"),
        other => panic!("expected Corrupt, got {other:?}"),
    }
}

/// A 2x2 float EXR of `C` channels whose data window is patched to claim `w x h` pixels.
fn exr_claiming<const C: usize>(path: &Path, names: [&str; C], w: i32, h: i32) {
    let img = polar_image::Image::<f32, C>::from_vec(2, 2, vec![1.0f32; 4 * C]).unwrap();
    polar_io::write_exr_with(path, &img, names, polar_io::ExrCompression::None).unwrap();
    // The data window is a box2i: xmin, ymin, xmax, ymax.
    let mut bytes = std::fs::read(path).unwrap();
    let key = b"dataWindow\0box2i\0";
    let at = bytes.windows(key.len()).position(|w| w == key).unwrap() + key.len() + 4;
    bytes[at + 8..at + 12].copy_from_slice(&(w - 1).to_le_bytes());
    bytes[at + 12..at + 16].copy_from_slice(&(h - 1).to_le_bytes());
    std::fs::write(path, bytes).unwrap();
}

/// Hostile input (issue #22, seen writing the `exr_stokes` fuzz target): every channel of
/// an EXR is decoded, so a file of many channels within the pixel limit could ask for any
/// amount of memory; pixels times channels above `MAX_EXR_SAMPLES` are now refused from the
/// header.
#[test]
fn tiny_exr_of_many_channels_is_refused_from_its_header() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("wide.exr");
    let names = ["A", "B", "C", "D", "E"];
    exr_claiming(&path, names, 10_000, 10_000);
    match polar_io::read_exr_channel(&path, "A") {
        Err(Error::TooManySamples {
            pixels,
            channels,
            max,
            ..
        }) => {
            assert_eq!((pixels, channels), (MAX_PIXELS, 5));
            assert_eq!(max, polar_io::MAX_EXR_SAMPLES);
        }
        other => panic!("expected TooManySamples, got {other:?}"),
    }
}

#[test]
fn images_at_the_limit_are_still_read() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("ok.png");
    polar_io::write_gray16_png(&path, &Gray::from_vec(4, 2, vec![7u16; 8]).unwrap()).unwrap();
    assert_eq!(polar_io::read_mosaic(&path).unwrap().image.size(), (4, 2));
}
