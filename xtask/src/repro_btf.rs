//! `cargo xtask repro btf`: per-view PCA compression of BTFs (thesis §5.4, Figs. 5.7/5.8) and
//! the linear basis decompositions of §2.1.12 side by side (Fig. 2.22), on the synthetic woven
//! BTF of `synth` (default parameters, H1 sampling).
//!
//! 1. **Full size** (skipped with `--quick`): the 81 × 81 BTF at 256² is written as PNGs in the
//!    UBO2003 naming and compressed from the folder by [`BtfPca::compress`] at c = 16 (the
//!    path of `crates/btf/examples/compress_dir.rs`): wall time, peak memory (VmHWM of the
//!    whole process, read before anything larger is allocated), `.btfpca` size, and the error
//!    on a fixed subset of 729 images. Rendered with one sample per texel: the compression
//!    does not depend on it, the rendering time does (4×).
//! 2. **Comparison** at 128² (Fig. 2.22): FMF, PCMF and PVMF from [`btf::compare`], with
//!    memory at the method's storage and in f32, error over all 6,561 images and time, and
//!    the memory the same parameters take at 256² by the formulas.
//! 3. **c sweep** at 128² (Figs. 5.7/5.8) on H1 and H2: error, compression time and `.btfpca`
//!    size for c ∈ [`SWEEP_C`]; eigenvalue decay λ_k/λ_1 of three view slots (Fig. 5.8's
//!    directions); a Fig. 5.7 panel of one 128² normtexture at c = 16, 10, 5 with difference
//!    images.
//!
//! Writes `target/repro/btf.md`, `btf-error.svg`, `btf-eigenvalues.svg` and `btf-fig5.7.png`.

use std::fmt::Write as _;
use std::path::Path;
use std::time::Instant;

use anyhow::Context as _;
use btf::compare::{
    AbrdfMatrix, Compared, FmfParams, MethodParams, PcmfParams, Reconstruction, compare, pvmf,
    pvmf_bytes, pvmf_stats, texel_model_bytes,
};
use btf::{
    BtfDir, BtfPca, BtfPcaParams, DIRECTIONS, Sampling, SlotPca, Storage, ViewSlot, linear_to_srgb,
    write_btf_view,
};
use figures::chart::{Axis, Series, chart_svg};
use synth::{WovenBtf, WovenBtfParams};

/// Resolution of the full-size timing (the thesis's and the 256²).
const FULL_RES: usize = 256;
/// Resolution of the FMF/PCMF/PVMF comparison.
const COMPARE_RES: usize = 128;
/// Resolution of the c sweep (the comparison's H1 matrix is reused).
const SWEEP_RES: usize = 128;
/// Component counts of the c sweep (Figs. 5.7/5.8).
const SWEEP_C: [usize; 8] = [1, 2, 4, 8, 12, 16, 24, 32];
/// Eigenvalues drawn per slot (Fig. 5.8).
const EIGEN_K: usize = 32;
/// Components of Fig. 5.7's reconstructions.
const PANEL_C: [usize; 3] = [16, 10, 5];
/// Difference images: the length of the 8-bit sRGB error vector at which the colour is fully
/// red (green = 0). The thesis's Fig. 5.7 uses 255; the woven BTF's errors are a few codes,
/// which 255 would leave uniformly green.
const DIFF_RED: f32 = 32.0;
/// Pixels per texel in the Fig. 5.7 panel.
const PANEL_ZOOM: usize = 2;
/// Pixels between the panel's tiles.
const PANEL_GAP: usize = 4;
/// The targets for the full-size compression.
const TARGET_SECONDS: f64 = 60.0;
const TARGET_MIB: f64 = 3072.0;

const MIB: f64 = 1024.0 * 1024.0;

/// Fig. 5.8's view slots (θ, φ) for a sampling: the thesis's (0°, 0°), (45°, 300°),
/// (75°, 45°) on H2, and the same rings on H1 (θ = 51°, 85°).
fn fig58_slots(s: Sampling) -> [(u32, u32); 3] {
    let t = s.ring_thetas();
    [(0, 0), (t[3], 300), (t[5], 45)]
}

fn woven(res: usize, supersample: usize) -> anyhow::Result<WovenBtf> {
    Ok(WovenBtf::new(&WovenBtfParams {
        res,
        supersample,
        ..Default::default()
    })?)
}

/// View slot j of the woven BTF, rendered in memory.
fn render_slot(w: &WovenBtf, s: Sampling, j: usize) -> btf::Result<ViewSlot> {
    let hits = w
        .view(s.vector(j))
        .expect("every sampled view is ≥ 5° above the horizon");
    let data = (0..DIRECTIONS)
        .flat_map(|i| hits.shade(s.vector(i)))
        .flatten()
        .collect();
    ViewSlot::new(j, w.res(), w.res(), data)
}

fn matrix(s: Sampling, res: usize) -> anyhow::Result<AbrdfMatrix> {
    let t = Instant::now();
    let w = woven(res, WovenBtfParams::default().supersample)?;
    let progress = |d: usize, n: usize| {
        if d.is_multiple_of(27) {
            eprintln!("  rendered {d}/{n} view slots");
        }
    };
    let m = AbrdfMatrix::from_slots(s, res, res, |j| render_slot(&w, s, j), Some(&progress))?;
    eprintln!(
        "{res}² {s} BTF rendered in {:.1} s ({:.0} MB of 8-bit codes)",
        t.elapsed().as_secs_f64(),
        m.bytes() as f64 / 1e6
    );
    Ok(m)
}

/// A field of /proc/self/status in MiB (Linux), e.g. "VmHWM" (peak resident memory).
fn proc_status_mib(field: &str) -> Option<f64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with(field))?;
    let kb: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb / 1024.0)
}

fn mib_or_na(v: Option<f64>) -> String {
    v.map_or("n/a".into(), |v| format!("{v:.0}"))
}

/// Step 1: compress a 256² BTF folder.
fn full_size(md: &mut String, out: &Path) -> anyhow::Result<()> {
    let s = Sampling::H1;
    let dir = out.join("btf-256-tmp");
    if dir.exists() {
        std::fs::remove_dir_all(&dir)?;
    }
    let t = Instant::now();
    let w = woven(FULL_RES, 1)?;
    for j in 0..DIRECTIONS {
        let hits = w
            .view(s.vector(j))
            .expect("every sampled view is ≥ 5° above the horizon");
        write_btf_view(&dir, s, FULL_RES, j, |i| hits.shade(s.vector(i)))?;
        if (j + 1).is_multiple_of(27) {
            eprintln!("  wrote {}/{DIRECTIONS} view slots at {FULL_RES}²", j + 1);
        }
    }
    drop(w);
    let render_s = t.elapsed().as_secs_f64();
    let disk: u64 = std::fs::read_dir(&dir)?
        .filter_map(|e| e.ok()?.metadata().ok())
        .map(|m| m.len())
        .sum();
    let (hwm0, rss0) = (proc_status_mib("VmHWM:"), proc_status_mib("VmRSS:"));
    eprintln!("{FULL_RES}² folder written in {render_s:.0} s; compressing");
    let t = Instant::now();
    let folder = BtfDir::open(&dir)?;
    let (pca, report) = BtfPca::compress(&folder, &BtfPcaParams::default())?;
    let seconds = t.elapsed().as_secs_f64();
    let hwm = proc_status_mib("VmHWM:");
    let file = pca.to_bytes().len();
    let subset: Vec<(usize, usize)> = (0..DIRECTIONS * DIRECTIONS)
        .step_by(9)
        .map(|p| (p / DIRECTIONS, p % DIRECTIONS))
        .collect();
    let e = pca.stats(&folder, Some(&subset))?;
    std::fs::remove_dir_all(&dir)?;
    let raw = (DIRECTIONS * DIRECTIONS * 3 * FULL_RES * FULL_RES) as f64;
    // The thesis's storage: 8-bit means as well (the default keeps them at 16 bits).
    let comps: Vec<usize> = pca.slots().iter().map(|s| s.components()).collect();
    let ranks: Vec<usize> = pca.slots().iter().map(|s| s.rank()).collect();
    let u8_means = pvmf_bytes(FULL_RES, FULL_RES, &comps, &ranks, Storage::U8, Storage::U8);
    let load: f64 = report.slots.iter().map(|r| r.load_seconds).sum();
    let fit: f64 = report.slots.iter().map(|r| r.fit_seconds).sum();
    let ok = |v: bool| if v { "yes" } else { "**no**" };
    let _ = writeln!(
        md,
        "## Full size: 81 × 81 images at {FULL_RES}², c = 16\n\n\
         The woven BTF (one sample per texel) written as {} PNGs ({:.0} MB on disk, {:.0} s to \
         render and encode), then `BtfPca::compress` on the folder with the default parameters \
         (c = 16, 8-bit eigen-normtextures, 16-bit means) — the code path of \
         `crates/btf/examples/compress_dir.rs`. Peak memory is the process's VmHWM \
         (/proc/self/status), which includes the rendering before it; nothing larger had been \
         allocated yet.\n\n\
         | quantity | measured | issue target | met |\n|---|---|---|---|\n\
         | compression wall time (decode 6,561 PNGs + 81 PCAs) | {seconds:.1} s | ≤ {TARGET_SECONDS:.0} s | {} |\n\
         | peak resident memory (VmHWM, whole process) | {} MiB | ≤ {TARGET_MIB:.0} MiB | {} |\n\
         | resident memory before compressing (VmRSS / VmHWM) | {} / {} MiB | | |\n\
         | raw 8-bit BTF | {:.0} MiB | | |\n\
         | `.btfpca` file | {:.1} MiB (ratio {:.2}) | | |\n\
         | the same with 8-bit means (formula, payload) | {:.1} MiB | | |\n\
         | RMS / PSNR on 729 images (every 9th pair) | {:.2} codes / {:.2} dB | | |\n\n\
         Summed over the workers: {load:.1} s loading, {fit:.1} s fitting. The thesis: \
         \"performing a principle component on the different view-slots reduces the size of \
         the data set from about 1230 megabytes to 260 megabytes per sample for a 256 × 256 \
         resolution\" (§5.4).\n",
        DIRECTIONS * DIRECTIONS,
        disk as f64 / 1e6,
        render_s,
        ok(seconds <= TARGET_SECONDS),
        mib_or_na(hwm),
        ok(hwm.is_some_and(|h| h <= TARGET_MIB)),
        mib_or_na(rss0),
        mib_or_na(hwm0),
        raw / MIB,
        file as f64 / MIB,
        raw / file as f64,
        u8_means as f64 / MIB,
        e.rms_srgb8,
        e.psnr_db,
    );
    eprintln!("{FULL_RES}²: compressed in {seconds:.1} s, VmHWM {hwm:?} MiB");
    Ok(())
}

/// The memory the same parameters take at 256² (65,536 texels), by the formulas (per-cluster
/// and per-slot term counts and ranks as fitted here).
fn bytes_at_256(row: &Compared, params: &MethodParams) -> usize {
    let n = FULL_RES * FULL_RES;
    match (&row.reconstruction, params) {
        (
            Reconstruction::Texel(m),
            MethodParams::Fmf(FmfParams {
                storage,
                mean_storage,
                ..
            }),
        )
        | (
            Reconstruction::Texel(m),
            MethodParams::Pcmf(PcmfParams {
                storage,
                mean_storage,
                ..
            }),
        ) => texel_model_bytes(n, &m.cluster_terms(), *storage, *mean_storage),
        (Reconstruction::PerView(p), _) => {
            let c: Vec<usize> = p.slots().iter().map(|s| s.components()).collect();
            let r: Vec<usize> = p.slots().iter().map(|s| s.rank()).collect();
            pvmf_bytes(FULL_RES, FULL_RES, &c, &r, p.storage(), p.mean_storage())
        }
        _ => 0,
    }
}

/// Step 2: FMF / PCMF / PVMF at 128².
fn comparison(md: &mut String, btf: &AbrdfMatrix) -> anyhow::Result<()> {
    let pvmf_at = |c| BtfPcaParams {
        components: c,
        ..Default::default()
    };
    // 8-bit bases as Fig. 2.22 (16-bit for PCMF); 16-bit means as `BtfPca`'s default.
    let fmf_at = |c| {
        let mut p = FmfParams::new(c, Storage::U8);
        p.mean_storage = Storage::U16;
        p
    };
    let f32s = Storage::F32;
    let runs = [
        MethodParams::Fmf(fmf_at(8)),
        MethodParams::Fmf(fmf_at(16)),
        MethodParams::Fmf(fmf_at(32)),
        MethodParams::Pcmf(PcmfParams::new(16, 8, Storage::U16)),
        MethodParams::Pcmf(PcmfParams::default()),
        MethodParams::Pcmf(PcmfParams::new(32, 16, Storage::U16)),
        MethodParams::Pvmf(pvmf_at(4)),
        MethodParams::Pvmf(pvmf_at(8)),
        MethodParams::Pvmf(pvmf_at(16)),
        MethodParams::Pvmf(pvmf_at(32)),
        // Equal precision: every texture in f32.
        MethodParams::Fmf(FmfParams::new(8, f32s)),
        MethodParams::Pcmf(PcmfParams::new(32, 8, f32s)),
        MethodParams::Pvmf(BtfPcaParams {
            components: 8,
            storage: f32s,
            mean_storage: f32s,
            ..Default::default()
        }),
    ];
    let res = btf.width();
    let _ = writeln!(
        md,
        "## FMF, PCMF and PVMF at {res}² (Fig. 2.22)\n\n\
         `btf::compare` on the {res}² woven BTF held once as 8-bit sRGB codes ({:.0} MB; \
         texels × 19,683-value ABRDFs). Error over all 6,561 images against those codes. \
         Memory: textures (means and bases) at the listed storage with an 8-byte range each, \
         f32 weights, 1-byte cluster ids (PCMF); \"f32\" stores every texture as f32. \
         FMF: one PCA of the {n} × 19,683 matrix by `clustering`'s `Auto` path (at 128²: \
         randomized subspace iteration — the Gram matrix would be 2.1 GB with an O(n³) \
         eigensolver, the covariance 3.1 GB); its fit decodes the codes to an f32 matrix \
         ({:.2} GB) for the duration. PCMF: local PCA (k-means start, ≤ 10 iterations) on \
         min(n, 4,096) random texels, then every texel \
         assigned by reconstruction error and each cluster refitted on all its texels. PVMF: \
         `BtfPca` (8-bit eigen-normtextures, 16-bit means). Fit time includes decoding.\n\n\
         | method | clusters × terms | storage (bases / means) | memory MB | f32 MB | at 256² MB | RMS (8-bit) | PSNR dB | max | fit s | eval s |\n\
         |---|---|---|---|---|---|---|---|---|---|---|",
        btf.bytes() as f64 / 1e6,
        4.0 * btf.bytes() as f64 / 1e9,
        n = btf.texels(),
    );
    for params in &runs {
        let name = match params {
            MethodParams::Fmf(p) => format!("FMF c = {}", p.terms),
            MethodParams::Pcmf(p) => format!("PCMF {} × {}", p.clusters, p.terms),
            MethodParams::Pvmf(p) => format!("PVMF c = {}", p.components),
        };
        eprintln!("comparison: {name}");
        let row = compare(btf, params)?;
        let storage = match params {
            MethodParams::Fmf(p) => format!("{:?} / {:?}", p.storage, p.mean_storage),
            MethodParams::Pcmf(p) => format!("{:?} / {:?}", p.storage, p.mean_storage),
            MethodParams::Pvmf(p) => format!("{:?} / {:?}", p.storage, p.mean_storage),
        };
        let paths = match &row.reconstruction {
            Reconstruction::Texel(m) => {
                let mut p: Vec<String> = m.pca_methods().iter().map(|m| format!("{m:?}")).collect();
                p.sort();
                p.dedup();
                format!(
                    " ({})",
                    p.iter()
                        .map(|s| s.split('(').next().unwrap_or(s))
                        .collect::<Vec<_>>()
                        .join(", ")
                )
            }
            Reconstruction::PerView(_) => String::new(),
        };
        let _ = writeln!(
            md,
            "| {}{paths} | {} × {} | {storage} | {:.2} | {:.2} | {:.1} | {:.2} | {:.2} | {:.1} | {:.1} | {:.1} |",
            row.reconstruction.method(),
            row.clusters,
            row.terms,
            row.bytes as f64 / 1e6,
            row.bytes_f32 as f64 / 1e6,
            bytes_at_256(&row, params) as f64 / 1e6,
            row.stats.rms_srgb8,
            row.stats.psnr_db,
            row.stats.max_abs_srgb8,
            row.fit_seconds,
            row.stats_seconds,
        );
        eprintln!(
            "  {name}: RMS {:.2}, {:.1} MB, fit {:.1} s",
            row.stats.rms_srgb8,
            row.bytes as f64 / 1e6,
            row.fit_seconds
        );
    }
    let _ = writeln!(
        md,
        "\nThe thesis (Fig. 2.22, PLASTERSTONE at 256², 8-bit except PCMF at 16 bit): original \
         1.2 GB, PVMF with 8 terms 121 MB, PCMF with 32 clusters × 8 terms 11 MB; \"the \
         qualitatively best result is achieved using per-view factorization but unfortunately \
         the memory requirements are very high\", and per-cluster factorization \"seems to \
         offer a good compromise\". Fig. 2.21 compares FMF with c = 8 and PCMF 32 × 8 on the \
         frontal view.\n"
    );
    Ok(())
}

/// One point of the c sweep.
struct SweepPoint {
    c: usize,
    rms: f64,
    psnr: f64,
    seconds: f64,
    file: usize,
}

/// Step 3: the c sweep on one sampling; returns the points and the eigenvalue series.
fn sweep(btf: &AbrdfMatrix) -> anyhow::Result<(Vec<SweepPoint>, Vec<Series>)> {
    let s = btf.sampling();
    let mut points = Vec::new();
    let mut last = None;
    for &c in &SWEEP_C {
        let params = BtfPcaParams {
            components: c,
            ..Default::default()
        };
        let (pca, report) = pvmf(btf, &params)?;
        let e = pvmf_stats(&pca, btf)?;
        points.push(SweepPoint {
            c,
            rms: e.rms_srgb8,
            psnr: e.psnr_db,
            seconds: report.seconds,
            file: pca.to_bytes().len(),
        });
        eprintln!(
            "  sweep {s} c = {c}: RMS {:.2}, {:.1} s",
            e.rms_srgb8, report.seconds
        );
        last = Some(pca);
    }
    let pca = last.context("empty sweep")?;
    let series = fig58_slots(s)
        .iter()
        .map(|&(theta, phi)| {
            let j = s
                .index_of(theta, phi)
                .context("Fig. 5.8 slot not measured")?;
            let ev = pca.slot(j).eigenvalues();
            let l1 = f64::from(ev.first().copied().unwrap_or(0.0));
            Ok(Series {
                label: format!("{s} view θ = {theta}°, φ = {phi}°"),
                points: ev
                    .iter()
                    .take(EIGEN_K)
                    .enumerate()
                    .map(|(k, &l)| ((k + 1) as f64, f64::from(l) / l1))
                    .collect(),
            })
        })
        .collect::<anyhow::Result<Vec<_>>>()?;
    Ok((points, series))
}

/// Step 3b: Fig. 5.7 — one normtexture at c = 16, 10, 5 and difference images.
fn fig57(md: &mut String, out: &Path, btf: &AbrdfMatrix) -> anyhow::Result<()> {
    let s = btf.sampling();
    let t = s.ring_thetas();
    let (view, light) = ((0, 0), (t[3], 60));
    let j = s.index_of(view.0, view.1).context("view")?;
    let i = s.index_of(light.0, light.1).context("light")?;
    let slot = btf.view_slot(j)?;
    let original = btf.image(j, i)?;
    let mut tiles = vec![original.clone()];
    let mut rms = Vec::new();
    for &c in &PANEL_C {
        let fit = SlotPca::fit(&slot, c, Storage::U8, Storage::U16)?;
        let mut img = fit.texture(0).dequantize();
        for (k, &p) in fit.light_weights(i).iter().enumerate() {
            let b = fit.texture(k + 1).dequantize();
            img.iter_mut().zip(&b).for_each(|(o, &v)| *o += p * v);
        }
        let img: Vec<[f32; 3]> = img.chunks_exact(3).map(|v| [v[0], v[1], v[2]]).collect();
        let sq: f64 = original
            .iter()
            .zip(&img)
            .flat_map(|(a, b)| (0..3).map(move |ch| (a[ch], b[ch])))
            .map(|(a, b)| f64::from((linear_to_srgb(a) - linear_to_srgb(b)) * 255.0).powi(2))
            .sum();
        rms.push((sq / (3 * original.len()) as f64).sqrt());
        tiles.push(img);
    }
    let (w, h) = (btf.width(), btf.height());
    let (tw, th) = (w * PANEL_ZOOM, h * PANEL_ZOOM);
    let (sx, sy) = (tw + PANEL_GAP, th + PANEL_GAP);
    let mut panel = image::RgbImage::from_pixel(
        (4 * sx - PANEL_GAP) as u32,
        (2 * sy - PANEL_GAP) as u32,
        [255; 3].into(),
    );
    let srgb8 = |v: f32| (linear_to_srgb(v) * 255.0).round() as u8;
    for (col, tile) in tiles.iter().enumerate() {
        for y in 0..th {
            for x in 0..tw {
                let t = (y / PANEL_ZOOM) * w + x / PANEL_ZOOM;
                let (px, py) = ((col * sx + x) as u32, y as u32);
                panel.put_pixel(px, py, tile[t].map(srgb8).into());
                if col > 0 {
                    let len = (0..3)
                        .map(|ch| {
                            (linear_to_srgb(original[t][ch]) - linear_to_srgb(tile[t][ch])) * 255.0
                        })
                        .map(|d| d * d)
                        .sum::<f32>()
                        .sqrt();
                    let a = (len / DIFF_RED).min(1.0);
                    let red = [(255.0 * a) as u8, (255.0 * (1.0 - a)) as u8, 0];
                    panel.put_pixel(px, py + sy as u32, red.into());
                }
            }
        }
    }
    let path = out.join("btf-fig5.7.png");
    panel.save(&path)?;
    let _ = writeln!(
        md,
        "### Fig. 5.7: one normtexture\n\n`btf-fig5.7.png`: view slot θ = {}°, φ = {}° \
         (frontal), light θ = {}°, φ = {}°, {w}² ({PANEL_ZOOM}× zoom). Top: original, c = 16, \
         10, 5 (8-bit eigen-normtextures); bottom (under the reconstructions): the length of the 8-bit sRGB error vector, \
         green = 0 to red ≥ {DIFF_RED} (the thesis's red is 255, which would leave these \
         errors uniformly green). RMS of this image: c = 16: {:.2}, c = 10: {:.2}, c = 5: {:.2} \
         codes.\n",
        view.0, view.1, light.0, light.1, rms[0], rms[1], rms[2]
    );
    Ok(())
}

/// Run the report (`quick`: 32² everywhere, no full-size timing).
pub fn run(out: &Path, quick: bool) -> anyhow::Result<()> {
    let total = Instant::now();
    let (compare_res, sweep_res) = if quick {
        (32, 32)
    } else {
        (COMPARE_RES, SWEEP_RES)
    };
    let mut md = String::new();
    let _ = writeln!(
        md,
        "# BTF compression (thesis §5.4, §2.1.12)\n\n`cargo xtask repro btf{}`. Data: the \
         synthetic woven BTF of `synth::WovenBtf` (default parameters: 4 × 4 yarns, 2 × 2 \
         samples per texel unless stated), rendered in memory, sampling H1 unless stated, \
         held as 8-bit sRGB like a UBO2003 measurement. Errors are RMS per value in 8-bit \
         sRGB units and PSNR = 20 log₁₀(255 / RMS), over all 6,561 images unless stated. \
         Times are wall-clock on this machine ({} rayon threads).\n",
        if quick { " --quick" } else { "" },
        rayon::current_num_threads()
    );
    if quick {
        let _ = writeln!(md, "`--quick`: the full-size timing is skipped.\n");
    } else {
        full_size(&mut md, out)?;
    }

    let btf = matrix(Sampling::H1, compare_res)?;
    comparison(&mut md, &btf)?;

    let _ = writeln!(
        md,
        "## Error against c at {sweep_res}² (Figs. 5.7/5.8)\n\n`BtfPca` with c components \
         per view slot, 8-bit eigen-normtextures and 16-bit means; time is the whole \
         compression of the in-memory BTF (81 slot PCAs), size the `.btfpca` file. The \
         thesis: \"c = 16 components were sufficient to reproduce the look and feel of the \
         sample materials\" (§5.4).\n\n\
         | sampling | c | RMS (8-bit) | PSNR dB | compress s | `.btfpca` MB |\n|---|---|---|---|---|---|"
    );
    let mut error_series = Vec::new();
    let mut eigen_series = Vec::new();
    for s in Sampling::ALL {
        let other;
        let data = if s == btf.sampling() && sweep_res == compare_res {
            &btf
        } else {
            other = matrix(s, sweep_res)?;
            &other
        };
        let (points, eigen) = sweep(data)?;
        for p in &points {
            let _ = writeln!(
                md,
                "| {s} | {} | {:.2} | {:.2} | {:.2} | {:.2} |",
                p.c,
                p.rms,
                p.psnr,
                p.seconds,
                p.file as f64 / 1e6
            );
        }
        error_series.push(Series {
            label: format!("{s} RMS (8-bit sRGB)"),
            points: points.iter().map(|p| (p.c as f64, p.rms)).collect(),
        });
        eigen_series.extend(eigen);
    }
    let _ = writeln!(
        md,
        "\nError against c: `btf-error.svg`. Eigenvalue decay λ_k / λ_1, k = 1…{EIGEN_K}, of \
         Fig. 5.8's view slots (θ, φ) = (0°, 0°), (45°, 300°), (75°, 45°) on H2 and the same \
         rings (51°, 85°) on H1: `btf-eigenvalues.svg` (log y).\n"
    );
    let ks = [2, 4, 8, 16, 32];
    let _ = writeln!(
        md,
        "| view slot | {} |\n|---|{}",
        ks.map(|k| format!("λ_{k}/λ_1")).join(" | "),
        "---|".repeat(ks.len())
    );
    for series in &eigen_series {
        let cells = ks.map(|k| {
            series
                .points
                .get(k - 1)
                .map_or("–".into(), |p| format!("{:.2e}", p.1))
        });
        let _ = writeln!(md, "| {} | {} |", series.label, cells.join(" | "));
    }
    let _ = writeln!(md);
    let svg = chart_svg(
        &format!("Per-view PCA error against c ({sweep_res}² woven BTF)"),
        [
            "c (eigen-normtextures per view slot)",
            "RMS error, 8-bit sRGB",
        ],
        [Axis::Linear, Axis::Linear],
        &error_series,
    );
    atomic_out::write_bytes(&out.join("btf-error.svg"), svg.as_bytes())?;
    let svg = chart_svg(
        &format!("Eigenvalue decay of three view slots ({sweep_res}², Fig. 5.8)"),
        ["k", "λ_k / λ_1"],
        [Axis::Linear, Axis::Log],
        &eigen_series,
    );
    atomic_out::write_bytes(&out.join("btf-eigenvalues.svg"), svg.as_bytes())?;
    fig57(&mut md, out, &btf)?;

    let _ = writeln!(
        md,
        "Peak resident memory of the whole run (VmHWM): {} MiB. The report took {:.0} s.",
        mib_or_na(proc_status_mib("VmHWM:")),
        total.elapsed().as_secs_f64()
    );
    atomic_out::write_bytes(&out.join("btf.md"), md.as_bytes())?;
    eprintln!("wrote {}", out.join("btf.md").display());
    Ok(())
}
