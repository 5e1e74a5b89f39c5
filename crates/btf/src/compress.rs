//! Per-view PCA compression (thesis §5.4, eq. 5.1).
//!
//! For each view slot S_j the 81 normtextures N_ij are the rows of an 81 × 3hw matrix; its PCA
//! gives the eigen-normtextures B_kj and the weights p_ikj of eq. 5.1. The thesis writes
//! N_ij ≈ Σ_k p_ikj B_kj with p_ikj = N_ij · B_kj, an approximation by the affine subspace; we
//! keep the affine part explicitly as the mean texture B_0j with weight p_i0j = 1 (eq. 5.4
//! indexes from B_0j), so p_ikj = (N_ij − B_0j) · B_kj and c components reconstruct the
//! images with the least squared error.
//!
//! The PCA takes the Gram path of `clustering` (n = 81 samples ≪ 3hw features; the 81 × 81
//! Gram matrix is accumulated in f64). At most n − 1 = 80 components exist; a request for more,
//! or for more than the slot's numerical rank, is clamped and reported in
//! [`CompressReport`], not an error. A slot whose 81 images are identical has rank 0 and keeps
//! only its mean.
//!
//! **Streaming.** Slots are compressed one at a time per worker — load the 81 images, fit,
//! quantize, drop the images — with at most [`BtfPcaParams::parallel_slots`] slots in memory;
//! decoding and the PCA inside a slot run on rayon's pool. Memory per slot in flight at 256²:
//! the 64 MB of f32 images, an f64 copy for the projection (127 MB) and the components
//! (25 MB).

use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::time::Instant;

use clustering::{ComponentCount, Pca, PcaMethod, PcaParams};
use faer::MatRef;

use crate::dataset::{BtfDir, ViewSlot};
use crate::error::{BtfError, Result};
use crate::model::{BtfPca, LIGHTS, SlotPca, Storage, Texture};
use crate::sampling::{DIRECTIONS, Sampling};

/// The most components a slot can have: n − 1 for n = 81 centred samples.
pub const MAX_COMPONENTS: usize = LIGHTS - 1;

/// The thesis's component count: "c = 16 components were sufficient to reproduce the look and
/// feel of the sample materials" (§5.4).
pub const DEFAULT_COMPONENTS: usize = 16;

/// Slots in memory at once when [`BtfPcaParams::parallel_slots`] is 0: enough to keep two to
/// four cores busy while one slot decodes and another fits, ≤ 1 GB at 256².
const AUTO_PARALLEL_SLOTS_MAX: usize = 4;

/// Parameters of [`BtfPca::compress`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BtfPcaParams {
    /// Eigen-normtextures per view slot c (default 16); clamped to 80 and to each slot's rank.
    pub components: usize,
    /// Storage of the eigen-normtextures (default 8 bits, the thesis's).
    pub storage: Storage,
    /// Storage of the mean normtextures (default 16 bits: the mean carries the whole
    /// brightness of the slot, and 8 linear bits would band dark texels by several sRGB
    /// codes; it costs 1/17 more at c = 16).
    pub mean_storage: Storage,
    /// Slots in memory at once; 0 = min(rayon threads, 4).
    pub parallel_slots: usize,
}

impl Default for BtfPcaParams {
    fn default() -> Self {
        Self {
            components: DEFAULT_COMPONENTS,
            storage: Storage::U8,
            mean_storage: Storage::U16,
            parallel_slots: 0,
        }
    }
}

/// What one slot's compression did.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SlotReport {
    /// Components kept c_j.
    pub components: usize,
    /// Numerical rank of the slot's centred data.
    pub rank: usize,
    /// Seconds spent loading the slot's images.
    pub load_seconds: f64,
    /// Seconds spent in the PCA, projection and quantization.
    pub fit_seconds: f64,
}

/// What [`BtfPca::compress`] did: requested and kept components per slot, and timings.
#[derive(Clone, Debug, PartialEq)]
pub struct CompressReport {
    /// The c asked for.
    pub requested: usize,
    /// Per view slot.
    pub slots: Vec<SlotReport>,
    /// Wall-clock seconds of the whole compression.
    pub seconds: f64,
}

impl CompressReport {
    /// True when some slot kept fewer components than requested (c > 80 or c > rank).
    pub fn clamped(&self) -> bool {
        self.slots.iter().any(|s| s.components < self.requested)
    }

    /// The smallest c_j over the slots.
    pub fn min_components(&self) -> usize {
        self.slots.iter().map(|s| s.components).min().unwrap_or(0)
    }
}

impl SlotPca {
    /// Fits the PCA of one view slot (eq. 5.1) and quantizes it.
    ///
    /// # Errors
    /// [`BtfError::Pca`] if the decomposition fails.
    pub fn fit(
        slot: &ViewSlot,
        components: usize,
        storage: Storage,
        mean_storage: Storage,
    ) -> Result<Self> {
        let d = 3 * slot.width() * slot.height();
        let x = MatRef::from_row_major_slice(slot.data(), LIGHTS, d);
        let pca_err = |source| BtfError::Pca {
            view: slot.view(),
            source,
        };
        let params = PcaParams {
            components: ComponentCount::Fixed(components.min(MAX_COMPONENTS)),
            method: PcaMethod::Gram,
            seed: 0,
        };
        let pca = Pca::fit(x, &params).map_err(pca_err)?;
        let c = pca.n_components();
        let mut textures = Vec::with_capacity(c + 1);
        textures.push(Texture::quantize(pca.mean(), mean_storage));
        for k in 0..c {
            textures.push(Texture::quantize(pca.component(k), storage));
        }
        // p_ikj = (N_ij − B_0j) · B_kj with the exact mean and axes.
        let p = pca.project(x).map_err(pca_err)?;
        let mut weights = Vec::with_capacity(LIGHTS * c);
        for i in 0..LIGHTS {
            weights.extend((0..c).map(|k| *p.get(i, k) as f32));
        }
        let eigenvalues = pca.spectrum()[..pca.rank()]
            .iter()
            .map(|&l| l as f32)
            .collect();
        Ok(Self {
            textures,
            weights,
            eigenvalues,
        })
    }
}

impl BtfPca {
    /// Compresses a BTF folder slot by slot (see the [module docs](crate::compress)).
    ///
    /// # Errors
    /// [`BtfError::InvalidParameter`] for a bad parameter; whatever [`BtfDir::load_view`] or
    /// [`SlotPca::fit`] fail with, for the lowest failing slot that ran.
    pub fn compress(dir: &BtfDir, params: &BtfPcaParams) -> Result<(Self, CompressReport)> {
        Self::compress_with(
            dir.sampling(),
            dir.width(),
            dir.height(),
            params,
            |j| dir.load_view(j),
            None,
        )
    }

    /// Compresses a BTF whose view slots come from `load(j)` (a folder, a generator, memory),
    /// with at most `params.parallel_slots` slots in memory; `progress(done, 81)` is called
    /// after each slot.
    ///
    /// # Errors
    /// [`BtfError::InvalidParameter`] for a zero size; [`BtfError::LengthMismatch`] if a slot
    /// has another size or view index than asked for; whatever `load` or [`SlotPca::fit`]
    /// return.
    ///
    /// # Examples
    /// ```
    /// use btf::{BtfPca, BtfPcaParams, Sampling, ViewSlot};
    /// // A 2 × 2 BTF whose every image is a constant grey scaled by the light's cosine.
    /// let s = Sampling::H1;
    /// let load = |j: usize| {
    ///     let data = (0..81).flat_map(|i| vec![0.5 * s.vector(i).z; 12]).collect();
    ///     ViewSlot::new(j, 2, 2, data)
    /// };
    /// let (pca, report) = BtfPca::compress_with(s, 2, 2, &BtfPcaParams::default(), load, None).unwrap();
    /// assert_eq!(report.min_components(), 1); // rank 1: one eigen-normtexture suffices
    /// assert!(report.clamped());
    /// let img = pca.image(0, 40);
    /// assert!((img[0][0] - 0.5 * s.vector(40).z).abs() < 1e-3);
    /// ```
    pub fn compress_with<L>(
        sampling: Sampling,
        width: usize,
        height: usize,
        params: &BtfPcaParams,
        load: L,
        progress: Option<&(dyn Fn(usize, usize) + Sync)>,
    ) -> Result<(Self, CompressReport)>
    where
        L: Fn(usize) -> Result<ViewSlot> + Sync,
    {
        if width == 0 || height == 0 {
            return Err(BtfError::InvalidParameter {
                what: "BtfPca::compress_with",
                name: "width × height",
                value: format!("{width} × {height}"),
                reason: "a normtexture has at least one texel",
            });
        }
        let start = Instant::now();
        let workers = resolve_workers(params.parallel_slots);
        let done = AtomicUsize::new(0);
        let results = for_each_slot_bounded(workers, DIRECTIONS, |j| {
            let t0 = Instant::now();
            let slot = load(j)?;
            if slot.view() != j || slot.width() != width || slot.height() != height {
                return Err(BtfError::LengthMismatch {
                    what: "compress_with load(j)",
                    expected: width * height,
                    found: slot.width() * slot.height(),
                    hint: "return the slot asked for (ViewSlot::view() = j) at the BTF's size",
                });
            }
            let t1 = Instant::now();
            let fit = SlotPca::fit(
                &slot,
                params.components,
                params.storage,
                params.mean_storage,
            )?;
            drop(slot);
            let report = SlotReport {
                components: fit.components(),
                rank: fit.rank(),
                load_seconds: (t1 - t0).as_secs_f64(),
                fit_seconds: t1.elapsed().as_secs_f64(),
            };
            let d = done.fetch_add(1, Ordering::Relaxed) + 1;
            if let Some(p) = progress {
                p(d, DIRECTIONS);
            }
            Ok((fit, report))
        })?;
        let (slots, reports): (Vec<_>, Vec<_>) = results.into_iter().unzip();
        let pca = Self {
            sampling,
            width,
            height,
            requested_components: params.components,
            storage: params.storage,
            mean_storage: params.mean_storage,
            slots,
        };
        let report = CompressReport {
            requested: params.components,
            slots: reports,
            seconds: start.elapsed().as_secs_f64(),
        };
        Ok((pca, report))
    }
}

/// The worker count for `parallel_slots` (0 = auto).
pub(crate) fn resolve_workers(parallel_slots: usize) -> usize {
    if parallel_slots == 0 {
        rayon::current_num_threads().clamp(1, AUTO_PARALLEL_SLOTS_MAX)
    } else {
        parallel_slots
    }
}

/// Runs `f(j)` for j in 0..n on `workers` scoped threads, each taking the next index, so at
/// most `workers` calls are in flight (bounded memory; the calls themselves may use rayon).
/// Stops handing out indices after the first error and returns the error of the lowest failing
/// index. Not a rayon `par_iter`: a rayon worker waiting inside a nested join may steal another
/// top-level item, which would break the bound.
pub(crate) fn for_each_slot_bounded<T: Send>(
    workers: usize,
    n: usize,
    f: impl Fn(usize) -> Result<T> + Sync,
) -> Result<Vec<T>> {
    let next = AtomicUsize::new(0);
    let failed = AtomicBool::new(false);
    let results: Mutex<Vec<Option<Result<T>>>> = Mutex::new((0..n).map(|_| None).collect());
    std::thread::scope(|scope| {
        for _ in 0..workers.clamp(1, n.max(1)) {
            scope.spawn(|| {
                loop {
                    if failed.load(Ordering::Relaxed) {
                        break;
                    }
                    let j = next.fetch_add(1, Ordering::Relaxed);
                    if j >= n {
                        break;
                    }
                    let r = f(j);
                    if r.is_err() {
                        failed.store(true, Ordering::Relaxed);
                    }
                    // A poisoned lock means another worker panicked; the scope re-raises it.
                    if let Ok(mut guard) = results.lock() {
                        guard[j] = Some(r);
                    }
                }
            });
        }
    });
    let results = results
        .into_inner()
        .unwrap_or_else(std::sync::PoisonError::into_inner);
    let mut out = Vec::with_capacity(n);
    let mut missing = false;
    for r in results {
        match r {
            Some(Ok(v)) => out.push(v),
            Some(Err(e)) => return Err(e),
            None => missing = true,
        }
    }
    // Only reachable after an error, which the loop above returned.
    assert!(!missing, "a slot was not processed without an error");
    Ok(out)
}
