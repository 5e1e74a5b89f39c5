//! Locates the real data in `../shared/data` for tests and benchmarks.
//!
//! The project's rule: a test that needs `../shared/data` (or a GPU adapter) **fails** when the
//! `CI` environment variable is set, and **skips with a printed warning** otherwise, so that a
//! user's fresh clone passes and CI tests everything.
//!
//! The data root is `$CLOTH_VIS_DATA` when set, else `<workspace>/../shared/data`.
//!
//! ```
//! // In a test: returns None (after printing a warning) when the file is absent and CI is unset.
//! if let Some(path) = test_data::shared_file("meshes/bun_zipper.ply") {
//!     assert!(path.is_file());
//! }
//! ```

use std::path::PathBuf;

/// Environment variable that overrides the data root.
pub const DATA_ENV: &str = "CLOTH_VIS_DATA";

/// True when running under CI (`CI` set to anything but `""`, `0` or `false`).
pub fn in_ci() -> bool {
    std::env::var("CI").is_ok_and(|v| !v.is_empty() && v != "0" && !v.eq_ignore_ascii_case("false"))
}

/// The root of the shared data, whether or not it exists.
pub fn data_root() -> PathBuf {
    if let Ok(dir) = std::env::var(DATA_ENV) {
        return PathBuf::from(dir);
    }
    // crates/test-data -> workspace root -> ../shared/data
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data")
}

/// Path of `relative` under the shared data root if it exists.
///
/// # Panics
/// When the path is missing and [`in_ci`] is true: CI must test everything.
/// Otherwise a missing path prints a warning to stderr and returns `None`.
#[track_caller]
pub fn shared_file(relative: &str) -> Option<PathBuf> {
    let path = data_root().join(relative);
    if path.exists() {
        return Some(path);
    }
    skip(&format!("shared data file {} not found", path.display()))
}

/// Skips so far in this test binary.
static SKIPS: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);

/// Report that a test cannot run for `reason` (missing data or GPU adapter).
///
/// The message goes to the process's stderr handle directly, not through `eprintln!`: libtest
/// captures the macros' output of passing tests, so a skip printed with them never reaches the
/// terminal and "N passed" would hide tests that did nothing.
///
/// # Panics
/// When [`in_ci`] is true. Otherwise prints
/// `SKIPPED (n in this binary): <caller>: <reason>` to stderr and returns `None`.
#[track_caller]
pub fn skip<T>(reason: &str) -> Option<T> {
    use std::io::Write;
    let caller = std::panic::Location::caller();
    if in_ci() {
        panic!("{caller}: {reason} (CI is set, so this test must not be skipped)");
    }
    let n = SKIPS.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
    // One write of the whole line, so it does not interleave with libtest's own lines; a
    // failed write to stderr leaves nothing better to report to.
    let line = format!(
        "SKIPPED ({n} in this binary): {caller}: {reason} (set CI=1 to make this a failure)\n"
    );
    let _ = std::io::stderr().lock().write_all(line.as_bytes());
    None
}

/// How many tests of this binary have skipped so far.
pub fn skipped_so_far() -> usize {
    SKIPS.load(std::sync::atomic::Ordering::Relaxed)
}

/// Creates a FIFO (named pipe) at `path` with the system's `mkfifo`, for the tests that check
/// a reader refuses it instead of blocking on it (issue #12). Unix only.
///
/// # Panics
/// When `mkfifo` cannot run or fails: the test cannot do what it means to.
#[cfg(unix)]
pub fn make_fifo(path: &std::path::Path) {
    let status = std::process::Command::new("mkfifo")
        .arg(path)
        .status()
        .expect("mkfifo runs");
    assert!(status.success(), "mkfifo {} failed", path.display());
}

/// Environment variable naming the `node_modules` folder that holds the npm package
/// `gltf-validator` (default: `<workspace>/target/gltf-validator/node_modules`, where `.ci/run`
/// installs it with `npm install --prefix target/gltf-validator gltf-validator`).
pub const GLTF_VALIDATOR_ENV: &str = "GLTF_VALIDATOR_MODULES";

/// The Khronos glTF validator's verdict on a file.
#[derive(Clone, Debug)]
pub struct GltfValidation {
    /// Whether it reported no error.
    pub ok: bool,
    /// Its one-line JSON summary: `{"errors":…,"warnings":…,"infos":…,"hints":…,"messages":[…]}`.
    pub summary: String,
}

/// The folder of the npm packages the tests use (`.ci/run` installs them under
/// `target/gltf-validator`; [`GLTF_VALIDATOR_ENV`] overrides it).
fn node_modules() -> PathBuf {
    std::env::var(GLTF_VALIDATOR_ENV).map_or_else(
        |_| {
            PathBuf::from(env!("CARGO_MANIFEST_DIR"))
                .join("../../target/gltf-validator/node_modules")
        },
        PathBuf::from,
    )
}

/// Runs `js/SCRIPT` on `path` with node, the npm package `package` required in
/// [`node_modules`]; `None` (after [`skip`]) when the package or node is missing.
#[track_caller]
fn run_node_script(
    script: &str,
    package: &str,
    path: &std::path::Path,
) -> Option<std::process::Output> {
    let modules = node_modules();
    if !modules.join(package).is_dir() {
        return skip(&format!(
            "the npm package {package} is not installed in {} (npm install --prefix target/gltf-validator {package})",
            modules.display()
        ));
    }
    let script = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("js")
        .join(script);
    match std::process::Command::new("node")
        .arg(&script)
        .arg(path)
        .env("NODE_PATH", &modules)
        .output()
    {
        Ok(output) => Some(output),
        Err(e) => skip(&format!("node cannot run ({e}); install Node.js")),
    }
}

/// Runs the Khronos glTF validator (node + the npm package `gltf-validator`) on `path`.
///
/// # Panics
/// When node or the package is missing and [`in_ci`] is true (through [`skip`]), or when node
/// cannot run the validator at all. Otherwise a missing validator prints a warning and returns
/// `None`.
#[track_caller]
pub fn validate_gltf(path: &std::path::Path) -> Option<GltfValidation> {
    let output = run_node_script("validate-gltf.cjs", "gltf-validator", path)?;
    let summary = String::from_utf8_lossy(&output.stdout).trim().to_owned();
    assert!(
        matches!(output.status.code(), Some(0 | 1)),
        "the validator failed on {}: {}",
        path.display(),
        String::from_utf8_lossy(&output.stderr)
    );
    Some(GltfValidation {
        ok: output.status.success(),
        summary,
    })
}

/// Runs gltfpack (meshoptimizer's glTF packer, the npm package `gltfpack`, installed beside the
/// validator by `.ci/run`) with `args`; `Some(())` when it succeeded.
///
/// # Panics
/// When gltfpack is missing and [`in_ci`] is true (through [`skip`]), or when it runs and
/// fails: the test cannot do what it means to.
#[track_caller]
pub fn gltfpack(args: &[&std::ffi::OsStr]) -> Option<()> {
    let modules = node_modules();
    let cli = modules.join("gltfpack/cli.js");
    if !cli.is_file() {
        return skip(&format!(
            "gltfpack is not installed in {} (npm install --prefix target/gltf-validator gltfpack)",
            modules.display()
        ));
    }
    let output = match std::process::Command::new("node")
        .arg(&cli)
        .args(args)
        .output()
    {
        Ok(output) => output,
        Err(e) => return skip(&format!("node cannot run ({e}); install Node.js")),
    };
    assert!(
        output.status.success(),
        "gltfpack {args:?} failed: {}",
        String::from_utf8_lossy(&output.stderr)
    );
    Some(())
}

/// Decodes every meshopt-compressed buffer view (either extension) of the `.glb` at `path`
/// with meshoptimizer's own decoder (the npm package `meshoptimizer`, installed beside the
/// validator by `.ci/run`): (view index, its `count × byteStride` decoded bytes) per view.
///
/// # Panics
/// When the package is missing and [`in_ci`] is true (through [`skip`]), or when the decoder
/// fails on the file.
#[track_caller]
pub fn meshopt_reference_decode(path: &std::path::Path) -> Option<Vec<(usize, Vec<u8>)>> {
    let output = run_node_script("meshopt-decode.cjs", "meshoptimizer", path)?;
    assert!(
        output.status.success(),
        "meshoptimizer's decoder failed on {}: {}",
        path.display(),
        String::from_utf8_lossy(&output.stderr)
    );
    let views: Vec<serde_json::Value> = serde_json::from_slice(&output.stdout)
        .unwrap_or_else(|e| panic!("the reference decoder's output is not JSON: {e}"));
    Some(
        views
            .iter()
            .map(|v| {
                let view = v["view"].as_u64().expect("view index") as usize;
                let bytes = base64_decode(v["bytes"].as_str().expect("base64 bytes"));
                (view, bytes)
            })
            .collect(),
    )
}

/// Standard base64 (with padding) to bytes.
fn base64_decode(text: &str) -> Vec<u8> {
    let value = |c: u8| match c {
        b'A'..=b'Z' => u32::from(c - b'A'),
        b'a'..=b'z' => u32::from(c - b'a') + 26,
        b'0'..=b'9' => u32::from(c - b'0') + 52,
        b'+' => 62,
        b'/' => 63,
        _ => panic!("not base64: {c}"),
    };
    let mut out = Vec::with_capacity(text.len() / 4 * 3);
    for group in text.as_bytes().chunks(4) {
        let data: Vec<u8> = group.iter().copied().filter(|&c| c != b'=').collect();
        let bits = data
            .iter()
            .enumerate()
            .fold(0u32, |acc, (k, &c)| acc | value(c) << (18 - 6 * k));
        out.extend(&bits.to_be_bytes()[1..data.len()]);
    }
    out
}
