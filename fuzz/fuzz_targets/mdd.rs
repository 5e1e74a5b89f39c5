//! Fuzz target `mdd`: arbitrary bytes through the reader (see `cross_crate_tests::fuzz`).
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| cross_crate_tests::fuzz::run("mdd", data));
