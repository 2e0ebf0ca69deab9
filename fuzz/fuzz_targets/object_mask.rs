//! Fuzz target `object_mask`: see `harness::OBJECT_MASK`.

#![no_main]

#[allow(dead_code)] // each target uses one harness
#[path = "../harness.rs"]
mod harness;

libfuzzer_sys::fuzz_target!(|data: &[u8]| harness::check(&harness::OBJECT_MASK, data));
