//! Quality and time of this crate next to linfa-clustering on the benchmark data, and the data
//! itself as .npy for `xtask/scripts/sklearn_compare.py` (scikit-learn on the same numbers).
//!
//! ```text
//! cargo run --release -p clustering --example compare -- [OUT_DIR] [--quick]
//! /work/main/.venv/bin/python xtask/scripts/sklearn_compare.py [OUT_DIR]
//! ```
//! OUT_DIR defaults to `target/clustering-compare`. Writes `btf_slot.npy` (81 × 196,608 f32),
//! `blobs.npy` (50,000 × 32), `trajectories.npy` (10,000 × 600), `chicken.npy` (3,030 × 510, when
//! the shared data is present) and `rust_results.json`; prints a markdown table.
//!
//! Budgets, matched with the Python script: PCA keeps c = 16 components (and all 80);
//! k-means k = 32, k-means++ init, one init per run, at most 300 Lloyd iterations, run to a
//! stable assignment (our tolerance 0; scikit-learn tol = 0; linfa tolerance = smallest positive
//! f64, i.e. centroids unchanged), seeds 0..5, inertia recomputed from the returned centers;
//! ours is run with its default seeding (k-means++ + 2k local-search swaps) and with plain
//! greedy k-means++ (scikit-learn's seeding); local PCA k = 10, c = 20, tolerance 1e-4 on the
//! mean error, seeds 0..5, k-means start (default) and random-sample start (as published).

#[path = "../benches/support/mod.rs"]
mod support;

use std::path::PathBuf;
use std::time::Instant;

use clustering::{
    ComponentCount, KMeans, KMeansParams, LocalPca, LocalPcaInit, LocalPcaParams, Pca, PcaParams,
};
use faer::MatRef;

/// Result row.
struct Row {
    case: String,
    implementation: &'static str,
    times: Vec<f64>,
    metric_name: &'static str,
    metrics: Vec<f64>,
    note: String,
}

fn median(v: &[f64]) -> f64 {
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    if s.is_empty() {
        f64::NAN
    } else {
        s[s.len() / 2]
    }
}

fn time<R>(f: impl FnOnce() -> R) -> (R, f64) {
    let t = Instant::now();
    let r = f();
    (r, t.elapsed().as_secs_f64())
}

/// Inertia of `centers` (k × d row-major) on row-major data, brute force (f64 differences).
fn inertia(x: &[f64], d: usize, centers: &[f64]) -> f64 {
    use rayon::prelude::*;
    x.par_chunks(d)
        .map(|p| {
            centers
                .chunks(d)
                .map(|c| p.iter().zip(c).map(|(a, b)| (a - b) * (a - b)).sum::<f64>())
                .fold(f64::INFINITY, f64::min)
        })
        .sum()
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let quick = args.iter().any(|a| a == "--quick");
    let out = args
        .iter()
        .find(|a| !a.starts_with("--"))
        .map(PathBuf::from)
        .unwrap_or_else(|| {
            PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../target/clustering-compare")
        });
    std::fs::create_dir_all(&out)?;
    let reps = if quick { 1 } else { 5 };
    let seeds: Vec<u64> = (0..if quick { 1 } else { 5 }).collect();
    let mut rows = Vec::new();
    eprintln!("threads: {}", rayon::current_num_threads());

    // --- PCA of a BTF view slot --------------------------------------------------------
    let slot = support::btf_slot(1);
    support::write_npy(
        &out.join("btf_slot.npy"),
        support::BTF_LIGHTS,
        support::BTF_FEATURES,
        "<f4",
        &support::f32_bytes(&slot),
    )?;
    let x = MatRef::from_row_major_slice(&slot, support::BTF_LIGHTS, support::BTF_FEATURES);
    let elems = (support::BTF_LIGHTS * support::BTF_FEATURES) as f64;
    for (c, label) in [
        (ComponentCount::Fixed(16), "c=16"),
        (ComponentCount::All, "all (80)"),
    ] {
        let params = PcaParams {
            components: c,
            ..Default::default()
        };
        let mut times = Vec::new();
        let mut fit = None;
        for _ in 0..reps {
            let (p, t) = time(|| Pca::fit(x, &params));
            times.push(t);
            fit = Some(p?);
        }
        let p = fit.ok_or("no fit")?;
        let mse = p.squared_error(x)? / elems;
        rows.push(Row {
            case: format!("PCA 81×196,608 f32, {label}"),
            implementation: "clustering",
            times,
            metric_name: "MSE/elem",
            metrics: vec![mse],
            note: format!("{:?}, {} comps", p.method(), p.n_components()),
        });
    }
    drop(slot);

    // --- k-means 50,000 × 32, k = 32 ---------------------------------------------------
    let (blobs, _) = support::kmeans_blobs(2);
    support::write_npy(
        &out.join("blobs.npy"),
        support::BLOB_N,
        support::BLOB_D,
        "<f8",
        &support::f64_bytes(&blobs),
    )?;
    let xb = MatRef::from_row_major_slice(&blobs, support::BLOB_N, support::BLOB_D);
    for (label, steps) in [
        ("clustering", None),
        ("clustering, plain k-means++ (no local search)", Some(0)),
    ] {
        let (mut times, mut metrics, mut iters) = (Vec::new(), Vec::new(), Vec::new());
        for &seed in &seeds {
            let params = KMeansParams {
                k: support::BLOB_K,
                tolerance: 0.0,
                max_iterations: 300,
                local_search_steps: steps,
                seed,
                ..Default::default()
            };
            let (km, t) = time(|| KMeans::fit(xb, &params));
            let km = km?;
            let centers: Vec<f64> = (0..km.k()).flat_map(|j| km.center(j).to_vec()).collect();
            times.push(t);
            metrics.push(inertia(&blobs, support::BLOB_D, &centers));
            iters.push(km.iterations());
        }
        rows.push(Row {
            case: "k-means 50k×32, k=32".into(),
            implementation: label,
            times,
            metric_name: "inertia",
            metrics,
            note: format!("iterations {iters:?}"),
        });
    }

    let (mut times, mut metrics) = (Vec::new(), Vec::new());
    {
        use linfa::traits::Fit;
        use rand_xoshiro::rand_core::SeedableRng;
        let arr =
            ndarray::Array2::from_shape_vec((support::BLOB_N, support::BLOB_D), blobs.clone())?;
        let ds = linfa::DatasetBase::from(arr);
        for &seed in &seeds {
            let rng = rand_xoshiro::Xoshiro256Plus::seed_from_u64(seed);
            let params = linfa_clustering::KMeans::params_with_rng(support::BLOB_K, rng)
                .n_runs(1)
                .max_n_iterations(300)
                .tolerance(f64::MIN_POSITIVE);
            let (km, t) = time(|| params.fit(&ds));
            let km = km?;
            let centers: Vec<f64> = km.centroids().iter().copied().collect();
            times.push(t);
            metrics.push(inertia(&blobs, support::BLOB_D, &centers));
        }
    }
    rows.push(Row {
        case: "k-means 50k×32, k=32".into(),
        implementation: "linfa-clustering 0.8",
        times,
        metric_name: "inertia",
        metrics,
        note: String::new(),
    });
    drop(blobs);

    // --- local PCA on trajectories -------------------------------------------------------
    let traj = support::trajectories(3);
    support::write_npy(
        &out.join("trajectories.npy"),
        support::TRAJ_V,
        3 * support::TRAJ_F,
        "<f8",
        &support::f64_bytes(&traj),
    )?;
    let mut cases = vec![(
        "trajectories 10,000×600".to_string(),
        traj,
        support::TRAJ_V,
        3 * support::TRAJ_F,
    )];
    if let Some((ch, v, d)) = support::chicken() {
        support::write_npy(
            &out.join("chicken.npy"),
            v,
            d,
            "<f8",
            &support::f64_bytes(&ch),
        )?;
        cases.push((format!("chicken {v}×{d}"), ch, v, d));
    }
    for (name, data, n, d) in &cases {
        let x = MatRef::from_row_major_slice(data, *n, *d);
        for (label, init) in [
            ("clustering", LocalPcaInit::KMeans),
            (
                "clustering, random-sample init (as published)",
                LocalPcaInit::RandomSamples,
            ),
        ] {
            let (mut times, mut metrics, mut iters) = (Vec::new(), Vec::new(), Vec::new());
            for &seed in &seeds {
                let params = LocalPcaParams {
                    k: 10,
                    components: 20,
                    init,
                    seed,
                    ..Default::default()
                };
                let (l, t) = time(|| LocalPca::fit(x, &params));
                let l = l?;
                times.push(t);
                metrics.push(l.mean_error());
                iters.push(l.iterations());
            }
            rows.push(Row {
                case: format!("local PCA {name}, k=10, c=20"),
                implementation: label,
                times,
                metric_name: "mean sq. err/sample",
                metrics,
                note: format!("iterations {iters:?}"),
            });
        }
        // Global PCA with the same total number of stored scalars per sample for context.
        let p = Pca::fit(
            x,
            &PcaParams {
                components: ComponentCount::Fixed(20),
                ..Default::default()
            },
        )?;
        rows.push(Row {
            case: format!("local PCA {name}, k=10, c=20"),
            implementation: "clustering global PCA c=20",
            times: vec![],
            metric_name: "mean sq. err/sample",
            metrics: vec![p.squared_error(x)? / *n as f64],
            note: "reference: one cluster".into(),
        });
    }

    // --- report ---------------------------------------------------------------------------
    let mut json = String::from("[\n");
    println!("| case | implementation | median time (s) | metric (median) | note |");
    println!("|---|---|---:|---:|---|");
    for (i, r) in rows.iter().enumerate() {
        let t = median(&r.times);
        let m = median(&r.metrics);
        println!(
            "| {} | {} | {:.3} | {} = {:.6e} | {} |",
            r.case, r.implementation, t, r.metric_name, m, r.note
        );
        let list = |v: &[f64]| {
            v.iter()
                .map(|x| format!("{x:e}"))
                .collect::<Vec<_>>()
                .join(", ")
        };
        json.push_str(&format!(
            "  {{\"case\": \"{}\", \"impl\": \"{}\", \"times\": [{}], \"metric\": \"{}\", \"values\": [{}], \"note\": \"{}\"}}{}\n",
            r.case,
            r.implementation,
            list(&r.times),
            r.metric_name,
            list(&r.metrics),
            r.note,
            if i + 1 < rows.len() { "," } else { "" }
        ));
    }
    json.push_str("]\n");
    std::fs::write(out.join("rust_results.json"), json)?;
    eprintln!("wrote {}", out.display());
    Ok(())
}
