//! Endless random play from the jump map (thesis §3.2.2 "Generate Jump Map", "Blending
//! Transitions", "Variable Length Transitions", eqs. 3.9–3.11).
//!
//! At every key frame i the player draws the next key frame j from row i of the pruned jump
//! map ([`JumpMap::sampling_matrix`]), skipping the last m visited key frames (the thesis's
//! memory against back-and-forth jitter). When no candidate is left it takes the natural
//! successor i + 1 if the pruning allows it, else it ignores the memory. j = i + 1 is normal
//! playback; anything else is a *transition*, optionally blended over b frames.
//!
//! # Blending (eq. 3.9–3.10)
//! Eq. 3.10 as printed, w_i + (w_j − w_i)/(b(b − t + 1)), is not a linear ramp: the fraction
//! of the way to w_j runs 1/b², 1/(b(b−1)), …, 1/b over t = 1 … b (for b = 3: 1/9, 1/6, 1/3),
//! unequally spaced and only 1/b of the way at the last blend frame, so the cut it was meant to
//! hide is still (1 − 1/b) of the jump. The intended linear ramp w_i + (w_j − w_i)·t/(b+1) between the two
//! *still* poses is not right either: since j resembles i + 1 (eq. 3.3), w_j − w_i is about one
//! frame's motion, and spreading it over b + 1 frames slows the motion to 1/(b+1) of its speed
//! for the blend: a velocity drop at every transition. We therefore ramp the blend weight
//! linearly, α_t = t/(b+1), between two *advancing* streams, as video textures cross-fade:
//!
//! w_{i'_t} = (1 − α_t)·w_{i+t} + α_t·w_{j−(b+1)+t},  t = 1 … b,
//!
//! the source playing on from i and the target arriving at j. At t = 0 this is w_i, at
//! t = b + 1 it is w_j; both streams move at the clip's own speed, and the residual
//! w_{i+1} − w_j is spread over b + 1 frames. Where a stream would leave the clip (i + b > l−1
//! or j − b − 1 < 0) the blend is shortened to b' = min(b, l − 1 − i, j), so a jump from the
//! last frame (which only goes to frames whose predecessor matches it) is a plain cut.
//!
//! Blending does not touch the random stream: the key frames visited for a seed are the same
//! whatever the blend, so runs with and without blending can be compared jump by jump.
//!
//! # Variable length (eq. 3.11)
//! b = ‖Ã_{i+1} − Ã_j‖₂ / s, rounded, at most [`MAX_BLEND_FRAMES`]. The thesis divides
//! ‖Ã_i − Ã_j‖₂; we use the jump residual ([`JumpMap::jump_residual`]) because that is the
//! discontinuity the blend has to hide (‖Ã_i − Ã_j‖ is about one frame step even for a
//! perfect jump). s is given in units of d̄, the clip's mean frame-to-frame distance (the
//! thesis's suggested start value is s = d̄, i.e. 1.0 here).

use std::collections::VecDeque;

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::JumpMap;
use crate::error::{Result, invalid};

/// The memory m must be below this (thesis: "m < 5").
pub const MAX_MEMORY_EXCLUSIVE: usize = 5;
/// Upper bound on blend frames b (fixed or from eq. 3.11): a transition longer than this is
/// no longer a transition but new motion. Set to about one second at 30 fps.
pub const MAX_BLEND_FRAMES: usize = 32;

/// Default [`PlaybackParams::control_horizon`]: about one second at 30 fps.
pub const DEFAULT_CONTROL_HORIZON: usize = 30;

const WHAT: &str = "Player::new";

/// How transitions are blended.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Blend {
    /// Cut straight from i to j.
    None,
    /// b blend frames per transition (eq. 3.9; the thesis uses b = 3), ≤ [`MAX_BLEND_FRAMES`].
    Fixed(usize),
    /// Variable length from the smoothness s (eq. 3.11), in units of the clip's mean
    /// frame-to-frame distance d̄ (> 0, finite).
    Smoothness(f64),
}

/// Parameters of [`Player`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlaybackParams {
    /// m: how many of the last visited key frames are forbidden as jump targets (< 5). The
    /// current frame counts, so m ≥ 1 forbids standing still.
    pub memory: usize,
    /// Transition blending.
    pub blend: Blend,
    /// First key frame.
    pub start_frame: usize,
    /// Seed of the ChaCha8 stream that draws the jumps.
    pub seed: u64,
    /// How many frames ahead the player looks for the best place to leave its cell after
    /// [`Player::set_target_cell`] (≥ 1; the thesis's motion control, §3.2.2).
    pub control_horizon: usize,
}

impl Default for PlaybackParams {
    fn default() -> Self {
        Self {
            memory: 2,
            blend: Blend::Fixed(3),
            start_frame: 0,
            seed: 0,
            control_horizon: DEFAULT_CONTROL_HORIZON,
        }
    }
}

/// One generated frame: the blend (1 − α)·w_from + α·w_to of two clip frames' PCA weights.
/// A plain key frame has `from == to` and α = 0.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GeneratedFrame {
    /// Source clip frame.
    pub from: usize,
    /// Target clip frame.
    pub to: usize,
    /// Blend weight α ∈ [0, 1).
    pub alpha: f64,
}

impl GeneratedFrame {
    /// The key frame i.
    pub fn key(i: usize) -> Self {
        Self {
            from: i,
            to: i,
            alpha: 0.0,
        }
    }

    /// Whether this is a plain clip frame.
    pub fn is_key(&self) -> bool {
        self.from == self.to || self.alpha == 0.0
    }

    /// Its attribute weights into `out` (length
    /// [`AttributeReconstructor::components`](super::AttributeReconstructor::components);
    /// nothing to do for a map without attributes).
    ///
    /// # Panics
    /// If `out` has the wrong length or the frame indices are out of the map's range.
    pub fn attribute_weights_into(&self, map: &JumpMap, out: &mut [f64]) {
        let (a, b) = (
            map.attribute_weights(self.from),
            map.attribute_weights(self.to),
        );
        assert_eq!(out.len(), a.len(), "attribute weights buffer length");
        for ((o, x), y) in out.iter_mut().zip(a).zip(b) {
            *o = (1.0 - self.alpha) * x + self.alpha * y;
        }
    }

    /// Its PCA weights into `out` (length [`JumpMap::components`]).
    ///
    /// # Panics
    /// If `out` has the wrong length or the frame indices are out of the map's range.
    pub fn weights_into(&self, map: &JumpMap, out: &mut [f64]) {
        let (a, b) = (map.weights(self.from), map.weights(self.to));
        assert_eq!(out.len(), a.len(), "weights buffer length");
        for ((o, x), y) in out.iter_mut().zip(a).zip(b) {
            *o = (1.0 - self.alpha) * x + self.alpha * y;
        }
    }
}

/// A transition i → j (j ≠ i + 1) taken during play.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Transition {
    /// Index, in the generated sequence, of the source key frame i.
    pub index: usize,
    /// Source key frame i.
    pub from: usize,
    /// Target key frame j (generated at `index + blend_frames + 1`).
    pub to: usize,
    /// Blend frames b actually inserted.
    pub blend_frames: usize,
}

/// A finite piece of generated animation with its transition log.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Generated {
    /// The frames, in play order.
    pub frames: Vec<GeneratedFrame>,
    /// Every transition taken, in order.
    pub transitions: Vec<Transition>,
}

/// Endless random play over a [`JumpMap`]; an [`Iterator`] that never ends.
#[derive(Clone, Debug)]
pub struct Player<'a> {
    map: &'a JumpMap,
    params: PlaybackParams,
    rng: ChaCha8Rng,
    current: usize,
    memory: VecDeque<usize>,
    queue: VecDeque<GeneratedFrame>,
    emitted: usize,
    last_transition: Option<Transition>,
    target_cell: Option<usize>,
}

impl<'a> Player<'a> {
    /// A player starting at `params.start_frame`.
    ///
    /// # Errors
    /// [`crate::AnimPcaError::InvalidParameter`] for m ≥ 5, a start frame outside the clip,
    /// b > [`MAX_BLEND_FRAMES`], or a smoothness that is not finite and > 0.
    pub fn new(map: &'a JumpMap, params: &PlaybackParams) -> Result<Self> {
        if params.memory >= MAX_MEMORY_EXCLUSIVE {
            return Err(invalid(
                WHAT,
                "memory",
                params.memory,
                "m must be < 5 (thesis §3.2.2)",
            ));
        }
        if params.start_frame >= map.n_frames() {
            return Err(invalid(
                WHAT,
                "start_frame",
                params.start_frame,
                "the start frame must be < the clip's frame count",
            ));
        }
        match params.blend {
            Blend::Fixed(b) if b > MAX_BLEND_FRAMES => {
                return Err(invalid(
                    WHAT,
                    "blend",
                    b,
                    "b must be ≤ MAX_BLEND_FRAMES (32)",
                ));
            }
            Blend::Smoothness(s) if !(s.is_finite() && s > 0.0) => {
                return Err(invalid(WHAT, "smoothness", s, "s must be finite and > 0"));
            }
            _ => {}
        }
        let mut queue = VecDeque::new();
        queue.push_back(GeneratedFrame::key(params.start_frame));
        let mut memory = VecDeque::with_capacity(MAX_MEMORY_EXCLUSIVE);
        if params.memory > 0 {
            memory.push_back(params.start_frame);
        }
        Ok(Self {
            map,
            params: *params,
            rng: ChaCha8Rng::seed_from_u64(params.seed),
            current: params.start_frame,
            memory,
            queue,
            emitted: 0,
            last_transition: None,
            target_cell: None,
        })
    }

    /// The key frame most recently scheduled (the last frame of the queued blend).
    pub fn current_key(&self) -> usize {
        self.current
    }

    /// The most recent transition (j ≠ i + 1), if any.
    pub fn last_transition(&self) -> Option<Transition> {
        self.last_transition
    }

    /// The next `n` frames with the transitions taken among them.
    pub fn generate(&mut self, n: usize) -> Generated {
        let mut out = Generated {
            frames: Vec::with_capacity(n),
            transitions: Vec::new(),
        };
        let mut last = self.last_transition;
        for _ in 0..n {
            out.frames.push(self.next_frame());
            if self.last_transition != last {
                last = self.last_transition;
                out.transitions.extend(last);
            }
        }
        out
    }

    /// The next generated frame.
    pub fn next_frame(&mut self) -> GeneratedFrame {
        if self.queue.is_empty() {
            self.schedule();
        }
        self.emitted += 1;
        // schedule() always queues at least the key frame j.
        self.queue
            .pop_front()
            .unwrap_or(GeneratedFrame::key(self.current))
    }

    /// Draws the next key frame and queues the blend frames and the key frame; carries out a
    /// pending cell change instead when there is one.
    fn schedule(&mut self) {
        let layout = self.map.layout();
        let i = self.current;
        let j = match self.target_cell.take() {
            Some(cell) => {
                let (k, j) = self.route(i, cell);
                let mut at = i;
                while at != k {
                    at += 1; // k lies on the natural path from i
                    self.queue.push_back(GeneratedFrame::key(at));
                    self.remember(at);
                }
                self.current = k;
                j
            }
            None => self.choose(i),
        };
        let i = self.current;
        if layout.is_jump(i, j) {
            let b = blend_frames(self.map, self.params.blend, i, j);
            self.queue.extend(blend_sequence(i, j, b));
            self.last_transition = Some(Transition {
                index: self.emitted + self.queue.len() - b - 1,
                from: i,
                to: j,
                blend_frames: b,
            });
        }
        self.queue.push_back(GeneratedFrame::key(j));
        self.current = j;
        self.remember(j);
    }

    fn remember(&mut self, j: usize) {
        if self.params.memory > 0 {
            if self.memory.len() == self.params.memory {
                self.memory.pop_front();
            }
            self.memory.push_back(j);
        }
    }

    /// The cell the player is in (that of [`Player::current_key`]).
    pub fn current_cell(&self) -> usize {
        self.map.cell_of(self.current)
    }

    /// Motion control (thesis §3.2.2, Fig. 3.5): asks the player to move into cell `cell`.
    ///
    /// When the frames already queued have played, the player looks ahead along the natural
    /// play of its current cell, up to [`PlaybackParams::control_horizon`] frames (or the
    /// cell's end), for the frame k and the target-cell core frame j with the best
    /// [`JumpMap::transition_score`] (earliest on ties), plays on to k, blends into j as any
    /// transition, and from then on plays randomly inside the target cell. Asking for the
    /// current cell cancels a pending request.
    ///
    /// # Errors
    /// [`crate::AnimPcaError::InvalidCell`] if `cell ≥ n_cells()`.
    pub fn set_target_cell(&mut self, cell: usize) -> Result<()> {
        if cell >= self.map.n_cells() {
            return Err(crate::AnimPcaError::InvalidCell {
                what: "Player::set_target_cell",
                cell,
                reason: format!("the map has {} cell(s)", self.map.n_cells()),
            });
        }
        self.target_cell = (cell != self.current_cell()).then_some(cell);
        Ok(())
    }

    /// The pending target cell, if a request has not been carried out yet.
    pub fn target_cell(&self) -> Option<usize> {
        self.target_cell
    }

    /// The exit frame k (on the natural path from `i`) and entry frame j into `cell`.
    fn route(&self, i: usize, cell: usize) -> (usize, usize) {
        let map = self.map;
        let layout = map.layout();
        let targets: Vec<usize> = map.cell_range(cell).filter(|&j| map.core()[j]).collect();
        let mut best: Option<(f64, usize, usize)> = None;
        let mut k = i;
        for _ in 0..=self.params.control_horizon.max(1) {
            for &j in &targets {
                if !layout.is_candidate(k, j) {
                    continue;
                }
                let score = map.transition_score(k, j);
                if best.is_none_or(|(b, _, _)| score > b) {
                    best = Some((score, k, j));
                }
            }
            match layout.successor(k) {
                Some(next) => k = next,
                None => break,
            }
        }
        // Any target is a candidate from a frame with a successor, and any target with a
        // predecessor from a cell's last frame. So `best` is empty only when the window is a
        // lone last frame and no target-core frame has a predecessor (a one-frame core at the
        // start of its cell): then enter at that frame.
        best.map_or((i, targets.first().copied().unwrap_or(i)), |(_, k, j)| {
            (k, j)
        })
    }

    /// Samples row i of the sampling matrix, avoiding the memory (see the module docs).
    fn choose(&mut self, i: usize) -> usize {
        let row = self.map.sampling_matrix().row(i);
        let masked: f64 = (0..row.len())
            .filter(|j| !self.memory.contains(j))
            .map(|j| row[j])
            .sum();
        if masked > 0.0 {
            let memory = &self.memory;
            let fallback = self.map.successor(i).unwrap_or(i);
            return sample(
                &mut self.rng,
                row,
                masked,
                |j| !memory.contains(&j),
                fallback,
            );
        }
        let fallback = self.map.successor(i).unwrap_or(i);
        if fallback != i && row[fallback] > 0.0 {
            return fallback;
        }
        let total: f64 = row.iter().sum();
        sample(&mut self.rng, row, total, |_| true, fallback)
    }
}

/// Blend frames b for the transition i → j under `blend` (eq. 3.9, or eq. 3.11 for a
/// smoothness), shortened so that both streams stay inside their cells:
/// b' = min(b, last(i) − i, j − first(j)).
pub(crate) fn blend_frames(map: &JumpMap, blend: Blend, i: usize, j: usize) -> usize {
    let b = match blend {
        Blend::None => 0,
        Blend::Fixed(b) => b,
        Blend::Smoothness(s) => {
            let unit = s * map.mean_frame_distance();
            if unit > 0.0 {
                let b = (map.jump_residual(i, j) / unit).round();
                if b.is_finite() {
                    (b as usize).min(MAX_BLEND_FRAMES)
                } else {
                    MAX_BLEND_FRAMES
                }
            } else {
                0
            }
        }
    };
    let (ri, rj) = (map.layout().range_of(i), map.layout().range_of(j));
    b.min(ri.end - 1 - i).min(j - rj.start)
}

/// The b blend frames of eq. 3.9 for i → j: (1 − α_t)·w_{i+t} + α_t·w_{j−(b+1)+t},
/// α_t = t/(b+1), t = 1 … b (see the module docs).
pub(crate) fn blend_sequence(i: usize, j: usize, b: usize) -> impl Iterator<Item = GeneratedFrame> {
    (1..=b).map(move |t| GeneratedFrame {
        from: i + t,
        to: j + t - (b + 1),
        alpha: t as f64 / (b + 1) as f64,
    })
}

/// Draws j with probability row[j] / total among the allowed j (`fallback` if none).
fn sample(
    rng: &mut ChaCha8Rng,
    row: &[f64],
    total: f64,
    allowed: impl Fn(usize) -> bool,
    fallback: usize,
) -> usize {
    let u = (rng.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64);
    let target = u * total;
    let mut acc = 0.0;
    let mut last = None;
    for (j, &p) in row.iter().enumerate() {
        if p > 0.0 && allowed(j) {
            acc += p;
            last = Some(j);
            if acc > target {
                return j;
            }
        }
    }
    // Rounding left `target` just above the sum: take the last allowed candidate.
    last.unwrap_or(fallback)
}

impl Iterator for Player<'_> {
    type Item = GeneratedFrame;

    /// Always `Some`: play is endless.
    fn next(&mut self) -> Option<GeneratedFrame> {
        Some(self.next_frame())
    }
}
