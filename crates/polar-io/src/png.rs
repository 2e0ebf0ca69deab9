//! Grayscale (8/16-bit) and RGB (8-bit) PNG through the `png` crate (the `image` crate's codec,
//! used directly because `image` silently rescales 1/2/4-bit files to 8 bits).
//! Mosaics, label maps and masks are grayscale; RGB and 8-bit palette images (read back as
//! RGB) are for visualisations only.

use std::fs::File;
use std::io::{BufRead, BufReader, Seek, Write};
use std::path::Path;

use polar_image::kind::RawMosaic;
use polar_image::{Gray, Image, Plain};

use crate::atomic::{Durability, write_file_atomic};
use crate::error::{Error, Result};

/// Largest decoded image accepted (bytes). Guards against headers that claim absurd sizes.
const MAX_DECODED_BYTES: usize = 1 << 30;

/// Bits per sample of a grayscale PNG. Only 8 and 16 are used by the project.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum BitDepth {
    /// 8 bits per sample, values 0..=255.
    Eight,
    /// 16 bits per sample, values 0..=65535.
    Sixteen,
}

impl BitDepth {
    /// Bits per sample: 8 or 16.
    pub fn bits(self) -> u8 {
        match self {
            BitDepth::Eight => 8,
            BitDepth::Sixteen => 16,
        }
    }

    /// Largest representable value: 255 or 65535.
    pub fn max_value(self) -> u16 {
        match self {
            BitDepth::Eight => u16::from(u8::MAX),
            BitDepth::Sixteen => u16::MAX,
        }
    }
}

/// A grayscale PNG as read: samples widened to `u16` (values unchanged, not rescaled),
/// plus the bit depth the file stored them at; `K` is what the image means
/// ([`MosaicPng`] for a raw mosaic).
#[derive(Clone, Debug, PartialEq)]
pub struct GrayPng<K = Plain> {
    /// The samples, row 0 at the top.
    pub image: Image<u16, 1, K>,
    /// The depth in the file; every sample is `<= bit_depth.max_value()`.
    pub bit_depth: BitDepth,
}

/// A raw division-of-focal-plane mosaic as read from its PNG ([`read_mosaic`]).
pub type MosaicPng = GrayPng<RawMosaic>;

/// Reads an 8- or 16-bit grayscale PNG. Colour PNGs give [`Error::ColorType`],
/// 1/2/4-bit ones [`Error::BitDepth`] (their values would need rescaling to mean DN).
pub fn read_gray_png(path: impl AsRef<Path>) -> Result<GrayPng> {
    let path = path.as_ref();
    read_gray_png_from(path, open(path)?)
}

/// [`read_gray_png`] from any reader (e.g. bytes in memory); `path` only names it in errors.
pub fn read_gray_png_from(path: &Path, reader: impl BufRead + Seek) -> Result<GrayPng> {
    let accept = |color, depth| gray_of_depth(path, color, depth, &[8, 16], "8 or 16");
    let d = decode(path, reader, accept)?;
    let (bit_depth, data) = if d.depth == png::BitDepth::Sixteen {
        (BitDepth::Sixteen, u16_from_be_bytes(&d.bytes))
    } else {
        (
            BitDepth::Eight,
            d.bytes.into_iter().map(u16::from).collect(),
        )
    };
    Ok(GrayPng {
        image: gray_from_vec(path, d.size, data)?,
        bit_depth,
    })
}

/// Reads an 8-bit grayscale PNG (label maps, masks); another depth gives [`Error::BitDepth`].
pub fn read_gray8_png(path: impl AsRef<Path>) -> Result<Gray<u8>> {
    let path = path.as_ref();
    let accept = |color, depth| gray_of_depth(path, color, depth, &[8], "8");
    let d = decode(path, open(path)?, accept)?;
    gray_from_vec(path, d.size, d.bytes)
}

/// Reads an object mask as any segmenter may write it: a PNG of any colour type and bit
/// depth, 255 where a colour sample is non-zero and the alpha, where the file has one, is
/// non-zero (a transparent pixel is nothing), else 0. A palette image counts by its
/// colours (a black entry is background), grayscale of 1 to 16 bits by value. A mask of
/// another size than the `frame` (`(width, height)`) it goes with is [`Error::FrameSize`],
/// refused from its header: a file of a few bytes cannot make the reader hold the
/// pixels of the largest image it accepts.
pub fn read_mask_png(path: impl AsRef<Path>, frame: (usize, usize)) -> Result<Gray<u8>> {
    let path = path.as_ref();
    read_mask_png_from(path, open(path)?, frame)
}

/// [`read_mask_png`] from any reader (e.g. bytes in memory); `path` only names it in errors.
pub fn read_mask_png_from(
    path: &Path,
    reader: impl BufRead + Seek,
    frame: (usize, usize),
) -> Result<Gray<u8>> {
    let same_size = |info: &png::Info| {
        let found = (info.width as usize, info.height as usize);
        match found == frame {
            true => Ok(()),
            false => Err(Error::FrameSize {
                path: path.to_owned(),
                found,
                frame,
            }),
        }
    };
    let expand = png::Transformations::EXPAND;
    let d = decode_with(path, reader, expand, same_size)?;
    let bytes = usize::from(d.depth == png::BitDepth::Sixteen) + 1;
    let samples = d.color.samples();
    let colours = match d.color {
        png::ColorType::GrayscaleAlpha | png::ColorType::Rgba => samples - 1,
        _ => samples,
    };
    let pixel = samples * bytes;
    let on = |p: &[u8]| {
        let (colour, alpha) = p.split_at(colours * bytes);
        colour.iter().any(|&b| b != 0) && (alpha.is_empty() || alpha.iter().any(|&b| b != 0))
    };
    let mask = d
        .bytes
        .chunks_exact(pixel)
        .map(|p| if on(p) { u8::MAX } else { 0 });
    gray_from_vec(path, d.size, mask.collect())
}

/// Accepts grayscale of a bit depth in `bits` (described by `expected`).
fn gray_of_depth(
    path: &Path,
    color: png::ColorType,
    depth: png::BitDepth,
    bits: &[u8],
    expected: &'static str,
) -> Result<()> {
    if color != png::ColorType::Grayscale {
        return Err(color_error(path, color, depth, "grayscale"));
    }
    if !bits.contains(&(depth as u8)) {
        return Err(Error::BitDepth {
            path: path.to_owned(),
            found: depth as u8,
            expected,
        });
    }
    Ok(())
}

/// Reads a division-of-focal-plane mosaic: an 8- or 16-bit grayscale PNG whose width and
/// height are even and at least 2 (whole 2x2 super-pixels, layout in the conventions).
pub fn read_mosaic(path: impl AsRef<Path>) -> Result<MosaicPng> {
    let path = path.as_ref();
    read_mosaic_from(path, open(path)?)
}

/// [`read_mosaic`] from any reader (e.g. bytes in memory); `path` only names it in errors.
pub fn read_mosaic_from(path: &Path, reader: impl BufRead + Seek) -> Result<MosaicPng> {
    let png = read_gray_png_from(path, reader)?;
    check_mosaic_size(path, png.image.width(), png.image.height())?;
    Ok(MosaicPng {
        image: png.image.into_kind(),
        bit_depth: png.bit_depth,
    })
}

/// Checks that a `width x height` mosaic holds whole 2x2 super-pixels.
pub fn check_mosaic_size(path: &Path, width: usize, height: usize) -> Result<()> {
    if polar_image::is_mosaic_size(width, height) {
        Ok(())
    } else {
        Err(Error::MosaicSize {
            path: path.to_owned(),
            width,
            height,
        })
    }
}

/// Reads an 8-bit RGB PNG (no alpha), or an 8-bit palette PNG as the RGB of its palette (an
/// index beyond the palette: [`Error::Corrupt`]).
pub fn read_rgb8_png(path: impl AsRef<Path>) -> Result<Image<u8, 3>> {
    let path = path.as_ref();
    let accept = |color, depth| match (color, depth) {
        (png::ColorType::Rgb | png::ColorType::Indexed, png::BitDepth::Eight) => Ok(()),
        _ => Err(color_error(path, color, depth, "Rgb or Indexed, 8-bit")),
    };
    let d = decode(path, open(path)?, accept)?;
    let bytes = match &d.palette {
        None => d.bytes,
        Some(palette) => expand_palette(path, &d.bytes, palette)?,
    };
    Image::from_vec(d.size.0, d.size.1, bytes).map_err(|e| Error::corrupt(path, "PNG", e))
}

/// The RGB bytes of palette `indices` (`palette` as stored: three bytes an entry).
fn expand_palette(path: &Path, indices: &[u8], palette: &[u8]) -> Result<Vec<u8>> {
    let entries = palette.as_chunks::<3>().0;
    let mut rgb = Vec::with_capacity(3 * indices.len());
    for &i in indices {
        let entry = entries.get(usize::from(i)).ok_or_else(|| {
            let why = format!("palette index {i} beyond its {} entries", entries.len());
            Error::corrupt(path, "PNG", why)
        })?;
        rgb.extend_from_slice(entry);
    }
    Ok(rgb)
}

/// Writes an 8-bit grayscale PNG, atomically.
pub fn write_gray8_png<K>(path: impl AsRef<Path>, image: &Image<u8, 1, K>) -> Result<()> {
    let bytes = image.as_slice();
    let layout = Layout::new(
        image.size(),
        png::ColorType::Grayscale,
        png::BitDepth::Eight,
    );
    encode(path.as_ref(), layout, |y, rows| {
        rows.copy_from_slice(&bytes[y * layout.row_bytes..][..rows.len()]);
    })
}

/// Writes a 16-bit grayscale PNG, atomically.
pub fn write_gray16_png<K>(path: impl AsRef<Path>, image: &Image<u16, 1, K>) -> Result<()> {
    let samples = image.as_slice();
    let layout = Layout::new(
        image.size(),
        png::ColorType::Grayscale,
        png::BitDepth::Sixteen,
    );
    encode(path.as_ref(), layout, |y, rows| {
        let first = y * image.width();
        for (out, v) in rows.chunks_exact_mut(2).zip(&samples[first..]) {
            out.copy_from_slice(&v.to_be_bytes());
        }
    })
}

/// Writes `png.image` at `png.bit_depth`; at 8 bits a sample above 255 gives
/// [`Error::ValueRange`] (never silently clipped).
pub fn write_gray_png<K>(path: impl AsRef<Path>, png: &GrayPng<K>) -> Result<()> {
    let path = path.as_ref();
    match png.bit_depth {
        BitDepth::Sixteen => write_gray16_png(path, &png.image),
        BitDepth::Eight => write_gray8_png(path, &narrow_to_u8(path, &png.image)?),
    }
}

/// Writes an 8-bit RGB PNG (visualisations such as the AoLP/DoLP picture), atomically.
pub fn write_rgb8_png(path: impl AsRef<Path>, image: &Image<u8, 3>) -> Result<()> {
    let bytes = image.as_slice();
    write_rgb8_png_rows(path, image.size(), |y, rows| {
        rows.copy_from_slice(&bytes[y * 3 * image.width()..][..rows.len()]);
    })
}

/// Writes an 8-bit RGB PNG whose rows `fill(y, rows)` computes a block at a time (`rows`
/// holds whole rows from row `y` on, a few dozen at a time), atomically: a
/// picture computed from float planes is never held whole in memory.
pub fn write_rgb8_png_rows(
    path: impl AsRef<Path>,
    size: (usize, usize),
    fill: impl FnMut(usize, &mut [u8]),
) -> Result<()> {
    let layout = Layout::new(size, png::ColorType::Rgb, png::BitDepth::Eight);
    encode(path.as_ref(), layout, fill)
}

/// Writes `indices` as an 8-bit palette PNG of `palette`, atomically (see
/// [`write_indexed8_png_rows`]).
pub fn write_indexed8_png<K>(
    path: impl AsRef<Path>,
    indices: &Image<u8, 1, K>,
    palette: &[[u8; 3]],
) -> Result<()> {
    let bytes = indices.as_slice();
    write_indexed8_png_rows(path, indices.size(), palette, |y, rows| {
        rows.copy_from_slice(&bytes[y * indices.width()..][..rows.len()]);
    })
}

/// Writes an 8-bit palette PNG whose indices `fill(y, rows)` computes a block of rows at a
/// time (as [`write_rgb8_png_rows`]), atomically: a third of the bytes of the same picture
/// in RGB to filter and deflate. `palette` holds 1 to 256 colours (else
/// [`Error::Palette`]); every index written must name one.
pub fn write_indexed8_png_rows(
    path: impl AsRef<Path>,
    size: (usize, usize),
    palette: &[[u8; 3]],
    fill: impl FnMut(usize, &mut [u8]),
) -> Result<()> {
    let path = path.as_ref();
    if !(1..=256).contains(&palette.len()) {
        return Err(Error::Palette {
            path: path.to_owned(),
            entries: palette.len(),
        });
    }
    let layout = Layout {
        palette: Some(palette.as_flattened()),
        ..Layout::new(size, png::ColorType::Indexed, png::BitDepth::Eight)
    };
    encode(path, layout, fill)
}

/// Rows per block handed to a row filler: enough to fill both cores, small beside the image.
const ROW_BLOCK: usize = 64;

/// `u16` samples as `u8`, failing on the first that does not fit.
fn narrow_to_u8<K>(path: &Path, image: &Image<u16, 1, K>) -> Result<Image<u8, 1, K>> {
    let width = image.width().max(1);
    let data = image
        .as_slice()
        .iter()
        .enumerate()
        .map(|(i, &v)| {
            u8::try_from(v).map_err(|_| Error::ValueRange {
                path: path.to_owned(),
                x: i % width,
                y: i / width,
                value: u32::from(v),
                bits: 8,
            })
        })
        .collect::<Result<Vec<u8>>>()?;
    gray_from_vec(path, image.size(), data)
}

fn gray_from_vec<T, K>(
    path: &Path,
    (width, height): (usize, usize),
    data: Vec<T>,
) -> Result<Image<T, 1, K>> {
    Image::from_vec(width, height, data).map_err(|e| Error::corrupt(path, "PNG", e))
}

fn u16_from_be_bytes(bytes: &[u8]) -> Vec<u16> {
    bytes
        .as_chunks::<2>()
        .0
        .iter()
        .map(|&b| u16::from_be_bytes(b))
        .collect()
}

/// The file at `path`, buffered for [`decode`].
fn open(path: &Path) -> Result<BufReader<File>> {
    let file = File::open(path).map_err(|e| Error::io(path, "PNG", e))?;
    Ok(BufReader::new(file))
}

/// Decodes a PNG without transformations (values as stored, big-endian for 16 bits), with
/// its colour type, bit depth and `(width, height)`; `path` names the source in errors.
/// `accept` judges the header's colour type and bit depth before any pixel buffer exists.
fn decode(
    path: &Path,
    reader: impl BufRead + Seek,
    accept: impl FnOnce(png::ColorType, png::BitDepth) -> Result<()>,
) -> Result<Decoded> {
    let accept = |info: &png::Info| accept(info.color_type, info.bit_depth);
    decode_with(path, reader, png::Transformations::IDENTITY, accept)
}

/// [`decode`] with the `png` crate's `transformations` applied to the samples; `accept`
/// judges the whole header.
fn decode_with(
    path: &Path,
    reader: impl BufRead + Seek,
    transformations: png::Transformations,
    accept: impl FnOnce(&png::Info) -> Result<()>,
) -> Result<Decoded> {
    let limits = png::Limits {
        bytes: MAX_DECODED_BYTES,
    };
    let mut decoder = png::Decoder::new_with_limits(reader, limits);
    decoder.set_transformations(transformations);
    let mut reader = decoder.read_info().map_err(|e| decode_error(path, e))?;
    let info = reader.info();
    crate::check_pixels(path, info.width as usize, info.height as usize)?;
    whole_palette_entries(path, info)?;
    accept(info)?;
    let len = reader
        .output_buffer_size()
        .ok_or_else(|| Error::corrupt(path, "PNG", "image size overflows memory"))?;
    let mut bytes = vec![0; len];
    let frame = reader
        .next_frame(&mut bytes)
        .map_err(|e| decode_error(path, e))?;
    bytes.truncate(frame.buffer_size());
    let palette = (frame.color_type == png::ColorType::Indexed).then(|| {
        reader
            .info()
            .palette
            .as_deref()
            .unwrap_or_default()
            .to_vec()
    });
    Ok(Decoded {
        color: frame.color_type,
        depth: frame.bit_depth,
        size: (frame.width as usize, frame.height as usize),
        bytes,
        palette,
    })
}

/// A PLTE chunk must hold whole RGB entries (PNG 11.2.3); `png` 0.18.1 accepts any length
/// and then panics expanding a partial entry (image-rs/image-png#694).
fn whole_palette_entries(path: &Path, info: &png::Info) -> Result<()> {
    match info.palette.as_deref() {
        Some(p) if p.len() % 3 != 0 => Err(Error::corrupt(
            path,
            "PNG",
            format!("a PLTE chunk of {} bytes, not whole RGB entries", p.len()),
        )),
        _ => Ok(()),
    }
}

/// A decoded PNG, samples as stored.
struct Decoded {
    color: png::ColorType,
    depth: png::BitDepth,
    size: (usize, usize),
    bytes: Vec<u8>,
    /// A palette image's PLTE bytes (empty if the file has none); `None` for other colour types.
    palette: Option<Vec<u8>>,
}

/// Maps a `png` decoding error: I/O keeps its kind, the rest is a corrupt file.
fn decode_error(path: &Path, err: png::DecodingError) -> Error {
    match err {
        png::DecodingError::IoError(e) => Error::io(path, "PNG", e),
        other => Error::corrupt(path, "PNG", other),
    }
}

/// "Rgb, 8-bit" and the like, for error messages.
fn describe(color: png::ColorType, depth: png::BitDepth) -> String {
    format!("{color:?}, {}-bit", depth as u8)
}

fn color_error(
    path: &Path,
    color: png::ColorType,
    depth: png::BitDepth,
    expected: &'static str,
) -> Error {
    Error::ColorType {
        path: path.to_owned(),
        found: describe(color, depth),
        expected,
    }
}

/// Size and sample format of an image being encoded.
#[derive(Clone, Copy)]
struct Layout<'a> {
    width: usize,
    height: usize,
    row_bytes: usize,
    color: png::ColorType,
    depth: png::BitDepth,
    /// The PLTE chunk's bytes (three an entry) of a palette image.
    palette: Option<&'a [u8]>,
}

impl Layout<'_> {
    fn new((width, height): (usize, usize), color: png::ColorType, depth: png::BitDepth) -> Self {
        let sample_bytes = if depth == png::BitDepth::Sixteen {
            2
        } else {
            1
        };
        let row_bytes = width * color.samples() * sample_bytes;
        Layout {
            width,
            height,
            row_bytes,
            color,
            depth,
            palette: None,
        }
    }
}

/// Encodes the rows that `fill` produces block by block (see [`write_rgb8_png_rows`]),
/// streaming them to `path` atomically (16-bit samples big-endian, as PNG stores them).
/// Fast deflate: mosaics are noisy, so stronger compression costs much time for few bytes.
fn encode(path: &Path, layout: Layout, mut fill: impl FnMut(usize, &mut [u8])) -> Result<()> {
    let dims_error = || Error::Dimensions {
        path: path.to_owned(),
        width: layout.width,
        height: layout.height,
    };
    let w = u32::try_from(layout.width).map_err(|_| dims_error())?;
    let h = u32::try_from(layout.height).map_err(|_| dims_error())?;
    if w == 0 || h == 0 {
        return Err(dims_error());
    }
    let encode_error = |e: png::EncodingError| match e {
        png::EncodingError::IoError(io) => Error::io(path, "PNG", io),
        other => Error::Io {
            path: path.to_owned(),
            source: std::io::Error::other(other),
        },
    };
    let mut block = vec![0u8; layout.row_bytes * ROW_BLOCK.min(layout.height)];
    write_file_atomic(path, Durability::Cached, |writer| {
        let mut encoder = png::Encoder::new(writer, w, h);
        encoder.set_color(layout.color);
        encoder.set_depth(layout.depth);
        if let Some(palette) = layout.palette {
            encoder.set_palette(palette);
        }
        encoder.set_compression(png::Compression::Fast);
        let mut png_writer = encoder.write_header().map_err(encode_error)?;
        let mut stream = png_writer.stream_writer().map_err(encode_error)?;
        for y in (0..layout.height).step_by(ROW_BLOCK) {
            let rows = &mut block[..layout.row_bytes * ROW_BLOCK.min(layout.height - y)];
            fill(y, rows);
            stream
                .write_all(rows)
                .map_err(|e| Error::io(path, "PNG", e))?;
        }
        stream.finish().map_err(encode_error)?;
        png_writer.finish().map_err(encode_error)
    })
}
