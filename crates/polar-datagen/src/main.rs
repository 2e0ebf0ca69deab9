//! `polar-datagen`: reproducible synthetic polarization datasets (see `--help`).

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand};
use polar_datagen::demo::{check_sample_target, load_render_scene, run_demo};
use polar_datagen::progress::Progress;
use polar_datagen::run::{MAX_JOBS, RunOptions, Shard, prepare_output, run_suite};
use polar_datagen::sample::RenderWorker;
use polar_datagen::suite::{SizeName, Suite};
use polar_datagen::{Error, merge, store};
use polar_render::scene::{MAX_IMAGE_SIDE, MAX_SPP};

/// The allocator of the binaries (see the workspace Cargo.toml).
#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;

/// Make synthetic polarization-camera datasets with the polar-render path tracer.
///
/// Every sample directory holds meta.json, raw.png (16-bit DoFP mosaic, 90/45/135/0 layout),
/// stokes.exr (S0..S3), polarizers.exr (I0, I45, I90, I135, noiseless) and gt/ (normal.exr, depth.exr, material.png, transparent.png), as in
/// the project's conventions. Images are deterministic: the same suite and seed give
/// byte-identical images whatever --jobs or --shard.
///
/// Suite format: datasets-synth/suites/README.md. Clusters (Slurm job array, Kubernetes
/// Indexed Job): tools/datagen-cluster.md.
#[derive(Parser, Debug)]
#[command(name = "polar-datagen", version, about, long_about)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Render the built-in demo scene (plastic, gold, glass and textured objects; no files
    /// needed) into a sample directory DIR plus DIR/pictures/{s0,dolp,aolp}.png.
    Demo {
        /// Output sample directory (created; an earlier sample there is replaced).
        #[arg(long)]
        out: PathBuf,
        /// Image width and height in pixels (even).
        #[arg(long, default_value_t = 256, value_parser = even_size)]
        size: u32,
        /// Samples per pixel (at most 1048576).
        #[arg(long, default_value_t = 64, value_parser = spp_value)]
        spp: u32,
    },
    /// Render one scene file (polar-render TOML, `version = 1`) into a sample directory. The
    /// scene's optional [sensor] table sets full_well_e, read_noise_e, bits, shot_noise and
    /// extinction_ratio (defaults: an IMX250MZR-like 12-bit sensor).
    Render {
        /// The scene file.
        scene: PathBuf,
        /// Output sample directory (created; an earlier sample there is replaced).
        #[arg(long)]
        out: PathBuf,
        /// Samples per pixel, overriding the scene's (at most 1048576).
        #[arg(long, value_parser = spp_value)]
        spp: Option<u32>,
        /// Seed of the render and of the sensor noise, overriding the scene's.
        #[arg(long)]
        seed: Option<u64>,
    },
    /// Make (or resume) a dataset from a suite file (datasets-synth/suites/*.toml). A run
    /// killed at any moment can be started again with the same arguments: committed samples
    /// are kept (checksums verified), the rest are made. Writes DIR/<family>-<index>/ sample
    /// directories, DIR/manifest.jsonl (id, seed, parameters, sha256 of every file, timings),
    /// DIR/run.json and DIR/suite.toml.
    Suite {
        /// The suite file.
        suite: PathBuf,
        /// Output dataset directory (created; must be new or hold this same run).
        #[arg(long)]
        out: PathBuf,
        /// Make only shard K of N (1-based): samples whose global index i has i mod N = K-1.
        /// Run N jobs (e.g. a Slurm array or Kubernetes Indexed Job), then `merge` them.
        #[arg(long, default_value = "1/1")]
        shard: Shard,
        /// Samples rendered at once (0 = one per CPU; at most 1024).
        #[arg(long, default_value_t = 0)]
        jobs: usize,
        /// Which size of every family to make: `ci` (seconds) or `full`.
        #[arg(long, value_enum, default_value_t = SizeName::Ci)]
        size: SizeName,
        /// Plain progress lines even on a terminal (no bar).
        #[arg(long, conflicts_with = "quiet")]
        plain: bool,
        /// No progress output (the summary table is still printed).
        #[arg(long)]
        quiet: bool,
    },
    /// Join shard directories into one dataset, verifying every file's sha256 against its
    /// shard's manifest first, and that all N shards of one run are present and complete.
    Merge {
        /// The shard output directories.
        #[arg(required = true)]
        shards: Vec<PathBuf>,
        /// Output dataset directory (must not hold a dataset yet).
        #[arg(long)]
        out: PathBuf,
    },
}

fn even_size(s: &str) -> Result<u32, String> {
    match s.parse::<u32>() {
        Ok(v) if v >= 2 && v % 2 == 0 && v as usize <= MAX_IMAGE_SIDE => Ok(v),
        _ => Err(format!(
            "'{s}' must be an even number of pixels in 2..={MAX_IMAGE_SIDE}"
        )),
    }
}

fn spp_value(s: &str) -> Result<u32, String> {
    match s.parse::<u32>() {
        Ok(v) if (1..=MAX_SPP).contains(&v) => Ok(v),
        _ => Err(format!(
            "'{s}' must be a number of samples in 1..={MAX_SPP}"
        )),
    }
}

fn main() -> ExitCode {
    match run(Cli::parse()) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("polar-datagen: error: {e}");
            ExitCode::FAILURE
        }
    }
}

fn run(cli: Cli) -> Result<(), Error> {
    match cli.command {
        Command::Demo { out, size, spp } => {
            let model = run_demo(&out, size, size, spp)?;
            println!(
                "wrote {} ({model:?} transport); pictures in {}",
                out.display(),
                out.join(polar_io::files::vision::PICTURES).display()
            );
            Ok(())
        }
        Command::Render {
            scene,
            out,
            spp,
            seed,
        } => {
            let (s, noise) = load_render_scene(&scene, spp, seed)?;
            check_sample_target(&out)?;
            let record = serde_json::json!({ "file": scene.display().to_string(), "spp": s.settings.spp, "seed": s.settings.seed });
            let model = polar_datagen::demo::render_into(&out, &s, &noise, &record)?;
            println!("wrote {} ({model:?} transport)", out.display());
            Ok(())
        }
        Command::Suite {
            suite,
            out,
            shard,
            jobs,
            size,
            plain,
            quiet,
        } => {
            let text = std::fs::read_to_string(&suite).map_err(Error::io(&suite))?;
            let parsed = Suite::parse(&text).map_err(|message| Error::Suite {
                path: suite.clone(),
                message,
            })?;
            let progress = if quiet {
                Progress::Quiet
            } else if plain {
                Progress::Plain
            } else {
                Progress::Auto
            };
            let jobs = if jobs == 0 {
                std::thread::available_parallelism().map_or(1, |n| usize::from(n).min(MAX_JOBS))
            } else {
                jobs
            };
            let opts = RunOptions {
                out,
                size,
                shard,
                jobs,
                progress,
            };
            let _locked = prepare_output(&parsed, &text, &opts)?;
            let summary = run_suite(&parsed, &opts, &RenderWorker)?;
            print!("{}", summary.table());
            println!(
                "dataset: {} (manifest {})",
                opts.out.display(),
                opts.out.join(store::MANIFEST).display()
            );
            Ok(())
        }
        Command::Merge { shards, out } => {
            let n = merge::merge(&shards, &out)?;
            println!(
                "merged {} shards, {n} samples, checksums verified, into {}",
                shards.len(),
                out.display()
            );
            Ok(())
        }
    }
}
