//! The three linear basis decompositions of thesis Fig. 2.22 (`btf::compare`) on the 16²
//! woven BTF of `synth`: all terms reproduce the BTF, the error falls with the terms, PCMF with
//! one cluster is FMF, and the memory formulas count the data.

use std::sync::OnceLock;

use btf::compare::{
    ABRDF_LEN, AbrdfMatrix, BTFPCA_OVERHEAD, FmfParams, PcmfParams, TexelModel, abrdf_index, pvmf,
    pvmf_bytes, pvmf_stats, texel_model_bytes,
};
use btf::{BtfPca, BtfPcaParams, DIRECTIONS, Sampling, Storage, ViewSlot, linear_to_srgb8};
use synth::{WovenBtf, WovenBtfParams};

const RES: usize = 16;

/// View slot j of the 16² woven BTF, rendered in memory.
fn slot(woven: &WovenBtf, s: Sampling, j: usize) -> btf::Result<ViewSlot> {
    let hits = woven.view(s.vector(j)).expect("view above the horizon");
    let data = (0..DIRECTIONS)
        .flat_map(|i| hits.shade(s.vector(i)))
        .flatten()
        .collect();
    ViewSlot::new(j, RES, RES, data)
}

fn woven() -> &'static WovenBtf {
    static W: OnceLock<WovenBtf> = OnceLock::new();
    W.get_or_init(|| {
        WovenBtf::new(&WovenBtfParams {
            res: RES,
            supersample: 1,
            ..Default::default()
        })
        .expect("woven BTF")
    })
}

fn btf() -> &'static AbrdfMatrix {
    static B: OnceLock<AbrdfMatrix> = OnceLock::new();
    B.get_or_init(|| {
        let s = Sampling::H1;
        AbrdfMatrix::from_slots(s, RES, RES, |j| slot(woven(), s, j), None).unwrap()
    })
}

fn pvmf_params(components: usize, storage: Storage) -> BtfPcaParams {
    BtfPcaParams {
        components,
        storage,
        mean_storage: if storage == Storage::U8 {
            Storage::U16
        } else {
            storage
        },
        ..Default::default()
    }
}

#[track_caller]
fn assert_exact(what: &str, rms: f64) {
    // f32 storage of f64 axes: rounding only, far below one code.
    assert!(rms < 1e-2, "{what}: RMS {rms} sRGB codes with all terms");
}

#[test]
fn matrix_layout_and_slots_round_trip() {
    let b = btf();
    assert_eq!((b.texels(), b.bytes()), (RES * RES, RES * RES * ABRDF_LEN));
    let s = Sampling::H1;
    for j in [0, 40, 80] {
        let original = slot(woven(), s, j).unwrap();
        let decoded = b.view_slot(j).unwrap();
        for i in [0, 7, 80] {
            for t in [0, 17, RES * RES - 1] {
                for c in 0..3 {
                    let v = original.image(i)[3 * t + c];
                    let q = b.abrdf(t)[abrdf_index(j, i, c)];
                    assert_eq!(q, linear_to_srgb8(v));
                    assert_eq!(linear_to_srgb8(decoded.image(i)[3 * t + c]), q);
                }
            }
            let img = b.image(j, i).unwrap();
            assert_eq!(img.as_flattened(), decoded.image(i));
        }
    }
    assert!(b.view_slot(81).is_err() && b.image(0, 81).is_err());
}

#[test]
fn every_method_with_all_terms_reproduces_the_btf() {
    let b = btf();
    let n = b.texels();
    // n − 1 = 255 centred texels span at most 255 directions.
    let fmf = TexelModel::fmf(b, &FmfParams::new(n - 1, Storage::F32)).unwrap();
    assert_exact("FMF", fmf.stats(b).unwrap().rms_srgb8);
    let pcmf = TexelModel::pcmf(b, &PcmfParams::new(4, n - 1, Storage::F32)).unwrap();
    assert_eq!(pcmf.clusters(), 4);
    assert_exact("PCMF", pcmf.stats(b).unwrap().rms_srgb8);
    let (pca, _) = pvmf(b, &pvmf_params(80, Storage::F32)).unwrap();
    let e = pvmf_stats(&pca, b).unwrap();
    assert_eq!(e.images, DIRECTIONS * DIRECTIONS);
    assert_eq!(e.values, (DIRECTIONS * DIRECTIONS * 3 * n) as u64);
    assert_exact("PVMF", e.rms_srgb8);

    // At 8/16-bit storage only quantization is lost. Its error grows as √c with the terms
    // summed: FMF's 255 u8 axes lose 1.8 codes RMS, PVMF's 80 u8 eigen-normtextures and
    // PCMF's u16 axes under one.
    let fmf8 = TexelModel::fmf(b, &FmfParams::new(n - 1, Storage::U8)).unwrap();
    let (pca8, _) = pvmf(b, &pvmf_params(80, Storage::U8)).unwrap();
    let pcmf16 = TexelModel::pcmf(b, &PcmfParams::new(4, n - 1, Storage::U16)).unwrap();
    for (what, rms, bound) in [
        ("FMF u8", fmf8.stats(b).unwrap().rms_srgb8, 3.0),
        ("PVMF u8", pvmf_stats(&pca8, b).unwrap().rms_srgb8, 1.0),
        ("PCMF u16", pcmf16.stats(b).unwrap().rms_srgb8, 1.0),
    ] {
        assert!(rms < bound, "{what}: RMS {rms}");
    }
}

#[test]
fn error_falls_as_terms_rise() {
    let b = btf();
    let f32s = Storage::F32;
    let terms = [1, 4, 16];
    let fmf: Vec<f64> = terms
        .iter()
        .map(|&c| {
            let m = TexelModel::fmf(b, &FmfParams::new(c, f32s)).unwrap();
            m.stats(b).unwrap().rms_srgb8
        })
        .collect();
    let pcmf: Vec<f64> = terms
        .iter()
        .map(|&c| {
            let m = TexelModel::pcmf(b, &PcmfParams::new(4, c, f32s)).unwrap();
            m.stats(b).unwrap().rms_srgb8
        })
        .collect();
    let pvmf_rms: Vec<f64> = terms
        .iter()
        .map(|&c| {
            let (p, _) = pvmf(b, &pvmf_params(c, f32s)).unwrap();
            pvmf_stats(&p, b).unwrap().rms_srgb8
        })
        .collect();
    for (what, e) in [("FMF", &fmf), ("PCMF", &pcmf), ("PVMF", &pvmf_rms)] {
        assert!(e.windows(2).all(|w| w[1] < w[0]), "{what}: {e:?}");
    }
    // Per-view and per-cluster bases are at least as good as one global basis of as many
    // terms (both contain FMF's mean-plus-c-terms model as a special case up to clustering).
    assert!(pvmf_rms[1] < fmf[1], "PVMF {pvmf_rms:?} vs FMF {fmf:?}");
    assert!(pcmf[1] <= fmf[1] * 1.001, "PCMF {pcmf:?} vs FMF {fmf:?}");
}

#[test]
fn pcmf_with_one_cluster_is_fmf() {
    let b = btf();
    for storage in [Storage::F32, Storage::U8] {
        let fmf = TexelModel::fmf(b, &FmfParams::new(8, storage)).unwrap();
        let pcmf = TexelModel::pcmf(b, &PcmfParams::new(1, 8, storage)).unwrap();
        assert_eq!(pcmf.clusters(), 1);
        assert_eq!(pcmf.bytes(), fmf.bytes());
        let (ef, ep) = (fmf.stats(b).unwrap(), pcmf.stats(b).unwrap());
        assert!(
            (ef.rms_srgb8 - ep.rms_srgb8).abs() <= 1e-9 * ef.rms_srgb8,
            "{storage:?}: FMF {ef:?} PCMF {ep:?}"
        );
        let mut a = vec![0.0; ABRDF_LEN];
        let mut p = vec![0.0; ABRDF_LEN];
        for t in [0, 100, 255] {
            fmf.reconstruct_abrdf(t, &mut a);
            pcmf.reconstruct_abrdf(t, &mut p);
            let worst = a
                .iter()
                .zip(&p)
                .map(|(x, y)| (x - y).abs())
                .fold(0.0, f32::max);
            assert!(worst <= 1e-6, "texel {t}: {worst}");
        }
    }
}

#[test]
fn memory_formulas_count_the_data() {
    let b = btf();
    let n = b.texels();
    for storage in [Storage::U8, Storage::U16, Storage::F32] {
        let fmf = TexelModel::fmf(b, &FmfParams::new(8, storage)).unwrap();
        assert_eq!(
            fmf.bytes(),
            texel_model_bytes(n, &fmf.cluster_terms(), storage, storage)
        );
        assert_eq!(fmf.cluster_terms(), vec![8]);
        // Mean + 8 axes of 19,683 values with ranges, 256 × 8 f32 weights, no cluster ids.
        assert_eq!(
            fmf.bytes(),
            9 * (ABRDF_LEN * storage.bytes() + 8) + 4 * n * 8
        );
        let pcmf = TexelModel::pcmf(b, &PcmfParams::new(4, 8, storage)).unwrap();
        let terms = pcmf.cluster_terms();
        assert_eq!(pcmf.bytes(), texel_model_bytes(n, &terms, storage, storage));
        let textures: usize = (0..pcmf.clusters())
            .flat_map(|k| (0..=terms[k]).map(move |j| (k, j)))
            .map(|(k, j)| pcmf.texture(k, j).len() * storage.bytes() + 8)
            .sum();
        let stride = terms.iter().copied().max().unwrap();
        assert_eq!(pcmf.bytes(), textures + 4 * n * stride + n); // 1-byte cluster ids
        assert_eq!(
            pcmf.bytes_f32(),
            texel_model_bytes(n, &terms, Storage::F32, Storage::F32)
        );

        let (pca, _) = pvmf(b, &pvmf_params(8, storage)).unwrap();
        let comps: Vec<usize> = pca.slots().iter().map(|s| s.components()).collect();
        let ranks: Vec<usize> = pca.slots().iter().map(|s| s.rank()).collect();
        let formula = pvmf_bytes(RES, RES, &comps, &ranks, pca.storage(), pca.mean_storage());
        assert_eq!(formula, pca.payload_bytes());
        assert_eq!(formula + BTFPCA_OVERHEAD, pca.to_bytes().len());
        assert_eq!(
            BtfPca::from_bytes(&pca.to_bytes()).unwrap().payload_bytes(),
            formula
        );
    }
}

#[test]
fn bad_parameters_are_errors() {
    let b = btf();
    assert!(TexelModel::fmf(b, &FmfParams::new(0, Storage::U8)).is_err());
    assert!(TexelModel::pcmf(b, &PcmfParams::new(0, 4, Storage::U8)).is_err());
    assert!(TexelModel::pcmf(b, &PcmfParams::new(257, 4, Storage::U8)).is_err());
    assert!(TexelModel::pcmf(b, &PcmfParams::new(4, 0, Storage::U8)).is_err());
    let s = Sampling::H1;
    let wrong = AbrdfMatrix::from_slots(s, 2, 2, |j| slot(woven(), s, j), None);
    assert!(wrong.is_err(), "a 16² slot for a 2² matrix");
    assert!(AbrdfMatrix::from_slots(s, 0, 2, |j| slot(woven(), s, j), None).is_err());
    let small = AbrdfMatrix::from_slots(
        s,
        1,
        1,
        |j| ViewSlot::new(j, 1, 1, vec![0.5; 3 * DIRECTIONS]),
        None,
    )
    .unwrap();
    let fmf = TexelModel::fmf(b, &FmfParams::new(2, Storage::U8)).unwrap();
    assert!(fmf.stats(&small).is_err());
}
