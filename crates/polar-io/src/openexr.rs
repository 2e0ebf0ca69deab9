//! Float OpenEXR images with named channels (S0..S3; R, G, B; Y), through the `exr` crate.
//! Files are written single-layer, float32 scanlines (ZIP per line by default); any
//! single-layer file (scanline or tiled, any compression, f16/f32/u32 samples) is readable.

use std::fs::File;
use std::io::{BufReader, Read, Seek};
use std::path::Path;

use exr::block::BlockIndex;
use exr::block::writer::ChunksWriter;
use exr::image::write::channels::WritableChannels;
use exr::prelude::{
    AnyChannel, AnyChannels, Blocks, Compression, Encoding, FlatSamples, Layer, LayerAttributes,
    LineOrder, MetaData, ReadChannels, ReadLayers, Text, WritableImage, read,
};
use polar_image::{Gray, Image};

use crate::atomic::{Durability, write_file_atomic};
use crate::error::{Error, Result};

/// Lossless compression of written EXR files. Noisy float data barely deflates, so ZIP
/// saves a few percent of the bytes for several times RLE's time (`benches/io.rs`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum ExrCompression {
    /// Raw samples: fastest, largest.
    None,
    /// Run-length: nearly free, shrinks only constant runs (backgrounds, masks).
    Rle,
    /// Deflate per scanline (OpenEXR `ZIPS`): also shrinks smooth data; the default.
    #[default]
    Zip,
}

impl ExrCompression {
    fn encoding(self) -> Encoding {
        let compression = match self {
            ExrCompression::None => Compression::Uncompressed,
            ExrCompression::Rle => Compression::RLE,
            ExrCompression::Zip => Compression::ZIP1,
        };
        Encoding {
            compression,
            blocks: Blocks::ScanLines,
            line_order: LineOrder::Increasing,
        }
    }
}

/// Writes `image` as a single-layer float32 EXR whose channel `c` is named `names[c]`,
/// atomically, with the default [`ExrCompression`]. Names must be non-empty, distinct and
/// Latin-1 (an EXR rule).
pub fn write_exr<const C: usize, K>(
    path: impl AsRef<Path>,
    image: &Image<f32, C, K>,
    names: [&str; C],
) -> Result<()> {
    write_exr_with(path, image, names, ExrCompression::default())
}

/// [`write_exr`] with a chosen compression.
pub fn write_exr_with<const C: usize, K>(
    path: impl AsRef<Path>,
    image: &Image<f32, C, K>,
    names: [&str; C],
    compression: ExrCompression,
) -> Result<()> {
    let planes: Vec<Vec<f32>> = (0..C)
        .map(|c| image.pixels().iter().map(|p| p[c]).collect())
        .collect();
    let planes: Vec<&[f32]> = planes.iter().map(Vec::as_slice).collect();
    write_planes(path.as_ref(), image.size(), &planes, &names, compression)
}

/// Writes one plane as the float32 channel `name` of a single-layer EXR, atomically; the
/// encoder reads the plane in place (the file equals [`write_exr_with`]'s of the same pixels).
pub fn write_exr_plane(
    path: impl AsRef<Path>,
    plane: &Gray<f32>,
    name: &str,
    compression: ExrCompression,
) -> Result<()> {
    let path = path.as_ref();
    let size = checked_size(path, &[plane])?;
    write_planes(path, size, &[plane.as_slice()], &[name], compression)
}

/// Writes three planes of one size as the float32 channels `names` of a single-layer EXR,
/// atomically: the encoder reads the planes in place, block by block, so no interleaved
/// or per-channel copy of the image is made (the file equals [`write_exr_with`]'s of the
/// same pixels).
pub fn write_exr_planes3(
    path: impl AsRef<Path>,
    planes: [&Gray<f32>; 3],
    names: [&str; 3],
    compression: ExrCompression,
) -> Result<()> {
    let path = path.as_ref();
    let size = checked_size(path, &planes)?;
    write_planes(
        path,
        size,
        &planes.map(|p| p.as_slice()),
        &names,
        compression,
    )
}

/// Writes any number of planes of one size as the float32 channels `names` (one per plane)
/// of a single-layer EXR, atomically (e.g. the nine `S0.R` ... `S2.B` of a colour Stokes
/// image), read in place like [`write_exr_planes3`]; the file equals [`write_exr_with`]'s
/// of the same pixels.
pub fn write_exr_planes(
    path: impl AsRef<Path>,
    planes: &[&Gray<f32>],
    names: &[&str],
    compression: ExrCompression,
) -> Result<()> {
    let path = path.as_ref();
    if planes.len() != names.len() {
        return Err(Error::ChannelNames {
            path: path.to_owned(),
            names: names.iter().map(|s| s.to_string()).collect(),
            reason: "one name per plane is needed",
        });
    }
    let size = checked_size(path, planes)?;
    let planes: Vec<&[f32]> = planes.iter().map(|p| p.as_slice()).collect();
    write_planes(path, size, &planes, names, compression)
}

/// Writes `planes` (row-major, all of `size`) as the float32 channels `names` of a
/// single-layer scanline EXR, atomically. `exr` makes the header and compresses the blocks
/// (in parallel); each block's bytes are copied from the planes' rows, channels in the
/// file's alphabetical order (a per-pixel channel closure costs more than the copy).
fn write_planes(
    path: &Path,
    size: (usize, usize),
    planes: &[&[f32]],
    names: &[&str],
    compression: ExrCompression,
) -> Result<()> {
    let texts = channel_texts(path, names)?;
    let (width, _) = nonempty(path, size)?;
    let mut order: Vec<usize> = (0..planes.len()).collect();
    order.sort_by(|&a, &b| texts[a].cmp(&texts[b]));
    let sorted: Vec<&[f32]> = order.iter().map(|&i| planes[i]).collect();
    let channels: Vec<AnyChannel<FlatSamples>> = texts
        .into_iter()
        .map(|name| AnyChannel::new(name, FlatSamples::F32(Vec::new())))
        .collect();
    let layer = single_layer(size, compression, AnyChannels::sort(channels.into()));
    let headers = layer.write().infer_meta_data();
    write_file_atomic(path, Durability::Cached, |writer| {
        exr::block::write(writer, headers, true, |meta, chunks| {
            let blocks = meta.collect_ordered_block_data(|b| block_bytes(&sorted, width, b));
            chunks
                .on_progress(|_| ())
                .compress_all_blocks_parallel(&meta, blocks)
        })
        .map_err(|e| exr_error(path, e))
    })
}

/// The uncompressed bytes of one scanline block: per line, each plane's part of the row as
/// little-endian f32.
fn block_bytes(planes: &[&[f32]], width: usize, block: BlockIndex) -> Vec<u8> {
    let (x0, y0) = (block.pixel_position.x(), block.pixel_position.y());
    let (w, h) = (block.pixel_size.width(), block.pixel_size.height());
    let mut out = Vec::with_capacity(w * h * planes.len() * 4);
    for y in y0..y0 + h {
        for plane in planes {
            let row = &plane[y * width + x0..y * width + x0 + w];
            out.extend(row.iter().flat_map(|v| v.to_le_bytes()));
        }
    }
    out
}

/// The common size of `planes`, refusing an empty image or planes of different sizes.
fn checked_size(path: &Path, planes: &[&Gray<f32>]) -> Result<(usize, usize)> {
    let (width, height) = nonempty(path, planes[0].size())?;
    if let Some(p) = planes.iter().find(|p| p.size() != (width, height)) {
        return Err(Error::SizeMismatch {
            path: path.to_owned(),
            found: p.size(),
            expected: (width, height),
            reference: path.to_owned(),
        });
    }
    Ok((width, height))
}

/// `size`, refusing an empty image (EXR has no zero-sized data window).
fn nonempty(path: &Path, (width, height): (usize, usize)) -> Result<(usize, usize)> {
    if width == 0 || height == 0 {
        return Err(Error::Dimensions {
            path: path.to_owned(),
            width,
            height,
        });
    }
    Ok((width, height))
}

/// One layer of `channels` as an image to write.
fn single_layer<'c, C: WritableChannels<'c> + 'c>(
    size: (usize, usize),
    compression: ExrCompression,
    channels: C,
) -> exr::prelude::Image<Layer<C>> {
    let layer = Layer::new(
        size,
        LayerAttributes::default(),
        compression.encoding(),
        channels,
    );
    exr::prelude::Image::from_layer(layer)
}

/// Reads the channels `names` (in that order) of a single-layer EXR into a `C`-channel image
/// of the kind the caller asks for (e.g. a `StokesImage` for [`crate::STOKES_CHANNELS`]).
/// A channel the file lacks gives [`Error::MissingChannel`], naming the channels present.
pub fn read_exr<const C: usize, K>(
    path: impl AsRef<Path>,
    names: [&str; C],
) -> Result<Image<f32, C, K>> {
    let path = path.as_ref();
    let file = File::open(path).map_err(|e| Error::io(path, "EXR", e))?;
    read_exr_from(path, BufReader::new(file), names)
}

/// [`read_exr`] from any buffered reader (e.g. bytes in memory); `path` only names it in errors.
pub fn read_exr_from<const C: usize, K>(
    path: &Path,
    reader: impl Read + Seek,
    names: [&str; C],
) -> Result<Image<f32, C, K>> {
    let layer = read_single_layer(path, reader)?;
    let (width, height) = (layer.size.0, layer.size.1);
    let planes = names.map(|name| find_channel(path, &layer, name));
    let mut data = vec![0.0f32; width * height * C];
    for (c, plane) in planes.into_iter().enumerate() {
        let samples = &plane?.sample_data;
        if samples.len() != width * height {
            return Err(Error::corrupt(
                path,
                "EXR",
                "subsampled channels are not supported",
            ));
        }
        for (dst, v) in data
            .iter_mut()
            .skip(c)
            .step_by(C)
            .zip(samples.values_as_f32())
        {
            *dst = v;
        }
    }
    Image::from_vec(width, height, data).map_err(|e| Error::corrupt(path, "EXR", e))
}

/// Reads the one channel `name` of a single-layer EXR.
pub fn read_exr_channel(path: impl AsRef<Path>, name: &str) -> Result<Gray<f32>> {
    read_exr(path, [name])
}

/// The channel names of an EXR file's first layer, from its header only (no pixels decoded).
pub fn exr_channel_names(path: impl AsRef<Path>) -> Result<Vec<String>> {
    let path = path.as_ref();
    let meta = MetaData::read_from_file(path, false).map_err(|e| exr_error(path, e))?;
    let header = meta.headers.first().ok_or_else(|| Error::LayerCount {
        path: path.to_owned(),
        layers: 0,
    })?;
    Ok(header
        .channels
        .list
        .iter()
        .map(|c| c.name.to_string())
        .collect())
}

type AnyLayer = Layer<AnyChannels<FlatSamples>>;

fn read_single_layer(path: &Path, mut reader: impl Read + Seek) -> Result<AnyLayer> {
    let meta = MetaData::read_from_buffered(&mut reader, false).map_err(|e| exr_error(path, e))?;
    let [header] = meta.headers.as_slice() else {
        return Err(Error::LayerCount {
            path: path.to_owned(),
            layers: meta.headers.len(),
        });
    };
    let (width, height) = (header.layer_size.0, header.layer_size.1);
    crate::check_pixels(path, width, height)?;
    check_samples(path, width * height, header.channels.list.len())?;
    reader.rewind().map_err(|e| Error::io(path, "EXR", e))?;
    let image = read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .all_layers()
        .all_attributes()
        .from_buffered(reader)
        .map_err(|e| exr_error(path, e))?;
    let layers = image.layer_data.len();
    match <[AnyLayer; 1]>::try_from(image.layer_data.into_vec()) {
        Ok([layer]) => Ok(layer),
        Err(_) => Err(Error::LayerCount {
            path: path.to_owned(),
            layers,
        }),
    }
}

/// Refuses a layer of more than 4 samples per allowed pixel ([`crate::MAX_EXR_SAMPLES`]
/// at the default limit): every channel is decoded, so the pixel limit alone would not
/// bound memory.
fn check_samples(path: &Path, pixels: usize, channels: usize) -> Result<()> {
    let max = crate::max_pixels().saturating_mul(4);
    match pixels.checked_mul(channels) {
        Some(n) if n <= max => Ok(()),
        _ => Err(Error::TooManySamples {
            path: path.to_owned(),
            pixels,
            channels,
            max,
        }),
    }
}

fn find_channel<'a>(
    path: &Path,
    layer: &'a AnyLayer,
    name: &str,
) -> Result<&'a AnyChannel<FlatSamples>> {
    let list = &layer.channel_data.list;
    list.iter()
        .find(|c| c.name == *name)
        .ok_or_else(|| Error::MissingChannel {
            path: path.to_owned(),
            channel: name.to_owned(),
            present: list.iter().map(|c| c.name.to_string()).collect(),
        })
}

/// Validates channel names for writing and converts them to EXR text.
fn channel_texts(path: &Path, names: &[&str]) -> Result<Vec<Text>> {
    let bad = |reason| Error::ChannelNames {
        path: path.to_owned(),
        names: names.iter().map(|s| s.to_string()).collect(),
        reason,
    };
    if names.is_empty() {
        return Err(bad("at least one channel is needed"));
    }
    if names.iter().any(|n| n.is_empty()) {
        return Err(bad("a name is empty"));
    }
    if names
        .iter()
        .enumerate()
        .any(|(i, n)| names[..i].contains(n))
    {
        return Err(bad("a name is repeated"));
    }
    names
        .iter()
        .map(|n| Text::new_or_none(n).ok_or_else(|| bad("a name is not Latin-1")))
        .collect()
}

/// Maps an `exr` error: I/O keeps its kind (not found, ...); anything the decoder rejects
/// (including an unexpected end of file, which `exr` reports as invalid) is a corrupt file.
fn exr_error(path: &Path, err: exr::error::Error) -> Error {
    match err {
        exr::error::Error::Io(e) => Error::io(path, "EXR", e),
        other => Error::corrupt(path, "EXR", other),
    }
}
