//! Fuzz target `meta_json`: see `harness::META_JSON`.

#![no_main]

#[allow(dead_code)] // each target uses one harness
#[path = "../harness.rs"]
mod harness;

libfuzzer_sys::fuzz_target!(|data: &[u8]| harness::check(&harness::META_JSON, data));
