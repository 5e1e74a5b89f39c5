//! One entry point per reader for fuzzing (issue #12): each takes arbitrary bytes, hands them
//! to the reader the way a user's file would arrive (through a file with the right extension
//! in a scratch folder, since the readers' rules — regular files only, references confined to
//! the folder — are part of what is tested), and ignores the result. A fuzzer finds panics,
//! aborts, hangs, leaks and oversized allocations; an `Err` is the correct outcome for most
//! inputs.
//!
//! ```
//! // Any bytes: an error, never a panic.
//! cross_crate_tests::fuzz::run("ply", b"ply\nformat ascii 1.0\nelement vertex 99999999999\n");
//! ```

use std::path::{Path, PathBuf};

/// The fuzzed readers, by target name (the `fuzz/fuzz_targets/*.rs` file names and the folders
/// of `fuzz/corpus/` and `fuzz/regressions/`).
pub const TARGETS: &[&str] = &[
    "ply",
    "obj",
    "obj_frames",
    "gltf",
    "glb",
    "npy",
    "pc2",
    "mdd",
    "hdr",
    "exr",
    "cpca",
    "btfpca",
    "btf_image",
    "scene_toml",
];

/// Runs the reader of `target` on `data`.
///
/// # Panics
/// For an unknown target name (a bug in the caller); and wherever the reader panics, which is
/// what fuzzing looks for.
pub fn run(target: &str, data: &[u8]) {
    match target {
        "ply" => mesh(data, "mesh.ply"),
        "obj" => mesh(data, "mesh.obj"),
        "obj_frames" => obj_frames(data),
        "gltf" => mesh(data, "scene.gltf"),
        "glb" => {
            mesh(data, "scene.glb");
            animation(data, "scene.glb");
        }
        "npy" => animation(data, "frames.npy"),
        "pc2" => animation(data, "cache.pc2"),
        "mdd" => animation(data, "cache.mdd"),
        "hdr" => environment(data, "sky.hdr"),
        "exr" => environment(data, "sky.exr"),
        "cpca" => {
            for bytes in [data, &resealed(data)] {
                let _ = anim_pca::Compressed::from_bytes(bytes).map(|c| {
                    // A valid container is decoded frame by frame, as `anim decompress` does.
                    let decoder = anim_pca::Decoder::new(&c);
                    let mut scratch = decoder.scratch();
                    let mut out = vec![glam::Vec3::ZERO; decoder.vertices()];
                    for f in 0..decoder.frames().min(4) {
                        let _ = decoder.frame_into(f, &mut out, &mut scratch);
                    }
                });
            }
        }
        "btfpca" => {
            for bytes in [data, &resealed(data)] {
                let _ = btf::BtfPca::from_bytes(bytes);
            }
        }
        "btf_image" => {
            for name in ["tl000 pl000 tv000 pv000.png", "tl000 pl000 tv000 pv000.exr"] {
                let path = scratch_file(name, data);
                let _ = btf::read_image(&path);
            }
        }
        "scene_toml" => {
            let text = String::from_utf8_lossy(data);
            if let Ok(scene) = cloth_vis::Scene::from_toml(&text, &scratch_dir(), "fuzz.toml") {
                let _ = scene.validate();
            }
        }
        other => panic!("unknown fuzz target {other:?}; the targets are {TARGETS:?}"),
    }
}

/// `data` with its last four bytes replaced by the CRC-32 of the rest: both containers end in
/// that checksum, which almost every mutation breaks, so without this the fuzzer would test the
/// checksum and little behind it (1 M executions on the raw bytes added 2 corpus entries).
fn resealed(data: &[u8]) -> Vec<u8> {
    let mut bytes = data.to_vec();
    if let Some(body) = bytes.len().checked_sub(4) {
        let crc = crc32fast::hash(&bytes[..body]);
        bytes[body..].copy_from_slice(&crc.to_le_bytes());
    }
    bytes
}

fn mesh(data: &[u8], name: &str) {
    let path = scratch_file(name, data);
    let _ = meshio::load_mesh(&path, &meshio::LoadOptions::default());
}

fn animation(data: &[u8], name: &str) {
    let path = scratch_file(name, data);
    let _ = meshio::load_animation(&path, &meshio::AnimationOptions::default());
}

fn environment(data: &[u8], name: &str) {
    let path = scratch_file(name, data);
    let _ = lightsphere::Environment::load(&path);
}

/// Two OBJ frames, split at the first `#---` line (or the whole input twice).
fn obj_frames(data: &[u8]) {
    let marker = b"\n#---\n";
    let (first, second) = match data.windows(marker.len()).position(|w| w == marker) {
        Some(at) => (&data[..at], &data[at + marker.len()..]),
        None => (data, data),
    };
    let dir = scratch_dir().join("frames");
    let _ = std::fs::create_dir_all(&dir);
    let _ = std::fs::write(dir.join("0001.obj"), first);
    let _ = std::fs::write(dir.join("0002.obj"), second);
    let _ = meshio::load_animation(&dir, &meshio::AnimationOptions::default());
}

/// A scratch folder of this process and thread (in memory where `/dev/shm` exists).
fn scratch_dir() -> PathBuf {
    let root = Path::new("/dev/shm");
    let root = if root.is_dir() {
        root.to_path_buf()
    } else {
        std::env::temp_dir()
    };
    let dir = root.join(format!(
        "cloth-vis-fuzz-{}-{:?}",
        std::process::id(),
        std::thread::current().id()
    ));
    let _ = std::fs::create_dir_all(&dir);
    dir
}

fn scratch_file(name: &str, data: &[u8]) -> PathBuf {
    let path = scratch_dir().join(name);
    std::fs::write(&path, data).expect("the scratch folder is writable");
    path
}
