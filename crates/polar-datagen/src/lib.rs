//! Reproducible synthetic polarization datasets.
//!
//! A suite file ([`suite`]) lists families of samples; [`params`] draws every sample's
//! parameters from a seed, [`run`] makes a shard of them with any number of threads through a
//! [`run::SampleWorker`] ([`sample::RenderWorker`]: [`scene`] -> polar-render -> polar-sensor -> files,
//! or a stand-in in tests), committing each sample
//! directory atomically and recording it in `manifest.jsonl` ([`store`]); [`merge`] joins
//! shards after verifying every checksum.

pub mod demo;
mod error;
pub mod merge;
pub mod mesh;
pub mod params;
pub mod progress;
pub mod run;
pub mod sample;
pub mod scene;
pub mod store;
pub mod suite;

pub use error::Error;
