//! Time of material classification on a 1-megapixel frame, physics rule against kNN:
//! a sample's Stokes planes (stokes.exr) tiled to 1024x1024, no normals, timed over
//! three runs each (the median is printed), on all cores of the rayon pool.
//!
//! `cargo run --release -p polar-material --example knn_bench -- SAMPLE_DIR [MODEL]`
//! (MODEL: a model file; default the shipped one). Set RAYON_NUM_THREADS=2 for 2 cores.
//! Built with the binaries' allocator (mimalloc), as the times are what the CLI sees.

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Instant;

use polar_image::LinearStokesImage;
use polar_material::knn::{BUILTIN_MODEL, EXPECT, KnnClassifier};
use polar_material::{Classifier, MaterialOptions, classify};
use polar_optics::pixel_frame::CameraModel;
use polar_sensor::{Observation, StokesPlanes};

/// The binaries' allocator, so the times are what `polar-vision run` sees.
#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;

const SIDE: usize = 1024;

fn tiled(sample: &Path) -> Observation {
    let s: LinearStokesImage = polar_io::read_exr(
        sample.join(polar_io::files::STOKES),
        polar_io::LINEAR_STOKES_CHANNELS,
    )
    .expect("a sample directory with stokes.exr");
    let (w, h) = s.size();
    let mut big = LinearStokesImage::new(SIDE, SIDE);
    for y in 0..SIDE {
        for x in 0..SIDE {
            big.pixels_mut()[y * SIDE + x] = s.pixels()[(y % h) * w + x % w];
        }
    }
    Observation::new(
        StokesPlanes::from_linear_stokes(&big),
        CameraModel::Orthographic,
    )
}

fn median_seconds(obs: &Observation, clf: &Classifier) -> f64 {
    let mut t: Vec<f64> = (0..3)
        .map(|_| {
            let t0 = Instant::now();
            classify(obs, None, None, None, clf, &MaterialOptions::default()).expect("classify");
            t0.elapsed().as_secs_f64()
        })
        .collect();
    t.sort_by(f64::total_cmp);
    t[1]
}

fn main() {
    let args: Vec<PathBuf> = std::env::args_os().skip(1).map(PathBuf::from).collect();
    let sample = args.first().expect("usage: knn_bench SAMPLE_DIR [MODEL]");
    let knn = match args.get(1) {
        Some(p) => KnnClassifier::load(p, EXPECT),
        None => KnnClassifier::from_bytes(BUILTIN_MODEL, Path::new("builtin"), EXPECT),
    }
    .expect("a material model");
    let h = knn.model().header.clone();
    let obs = tiled(sample);
    println!(
        "| classifier | s per 1 MP ({} threads) |",
        rayon::current_num_threads()
    );
    println!("|---|---|");
    println!(
        "| physics rule | {:.3} |",
        median_seconds(&obs, &Classifier::Physics)
    );
    let clf = Classifier::Knn(Arc::new(knn));
    println!(
        "| kNN (k = {}, {} points) | {:.3} |",
        h.k,
        h.points,
        median_seconds(&obs, &clf)
    );
}
