//! Helpers of the subcommand tests.

use std::path::{Path, PathBuf};

/// The `cloth-vis` executable cargo built beside this test executable (`target/<profile>/`
/// holds it, `target/<profile>/deps/` this test; the way `assert_cmd::cargo_bin` finds it).
/// Cargo builds the binary for the package's integration tests before any test runs.
pub fn binary() -> PathBuf {
    let exe = std::env::current_exe().expect("the test executable has a path");
    let profile_dir = exe
        .parent()
        .and_then(Path::parent)
        .expect("test executables live in target/<profile>/deps");
    let path = profile_dir.join(format!("cloth-vis{}", std::env::consts::EXE_SUFFIX));
    assert!(
        path.is_file(),
        "{} is missing: run the tests with `cargo test -p cloth-vis`, which builds it",
        path.display()
    );
    path
}

/// Runs the `cloth-vis` binary with `args`.
pub fn cli(args: &[&str]) -> std::process::Output {
    std::process::Command::new(binary())
        .args(args)
        .output()
        .unwrap()
}

/// Runs the `cloth-vis` binary with `args` and the environment variables `envs` set.
pub fn cli_env(args: &[&str], envs: &[(&str, &str)]) -> std::process::Output {
    std::process::Command::new(binary())
        .args(args)
        .envs(envs.iter().copied())
        .output()
        .unwrap()
}

/// A path as a command-line argument.
pub fn text(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// An RGBA float EXR: width, height and the pixels row-major from the top.
pub fn read_exr_rgba(path: &Path) -> (usize, usize, Vec<[f32; 4]>) {
    let image = exr::prelude::read_first_rgba_layer_from_file(
        path,
        |size, _| {
            (
                size.width(),
                vec![[0.0f32; 4]; size.width() * size.height()],
            )
        },
        |(w, px), pos, (r, g, b, a): (f32, f32, f32, f32)| {
            px[pos.y() * *w + pos.x()] = [r, g, b, a]
        },
    )
    .unwrap();
    let size = image.layer_data.size;
    (
        size.width(),
        size.height(),
        image.layer_data.channel_data.pixels.1,
    )
}

/// The OBJ `obj` authored Z-up, written beside it as `z_up.obj`: every vertex (x, y, z) becomes
/// (x, −z, y), a quarter turn about +x that takes +y to +z.
pub fn z_up_copy(obj: &Path) -> PathBuf {
    let turned: String = std::fs::read_to_string(obj)
        .unwrap()
        .lines()
        .map(|line| match line.strip_prefix("v ") {
            Some(rest) => {
                let v: Vec<f32> = rest.split(' ').map(|t| t.parse().unwrap()).collect();
                format!("v {} {} {}\n", v[0], -v[2], v[1])
            }
            None => format!("{line}\n"),
        })
        .collect();
    let path = obj.with_file_name("z_up.obj");
    std::fs::write(&path, turned).unwrap();
    path
}
