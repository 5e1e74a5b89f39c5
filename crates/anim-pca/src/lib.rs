//! New animation from a short mesh clip, computed on its principal components (thesis §3.2).
//!
//! A short basis animation (a walk cycle, a gallop, cloth flapping) is analysed once: PCA
//! compresses every frame to c weights, frame-to-frame distances of positions and velocities
//! on those weights become transition probabilities, and their product is the *jump map*
//! (thesis §3.2 "Sequence Generation", eqs. 3.1–3.13, after Schödl et al.'s video textures).
//! A player then walks the jump map forever, frame by frame, jumping wherever the clip
//! resembles itself, with blended transitions; the frames are rebuilt from their weights.
//!
//! * [`JumpMap`] — analysis (§3.2.2): D, D*, P, P*, P̂ (eqs. 3.2–3.8) and dead-end pruning.
//! * [`Player`] — endless seeded play with memory and blending (eqs. 3.9–3.11), and motion
//!   control between cells ([`JumpMap::analyze_cells`], [`Player::set_target_cell`]).
//! * [`LoopTable`] — the cheapest fixed-length loop of every length (Fig. 3.2).
//! * [`Reconstructor`] — frames from weights (eq. 3.1).
//! * [`jumpmap::metrics`] — E(c), E*(c) (eqs. 3.12–3.13) and quality of a generated run.
//! * [`compress`] — clustered-PCA compression (§3.3): encoder, `.cpca` container, random-access
//!   CPU decoder, d_a/d_f and bpvf (eqs. 3.14–3.18).
//!
//! Where the implementation departs from the printed equations (the distance unit, the last
//! frame, eq. 3.10) is listed in [`jumpmap`]. Frames come in as `glam::Vec3` per vertex; the
//! PCA is `clustering`'s, all distances and probabilities are f64.
//!
//! ```
//! use anim_pca::{JumpMap, JumpMapParams, PlaybackParams, Player};
//! use glam::Vec3;
//!
//! // A 16-vertex strip waving with a period of 10 frames, 35 frames long.
//! let frames: Vec<Vec<Vec3>> = (0..35)
//!     .map(|t| {
//!         (0..16)
//!             .map(|n| {
//!                 let phase = (t as f32 / 10.0 + n as f32 / 16.0) * std::f32::consts::TAU;
//!                 Vec3::new(n as f32, phase.sin(), 0.0)
//!             })
//!             .collect()
//!     })
//!     .collect();
//! let map = JumpMap::analyze(&frames, &JumpMapParams::default()).unwrap();
//! let mut player = Player::new(&map, &PlaybackParams::default()).unwrap();
//! let run = player.generate(1000);
//!
//! // Rebuild frame 500 of the new sequence.
//! let mut w = vec![0.0; map.components()];
//! run.frames[500].weights_into(&map, &mut w);
//! let mut mesh = vec![Vec3::ZERO; 16];
//! map.reconstructor().reconstruct(&w, &mut mesh).unwrap();
//! assert!(mesh.iter().all(|v| v.is_finite()));
//! assert!(!run.transitions.is_empty()); // it did loop
//! ```

pub mod compress;
mod error;
pub mod jumpmap;
mod matrix;

pub use compress::{Compressed, CpcaModel, CpcaParams, Decoder};
pub use error::{AnimPcaError, Result};
pub use jumpmap::metrics::{ReconstructionError, SequenceStats};
pub use jumpmap::{
    AttributeReconstructor, Blend, Clip, Generated, GeneratedFrame, JumpMap, JumpMapParams, Loop,
    LoopTable, PlaybackParams, Player, Reconstructor, RootMotion, Transition,
};
pub use matrix::SquareMatrix;
