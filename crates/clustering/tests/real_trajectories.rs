//! Local PCA on the real chickenCrossing trajectories (../shared/data; skipped with a warning
//! when absent, failing under CI).

mod common;

use clustering::{ComponentCount, LocalPca, LocalPcaParams, Pca, PcaParams};
use faer::Mat;

/// Frames used (of 170) to keep the test short.
const FRAMES: usize = 40;

/// Trajectory matrix V × 3F from the `v` lines of the OBJ frames.
fn chicken() -> Option<Mat<f64>> {
    let first = test_data::shared_file("anim/chickenCrossing/1.obj")?;
    let dir = first.parent()?.to_path_buf();
    let frames: Vec<Vec<[f64; 3]>> = (1..=FRAMES)
        .map(|f| {
            let text =
                std::fs::read_to_string(dir.join(format!("{f}.obj"))).expect("readable OBJ frame");
            text.lines()
                .filter_map(|l| l.strip_prefix("v "))
                .map(|l| {
                    let v: Vec<f64> = l
                        .split_whitespace()
                        .map(|t| t.parse().expect("vertex coordinate"))
                        .collect();
                    [v[0], v[1], v[2]]
                })
                .collect()
        })
        .collect();
    let n = frames[0].len();
    assert!(frames.iter().all(|f| f.len() == n), "constant connectivity");
    Some(Mat::from_fn(n, 3 * FRAMES, |i, j| frames[j / 3][i][j % 3]))
}

#[test]
fn chicken_local_pca_beats_global_pca_and_converges() {
    let Some(x) = chicken() else { return };
    assert_eq!(x.nrows(), 3030);
    let c = 6;
    let l = LocalPca::fit(
        x.as_ref(),
        &LocalPcaParams {
            k: 10,
            components: c,
            ..Default::default()
        },
    )
    .unwrap();
    let h = l.error_history();
    for w in h.windows(2) {
        assert!(w[1] <= w[0] * (1.0 + 1e-9), "error increased: {h:?}");
    }
    assert!(
        l.cluster_sizes().iter().all(|&s| s > 0),
        "every cluster used: {:?}",
        l.cluster_sizes()
    );
    let p = Pca::fit(
        x.as_ref(),
        &PcaParams {
            components: ComponentCount::Fixed(c),
            ..Default::default()
        },
    )
    .unwrap();
    let global = p.squared_error(x.as_ref()).unwrap() / x.nrows() as f64;
    // The thesis's premise (§3.3.2): trajectories are locally linear, so clustering pays.
    assert!(
        l.mean_error() < 0.1 * global,
        "local {} vs global {global}",
        l.mean_error()
    );
    // Errors are those of the reconstruction.
    let back = l.reconstruct();
    let direct: f64 = (0..x.nrows())
        .map(|i| common::sq_dist(&common::row(&x, i), &common::row(&back, i)))
        .sum::<f64>()
        / x.nrows() as f64;
    common::assert_close(l.mean_error(), direct, 1e-9 * direct, "mean error");
}
