//! The fuzz harnesses, one function per target, shared by the cargo-fuzz targets
//! (`fuzz/fuzz_targets/*.rs`) and the stable replay of their corpus (`tests/fuzz_corpus.rs`):
//! each feeds arbitrary bytes to one reader and checks that it returns `Ok` or an error naming
//! the file, never panics, and that the bytes it allocates stay under the target's bound.
//!
//! Included with `#[path]` by both crates, it installs a counting global allocator in the
//! binary that includes it.

#![allow(unsafe_code)] // the counting allocator: `GlobalAlloc` is an unsafe trait

use std::alloc::{GlobalAlloc, Layout, System};
use std::ffi::OsStr;
use std::io::Cursor;
use std::path::Path;
use std::sync::atomic::{AtomicUsize, Ordering};

use polar_io::{MAX_PIXELS, STOKES_CHANNELS, files};

/// One fuzz target: a name (also its corpus folder `fuzz/corpus/<name>`), the function that
/// feeds it bytes, and its allocation bound.
pub struct Target {
    /// The target's name.
    pub name: &'static str,
    /// Feeds `data` to the reader; panics only on a bug.
    pub run: fn(&[u8]),
    /// The most bytes the reader may hold at once for an input of `len` bytes.
    pub bound: fn(len: usize) -> usize,
}

/// Every target, in the order of `tools/fuzz.sh`.
pub const TARGETS: [Target; 10] = [
    PNG_MOSAIC,
    EXR_STOKES,
    SAMPLE,
    META_JSON,
    MANIFEST,
    SCENE,
    SUITE,
    VISION_RUN,
    MODEL_FILE,
    OBJECT_MASK,
];

const MIB: usize = 1 << 20;
/// Decoder state besides the pixels (zlib window, row and chunk buffers, reader buffers,
/// error strings): a generous constant.
const SLACK: usize = 64 * MIB;
/// Bytes a text format (JSON, TOML) may hold per input byte while parsing: a one-byte
/// value such as `0,` becomes a 32-byte `serde_json::Value` or TOML item, doubled while its
/// vector grows.
const TEXT_BYTES_PER_BYTE: usize = 128;

fn text_bound(len: usize) -> usize {
    SLACK + TEXT_BYTES_PER_BYTE * len
}

/// `raw.png` through `polar_io::read_mosaic_from`. Bound: 4 bytes per pixel of at most
/// `MAX_PIXELS` (the decoded 16-bit rows, then the same samples as `u16`), plus slack.
pub const PNG_MOSAIC: Target = Target {
    name: "png_mosaic",
    run: |data| {
        let path = Path::new(files::RAW);
        named(polar_io::read_mosaic_from(path, Cursor::new(data)), path);
    },
    bound: |_| 4 * MAX_PIXELS + SLACK,
};

/// `stokes.exr` through `polar_io::read_exr_from`. Bound: a file decodes to at most
/// `4 × MAX_PIXELS` float samples (`polar_io::MAX_EXR_SAMPLES`), 4 bytes each, copied once
/// into the interleaved image: 32 bytes per pixel of a 4-channel image, plus slack.
pub const EXR_STOKES: Target = Target {
    name: "exr_stokes",
    run: |data| {
        let path = Path::new(files::STOKES);
        let stokes: polar_io::Result<polar_image::StokesImage> =
            polar_io::read_exr_from(path, Cursor::new(data), STOKES_CHANNELS);
        named(stokes, path);
    },
    bound: |_| 2 * 4 * polar_io::MAX_EXR_SAMPLES + SLACK,
};

/// Files of a sample directory in the order the parts of a [`SAMPLE`] input fill them.
const SAMPLE_FILES: [&str; 5] = [
    files::META,
    files::RAW,
    files::STOKES,
    files::GT_MATERIAL,
    files::GT_DEPTH,
];

/// Separates the files of one [`SAMPLE`] or [`VISION_RUN`] input.
pub const PART_SEPARATOR: &[u8] = b"\n--POLAR-FUZZ-NEXT-FILE--\n";

/// A sample directory through `polar_io::read_sample`: the input is split at
/// [`PART_SEPARATOR`] into `meta.json`, `raw.png`, `stokes.exr`, `gt/material.png`,
/// `gt/depth.exr` (missing or empty parts are absent files). Bound: the sum of its readers'.
pub const SAMPLE: Target = Target {
    name: "sample",
    run: |data| {
        let dir = write_sample_dir(data, &SAMPLE_FILES);
        named(polar_io::read_sample(dir.path()), dir.path());
    },
    bound: |len| {
        let exr = 2 * 4 * polar_io::MAX_EXR_SAMPLES;
        2 * exr + 4 * MAX_PIXELS + MAX_PIXELS + text_bound(len)
    },
};

/// `meta.json` through `polar_io::parse_meta`. Bound: proportional to the input.
pub const META_JSON: Target = Target {
    name: "meta_json",
    run: |data| {
        let path = Path::new(files::META);
        named(polar_io::parse_meta(path, data), path);
    },
    bound: text_bound,
};

/// A dataset's `manifest.jsonl` through `polar_datagen::store::parse_manifest`. Bound:
/// proportional to the input.
pub const MANIFEST: Target = Target {
    name: "manifest",
    run: |data| {
        let path = Path::new(polar_datagen::store::MANIFEST);
        if let Ok(text) = std::str::from_utf8(data) {
            named(polar_datagen::store::parse_manifest(path, text), path);
        }
    },
    bound: text_bound,
};

/// A scene file through `polar_render::parse_scene`, in an empty temporary directory (so
/// relative mesh paths find nothing). Bound: proportional to the input, plus a height-fog
/// grid of `polar_render::medium::MAX_DENSITY_CELLS` f64 values (twice: built, then moved into place)
/// and, for every 32 bytes of input (shorter than any shape table asking for a fine
/// tessellation), one built-in mesh at `polar_render::shapes::MAX_SEGMENTS`.
pub const SCENE: Target = Target {
    name: "scene",
    run: |data| {
        let dir = tempfile::tempdir().expect("temp dir");
        let path = dir.path().join("scene.toml");
        if let Ok(text) = std::str::from_utf8(data) {
            named(polar_render::parse_scene(text, &path), &path);
        }
    },
    bound: |len| {
        let fog = 2 * 8 * polar_render::medium::MAX_DENSITY_CELLS;
        text_bound(len) + fog + (1 + len / 32) * max_mesh_bytes()
    },
};

/// Bytes of the finest built-in mesh: `2s × s` quads for `s = MAX_SEGMENTS`, each with a
/// vertex (position, normal: 24 bytes each; uv: 16) and two triangles (12 bytes each), times
/// 3 for vector growth and the transformed copy.
fn max_mesh_bytes() -> usize {
    let s = polar_render::shapes::MAX_SEGMENTS as usize;
    3 * (2 * s + 1) * (s + 1) * (24 + 24 + 16 + 2 * 12)
}

/// A dataset suite file through `polar_datagen::suite::Suite::parse` (its errors name no
/// file: `Suite::load` adds it). Bound: proportional to the input.
pub const SUITE: Target = Target {
    name: "suite",
    run: |data| {
        if let Ok(text) = std::str::from_utf8(data) {
            let _ = polar_datagen::suite::Suite::parse(text);
        }
    },
    bound: text_bound,
};

/// Files of a sample directory in the order the parts of a [`VISION_RUN`] input fill them.
const VISION_FILES: [&str; 3] = [files::META, files::RAW, files::STOKES];

/// `polar-vision run` (every task, one thread) on a sample directory made of the input as
/// for [`SAMPLE`]: `meta.json`, `raw.png`, `stokes.exr`. Bound: the sample's readers' plus
/// 1 KiB per pixel for the tasks' planes (shape from polarization, material, transparency
/// and dehazing each hold a few dozen float planes).
pub const VISION_RUN: Target = Target {
    name: "vision_run",
    run: |data| {
        let dir = write_sample_dir(data, &VISION_FILES);
        let out = dir.path().join("out");
        let args = [
            OsStr::new("polar-vision"),
            OsStr::new("run"),
            dir.path().as_os_str(),
            OsStr::new("--out"),
            out.as_os_str(),
            OsStr::new("--threads"),
            OsStr::new("1"),
        ];
        named(polar_vision::cli::run_cli(args), dir.path());
    },
    bound: |len| (SAMPLE.bound)(len) + 1024 * MAX_PIXELS,
};

/// A material model file (`--material-model FILE`) through `KnnClassifier::from_bytes`: the
/// header is checked, then the k-d tree built. Bound: the reader checks the file's length
/// against the header's counts before allocating, so the points and labels are at most the
/// file's size; the JSON header as text, and the tree (points plus an index and bucket
/// overhead per point) a few times the points.
pub const MODEL_FILE: Target = Target {
    name: "model_file",
    run: |data| {
        let path = Path::new("material-knn.bin");
        named(
            polar_material::knn::KnnClassifier::from_bytes(data, path, polar_material::knn::EXPECT),
            path,
        );
    },
    bound: |len| text_bound(len) + 8 * len,
};

/// The frame an [`OBJECT_MASK`] input goes with: the size of the seed dataset's images
/// (`tools/fuzz.sh seed`), so that most of the corpus decodes.
const MASK_FRAME: (usize, usize) = (16, 16);

/// An object mask (`polar-vision run --objects FILE`) through `polar_io::read_mask_png_from`,
/// which takes a PNG of any colour type and bit depth of the frame's size
/// ([`MASK_FRAME`]). Bound: the rows expanded to at most 8 bytes per pixel (16-bit RGBA)
/// of the frame, then the mask's byte per pixel, plus slack: a header of another size is
/// refused before any pixel buffer exists.
pub const OBJECT_MASK: Target = Target {
    name: "object_mask",
    run: |data| {
        let path = Path::new("objects.png");
        let mask = polar_io::read_mask_png_from(path, Cursor::new(data), MASK_FRAME);
        named(mask, path);
    },
    bound: |_| 9 * MASK_FRAME.0 * MASK_FRAME.1 + SLACK,
};

/// Runs `target` on `data` and asserts its allocation bound.
pub fn check(target: &Target, data: &[u8]) {
    let peak = peak_bytes(|| (target.run)(data));
    let bound = (target.bound)(data.len());
    assert!(
        peak <= bound,
        "{}: peak allocation {peak} bytes for a {}-byte input, above the bound {bound}",
        target.name,
        data.len()
    );
}

/// Asserts that an error names `path` (the user must learn which file is bad).
fn named<T, E: std::fmt::Display>(result: Result<T, E>, path: &Path) {
    if let Err(e) = result {
        let text = e.to_string();
        let name = path.file_name().expect("file name").to_string_lossy();
        assert!(
            text.contains(&*name) || text.contains(&*path.to_string_lossy()),
            "error does not name {}: {text}",
            path.display()
        );
    }
}

/// A temporary sample directory whose files `names` hold the parts of `data` split at
/// [`PART_SEPARATOR`]; an empty or missing part leaves its file out.
fn write_sample_dir(data: &[u8], names: &[&str]) -> tempfile::TempDir {
    let dir = tempfile::tempdir().expect("temp dir");
    std::fs::create_dir(dir.path().join("gt")).expect("gt dir");
    for (name, part) in names.iter().zip(split_parts(data)) {
        if !part.is_empty() {
            std::fs::write(dir.path().join(name), part).expect("write part");
        }
    }
    dir
}

/// `data` split at every [`PART_SEPARATOR`].
pub fn split_parts(data: &[u8]) -> Vec<&[u8]> {
    let mut parts = Vec::new();
    let mut rest = data;
    while let Some(i) = rest
        .windows(PART_SEPARATOR.len())
        .position(|w| w == PART_SEPARATOR)
    {
        parts.push(&rest[..i]);
        rest = &rest[i + PART_SEPARATOR.len()..];
    }
    parts.push(rest);
    parts
}

/// Bytes currently allocated through the global allocator, and the most since the last reset.
static CURRENT: AtomicUsize = AtomicUsize::new(0);
static PEAK: AtomicUsize = AtomicUsize::new(0);

/// The system allocator, counting the bytes it hands out.
pub struct Counting;

#[global_allocator]
static ALLOCATOR: Counting = Counting;

fn grew(bytes: usize) {
    let now = CURRENT.fetch_add(bytes, Ordering::Relaxed) + bytes;
    PEAK.fetch_max(now, Ordering::Relaxed);
}

fn shrank(bytes: usize) {
    CURRENT.fetch_sub(bytes, Ordering::Relaxed);
}

// SAFETY: every method forwards to `System` unchanged; the counters only observe sizes.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        // SAFETY: same contract as ours.
        let p = unsafe { System.alloc(layout) };
        if !p.is_null() {
            grew(layout.size());
        }
        p
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        // SAFETY: same contract as ours.
        let p = unsafe { System.alloc_zeroed(layout) };
        if !p.is_null() {
            grew(layout.size());
        }
        p
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: same contract as ours.
        unsafe { System.dealloc(ptr, layout) };
        shrank(layout.size());
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        // SAFETY: same contract as ours.
        let p = unsafe { System.realloc(ptr, layout, new_size) };
        if !p.is_null() {
            grew(new_size);
            shrank(layout.size());
        }
        p
    }
}

/// The most bytes held at once while `f` ran, above what was held when it started.
/// Allocations of other threads count too, so callers run one measurement at a time.
pub fn peak_bytes(f: impl FnOnce()) -> usize {
    let base = CURRENT.load(Ordering::Relaxed);
    PEAK.store(base, Ordering::Relaxed);
    f();
    PEAK.load(Ordering::Relaxed).saturating_sub(base)
}
