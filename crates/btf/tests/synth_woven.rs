//! The woven-cloth BTF of `synth` through the whole pipeline: write, open, compress, measure.

use btf::{BtfDir, BtfPca, BtfPcaParams, DIRECTIONS, Sampling, Storage, ViewSlot, write_btf_view};
use synth::{WovenBtf, WovenBtfParams};

const RES: usize = 16;

fn woven() -> WovenBtf {
    WovenBtf::new(&WovenBtfParams {
        res: RES,
        supersample: 1,
        ..Default::default()
    })
    .expect("woven BTF")
}

/// View slot j of the woven BTF, rendered in memory.
fn slot(btf: &WovenBtf, s: Sampling, j: usize) -> ViewSlot {
    let hits = btf.view(s.vector(j)).expect("view above the horizon");
    let data = (0..DIRECTIONS)
        .flat_map(|i| hits.shade(s.vector(i)))
        .flatten()
        .collect();
    ViewSlot::new(j, RES, RES, data).expect("finite radiance")
}

/// Compresses one rendered slot (repeated as all 81 view slots) and measures slot 0.
fn rms(slot: &ViewSlot, components: usize, storage: Storage) -> f64 {
    let params = BtfPcaParams {
        components,
        storage,
        mean_storage: if storage == Storage::F32 {
            Storage::F32
        } else {
            Storage::U16
        },
        ..Default::default()
    };
    let load = |j| ViewSlot::new(j, RES, RES, slot.data().to_vec());
    let (pca, _) = BtfPca::compress_with(Sampling::H1, RES, RES, &params, load, None).unwrap();
    let e = pca.slot(0).eigenvalues();
    assert!(e.windows(2).all(|w| w[0] >= w[1]), "eigenvalues descend");
    let measured = ViewSlot::new(0, RES, RES, slot.data().to_vec()).unwrap();
    pca.stats_slot(&measured).unwrap().rms_srgb8
}

/// The woven cloth's ray-cast hard shadows at 16² give slots of (nearly) full rank 80, so
/// c = 16 leaves ≈ 11 sRGB codes RMS (measured: 11.2 at view 0, 10.4 at view 45); the 8-bit
/// quantization adds < 0.1 % to that. The error falls with c and vanishes with all components.
#[test]
fn woven_btf_error_falls_with_components_and_quantization_costs_little() {
    let s = Sampling::H1;
    let woven = woven();
    for j in [0, 45] {
        let slot = slot(&woven, s, j);
        let (e4, e16, e32) = (
            rms(&slot, 4, Storage::F32),
            rms(&slot, 16, Storage::F32),
            rms(&slot, 32, Storage::F32),
        );
        assert!(e4 > e16 && e16 > e32, "view {j}: {e4} {e16} {e32}");
        let e16_u8 = rms(&slot, 16, Storage::U8);
        assert!(
            (e16_u8 - e16).abs() <= 0.01 * e16 + 0.05,
            "view {j}: u8 {e16_u8} vs f32 {e16}"
        );
        assert!(
            rms(&slot, 80, Storage::F32) < 1e-3,
            "view {j}: all components"
        );
        assert!(
            rms(&slot, 80, Storage::U8) < 1.5,
            "view {j}: all components, 8 bits"
        );
    }
}

#[test]
fn woven_btf_folder_round_trip_and_stats() {
    let s = Sampling::H2;
    let woven = woven();
    let dir = tempfile::tempdir().unwrap();
    for j in 0..DIRECTIONS {
        let hits = woven.view(s.vector(j)).unwrap();
        write_btf_view(dir.path(), s, RES, j, |i| hits.shade(s.vector(i))).unwrap();
    }
    let btf = BtfDir::open(dir.path()).unwrap();
    assert_eq!((btf.sampling(), btf.width()), (s, RES));
    let params = BtfPcaParams {
        components: 80,
        ..Default::default()
    };
    let (pca, report) = BtfPca::compress(&btf, &params).unwrap();
    assert_eq!(report.slots.len(), DIRECTIONS);
    let all = pca.stats(&btf, None).unwrap();
    assert_eq!(all.images, DIRECTIONS * DIRECTIONS);
    let some = pca
        .stats(&btf, Some(&[(0, 0), (40, 12), (80, 80)]))
        .unwrap();
    assert_eq!(some.images, 3);
    // The progress callback: once per slot compared, ending at (total, total), the same stats.
    let calls = std::sync::Mutex::new(Vec::new());
    let record = |done: usize, total: usize| calls.lock().unwrap().push((done, total));
    assert_eq!(pca.stats_with(&btf, None, Some(&record)).unwrap(), all);
    let seen = std::mem::take(&mut *calls.lock().unwrap());
    assert_eq!(seen.len(), DIRECTIONS);
    assert_eq!(seen.iter().map(|c| c.0).max(), Some(DIRECTIONS));
    assert!(
        seen.iter()
            .all(|&(d, t)| t == DIRECTIONS && (1..=t).contains(&d))
    );
    let subset = [(0, 0), (40, 12), (40, 13), (80, 80)];
    pca.stats_with(&btf, Some(&subset), Some(&record)).unwrap();
    let mut seen = calls.into_inner().unwrap();
    seen.sort_unstable();
    assert_eq!(seen, [(1, 3), (2, 3), (3, 3)], "three view slots touched");
    // All components: only the 8-bit storage of the eigen-normtextures is lost.
    assert!(all.rms_srgb8 < 1.5, "{all:?}");
    assert!(some.rms_srgb8.is_finite() && some.max_abs_srgb8 <= all.max_abs_srgb8);
    // The file round trip keeps every bit.
    let path = dir.path().join("woven.btfpca");
    pca.write(&path).unwrap();
    assert_eq!(BtfPca::read(&path).unwrap(), pca);
    // Light at a measured direction: eval reproduces the stored image's texel.
    let (j, i) = (30, 50);
    let img = pca.image(j, i);
    let rgb = pca.eval(s.vector(j), s.vector(i), 5.5 / RES as f32, 9.5 / RES as f32);
    assert_eq!(rgb, img[9 * RES + 5]);
}
