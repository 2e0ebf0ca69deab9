//! EXR round trips (bit-exact float32), channel lookup, tiled files, and the error cases.

use std::path::Path;

use exr::prelude::{
    AnyChannel, AnyChannels, Encoding, FlatSamples, ImageAttributes, Layer, LayerAttributes,
    WritableImage, f16,
};
use polar_image::{Gray, Image, StokesImage};
use polar_io::{
    Error, ExrCompression, RGB_LINEAR_STOKES_CHANNELS, Rule, STOKES_CHANNELS, check_channels,
    check_stokes, exr_channel_names, read_exr, read_exr_channel, write_exr, write_exr_plane,
    write_exr_planes, write_exr_planes3, write_exr_with,
};

/// A 4-channel image holding awkward floats: negative, subnormal, huge, signed zero.
fn awkward_stokes(width: usize, height: usize) -> StokesImage {
    let specials = [
        0.0,
        -0.0,
        1.0e-42,
        -3.5,
        1.0e30,
        f32::MIN_POSITIVE,
        0.1,
        f32::MAX,
    ];
    let data = (0..width * height * 4)
        .map(|i| {
            if i < specials.len() {
                specials[i]
            } else {
                (i as f32 * 0.618).sin() * 10.0
            }
        })
        .collect();
    Image::from_vec(width, height, data).unwrap()
}

fn bits<const C: usize, K>(img: &Image<f32, C, K>) -> Vec<u32> {
    img.as_slice().iter().map(|v| v.to_bits()).collect()
}

/// Reads the four Stokes channels of `path`.
fn read_stokes(path: &Path) -> polar_io::Result<StokesImage> {
    read_exr(path, STOKES_CHANNELS)
}

/// Writes a file with the `exr` crate directly, so tests can make tiled / f16 / multi-layer files.
fn write_with_exr_crate(path: &Path, layers: Vec<Layer<AnyChannels<FlatSamples>>>) {
    let size = layers[0].size;
    exr::prelude::Image::from_layers(ImageAttributes::with_size(size), layers)
        .write()
        .to_file(path)
        .unwrap();
}

fn layer(
    encoding: Encoding,
    size: (usize, usize),
    channels: Vec<(&str, FlatSamples)>,
) -> Layer<AnyChannels<FlatSamples>> {
    let list: Vec<_> = channels
        .into_iter()
        .map(|(n, s)| AnyChannel::new(n, s))
        .collect();
    Layer::new(
        size,
        LayerAttributes::named("main"),
        encoding,
        AnyChannels::sort(list.into()),
    )
}

#[test]
fn stokes_round_trip_is_bit_exact() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("stokes.exr");
    let img = awkward_stokes(37, 21);
    write_exr(&path, &img, STOKES_CHANNELS).unwrap();
    let back = read_stokes(&path).unwrap();
    assert_eq!(back.size(), (37, 21));
    assert_eq!(bits(&back), bits(&img));
    assert_eq!(exr_channel_names(&path).unwrap(), ["S0", "S1", "S2", "S3"]);
}

#[test]
fn every_compression_round_trips_bit_exact() {
    let dir = tempfile::tempdir().unwrap();
    let img = awkward_stokes(19, 23);
    for c in [
        ExrCompression::None,
        ExrCompression::Rle,
        ExrCompression::Zip,
    ] {
        let path = dir.path().join(format!("{c:?}.exr"));
        write_exr_with(&path, &img, STOKES_CHANNELS, c).unwrap();
        assert_eq!(bits(&read_stokes(&path).unwrap()), bits(&img), "{c:?}");
    }
}

/// One or three planes written in place give the same file, byte for byte, as the
/// interleaved image of the same pixels (and so read back bit-exact), for every compression.
#[test]
fn planes_in_place_write_the_same_file_as_an_image() {
    let dir = tempfile::tempdir().unwrap();
    let img = awkward_stokes(19, 23);
    let planes: [Gray<f32>; 3] = std::array::from_fn(|c| img.channel(c));
    let three: Image<f32, 3> = Image::from_channels([&planes[0], &planes[1], &planes[2]]).unwrap();
    let names = ["S0", "S1", "S2"];
    for c in [
        ExrCompression::None,
        ExrCompression::Rle,
        ExrCompression::Zip,
    ] {
        let (a, b) = (dir.path().join("a.exr"), dir.path().join("b.exr"));
        write_exr_with(&a, &three, names, c).unwrap();
        write_exr_planes3(&b, [&planes[0], &planes[1], &planes[2]], names, c).unwrap();
        assert!(
            std::fs::read(&a).unwrap() == std::fs::read(&b).unwrap(),
            "{c:?}"
        );
        write_exr_with(&a, &planes[1], ["Y"], c).unwrap();
        write_exr_plane(&b, &planes[1], "Y", c).unwrap();
        assert!(
            std::fs::read(&a).unwrap() == std::fs::read(&b).unwrap(),
            "one plane, {c:?}"
        );
    }
    let small = Gray::<f32>::new(3, 2);
    let err = write_exr_planes3(
        dir.path().join("c.exr"),
        [&planes[0], &small, &planes[2]],
        names,
        ExrCompression::Rle,
    )
    .unwrap_err();
    assert!(
        matches!(err, Error::SizeMismatch { found: (3, 2), .. }),
        "{err}"
    );
    let empty = Gray::<f32>::new(0, 2);
    let err = write_exr_plane(dir.path().join("d.exr"), &empty, "Y", ExrCompression::Rle);
    assert!(
        matches!(err, Err(Error::Dimensions { width: 0, .. })),
        "{err:?}"
    );
}

/// Nine planes under the colour Stokes names: the same file as the interleaved 9-channel
/// image, read back bit-exact by name; a name per plane is required.
/// The writers copy rows into blocks themselves; the file must be byte for byte the one
/// the `exr` crate's own image writer makes of the same channels (header, offset table,
/// blocks), for every compression and for channel names given out of alphabetical order.
/// Tolerance 0: same bytes.
#[test]
fn block_writer_equals_the_exr_crate_image_writer() {
    let dir = tempfile::tempdir().unwrap();
    let (w, h) = (37, 23);
    let stokes = awkward_stokes(w, h);
    let names = ["S2", "S0", "S3", "S1"];
    for compression in [
        ExrCompression::None,
        ExrCompression::Rle,
        ExrCompression::Zip,
    ] {
        let ours = dir.path().join("ours.exr");
        write_exr_with(&ours, &stokes, names, compression).unwrap();
        let list: Vec<_> = (0..4)
            .map(|c| {
                let plane = stokes.pixels().iter().map(|p| p[c]).collect();
                AnyChannel::new(names[c], FlatSamples::F32(plane))
            })
            .collect();
        let exr_compression = match compression {
            ExrCompression::None => exr::prelude::Compression::Uncompressed,
            ExrCompression::Rle => exr::prelude::Compression::RLE,
            ExrCompression::Zip => exr::prelude::Compression::ZIP1,
        };
        let encoding = Encoding {
            compression: exr_compression,
            blocks: exr::prelude::Blocks::ScanLines,
            line_order: exr::prelude::LineOrder::Increasing,
        };
        let theirs = dir.path().join("theirs.exr");
        let layer = Layer::new(
            (w, h),
            LayerAttributes::default(),
            encoding,
            AnyChannels::sort(list.into()),
        );
        exr::prelude::Image::from_layer(layer)
            .write()
            .to_file(&theirs)
            .unwrap();
        assert!(
            std::fs::read(&ours).unwrap() == std::fs::read(&theirs).unwrap(),
            "{compression:?}"
        );
    }
}

#[test]
fn colour_stokes_planes_round_trip_by_name() {
    let dir = tempfile::tempdir().unwrap();
    let (a, b) = (awkward_stokes(7, 5), awkward_stokes(7, 5));
    let planes: Vec<Gray<f32>> = (0..9)
        .map(|k| {
            if k < 4 {
                a.channel(k)
            } else {
                b.channel((k + 1) % 4)
            }
        })
        .collect();
    let refs: Vec<&Gray<f32>> = planes.iter().collect();
    let nine: Image<f32, 9> = Image::from_channels(refs.clone().try_into().unwrap()).unwrap();
    let (p, q) = (dir.path().join("p.exr"), dir.path().join("q.exr"));
    let rle = ExrCompression::Rle;
    write_exr_planes(&p, &refs, &RGB_LINEAR_STOKES_CHANNELS, rle).unwrap();
    write_exr_with(&q, &nine, RGB_LINEAR_STOKES_CHANNELS, rle).unwrap();
    assert!(std::fs::read(&p).unwrap() == std::fs::read(&q).unwrap());
    for (k, name) in RGB_LINEAR_STOKES_CHANNELS.into_iter().enumerate() {
        assert_eq!(
            bits(&read_exr_channel(&p, name).unwrap()),
            bits(&planes[k]),
            "{name}"
        );
    }
    let err = write_exr_planes(&p, &refs[..8], &RGB_LINEAR_STOKES_CHANNELS, rle).unwrap_err();
    assert!(matches!(err, Error::ChannelNames { .. }), "{err}");
}

#[test]
fn nan_and_inf_survive_a_plain_round_trip() {
    // DoLP/AoLP outputs hold NaN where undefined (conventions), so plain reads must keep it.
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("dolp.exr");
    let img =
        Image::<f32, 1>::from_vec(3, 1, vec![f32::NAN, f32::INFINITY, -f32::INFINITY]).unwrap();
    write_exr(&path, &img, ["Y"]).unwrap();
    assert_eq!(bits(&read_exr_channel(&path, "Y").unwrap()), bits(&img));
}

#[test]
fn channels_are_found_by_name_in_any_order() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("rgb.exr");
    let img = Image::<f32, 3>::from_vec(2, 1, vec![1.0, 2.0, 3.0, 4.0, 5.0, 6.0]).unwrap();
    write_exr(&path, &img, ["R", "G", "B"]).unwrap();
    let bgr: Image<f32, 3> = read_exr(&path, ["B", "G", "R"]).unwrap();
    assert_eq!(bgr.as_slice(), &[3.0, 2.0, 1.0, 6.0, 5.0, 4.0]);
    assert_eq!(
        read_exr_channel(&path, "G").unwrap().as_slice(),
        &[2.0, 5.0]
    );
}

#[test]
fn missing_channel_error_names_it_and_the_channels_present() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("linear.exr");
    write_exr(&path, &Image::<f32, 3>::new(2, 2), ["S0", "S1", "S2"]).unwrap();
    let err = read_stokes(&path).unwrap_err();
    match &err {
        Error::MissingChannel {
            channel, present, ..
        } => {
            assert_eq!(channel, "S3");
            assert_eq!(present, &["S0", "S1", "S2"]);
        }
        other => panic!("expected MissingChannel, got {other}"),
    }
    assert!(err.to_string().contains("linear.exr"));
}

#[test]
fn tiled_and_half_float_files_are_readable() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("tiled.exr");
    let (w, h) = (70, 65); // not a multiple of the 64x64 tile size
    let y: Vec<f32> = (0..w * h).map(|i| i as f32 * 0.25).collect();
    let half: Vec<f16> = (0..w * h)
        .map(|i| f16::from_f32((i % 100) as f32))
        .collect();
    let l = layer(
        Encoding::FAST_LOSSLESS,
        (w, h),
        vec![
            ("Y", FlatSamples::F32(y.clone())),
            ("H", FlatSamples::F16(half)),
        ],
    );
    write_with_exr_crate(&path, vec![l]);
    let img: Image<f32, 2> = read_exr(&path, ["Y", "H"]).unwrap();
    assert_eq!(img.size(), (w, h));
    assert!(img.pixels().iter().zip(&y).all(|(p, &v)| p[0] == v));
    // Integers below 2048 are exact in f16.
    assert!(
        img.pixels()
            .iter()
            .enumerate()
            .all(|(i, p)| p[1] == (i % 100) as f32)
    );
}

#[test]
fn multi_layer_file_is_a_layer_count_error() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("layers.exr");
    let a = layer(
        Encoding::UNCOMPRESSED,
        (2, 2),
        vec![("Y", FlatSamples::F32(vec![0.0; 4]))],
    );
    let mut b = layer(
        Encoding::UNCOMPRESSED,
        (2, 2),
        vec![("Y", FlatSamples::F32(vec![1.0; 4]))],
    );
    b.attributes.layer_name = Some("second".into());
    write_with_exr_crate(&path, vec![a, b]);
    let err = read_exr_channel(&path, "Y").unwrap_err();
    assert!(matches!(err, Error::LayerCount { layers: 2, .. }), "{err}");
}

#[test]
fn missing_exr_is_not_found() {
    let err = read_exr_channel("/nonexistent/depth.exr", "Y").unwrap_err();
    assert!(matches!(err, Error::NotFound { .. }), "{err}");
    let err = exr_channel_names("/nonexistent/depth.exr").unwrap_err();
    assert!(matches!(err, Error::NotFound { .. }), "{err}");
}

#[test]
fn truncated_exr_is_corrupt() {
    let dir = tempfile::tempdir().unwrap();
    let good = dir.path().join("good.exr");
    write_exr(&good, &awkward_stokes(64, 48), STOKES_CHANNELS).unwrap();
    let bytes = std::fs::read(&good).unwrap();
    // Empty, inside the magic number, inside the header, in the pixel data, one byte short.
    for cut in [0, 3, 40, bytes.len() / 2, bytes.len() - 1] {
        let path = dir.path().join(format!("cut{cut}.exr"));
        std::fs::write(&path, &bytes[..cut]).unwrap();
        let err = read_stokes(&path).unwrap_err();
        assert!(
            matches!(err, Error::Corrupt { format: "EXR", .. }),
            "cut {cut}: {err}"
        );
    }
}

#[test]
fn exr_with_bad_magic_is_corrupt_and_no_byte_flip_panics() {
    let dir = tempfile::tempdir().unwrap();
    let good = dir.path().join("good.exr");
    write_exr(&good, &awkward_stokes(16, 16), STOKES_CHANNELS).unwrap();
    let bytes = std::fs::read(&good).unwrap();
    let path = dir.path().join("bad.exr");
    let mut bad = bytes.clone();
    bad[0] ^= 0xff;
    std::fs::write(&path, &bad).unwrap();
    assert!(matches!(read_stokes(&path), Err(Error::Corrupt { .. })));
    // Flip every 7th byte in turn: any result is fine except a panic (bad input must be an error).
    for pos in (0..bytes.len()).step_by(7) {
        let mut bad = bytes.clone();
        bad[pos] ^= 0xa5;
        std::fs::write(&path, &bad).unwrap();
        let _ = read_stokes(&path);
    }
}

#[test]
fn bad_channel_names_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("x.exr");
    let img = Image::<f32, 2>::new(2, 2);
    for names in [["A", "A"], ["A", ""], ["A", "\u{3b1}"]] {
        let err = write_exr(&path, &img, names).unwrap_err();
        assert!(
            matches!(err, Error::ChannelNames { .. }),
            "{names:?}: {err}"
        );
    }
    assert!(!path.exists());
}

#[test]
fn stokes_check_rejects_nan_inf_and_negative_s0() {
    let p = Path::new("stokes.exr");
    let good = Image::from_vec(2, 1, vec![1.0, 0.5, -0.5, 0.0, 0.0, 0.0, 0.0, 0.0]).unwrap();
    check_stokes(p, &good).unwrap();
    let cases = [
        (4, f32::NAN, "S0"),
        (5, f32::INFINITY, "S1"),
        (4, -1e-3, "S0"),
        (3, f32::NAN, "S3"),
    ];
    for (i, value, name) in cases {
        let mut bad = good.clone();
        bad.as_mut_slice()[i] = value;
        match check_stokes(p, &bad).unwrap_err() {
            Error::InvalidValue { channel, x, y, .. } => {
                assert_eq!((channel.as_str(), x, y), (name, i / 4, 0));
            }
            other => panic!("{other}"),
        }
    }
}

#[test]
fn rule_any_accepts_nan() {
    let img = Image::<f32, 2>::from_vec(1, 1, vec![f32::NAN, 1.0]).unwrap();
    check_channels(
        Path::new("x"),
        &img,
        ["DoLP", "Y"],
        [Rule::Any, Rule::Finite],
    )
    .unwrap();
    let err = check_channels(
        Path::new("x"),
        &img,
        ["DoLP", "Y"],
        [Rule::Finite, Rule::Finite],
    )
    .unwrap_err();
    assert!(err.to_string().contains("DoLP"), "{err}");
}
