//! Jump maps: new, endless animation from a short mesh clip (thesis §3.2, eqs. 3.1–3.13).
//!
//! Video textures (Schödl et al. 2000) carried over to geometry and computed on PCA weights
//! (Sattler et al. 2004):
//!
//! 1. [`JumpMap::analyze`] (§3.2.2): PCA of the frame vectors A_i with c components (eq. 3.1),
//!    PCA of the central velocities with c* components (eq. 3.4), L1 distance matrices D, D*
//!    on the weights (eqs. 3.2, 3.5), transition probabilities P, P* (eqs. 3.3, 3.6) and the
//!    jump map P̂ (eq. 3.8), then a dead-end pruning pass ([`graph`]).
//! 2. [`Player`]: endless random play with a memory of m < 5 frames, blended (eq. 3.9–3.10)
//!    or variable-length (eq. 3.11) transitions, deterministic for a seed.
//!    Several clips analysed together are *cells* ([`JumpMap::analyze_cells`]): random play
//!    stays in its cell, and [`Player::set_target_cell`] moves to another one at the best
//!    transition ahead (§3.2.2 "Motion Control").
//! 3. [`LoopTable`]: the cheapest fixed-length loop of every length (Fig. 3.2, [`loops`]).
//! 4. Output frames: [`JumpMap::exact_frame_into`] gives the clip's own frames, bit for bit,
//!    outside blends and position-space cross-fades inside them ([`exact`]): c is a parameter
//!    of the analysis, not of the output. [`Reconstructor`] rebuilds frames from weights
//!    (eq. 3.1, f32, allocation-free) where only weights exist; attribute vectors R_i have a
//!    PCA and an [`AttributeReconstructor`] of their own.
//! 5. [`metrics`]: E(c), E*(c) (eqs. 3.12–3.13) and measures of a generated sequence.
//!
//! # Deviations from the thesis, and why
//! * **Distance unit.** D and D* are divided by their mean off-diagonal entry, so σ, σ* are
//!   fractions of a typical frame distance and the thesis's σ ≈ 0.05 (avatar) and 0.30
//!   (skeleton) mean the same on every clip, whatever its size, units or c.
//! * **Last frame** (no successor for eq. 3.3's D_{i+1,j}): its row uses the target's
//!   predecessor, P_{l−1,j} ∝ exp(−D_{l−1,j−1}/σ), j ∈ 1 … l−2; see [`probability`].
//! * **End velocities** (eq. 3.4 sets v_0 = v_l = 0): an end that repeats another frame (a
//!   cycle with a closing frame, within [`CLOSING_MATCH`]·d̄) takes that frame's neighbour
//!   into its central difference; other ends use one-sided differences. Zero end velocities
//!   would make the ends look like rest poses and forbid the very jumps a loop needs.
//! * **Eq. 3.10** is replaced by a linear cross-fade between two advancing streams; eq. 3.11
//!   measures the jump residual ‖Ã_{i+1} − Ã_j‖; see [`player`].
//! * **P̂** is row-normalised after eq. 3.8 so that it can be sampled.

pub mod exact;
pub mod graph;
pub mod loops;
pub mod metrics;
pub mod player;
pub mod probability;

mod analysis;
mod cells;
mod params;
mod reconstruct;
mod validate;

pub use analysis::{CLOSING_MATCH, Clip, JumpMap, JumpMapParams, RootMotion};
pub use loops::{Loop, LoopTable};
pub use player::{Blend, Generated, GeneratedFrame, PlaybackParams, Player, Transition};
pub use reconstruct::{AttributeReconstructor, Reconstructor};
