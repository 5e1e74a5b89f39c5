//! Simulates the default drape and renders the default sky, and writes files to look at:
//!
//! ```text
//! cargo run --release -p synth --example drape -- OUT_DIR
//! ```
//!
//! * `OUT_DIR/cloth_last.obj`: the last frame of the cloth (positions, uvs, smooth normals);
//! * `OUT_DIR/cloth_frame_NNN.obj` for every 30th frame;
//! * `OUT_DIR/sphere.obj`: the obstacle;
//! * `OUT_DIR/sky.pfm`: the HDR sky (little-endian PFM, bottom row first as PFM wants).

use glam::Vec3;
use std::error::Error;
use std::fmt::Write as _;
use std::path::PathBuf;
use synth::{ClothAnimation, ClothParams, LatLongImage, SkyParams};

fn main() -> Result<(), Box<dyn Error>> {
    atomic_out::remove_temporaries_on_signal()?;
    let Some(out_dir) = std::env::args_os().nth(1).map(PathBuf::from) else {
        return Err("usage: drape OUT_DIR".into());
    };
    std::fs::create_dir_all(&out_dir)?;

    let params = ClothParams::default();
    let start = std::time::Instant::now();
    let mut last_reported = 0;
    let anim = synth::simulate_cloth_with_progress(&params, &mut |done, total| {
        if done * 10 / total > last_reported {
            last_reported = done * 10 / total;
            eprint!("\rsimulating: {done}/{total} frames");
        }
    })?;
    eprintln!(
        "\r{} vertices × {} frames simulated in {:.2?}",
        anim.vertex_count(),
        anim.frame_count(),
        start.elapsed()
    );
    for frame in (0..anim.frame_count()).step_by(30) {
        atomic_out::write_bytes(
            &out_dir.join(format!("cloth_frame_{frame:03}.obj")),
            &cloth_obj(&anim, frame),
        )?;
    }
    atomic_out::write_bytes(
        &out_dir.join("cloth_last.obj"),
        &cloth_obj(&anim, anim.frame_count() - 1),
    )?;
    let (positions, triangles) = synth::obstacle_mesh(&anim.obstacle, 4);
    atomic_out::write_bytes(
        &out_dir.join("sphere.obj"),
        &mesh_obj(&positions, &triangles).into_bytes(),
    )?;

    let start = std::time::Instant::now();
    let image = synth::sky(&SkyParams::default())?;
    eprintln!(
        "{}×{} sky rendered in {:.2?}",
        image.width,
        image.height,
        start.elapsed()
    );
    atomic_out::write_bytes(&out_dir.join("sky.pfm"), &pfm(&image))?;
    eprintln!("wrote {}", out_dir.display());
    Ok(())
}

fn cloth_obj(anim: &ClothAnimation, frame: usize) -> Vec<u8> {
    let positions = &anim.frames[frame];
    let mut normals = vec![Vec3::ZERO; positions.len()];
    for t in &anim.triangles {
        let [a, b, c] = t.map(|v| positions[v as usize]);
        let area_normal = (b - a).cross(c - a);
        for v in t {
            normals[*v as usize] += area_normal;
        }
    }
    let mut s = String::new();
    for p in positions {
        let _ = writeln!(s, "v {} {} {}", p.x, p.y, p.z);
    }
    for uv in &anim.uvs {
        let _ = writeln!(s, "vt {} {}", uv.x, uv.y);
    }
    for n in &normals {
        let n = n.normalize_or_zero();
        let _ = writeln!(s, "vn {} {} {}", n.x, n.y, n.z);
    }
    for t in &anim.triangles {
        let [a, b, c] = t.map(|v| v + 1);
        let _ = writeln!(s, "f {a}/{a}/{a} {b}/{b}/{b} {c}/{c}/{c}");
    }
    s.into_bytes()
}

fn mesh_obj(positions: &[Vec3], triangles: &[[u32; 3]]) -> String {
    let mut s = String::new();
    for p in positions {
        let _ = writeln!(s, "v {} {} {}", p.x, p.y, p.z);
    }
    for t in triangles {
        let _ = writeln!(s, "f {} {} {}", t[0] + 1, t[1] + 1, t[2] + 1);
    }
    s
}

/// Portable float map: header, then rows bottom to top, little-endian RGB f32.
fn pfm(image: &LatLongImage) -> Vec<u8> {
    let mut bytes = format!("PF\n{} {}\n-1.0\n", image.width, image.height).into_bytes();
    for row in (0..image.height).rev() {
        for texel in &image.texels[row * image.width..(row + 1) * image.width] {
            for c in texel {
                bytes.extend_from_slice(&c.to_le_bytes());
            }
        }
    }
    bytes
}
