//! PCA, k-means and Kambhatla–Leen local PCA that stay exact on hard data (thesis §2.7).
//!
//! BTF compression (per-view PCA of the 81 light images), animation synthesis (the jump map's
//! PCA weights) and animation compression (clustered PCA of vertex trajectories) all stand on
//! this crate. It depends on no other project crate.
//!
//! * [`Pca`] — §2.7.2–2.7.3: mean-centred PCA (eq. 2.46–2.47) via faer's thin SVD (eq. 2.45),
//!   the n × n Gram matrix when n ≪ d or the d × d covariance when d ≪ n (the "covariance
//!   matrix of the smaller side", §3.3.2), randomized subspace iteration, and an out-of-core
//!   streaming path ([`Pca::fit_streaming`]); the number of components by an energy fraction or
//!   by the rule λᵢ < λ̄ (eq. 2.52–2.53, [`ComponentCount`]).
//! * [`KMeans`] — §2.7.4, eq. 2.54: Lloyd's algorithm with k-means++ seeding refined by
//!   local-search swaps (default) or random-sample initialisation (the thesis), empty clusters
//!   reseeded from the worst-served point, multi-threaded assignment.
//! * [`LocalPca`] — §2.7.4 "Clustered Principal Component Analysis", steps 1–5 (Kambhatla &
//!   Leen 1997): clusters assigned by squared reconstruction error; and
//!   [`LocalPca::search_k`], the outer search over k of §3.3.2 (target error or size budget).
//!
//! Data enters as a faer `MatRef<'_, T>` with `T` = `f32` or `f64` ([`Element`]), rows are
//! samples, any strides. All accumulation is f64. PCA's Gram, covariance and randomized paths
//! read the input block-wise, so f32 input (a BTF slot) is never duplicated; the SVD path,
//! k-means and local PCA work on one translated f64 copy. Every fit centres or translates the data before it forms a
//! product, so a 1e6 offset on unit-variance data costs no precision. NaN or infinite input is
//! an error ([`ClusteringError::NonFinite`]), never a panic. All randomness comes from a
//! `seed` (ChaCha8): results are deterministic for a seed and independent of the thread count
//! (work is split into fixed blocks reduced in a fixed order). faer's SIMD kernels may differ
//! in the last bits across CPU generations.
//!
//! ```
//! use clustering::{KMeans, KMeansParams, LocalPca, LocalPcaParams, Pca, PcaParams};
//! use faer::Mat;
//!
//! // Two lines in the plane: y = x near the origin and y = −x around (10, 0).
//! let data = Mat::from_fn(40, 2, |i, j| {
//!     let t = (i % 20) as f64 * 0.1;
//!     match (i < 20, j) {
//!         (true, 0) => t,
//!         (true, _) => t,
//!         (false, 0) => 10.0 + t,
//!         (false, _) => -t,
//!     }
//! });
//! let pca = Pca::fit(data.as_ref(), &PcaParams::default()).unwrap();
//! assert_eq!(pca.n_components(), 2);
//!
//! let km = KMeans::fit(data.as_ref(), &KMeansParams { k: 2, ..Default::default() }).unwrap();
//! assert_ne!(km.labels()[0], km.labels()[39]);
//!
//! // One axis per cluster reproduces both lines exactly.
//! let params = LocalPcaParams { k: 2, components: 1, ..Default::default() };
//! let lpca = LocalPca::fit(data.as_ref(), &params).unwrap();
//! assert!(lpca.mean_error() < 1e-20);
//! ```

mod element;
mod error;
mod kmeans;
mod linalg;
mod local_pca;
mod pca;
mod subspace;

pub use element::Element;
pub use error::{ClusteringError, Result, SourceError};
pub use kmeans::{KMeans, KMeansInit, KMeansParams};
pub use local_pca::{
    KSearch, KSearchParams, KSearchStep, KSearchStop, LocalPca, LocalPcaInit, LocalPcaParams,
};
pub use pca::{ColumnBlockSource, ComponentCount, Pca, PcaMethod, PcaParams, RandomizedParams};

pub use faer;
