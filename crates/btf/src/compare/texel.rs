//! FMF and PCMF: texel-by-texel models from clustered bases of ABRDFs (thesis eqs. 2.20,
//! 2.22; see the [parent module](super) for the paths, the subset deviation and the memory).

use clustering::{
    ClusteringError, ComponentCount, LocalPca, LocalPcaInit, LocalPcaParams, Pca, PcaMethod,
    PcaParams,
};
use faer::{Accum, Mat, MatRef, Par};
use rayon::prelude::*;

use super::matrix::check_size;
use super::measure::Acc;
use super::{ABRDF_LEN, AbrdfMatrix, Method, abrdf_index, label_bytes, texel_model_bytes};
use crate::error::{BtfError, Result};
use crate::io::srgb8_table;
use crate::model::{Storage, Texture};
use crate::sampling::DIRECTIONS;
use crate::stats::ErrorStats;

/// Parameters of [`TexelModel::fmf`].
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub struct FmfParams {
    /// Terms c (eigen-ABRDFs), ≥ 1; fewer are kept if the data has lower rank (default 8).
    pub terms: usize,
    /// Storage of the eigen-ABRDFs (default 8 bits, Fig. 2.22's for all but PCMF).
    pub storage: Storage,
    /// Storage of the mean ABRDF (default 16 bits, as [`BtfPcaParams::mean_storage`](crate::BtfPcaParams::mean_storage)).
    pub mean_storage: Storage,
    /// Seed of the randomized PCA.
    pub seed: u64,
}

impl Default for FmfParams {
    fn default() -> Self {
        Self {
            terms: 8,
            storage: Storage::U8,
            mean_storage: Storage::U16,
            seed: 0,
        }
    }
}

impl FmfParams {
    /// `terms` terms at `storage` for the basis and the mean.
    pub fn new(terms: usize, storage: Storage) -> Self {
        Self {
            terms,
            storage,
            mean_storage: storage,
            ..Self::default()
        }
    }
}

/// Texels the local PCA of [`TexelModel::pcmf`] clusters by default: its f64 copy is then
/// 645 MB, and one iteration at k = 32, c = 8 about 60 GFlop (tuned on the 128² woven BTF).
pub const DEFAULT_FIT_TEXELS: usize = 4096;

/// Parameters of [`TexelModel::pcmf`].
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub struct PcmfParams {
    /// Clusters k, 1 ≤ k ≤ texels (default 32, Fig. 2.22).
    pub clusters: usize,
    /// Terms c per cluster, ≥ 1 (default 8, Fig. 2.22).
    pub terms: usize,
    /// Storage of the basis ABRDFs (default 16 bits, Fig. 2.22's for PCMF).
    pub storage: Storage,
    /// Storage of the cluster means (default 16 bits).
    pub mean_storage: Storage,
    /// Texels the local PCA clusters (a fixed random subset; all if fewer; default
    /// [`DEFAULT_FIT_TEXELS`]).
    pub fit_texels: usize,
    /// Initialisation of the local PCA (default k-means, see [`LocalPcaInit`]).
    pub init: LocalPcaInit,
    /// Cap on local-PCA iterations (default 10).
    pub max_iterations: usize,
    /// Stop when the mean error changes by less than this fraction (default 1e-3).
    pub tolerance: f64,
    /// Seed of the subset, the local PCA and the per-cluster PCAs.
    pub seed: u64,
}

impl Default for PcmfParams {
    fn default() -> Self {
        Self {
            clusters: 32,
            terms: 8,
            storage: Storage::U16,
            mean_storage: Storage::U16,
            fit_texels: DEFAULT_FIT_TEXELS,
            init: LocalPcaInit::KMeans,
            max_iterations: 10,
            tolerance: 1e-3,
            seed: 0,
        }
    }
}

impl PcmfParams {
    /// k clusters of c terms at `storage` for bases and means.
    pub fn new(clusters: usize, terms: usize, storage: Storage) -> Self {
        Self {
            clusters,
            terms,
            storage,
            mean_storage: storage,
            ..Self::default()
        }
    }
}

/// A BTF approximated texel by texel from clustered bases of ABRDFs: FMF (one cluster) or
/// PCMF. Texel t ≈ mean_{k(t)} + Σ_j w_tj · basis_{k(t), j}.
#[derive(Clone, Debug, PartialEq)]
pub struct TexelModel {
    method: Method,
    width: usize,
    height: usize,
    terms: usize,
    /// Per cluster: `[0]` the mean ABRDF, `[1..=c_k]` the basis ABRDFs.
    clusters: Vec<Vec<Texture>>,
    /// Cluster of every texel.
    labels: Vec<u32>,
    /// n × stride, row-major (stride = the largest c_k); zero beyond a cluster's c_k.
    weights: Vec<f32>,
    /// The PCA path each cluster's fit took.
    pca_methods: Vec<PcaMethod>,
}

/// One fitted cluster: its textures, the weights of its members (m × c_k) and the PCA path.
struct ClusterFit {
    textures: Vec<Texture>,
    weights: Mat<f64>,
    method: PcaMethod,
}

fn pca_error(source: ClusteringError) -> BtfError {
    BtfError::Pca {
        view: DIRECTIONS,
        source,
    }
}

/// PCA of the given texels with c terms, quantized (FMF's fit, and PCMF's per cluster).
fn fit_cluster(
    btf: &AbrdfMatrix,
    members: &[usize],
    terms: usize,
    storage: Storage,
    mean_storage: Storage,
    seed: u64,
) -> Result<ClusterFit> {
    let x = btf.decode_rows(members);
    let x = MatRef::from_row_major_slice(&x, members.len(), ABRDF_LEN);
    let params = PcaParams {
        components: ComponentCount::Fixed(terms),
        method: PcaMethod::Auto,
        seed,
    };
    let pca = Pca::fit(x, &params).map_err(pca_error)?;
    let weights = pca.project(x).map_err(pca_error)?;
    let mut textures = Vec::with_capacity(pca.n_components() + 1);
    textures.push(Texture::quantize(pca.mean(), mean_storage));
    textures.extend((0..pca.n_components()).map(|k| Texture::quantize(pca.component(k), storage)));
    Ok(ClusterFit {
        textures,
        weights,
        method: pca.method(),
    })
}

fn check_terms(what: &'static str, terms: usize) -> Result<()> {
    if terms == 0 {
        return Err(BtfError::InvalidParameter {
            what,
            name: "terms",
            value: "0".into(),
            reason: "at least one term (the mean alone is not a factorization)",
        });
    }
    Ok(())
}

impl TexelModel {
    /// Full-matrix factorization (eq. 2.20): one PCA of all ABRDFs (see the
    /// [module docs](super) for the path and the memory it takes).
    ///
    /// # Errors
    /// [`BtfError::InvalidParameter`] for 0 terms; [`BtfError::Pca`] (view 81) if the PCA
    /// fails.
    pub fn fmf(btf: &AbrdfMatrix, params: &FmfParams) -> Result<Self> {
        check_terms("TexelModel::fmf", params.terms)?;
        let all: Vec<usize> = (0..btf.texels()).collect();
        let fit = fit_cluster(
            btf,
            &all,
            params.terms,
            params.storage,
            params.mean_storage,
            params.seed,
        )?;
        Ok(Self::assemble(
            Method::Fmf,
            btf,
            params.terms,
            vec![0; btf.texels()],
            vec![(all, fit)],
        ))
    }

    /// Per-cluster factorization (eq. 2.22): local PCA of a subset, assignment of every texel
    /// by reconstruction error, refit per cluster (see the [module docs](super)). Clusters left
    /// empty by the assignment are dropped. One cluster gives exactly [`TexelModel::fmf`].
    ///
    /// # Errors
    /// [`BtfError::InvalidParameter`] for 0 terms, 0 clusters or more clusters than texels;
    /// [`BtfError::Pca`] (view 81) if the local PCA or a cluster's PCA fails.
    pub fn pcmf(btf: &AbrdfMatrix, params: &PcmfParams) -> Result<Self> {
        check_terms("TexelModel::pcmf", params.terms)?;
        let n = btf.texels();
        if params.clusters == 0 || params.clusters > n.min(params.fit_texels.max(1)) {
            return Err(BtfError::InvalidParameter {
                what: "TexelModel::pcmf",
                name: "clusters",
                value: params.clusters.to_string(),
                reason: "1 ≤ clusters ≤ min(texels, fit_texels)",
            });
        }
        let labels = if params.clusters == 1 {
            vec![0u32; n]
        } else {
            let subset = random_subset(n, params.fit_texels, params.seed);
            let x = btf.decode_rows(&subset);
            let lp_params = LocalPcaParams {
                k: params.clusters,
                components: params.terms,
                init: params.init,
                max_iterations: params.max_iterations,
                tolerance: params.tolerance,
                seed: params.seed,
                ..LocalPcaParams::default()
            };
            let x = MatRef::from_row_major_slice(&x, subset.len(), ABRDF_LEN);
            let lp = LocalPca::fit(x, &lp_params).map_err(pca_error)?;
            assign(btf, &lp)
        };
        let mut members: Vec<Vec<usize>> = vec![Vec::new(); params.clusters];
        for (t, &l) in labels.iter().enumerate() {
            members[l as usize].push(t);
        }
        members.retain(|m| !m.is_empty());
        let mut labels = vec![0u32; n];
        let mut fits = Vec::with_capacity(members.len());
        for (k, m) in members.into_iter().enumerate() {
            m.iter().for_each(|&t| labels[t] = k as u32);
            let seed = params.seed ^ (k as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15);
            // One cluster: FMF's fit with FMF's seed.
            let seed = if params.clusters == 1 {
                params.seed
            } else {
                seed
            };
            let fit = fit_cluster(
                btf,
                &m,
                params.terms,
                params.storage,
                params.mean_storage,
                seed,
            )?;
            fits.push((m, fit));
        }
        Ok(Self::assemble(
            Method::Pcmf,
            btf,
            params.terms,
            labels,
            fits,
        ))
    }

    fn assemble(
        method: Method,
        btf: &AbrdfMatrix,
        terms: usize,
        labels: Vec<u32>,
        fits: Vec<(Vec<usize>, ClusterFit)>,
    ) -> Self {
        let stride = fits
            .iter()
            .map(|(_, f)| f.textures.len() - 1)
            .max()
            .unwrap_or(0);
        let mut weights = vec![0.0f32; btf.texels() * stride];
        let mut clusters = Vec::with_capacity(fits.len());
        let mut pca_methods = Vec::with_capacity(fits.len());
        for (members, fit) in fits {
            for (r, &t) in members.iter().enumerate() {
                for k in 0..fit.weights.ncols() {
                    weights[t * stride + k] = *fit.weights.get(r, k) as f32;
                }
            }
            clusters.push(fit.textures);
            pca_methods.push(fit.method);
        }
        Self {
            method,
            width: btf.width(),
            height: btf.height(),
            terms,
            clusters,
            labels,
            weights,
            pca_methods,
        }
    }

    /// FMF or PCMF.
    pub fn method(&self) -> Method {
        self.method
    }

    /// The terms c asked for.
    pub fn terms(&self) -> usize {
        self.terms
    }

    /// Number of clusters (1 for FMF).
    pub fn clusters(&self) -> usize {
        self.clusters.len()
    }

    /// Terms kept by each cluster (≤ c; fewer where a cluster has lower rank).
    pub fn cluster_terms(&self) -> Vec<usize> {
        self.clusters.iter().map(|c| c.len() - 1).collect()
    }

    /// Texture `j` of cluster `k`: 0 the mean ABRDF, 1..=c_k the basis ABRDFs.
    ///
    /// # Panics
    /// If `k ≥ clusters()` or `j > c_k`.
    pub fn texture(&self, k: usize, j: usize) -> &Texture {
        &self.clusters[k][j]
    }

    /// Cluster of every texel.
    pub fn labels(&self) -> &[u32] {
        &self.labels
    }

    /// The PCA path each cluster's fit took (`Randomized` or `Gram` for `Auto`).
    pub fn pca_methods(&self) -> &[PcaMethod] {
        &self.pca_methods
    }

    fn stride(&self) -> usize {
        self.weights.len() / self.labels.len().max(1)
    }

    /// Bytes of the stored data, counted from it: textures at their storage with their
    /// ranges, f32 weights, cluster ids ([`texel_model_bytes`] gives the same from counts).
    pub fn bytes(&self) -> usize {
        let textures: usize = self
            .clusters
            .iter()
            .flatten()
            .map(|t| t.stored_bytes() + 8)
            .sum();
        textures + 4 * self.weights.len() + self.labels.len() * label_bytes(self.clusters.len())
    }

    /// Bytes of the same data with every texture in f32.
    pub fn bytes_f32(&self) -> usize {
        texel_model_bytes(
            self.labels.len(),
            &self.cluster_terms(),
            Storage::F32,
            Storage::F32,
        )
    }

    /// Reconstructs texel `t`'s ABRDF (linear) into `out` ([`ABRDF_LEN`] values).
    ///
    /// # Panics
    /// If `t ≥ texels` or `out.len() ≠ ABRDF_LEN`.
    pub fn reconstruct_abrdf(&self, t: usize, out: &mut [f32]) {
        assert_eq!(out.len(), ABRDF_LEN, "an ABRDF has 19,683 values");
        out.iter_mut().for_each(|o| *o = 0.0);
        let cluster = &self.clusters[self.labels[t] as usize];
        let w = &self.weights[t * self.stride()..(t + 1) * self.stride()];
        cluster[0].add_scaled(1.0, out);
        for (tex, &wk) in cluster[1..].iter().zip(w) {
            tex.add_scaled(wk, out);
        }
    }

    /// The normtexture of (view slot, light), linear RGB, row-major.
    ///
    /// # Panics
    /// If `view` or `light` ≥ 81.
    pub fn image(&self, view: usize, light: usize) -> Vec<[f32; 3]> {
        let at = abrdf_index(view, light, 0);
        let stride = self.stride();
        (0..self.labels.len())
            .map(|t| {
                let cluster = &self.clusters[self.labels[t] as usize];
                let w = &self.weights[t * stride..(t + 1) * stride];
                std::array::from_fn(|c| {
                    let mut v = cluster[0].get(at + c);
                    for (tex, &wk) in cluster[1..].iter().zip(w) {
                        v += wk * tex.get(at + c);
                    }
                    v
                })
            })
            .collect()
    }

    /// Error against `btf` over all 6,561 images (see the [module docs](super)).
    ///
    /// # Errors
    /// [`BtfError::LengthMismatch`] if `btf` has another size.
    pub fn stats(&self, btf: &AbrdfMatrix) -> Result<ErrorStats> {
        check_size(btf, self.width, self.height)?;
        // Dense f32 copies of the textures, so the loop below is plain multiply–adds.
        let dense: Vec<Vec<Vec<f32>>> = self
            .clusters
            .iter()
            .map(|c| c.iter().map(Texture::dequantize).collect())
            .collect();
        let stride = self.stride();
        const CHUNK: usize = 64;
        let acc = (0..self.labels.len().div_ceil(CHUNK))
            .into_par_iter()
            .map(|b| {
                let mut acc = Acc::default();
                let mut out = vec![0.0f32; ABRDF_LEN];
                for t in b * CHUNK..((b + 1) * CHUNK).min(self.labels.len()) {
                    let tex = &dense[self.labels[t] as usize];
                    out.copy_from_slice(&tex[0]);
                    let w = &self.weights[t * stride..(t + 1) * stride];
                    for (basis, &wk) in tex[1..].iter().zip(w) {
                        out.iter_mut().zip(basis).for_each(|(o, &e)| *o += wk * e);
                    }
                    acc.add(btf.abrdf(t), &out);
                }
                acc
            })
            .reduce(Acc::default, Acc::merge);
        Ok(acc.finish(DIRECTIONS * DIRECTIONS))
    }
}

/// `m` distinct texels of `n` (all, in order, if m ≥ n), from a seeded Fisher–Yates shuffle,
/// sorted. Random rather than strided: a stride can alias with the weave's period.
fn random_subset(n: usize, m: usize, seed: u64) -> Vec<usize> {
    if m >= n {
        return (0..n).collect();
    }
    let mut state = seed ^ 0x5042_4d46; // "PBMF"
    let mut next = || {
        // SplitMix64.
        state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    };
    let mut all: Vec<usize> = (0..n).collect();
    for i in 0..m {
        let j = i + (next() % (n - i) as u64) as usize;
        all.swap(i, j);
    }
    all.truncate(m);
    all.sort_unstable();
    all
}

/// Step 2 of local PCA on every texel: the cluster of least squared reconstruction error
/// ‖x − r_k‖² − Σ_j ⟨x − r_k, e_kj⟩², from one GEMM per block of texels against
/// M = [E_1 … E_k | r_1 … r_k] (the ‖x‖² common to all clusters is left out).
fn assign(btf: &AbrdfMatrix, lp: &LocalPca) -> Vec<u32> {
    const ROWS: usize = 128;
    let (k, c, d) = (lp.k(), lp.n_components(), ABRDF_LEN);
    let mut big = Mat::<f64>::zeros(d, k * c + k);
    for j in 0..k {
        big.as_mut().subcols_mut(j * c, c).copy_from(lp.basis(j));
        big.col_as_slice_mut(k * c + j).copy_from_slice(lp.mean(j));
    }
    let dot = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(x, y)| x * y).sum::<f64>();
    let re: Vec<f64> = (0..k * c)
        .map(|col| dot(lp.mean(col / c), big.col_as_slice(col)))
        .collect();
    let rr: Vec<f64> = (0..k).map(|j| dot(lp.mean(j), lp.mean(j))).collect();
    let big = big.as_ref();
    let lut = srgb8_table();
    let n = btf.texels();
    (0..n.div_ceil(ROWS))
        .into_par_iter()
        .flat_map_iter(|b| {
            let rows = b * ROWS..((b + 1) * ROWS).min(n);
            let w = rows.len();
            let mut x = vec![0.0f64; w * d];
            for (o, t) in x.chunks_exact_mut(d).zip(rows) {
                o.iter_mut()
                    .zip(btf.abrdf(t))
                    .for_each(|(v, &q)| *v = f64::from(lut[usize::from(q)]));
            }
            let mut s = Mat::<f64>::zeros(w, k * c + k);
            let xt = MatRef::from_column_major_slice(&x, d, w);
            faer::linalg::matmul::matmul(
                s.as_mut(),
                Accum::Replace,
                xt.transpose(),
                big,
                1.0,
                Par::Seq,
            );
            (0..w)
                .map(|r| {
                    let err = |j: usize| {
                        let proj: f64 = (0..c)
                            .map(|i| (s.get(r, j * c + i) - re[j * c + i]).powi(2))
                            .sum();
                        rr[j] - 2.0 * s.get(r, k * c + j) - proj
                    };
                    (0..k)
                        .map(|j| (j, err(j)))
                        .min_by(|a, b| a.1.total_cmp(&b.1))
                        .map_or(0, |(j, _)| j as u32)
                })
                .collect::<Vec<_>>()
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn random_subset_is_distinct_and_sorted() {
        let s = random_subset(1000, 100, 3);
        assert_eq!(s.len(), 100);
        assert!(s.windows(2).all(|w| w[0] < w[1]) && s[99] < 1000);
        assert_eq!(random_subset(10, 20, 0), (0..10).collect::<Vec<_>>());
    }
}
