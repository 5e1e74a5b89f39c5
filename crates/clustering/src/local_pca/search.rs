//! The outer search over k of thesis §3.3.2: "the desired maximal reconstruction error or the
//! available bandwidth … can be used as a stopping criterium for increasing k, starting with
//! k = 1". Each k is a full [`LocalPca`] fit with the same seed and component count.

use faer::MatRef;

use super::{LocalPca, LocalPcaParams, WHAT, model_scalars, validate};
use crate::element::{Element, Samples, check_shape};
use crate::error::{ClusteringError, Result};

/// Parameters of [`LocalPca::search_k`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct KSearchParams {
    /// First k tried (the thesis starts at 1).
    pub k_min: usize,
    /// Last k tried (clamped to n).
    pub k_max: usize,
    /// Stop at the first k whose mean squared reconstruction error is ≤ this.
    pub target_mean_error: Option<f64>,
    /// Never fit a k whose model would need more scalars than this
    /// (see [`LocalPca::model_scalars`]).
    pub max_model_scalars: Option<usize>,
}

impl Default for KSearchParams {
    fn default() -> Self {
        Self {
            k_min: 1,
            k_max: 32,
            target_mean_error: None,
            max_model_scalars: None,
        }
    }
}

/// Why the search ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum KSearchStop {
    /// A fit reached `target_mean_error`; it is the returned model.
    TargetReached,
    /// The next k would exceed `max_model_scalars`; the best fit so far is returned.
    BudgetReached,
    /// `k_max` was fitted without reaching the target; the best fit is returned.
    KMaxReached,
}

/// One fitted k.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct KSearchStep {
    /// Clusters.
    pub k: usize,
    /// Mean squared reconstruction error.
    pub mean_error: f64,
    /// Model size in scalars.
    pub model_scalars: usize,
    /// Iterations the fit ran.
    pub iterations: usize,
}

/// Result of [`LocalPca::search_k`].
#[derive(Clone, Debug)]
pub struct KSearch {
    /// The chosen fit: the first to reach the target, else the one of lowest error.
    pub model: LocalPca,
    /// Every k fitted, in order.
    pub steps: Vec<KSearchStep>,
    /// Why the search stopped.
    pub stop: KSearchStop,
}

impl LocalPca {
    /// Increases k from `search.k_min` until the mean error reaches the target, the size
    /// budget would be exceeded or `k_max` is done (thesis §3.3.2). `params.k` is ignored.
    ///
    /// # Errors
    /// As [`LocalPca::fit`]; [`ClusteringError::InvalidParameter`] when `k_min` is 0 or above
    /// `k_max`, or when even `k_min` exceeds the size budget.
    ///
    /// # Examples
    /// ```
    /// use clustering::{KSearchParams, KSearchStop, LocalPca, LocalPcaParams};
    /// // Three separated points: k = 3 reproduces them exactly.
    /// let data = faer::Mat::from_fn(30, 2, |i, j| ((i % 3) * 10 + j) as f64);
    /// let base = LocalPcaParams { components: 0, ..Default::default() };
    /// let s = KSearchParams { target_mean_error: Some(1e-12), ..Default::default() };
    /// let r = LocalPca::search_k(data.as_ref(), &base, &s).unwrap();
    /// assert_eq!(r.stop, KSearchStop::TargetReached);
    /// assert_eq!(r.model.k(), 3);
    /// ```
    pub fn search_k<T: Element>(
        data: MatRef<'_, T>,
        params: &LocalPcaParams,
        search: &KSearchParams,
    ) -> Result<KSearch> {
        let (n, d) = (data.nrows(), data.ncols());
        check_shape(WHAT, n, d, 1)?;
        let bad = |name, value: String, reason| {
            Err(ClusteringError::InvalidParameter {
                what: "LocalPca::search_k",
                name,
                value,
                reason,
            })
        };
        if search.k_min == 0 || search.k_min > search.k_max {
            return bad(
                "k_min",
                search.k_min.to_string(),
                "k_min must be ≥ 1 and ≤ k_max",
            );
        }
        let c = params.components;
        if let Some(budget) = search.max_model_scalars {
            if model_scalars(search.k_min, d, c, n) > budget {
                return bad(
                    "max_model_scalars",
                    budget.to_string(),
                    "the budget is smaller than the model for k_min",
                );
            }
        }
        validate(
            &LocalPcaParams {
                k: search.k_min,
                ..*params
            },
            n,
            d,
        )?;
        let x = Samples::new(WHAT, data)?;
        let mut steps = Vec::new();
        let mut best: Option<LocalPca> = None;
        let mut stop = KSearchStop::KMaxReached;
        for k in search.k_min..=search.k_max.min(n) {
            let size = model_scalars(k, d, c, n);
            if search.max_model_scalars.is_some_and(|b| size > b) {
                stop = KSearchStop::BudgetReached;
                break;
            }
            let fit = LocalPca::fit_samples(&x, &LocalPcaParams { k, ..*params })?;
            let e = fit.mean_error();
            steps.push(KSearchStep {
                k,
                mean_error: e,
                model_scalars: size,
                iterations: fit.iterations(),
            });
            if search.target_mean_error.is_some_and(|t| e <= t) {
                return Ok(KSearch {
                    model: fit,
                    steps,
                    stop: KSearchStop::TargetReached,
                });
            }
            if best.as_ref().is_none_or(|b| e < b.mean_error()) {
                best = Some(fit);
            }
        }
        match best {
            Some(model) => Ok(KSearch { model, steps, stop }),
            None => bad(
                "k_min",
                search.k_min.to_string(),
                "no k in k_min..=k_max could be fitted",
            ),
        }
    }
}
