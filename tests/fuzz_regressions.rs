//! Replays every input under `fuzz/regressions/<target>/` through its reader (issue #12): the
//! inputs that once crashed, hung or over-allocated (the probe's findings, then the fuzzers').
//! Plain `cargo test`, no fuzzer needed; a panic here is a regression. Each target must keep
//! at least one input, so that a renamed folder cannot silently empty the test.

use std::path::PathBuf;

use cross_crate_tests::fuzz::{TARGETS, run};

fn regressions() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("..")
        .join("fuzz")
        .join("regressions")
}

#[test]
fn every_regression_input_is_an_error_or_a_result_not_a_crash() {
    let root = regressions();
    let mut replayed = 0;
    for target in TARGETS {
        let dir = root.join(target);
        let mut inputs: Vec<PathBuf> = std::fs::read_dir(&dir)
            .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
            .map(|e| e.unwrap().path())
            .filter(|p| p.is_file())
            .collect();
        inputs.sort();
        assert!(!inputs.is_empty(), "{} holds no input", dir.display());
        for input in inputs {
            let data = std::fs::read(&input).unwrap();
            eprintln!("replaying {}", input.display());
            run(target, &data);
            replayed += 1;
        }
    }
    assert!(replayed >= TARGETS.len());
}

#[test]
fn every_folder_of_regressions_is_a_target() {
    for entry in std::fs::read_dir(regressions()).unwrap() {
        let name = entry.unwrap().file_name().to_string_lossy().into_owned();
        assert!(
            TARGETS.contains(&name.as_str()),
            "fuzz/regressions/{name} is not a fuzz target ({TARGETS:?})"
        );
    }
}
