//! Progress inside one computation ([`VisibilityEngine::set_progress`]): every backend counts
//! exactly rows × new columns, never more, and reporting does not change M.

mod common;

use std::sync::{Arc, Mutex};

use common::*;
use lightsphere::Lightsphere;
use occlusion_gpu::{
    CpuMethod, CpuParams, ProgressFn, Scene, VisibilityEngine, VisibilityMatrix, VisibilityParams,
};

/// What a progress function saw: every (done, total) pair, in arrival order.
#[derive(Default)]
struct Seen {
    calls: Mutex<Vec<(u64, u64)>>,
}

impl Seen {
    fn function(self: &Arc<Self>) -> ProgressFn {
        let seen = Arc::clone(self);
        Arc::new(move |done, total| seen.calls.lock().unwrap().push((done, total)))
    }

    /// Takes the calls so far; checks that every call names the same total, no count exceeds
    /// it and the largest equals it (the whole call was counted once).
    fn finish(&self, expected_total: u64, what: &str) -> usize {
        let calls = std::mem::take(&mut *self.calls.lock().unwrap());
        assert!(!calls.is_empty(), "{what}: no progress reported");
        assert!(
            calls.iter().all(|&(_, total)| total == expected_total),
            "{what}: totals {calls:?} != {expected_total}"
        );
        let most = calls.iter().map(|&(done, _)| done).max().unwrap();
        assert_eq!(most, expected_total, "{what}: counted {most} cells");
        calls.len()
    }
}

fn compute(engine: &mut VisibilityEngine, scene: &Scene, sphere: &Lightsphere) -> VisibilityMatrix {
    engine.compute(scene, sphere).unwrap()
}

#[test]
fn cpu_methods_count_every_cell_once_and_leave_m_unchanged() {
    let scene = sphere_over_plane();
    let sphere = Lightsphere::new(3).unwrap();
    for method in [CpuMethod::Packets, CpuMethod::SingleRays, CpuMethod::Fans] {
        let params = VisibilityParams::default().with_cpu(CpuParams::default().with_method(method));
        let quiet = compute(&mut VisibilityEngine::cpu(params), &scene, &sphere);
        let seen = Arc::new(Seen::default());
        let mut engine = VisibilityEngine::cpu(params);
        engine.set_progress(Some(seen.function()));
        let reported = compute(&mut engine, &scene, &sphere);
        assert_eq!(reported, quiet, "{method:?}: M changed by reporting");
        let cells = (quiet.rows() * sphere.len()) as u64;
        let calls = seen.finish(cells, &format!("{method:?}"));
        // One call per chunk of 64 rows: a bar moves many times over one call.
        assert_eq!(calls, quiet.rows().div_ceil(64), "{method:?}");

        // Refinement counts only the new columns; vertex filtering only the listed rows.
        let coarse_sphere = Lightsphere::new(2).unwrap();
        let mut refined = compute(&mut engine, &scene, &coarse_sphere);
        seen.finish((quiet.rows() * coarse_sphere.len()) as u64, "coarse");
        engine.refine(&scene, &mut refined, &sphere).unwrap();
        let new = (sphere.len() - coarse_sphere.len()) * quiet.rows();
        seen.finish(new as u64, &format!("{method:?} refine"));
        engine
            .compute_rows(&scene, &mut refined, &[0, 5, 7])
            .unwrap();
        seen.finish(3 * sphere.len() as u64, &format!("{method:?} rows"));

        // Switched off: nothing more arrives.
        engine.set_progress(None);
        compute(&mut engine, &scene, &sphere);
        assert!(seen.calls.lock().unwrap().is_empty());
    }
}

#[cfg(feature = "gpu")]
#[test]
fn gpu_backends_count_every_batch_when_the_device_finishes_it() {
    use occlusion_gpu::{Backend, DepthParams};
    let Some(ctx) = gpu_context::testing::gpu_or_skip() else {
        return;
    };
    let scene = sphere_over_plane();
    let sphere = Lightsphere::new(3).unwrap();
    // Arrays of 16 layers so the depth backend takes 65 batches of directions.
    let mut depth = DepthParams::default().with_resolution(256);
    depth.max_array_bytes = 16 * 256 * 256 * 4;
    let params = VisibilityParams::default().with_depth(depth);
    for backend in [Backend::Depth, Backend::Query, Backend::Rays] {
        let mut quiet = VisibilityEngine::with_gpu(&ctx.device, &ctx.queue, backend, params);
        let expected = compute(&mut quiet, &scene, &sphere);
        let seen = Arc::new(Seen::default());
        let mut engine = VisibilityEngine::with_gpu(&ctx.device, &ctx.queue, backend, params);
        engine.set_progress(Some(seen.function()));
        assert_eq!(
            compute(&mut engine, &scene, &sphere),
            expected,
            "{backend:?}"
        );
        let calls = seen.finish(
            (expected.rows() * sphere.len()) as u64,
            &format!("{backend:?}"),
        );
        if backend == Backend::Depth {
            assert_eq!(calls, sphere.len().div_ceil(16), "one call per batch");
        }
        // The ambient-only path reports through the same batches.
        let ambient = engine.ambient(&scene, &sphere).unwrap();
        assert_eq!(ambient.len(), expected.rows());
        seen.finish(
            (expected.rows() * sphere.len()) as u64,
            &format!("{backend:?} a_i"),
        );
    }
}
