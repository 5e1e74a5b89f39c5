//! Cross-crate tests live in this package's `[[test]]` targets. The library holds one thing:
//! the fuzzing entry points ([`fuzz`]), shared by the `cargo-fuzz` targets in `fuzz/` (outside
//! the workspace) and by the plain `cargo test` that replays `fuzz/regressions/` in CI.

pub mod fuzz;
