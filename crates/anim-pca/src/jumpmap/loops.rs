//! Fixed-length loops: the *loop table* of thesis §3.2 (Fig. 3.2, "Generate Loops (store loop
//! table)"; "the resulting map now can be used either to generate infinite random or fixed
//! length looped sequences", after eq. 3.8).
//!
//! A loop of length n is a closed walk over the clip's frames that returns to where it began
//! after exactly n generated frames, blend frames included, so that it can be played forever
//! (a game's idle cycle, a background character, a looping texture of cloth). Its steps are
//! natural play i → i + 1 (cost 0, one frame) and jumps i → j (cost −ln s_ij with s the
//! unnormalised eq. 3.8 score [`JumpMap::transition_score`], 1 + b frames with b the blend of
//! eq. 3.9/3.11 for that jump). The loop table holds, for every length up to a maximum, the
//! cheapest such loop.
//!
//! # Method, and how it differs from video textures
//! Schödl et al. build loops from "primitive loops" (one backward jump each) with a dynamic
//! program over lengths and transitions. Here the search is a plain shortest-path dynamic
//! program over (length, frame) from every start frame: cost_t(v) = min over edges u → v of
//! cost_{t − len(u,v)}(u) + cost(u, v). It is exact over the candidate edges — every natural
//! step and, per frame, the [`LOOP_CANDIDATES`] jumps of highest score — and needs no special
//! structure: forward jumps (i → j > i + 1) are allowed as well, and blends make a jump's
//! length part of the search, so a table entry of length n really plays n frames. Loops stay
//! inside one cell and inside its core (see [`graph`](super::graph)). A jump to i itself (a
//! frozen frame) or to i − 1 (back-and-forth) is never a candidate, as with the player's
//! memory.
//!
//! Cost: O(starts · n_max · frames · (K + 1)) relaxations; for the 48-frame horse gallop and
//! n_max = 200 that is a few milliseconds; starts run in parallel.

use rayon::prelude::*;

use super::player::{Generated, GeneratedFrame, Transition, blend_frames, blend_sequence};
use super::{Blend, JumpMap};
use crate::error::{AnimPcaError, Result, invalid};

/// Jumps per frame the loop search considers (those of highest [`JumpMap::transition_score`]),
/// besides the natural successor.
pub const LOOP_CANDIDATES: usize = 16;

/// Longest loop a table may hold; with the frame count it bounds the table's memory.
pub const MAX_LOOP_LENGTH: usize = 100_000;

/// One fixed-length loop.
#[derive(Clone, Debug, PartialEq)]
pub struct Loop {
    /// The generated frames of one period, blend frames included; frame 0 is a key frame and
    /// the frame after the last is frame 0 again.
    pub frames: Vec<GeneratedFrame>,
    /// The jumps of one period, with `index` into `frames`. The jump that closes the loop (from
    /// the last key frame back to `frames[0]`) is among them, its blend frames at the end of
    /// `frames`.
    pub transitions: Vec<Transition>,
    /// Σ −ln s_ij over the jumps (0 for a period of perfect matches, e.g. a cycle clip with a
    /// closing frame).
    pub cost: f64,
}

impl Loop {
    /// Length n of one period in generated frames.
    pub fn len(&self) -> usize {
        self.frames.len()
    }

    /// Whether the loop is empty (never, for a loop from [`LoopTable`]).
    pub fn is_empty(&self) -> bool {
        self.frames.is_empty()
    }

    /// `n` frames of the loop played from its first frame, repeated as often as needed, with
    /// the transition log (indices into the result).
    pub fn play(&self, n: usize) -> Generated {
        let period = self.frames.len();
        let mut out = Generated {
            frames: Vec::with_capacity(n),
            transitions: Vec::new(),
        };
        if period == 0 {
            return out;
        }
        for k in 0..n.div_ceil(period) {
            for t in &self.transitions {
                let index = k * period + t.index;
                if index < n {
                    out.transitions.push(Transition { index, ..*t });
                }
            }
        }
        out.frames
            .extend(self.frames.iter().copied().cycle().take(n));
        out
    }
}

/// The cheapest loop of every length 2 … `max_len` in one cell (see the [module docs](self)).
#[derive(Clone, Debug)]
pub struct LoopTable {
    cell: usize,
    loops: Vec<Option<Loop>>,
}

impl LoopTable {
    /// Builds the table for `cell` of `map` with transitions blended by `blend`.
    ///
    /// # Errors
    /// [`AnimPcaError::InvalidCell`] for a cell out of range; [`AnimPcaError::InvalidParameter`]
    /// for `max_len` < 2 or > [`MAX_LOOP_LENGTH`], or a smoothness that is not finite and > 0.
    ///
    /// # Examples
    /// ```
    /// use anim_pca::{Blend, JumpMap, JumpMapParams, LoopTable};
    /// use glam::Vec3;
    /// // A point circling with a period of 8 frames, 3 turns.
    /// let frames: Vec<Vec<Vec3>> = (0..24)
    ///     .map(|t| {
    ///         let a = t as f32 * std::f32::consts::TAU / 8.0;
    ///         vec![Vec3::new(a.cos(), a.sin(), 0.0), Vec3::Z]
    ///     })
    ///     .collect();
    /// let map = JumpMap::analyze(&frames, &JumpMapParams::default()).unwrap();
    /// let table = LoopTable::build(&map, 0, 20, Blend::None).unwrap();
    /// // A loop of one period costs nothing: the jump lands exactly one period back.
    /// let one_turn = table.get(8).unwrap();
    /// assert!(one_turn.cost < 1e-3); // f32 rounding of the frames only
    /// assert_eq!(one_turn.play(16).frames.len(), 16);
    /// ```
    pub fn build(map: &JumpMap, cell: usize, max_len: usize, blend: Blend) -> Result<Self> {
        const WHAT: &str = "LoopTable::build";
        if cell >= map.n_cells() {
            return Err(AnimPcaError::InvalidCell {
                what: WHAT,
                cell,
                reason: format!("the map has {} cell(s)", map.n_cells()),
            });
        }
        if !(2..=MAX_LOOP_LENGTH).contains(&max_len) {
            return Err(invalid(
                WHAT,
                "max_len",
                max_len,
                "loops are 2 … 100000 frames long",
            ));
        }
        if let Blend::Smoothness(s) = blend
            && !(s.is_finite() && s > 0.0)
        {
            return Err(invalid(WHAT, "smoothness", s, "s must be finite and > 0"));
        }
        let range = map.cell_range(cell);
        let core: Vec<usize> = range.clone().filter(|&i| map.core()[i]).collect();
        let local = |i: usize| i - range.start;
        let n = range.len();

        // Edges (target, frames, cost) of every core frame.
        let mut edges: Vec<Vec<Edge>> = vec![Vec::new(); n];
        for &i in &core {
            let out = &mut edges[local(i)];
            if let Some(s) = map.successor(i).filter(|&s| map.core()[s]) {
                out.push(Edge {
                    to: s,
                    len: 1,
                    cost: 0.0,
                });
            }
            let mut jumps: Vec<(f64, usize)> = core
                .iter()
                .copied()
                .filter(|&j| {
                    j != i
                        && Some(j) != map.successor(i)
                        && j + 1 != i
                        && map.layout().is_candidate(i, j)
                })
                .map(|j| (map.transition_score(i, j), j))
                .filter(|(s, _)| *s > 0.0)
                .collect();
            jumps.sort_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)));
            jumps.truncate(LOOP_CANDIDATES);
            for (score, j) in jumps {
                out.push(Edge {
                    to: j,
                    len: 1 + blend_frames(map, blend, i, j),
                    cost: -score.ln(),
                });
            }
        }

        // Best closed walk of each length through each start; the start is the walk's lowest
        // frame, so every loop is found exactly once (from its lowest frame).
        let per_start: Vec<Vec<Option<Walk>>> = core
            .par_iter()
            .map(|&s| closed_walks(&edges, range.start, s, max_len))
            .collect();
        let mut loops: Vec<Option<Loop>> = vec![None; max_len + 1];
        for walks in per_start {
            for (len, walk) in walks.into_iter().enumerate() {
                let Some((cost, keys)) = walk else { continue };
                let better = loops[len].as_ref().is_none_or(|l| cost < l.cost);
                if better {
                    loops[len] = Some(realise(map, blend, &keys, cost));
                }
            }
        }
        Ok(Self { cell, loops })
    }

    /// The cell the loops play in.
    pub fn cell(&self) -> usize {
        self.cell
    }

    /// Longest length the table was built for.
    pub fn max_len(&self) -> usize {
        self.loops.len() - 1
    }

    /// The cheapest loop of exactly `len` frames, if one exists.
    pub fn get(&self, len: usize) -> Option<&Loop> {
        self.loops.get(len).and_then(Option::as_ref)
    }

    /// Every loop in the table, shortest first.
    pub fn iter(&self) -> impl Iterator<Item = &Loop> {
        self.loops.iter().flatten()
    }
}

/// A closed walk: its cost and its key frames from the start (without the final return).
type Walk = (f64, Vec<usize>);

#[derive(Clone, Copy, Debug)]
struct Edge {
    to: usize,
    len: usize,
    cost: f64,
}

/// For each length t ≤ `max_len`, the cheapest closed walk s → … → s of t frames that never
/// visits a frame below s, as (cost, key frames from s, without the final s).
fn closed_walks(edges: &[Vec<Edge>], first: usize, s: usize, max_len: usize) -> Vec<Option<Walk>> {
    let n = edges.len();
    let ls = s - first;
    let mut cost = vec![f64::INFINITY; (max_len + 1) * n];
    let mut pred = vec![u32::MAX; (max_len + 1) * n]; // predecessor frame (local)
    cost[ls] = 0.0;
    for t in 0..max_len {
        for v in ls..n {
            let c = cost[t * n + v];
            if !c.is_finite() {
                continue;
            }
            for e in &edges[v] {
                let w = e.to - first;
                let tt = t + e.len;
                if w < ls || tt > max_len {
                    continue;
                }
                let nc = c + e.cost;
                if nc < cost[tt * n + w] {
                    cost[tt * n + w] = nc;
                    pred[tt * n + w] = v as u32;
                }
            }
        }
    }
    let len_of = |u: usize, v: usize| {
        edges[u]
            .iter()
            .find(|e| e.to - first == v)
            .map_or(1, |e| e.len)
    };
    (0..=max_len)
        .map(|t| {
            if t < 2 || !cost[t * n + ls].is_finite() {
                return None;
            }
            // Walk the predecessors back from (t, s) to (0, s).
            let mut keys = Vec::new();
            let (mut tt, mut v) = (t, ls);
            while tt > 0 {
                let u = pred[tt * n + v] as usize;
                tt -= len_of(u, v);
                keys.push(u + first);
                v = u;
            }
            keys.reverse();
            Some((cost[t * n + ls], keys))
        })
        .collect()
}

/// The generated frames and jumps of a loop through `keys` (closing back to `keys[0]`).
fn realise(map: &JumpMap, blend: Blend, keys: &[usize], cost: f64) -> Loop {
    let mut frames = Vec::new();
    let mut transitions = Vec::new();
    for (k, &i) in keys.iter().enumerate() {
        frames.push(GeneratedFrame::key(i));
        let j = keys[(k + 1) % keys.len()];
        if map.layout().is_jump(i, j) {
            let b = blend_frames(map, blend, i, j);
            transitions.push(Transition {
                index: frames.len() - 1,
                from: i,
                to: j,
                blend_frames: b,
            });
            frames.extend(blend_sequence(i, j, b));
        }
    }
    Loop {
        frames,
        transitions,
        cost,
    }
}
