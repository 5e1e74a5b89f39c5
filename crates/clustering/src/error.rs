//! The crate's error type.

use std::ops::Range;

/// Boxed error returned by a user's [`ColumnBlockSource`](crate::ColumnBlockSource).
pub type SourceError = Box<dyn std::error::Error + Send + Sync + 'static>;

/// Everything that can go wrong in `clustering`.
///
/// Each variant names the call (`what`), the element and the value, and its message says how
/// to fix the input. Numerical failures of faer's decompositions are reported, never panicked on.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ClusteringError {
    /// An input element is NaN or infinite.
    #[error(
        "{what}: element (row {row}, column {col}) is {value}; PCA, k-means and local PCA need \
         finite numbers, so remove or impute NaN/infinite entries before fitting"
    )]
    NonFinite {
        /// The call that received the data, e.g. `"Pca::fit data"`.
        what: &'static str,
        /// Row (sample) index of the element.
        row: usize,
        /// Column (feature) index of the element.
        col: usize,
        /// The offending value.
        value: f64,
    },
    /// The data matrix has too few rows or no columns.
    #[error(
        "{what}: the data is {rows} × {cols}, but at least {min_rows} sample row(s) and one \
         feature column are needed; pass a larger matrix"
    )]
    TooFewSamples {
        /// The call that received the data.
        what: &'static str,
        /// Rows (samples) given.
        rows: usize,
        /// Columns (features) given.
        cols: usize,
        /// Rows needed.
        min_rows: usize,
    },
    /// New data has a different number of features than the fitted model.
    #[error(
        "{what}: the data has {found} feature columns but the model was fitted on {expected}; \
         pass rows with {expected} features"
    )]
    DimensionMismatch {
        /// The call that received the data.
        what: &'static str,
        /// Feature count of the model.
        expected: usize,
        /// Feature count of the data.
        found: usize,
    },
    /// A tuning parameter is out of range.
    #[error("{what}: parameter `{name}` = {value} is invalid: {reason}")]
    InvalidParameter {
        /// The call that received the parameter.
        what: &'static str,
        /// Field name, e.g. `"k"`.
        name: &'static str,
        /// The value given, printed.
        value: String,
        /// What range is valid.
        reason: &'static str,
    },
    /// More clusters were requested than there are samples.
    #[error(
        "{what}: k = {k} clusters requested but the data has only {samples} samples; choose \
         k ≤ {samples}"
    )]
    TooManyClusters {
        /// The call that received the parameter.
        what: &'static str,
        /// Clusters requested.
        k: usize,
        /// Samples available.
        samples: usize,
    },
    /// A faer decomposition did not converge.
    #[error(
        "{what}: faer's {decomposition} did not converge on a {rows} × {cols} matrix; the data \
         is probably badly scaled (rescale features to comparable magnitudes)"
    )]
    NoConvergence {
        /// The call that ran the decomposition.
        what: &'static str,
        /// Which decomposition (`"thin SVD"`, `"self-adjoint eigendecomposition"`).
        decomposition: &'static str,
        /// Rows of the decomposed matrix.
        rows: usize,
        /// Columns of the decomposed matrix.
        cols: usize,
    },
    /// A streaming source failed to deliver a block.
    #[error("{what}: the source failed while reading features {}..{}: {source}", features.start, features.end)]
    Source {
        /// The call that read the source.
        what: &'static str,
        /// The feature range that was requested.
        features: Range<usize>,
        /// The source's own error.
        #[source]
        source: SourceError,
    },
}

/// Result alias of this crate.
pub type Result<T, E = ClusteringError> = std::result::Result<T, E>;
