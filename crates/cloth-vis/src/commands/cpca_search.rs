//! `cloth-vis anim compress --target-da X | --target-bpvf X`: which search answers a target.
//!
//! By default the whole rate–distortion space is searched — k, c, c*, q_c and q_w
//! ([`search_rate_distortion`], issue #19) — so a rate budget is met by the best file any of
//! them gives. `--search k` keeps the thesis's own procedure (§3.3.2: raise k from 1 with c,
//! c* and the bits fixed; [`search_clusters`]), for reproducing it.

use anim_pca::compress::{
    Compressed, CpcaParams, RateTarget, RdLimits, RdPoint, SearchStep, search_clusters,
    search_rate_distortion,
};

/// How a target is searched.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SearchMode {
    /// Every parameter: (k, c, c*, q_c, q_w), within these limits.
    Full(RdLimits),
    /// k = 1, 2, … up to `k_max` with c, c* and the bits of the request (thesis §3.3.2).
    Clusters {
        /// Largest k tried.
        k_max: usize,
    },
}

/// What a search did.
#[derive(Clone, Debug, PartialEq)]
pub struct SearchReport {
    /// Whether it searched every parameter (else k alone).
    pub full: bool,
    /// Points judged: one per (k, c, c*) (or per k).
    pub points: usize,
    /// Local-PCA fits run.
    pub fits: usize,
    /// Encodings run.
    pub encodings: usize,
    /// Whether the chosen point meets the target (else it is the closest).
    pub reached: bool,
    /// (k, c) skipped by the cost bound (`--max-cost`).
    pub skipped_for_cost: usize,
}

impl SearchReport {
    /// The summary line's note on the search.
    pub fn text(&self) -> String {
        let what = if self.full {
            let costly = match self.skipped_for_cost {
                0 => String::new(),
                n => format!(
                    "; {n} larger (k, c) skipped as too slow to fit (--max-cost; raising it may \
                     find a better point, at more time)"
                ),
            };
            format!(
                "searched k, c, c*, q_c, q_w: {} points, {} fits, {} encodings{costly}",
                self.points, self.fits, self.encodings
            )
        } else {
            format!("searched k = 1..={}", self.points)
        };
        if self.reached {
            format!(" ({what}; target met)")
        } else {
            format!(" ({what}; target NOT met by any; kept the closest)")
        }
    }
}

/// Runs `mode` for `target` on `clip`; `params` gives the seed and local-PCA settings (and, for
/// [`SearchMode::Clusters`], c, c* and the bits). Each point judged goes to stderr.
pub(super) fn search(
    clip: &meshio::Animation,
    params: &CpcaParams,
    target: RateTarget,
    mode: SearchMode,
) -> anim_pca::Result<(Compressed, SearchReport)> {
    match mode {
        SearchMode::Clusters { k_max } => {
            let mut report = |s: &SearchStep| {
                eprintln!(
                    "  k = {:>3}: d_a = {:.4}, {:.3} bpvf (file), {:.2} s",
                    s.k, s.da, s.bpvf, s.seconds
                );
            };
            let found = search_clusters(
                &clip.frames,
                &clip.triangles,
                clip.frame_rate,
                params,
                target,
                k_max,
                &mut report,
            )?;
            let report = SearchReport {
                full: false,
                points: found.steps.len(),
                fits: found.steps.len(),
                encodings: found.steps.len(),
                reached: found.reached,
                skipped_for_cost: 0,
            };
            Ok((found.compressed, report))
        }
        SearchMode::Full(limits) => {
            let mut report = |p: &RdPoint| eprintln!("  {}", point_text(p));
            let found = search_rate_distortion(
                &clip.frames,
                &clip.triangles,
                clip.frame_rate,
                params,
                target,
                &limits,
                &mut report,
            )?;
            let report = SearchReport {
                full: true,
                points: found.points.len(),
                fits: found.fits,
                encodings: found.encodings,
                reached: found.reached(),
                skipped_for_cost: found.skipped_for_cost,
            };
            Ok((found.compressed, report))
        }
    }
}

/// One point of a full search, as printed while it runs.
pub fn point_text(p: &RdPoint) -> String {
    format!(
        "k = {:>3}, c = {:>2}, c* = {:>3}, q_c = {:>2}, q_w = {:>2}: d_a = {}, {:.3} bpvf{}",
        p.clusters,
        p.components,
        p.time_components
            .map_or_else(|| "-".to_owned(), |c| c.to_string()),
        p.bits_components,
        p.bits_weights,
        da_text(p.da),
        p.bpvf,
        if p.meets { "" } else { " (misses the target)" }
    )
}

/// How far above the searched point's d_a a file may be and still count as on the frontier:
/// 5 % (the search samples the bits and k, c on a lattice, so it is itself a few percent off
/// the true frontier).
pub const FRONTIER_SLACK: f64 = 0.05;

/// Where a `.cpca` file sits against the rate–distortion frontier (`anim stats --frontier`):
/// the point the full search finds at the file's own rate.
#[derive(Clone, Debug, PartialEq)]
pub struct FrontierPosition {
    /// The file's bpvf: the search's budget.
    pub budget: f64,
    /// The searched point within that budget.
    pub point: RdPoint,
    /// The file's d_a over the searched point's d_a: above 1, the file spends its bits less
    /// well than the frontier; at or below 1, it is on (or past) it.
    pub ratio: f64,
    /// Seconds the search took.
    pub seconds: f64,
}

impl FrontierPosition {
    /// Searches (k, c, c*, q_c, q_w) on `clip` within the file's rate `bpvf` and compares with
    /// the file's `da`.
    pub(super) fn measure(clip: &meshio::Animation, bpvf: f64, da: f64) -> anim_pca::Result<Self> {
        let found = search_rate_distortion(
            &clip.frames,
            &clip.triangles,
            clip.frame_rate,
            &CpcaParams::default(),
            RateTarget::Bpvf(bpvf),
            &RdLimits::default(),
            &mut |_| {},
        )?;
        Ok(Self {
            budget: bpvf,
            point: found.chosen,
            ratio: da / found.chosen.da,
            seconds: found.seconds,
        })
    }

    /// The stats line's note.
    pub fn text(&self) -> String {
        let verdict = if self.ratio > 1.0 + FRONTIER_SLACK {
            format!(
                "this file's d_a is {:.2}× the frontier's: `anim compress --target-bpvf {:.3}` \
                 would do better",
                self.ratio, self.budget
            )
        } else {
            format!(
                "this file is on the frontier (its d_a is {:.2}× the searched point's, within \
                 {:.0} %)",
                self.ratio,
                100.0 * FRONTIER_SLACK
            )
        };
        format!(
            "\nfrontier: at this file's rate the search reaches {} ({:.1} s); {verdict}",
            point_text(&self.point),
            self.seconds
        )
    }
}

/// `--search`: how a target is searched.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub(super) enum SearchArg {
    /// k, c, c*, q_c and q_w.
    Full,
    /// k alone (thesis §3.3.2).
    K,
}

/// Refuses search flags no search can use, naming the flag, before the clip is loaded: a
/// target (or the cost bound, `targets[2]`) that is not positive and finite, a limit of 0, and a parameter fixed on the command
/// line (`fixed`: flag, given) that a full search would search instead.
pub(super) fn check_flags(
    targets: [(&str, Option<f64>); 3],
    limits: [(&str, usize); 3],
    fixed: [(&str, bool); 4],
    search: SearchArg,
) -> anyhow::Result<()> {
    for (flag, value) in targets {
        if let Some(x) = value.filter(|x| !(x.is_finite() && *x > 0.0)) {
            anyhow::bail!("{flag} {x}: must be a positive finite number");
        }
    }
    if let Some((flag, _)) = limits.iter().find(|(_, n)| *n == 0) {
        anyhow::bail!("{flag} 0: a search limit must be at least 1");
    }
    let targeted = targets[..2].iter().any(|(_, t)| t.is_some());
    if let Some((flag, _)) = fixed.iter().find(|(_, given)| *given)
        && targeted
        && search == SearchArg::Full
    {
        anyhow::bail!(
            "{flag} is searched with --target-da/--target-bpvf; drop it, or add \
                 `--search k` to keep it fixed while k alone is searched (thesis §3.3.2)"
        );
    }
    Ok(())
}

/// d_a with four significant decimals, in scientific notation below 0.01 (exact clips reach
/// 10⁻⁵).
fn da_text(da: f64) -> String {
    if da != 0.0 && da.abs() < 0.01 {
        format!("{da:.3e}")
    } else {
        format!("{da:.4}")
    }
}
