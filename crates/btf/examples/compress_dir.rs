//! Compresses a BTF folder into a `.btfpca` file and reports time, size, memory and error.
//!
//! ```sh
//! cargo run --release -p btf --example compress_dir -- DIR OUT.btfpca [--components 16]
//!     [--generate 256] [--stats] [--storage u8|u16|f32] [--mean-storage u8|u16|f32]
//! ```
//!
//! `--generate RES` first writes a synthetic RES² BTF (H1) into DIR: a per-texel albedo with
//! hashed noise (so PNGs do not compress away), a view shift and max(l·n, 0), plus a lobe.

use std::path::PathBuf;
use std::time::Instant;

use anyhow::{Context, Result, bail};
use btf::{BtfDir, BtfPca, BtfPcaParams, Sampling, Storage, write_btf_dir};

fn hash(x: usize, y: usize, c: usize) -> f32 {
    let mut h = (x as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15)
        ^ (y as u64).wrapping_mul(0xC2B2_AE3D_27D4_EB4F)
        ^ (c as u64).wrapping_mul(0x1656_67B1_9E37_79F9);
    h ^= h >> 29;
    h = h.wrapping_mul(0xBF58_476D_1CE4_E5B9);
    h ^= h >> 32;
    (h % 1000) as f32 / 1000.0
}

fn generate(dir: &std::path::Path, res: usize) -> Result<()> {
    let s = Sampling::H1;
    let t = Instant::now();
    let progress = |done: usize, total: usize| {
        if done.is_multiple_of(729) {
            eprintln!("  wrote {done}/{total}");
        }
    };
    write_btf_dir(
        dir,
        s,
        res,
        |j, i| {
            let (v, l) = (s.vector(j), s.vector(i));
            let shift = (8.0 * v.x) as isize;
            (0..res * res)
                .map(|t| {
                    let (x, y) = (t % res, t / res);
                    let xs = (x as isize + shift).rem_euclid(res as isize) as usize;
                    let lobe = 0.3 * hash(xs, y, 9) * l.x.max(0.0) * l.y.abs();
                    [0, 1, 2].map(|c| {
                        (0.1 + 0.7 * hash(xs, y, c)) * l.z.max(0.0) * (1.0 + 0.2 * (1.0 - v.z))
                            + lobe
                    })
                })
                .collect()
        },
        Some(&progress),
    )?;
    eprintln!("generated {res}² BTF in {:.1} s", t.elapsed().as_secs_f64());
    Ok(())
}

fn peak_rss_mb() -> Option<f64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb / 1024.0)
}

fn main() -> Result<()> {
    atomic_out::remove_temporaries_on_signal()?;
    let mut args = std::env::args().skip(1);
    let (Some(dir), Some(out)) = (args.next(), args.next()) else {
        bail!(
            "usage: compress_dir DIR OUT.btfpca [--components C] [--generate RES] [--stats] [--storage u8|u16|f32] [--mean-storage u8|u16|f32]"
        );
    };
    let (dir, out) = (PathBuf::from(dir), PathBuf::from(out));
    let mut params = BtfPcaParams::default();
    let mut stats = false;
    while let Some(a) = args.next() {
        match a.as_str() {
            "--components" => params.components = args.next().context("--components C")?.parse()?,
            "--generate" => generate(&dir, args.next().context("--generate RES")?.parse()?)?,
            "--stats" => stats = true,
            "--mean-storage" => {
                params.mean_storage = match args.next().as_deref() {
                    Some("u8") => Storage::U8,
                    Some("u16") => Storage::U16,
                    Some("f32") => Storage::F32,
                    other => bail!("--mean-storage u8|u16|f32, got {other:?}"),
                }
            }
            "--storage" => {
                params.storage = match args.next().as_deref() {
                    Some("u8") => Storage::U8,
                    Some("u16") => Storage::U16,
                    Some("f32") => Storage::F32,
                    other => bail!("--storage u8|u16|f32, got {other:?}"),
                }
            }
            other => bail!("unknown argument {other}"),
        }
    }
    let t = Instant::now();
    let btf = BtfDir::open(&dir)?;
    println!(
        "open: {} {}×{} in {:.2} s",
        btf.sampling(),
        btf.width(),
        btf.height(),
        t.elapsed().as_secs_f64()
    );
    let (pca, report) = BtfPca::compress(&btf, &params)?;
    let load: f64 = report.slots.iter().map(|s| s.load_seconds).sum();
    let fit: f64 = report.slots.iter().map(|s| s.fit_seconds).sum();
    println!(
        "compress: c = {} (min kept {}), {:.1} s wall; per slot load {:.2} s, fit {:.2} s (summed over workers: {:.1} + {:.1} s)",
        report.requested,
        report.min_components(),
        report.seconds,
        load / 81.0,
        fit / 81.0,
        load,
        fit
    );
    pca.write(&out)?;
    let size = std::fs::metadata(&out)?.len();
    let raw = 6561u64 * 3 * (btf.width() * btf.height()) as u64;
    println!(
        "file: {} bytes = {:.1} MiB (raw 8-bit: {:.1} MiB, ratio {:.2})",
        size,
        size as f64 / 1048576.0,
        raw as f64 / 1048576.0,
        raw as f64 / size as f64
    );
    if let Some(mb) = peak_rss_mb() {
        println!("peak RSS after compression: {mb:.0} MiB");
    }
    if stats {
        let t = Instant::now();
        let e = pca.stats(&btf, None)?;
        println!(
            "stats over {} images: RMS {:.3} sRGB codes, PSNR {:.2} dB, max {:.1}, linear RMS {:.3} ({:.1} s)",
            e.images,
            e.rms_srgb8,
            e.psnr_db,
            e.max_abs_srgb8,
            e.rms_linear8,
            t.elapsed().as_secs_f64()
        );
        if let Some(mb) = peak_rss_mb() {
            println!("peak RSS after stats: {mb:.0} MiB");
        }
    }
    Ok(())
}
