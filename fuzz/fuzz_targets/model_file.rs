//! Fuzz target `model_file`: see `harness::MODEL_FILE`.

#![no_main]

#[allow(dead_code)] // each target uses one harness
#[path = "../harness.rs"]
mod harness;

libfuzzer_sys::fuzz_target!(|data: &[u8]| harness::check(&harness::MODEL_FILE, data));
