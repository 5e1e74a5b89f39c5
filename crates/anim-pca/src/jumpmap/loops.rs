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
//! # Acceptable loops: no oscillation over a handful of frames
//! The cheapest closed walk of a length is not always one a user would accept: on a clip
//! without a good long loop it can be a few frames played back and forth (the chicken's
//! `--loop 48` was a 6-frame ping-pong, 36 → 37 → 38 → blend → 36, eight times over). A loop
//! of n frames is therefore required to play every stretch of natural playback between two
//! jumps for at least
//!
//! R(n) = max(min(⌈n/4⌉, ⌈core/4⌉), b + 1, min(8, ⌈core/2⌉)) key frames ([`min_run`]),
//!
//! core being the cell's core frame count and b the longest blend among the candidate jumps.
//! Such a loop shows at least R distinct clip frames, repeats at most four times within its
//! period, and can never oscillate: each jump is followed by a quarter of the loop (or of the
//! clip) of ordinary play; by more clip frames than cross-fade frames (with b = 3, a 12-frame
//! "loop" of three frames, three blends, three frames, three blends is a stutter); and by at
//! least [`MIN_STRETCH`] = 8 frames, a quarter second at 30 fps, however short the loop or
//! small the core (a core of fewer than 16 frames: half of it). CesiumMan's walk, whose core
//! is 14 frames, otherwise loops 4 frames between blends. The table holds, for every length, the
//! cheapest loop that obeys the rule, or none; [`Loop::distinct_frames`] and
//! [`Loop::shortest_run`] report what a loop shows.
//!
//! # Method, and how it differs from video textures
//! Schödl et al. build loops from "primitive loops" (one backward jump each) with a dynamic
//! program over lengths and transitions. Here the search is a shortest-path dynamic program
//! over (length, frame, phase) from every start: *landed* at frame v at time t (a jump, or
//! the start, put v on screen), and *free* at v (the current run has lasted ≥ R frames, so v
//! may jump). free_t(v) = min(landed_{t−R+1}(v − R + 1) when v − R + 1 … v is natural play,
//! free_{t−1}(v − 1)); landed_{t+len}(w) = min over jumps v → w of free_t(v) + cost(v, w).
//! It is exact over the candidate edges — every natural step and, per frame, the
//! [`LOOP_CANDIDATES`] jumps of highest score — and needs no special structure: forward jumps
//! (i → j > i + 1) are allowed as well, and blends make a jump's length part of the search,
//! so a table entry of length n really plays n frames. A loop starts where a jump lands, at
//! its lowest landing frame, so each is found once. R depends on n, so lengths with the same
//! R share one run of the program. Loops stay inside one cell and inside its core (see
//! [`graph`](super::graph)). A jump to i itself (a frozen frame) or to i − 1 (back-and-forth)
//! is never a candidate, as with the player's memory.
//!
//! Cost: O(groups · starts · n_max · frames · (K + 2)) relaxations, with about n_max / 4
//! groups up to the clip's quarter; starts run in parallel.

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

    /// Distinct clip frames the loop's key frames show.
    pub fn distinct_frames(&self) -> usize {
        let mut keys: Vec<usize> = self
            .frames
            .iter()
            .filter(|f| f.is_key())
            .map(|f| f.from)
            .collect();
        keys.sort_unstable();
        keys.dedup();
        keys.len()
    }

    /// Key frames of the shortest stretch of natural play between two jumps (at least
    /// [`min_run`] of the loop's length; see the [module docs](self)).
    pub fn shortest_run(&self) -> usize {
        let n = self.frames.len();
        let t = &self.transitions;
        (0..t.len())
            .map(|k| {
                // From the landing of jump k − 1 to the source of jump k, cyclically.
                let prev = &t[(k + t.len() - 1) % t.len()];
                let landing = (prev.index + prev.blend_frames + 1) % n;
                (t[k].index + n - landing) % n + 1
            })
            .min()
            .unwrap_or(n)
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
    /// Core frames of the cell (R(n) is capped at a quarter of them).
    core_frames: usize,
    /// Longest blend among the candidate jumps (R(n) > it).
    blend_max: usize,
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
                    natural: true,
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
                    natural: false,
                    len: 1 + blend_frames(map, blend, i, j),
                    cost: -score.ln(),
                });
            }
        }

        // Lengths that share R(n) share one run of the program, up to their longest.
        let blend_max = edges
            .iter()
            .flatten()
            .filter(|e| !e.natural)
            .map(|e| e.len - 1)
            .max()
            .unwrap_or(0);
        let mut loops: Vec<Option<Loop>> = vec![None; max_len + 1];
        let mut len = 2;
        while len <= max_len {
            let run = min_run(len, core.len(), blend_max);
            let mut last = len;
            while last < max_len && min_run(last + 1, core.len(), blend_max) == run {
                last += 1;
            }
            let program = Program {
                edges: &edges,
                first: range.start,
                run,
                max_len: last,
            };
            let per_start: Vec<Vec<Option<Walk>>> =
                core.par_iter().map(|&s| program.closed_walks(s)).collect();
            for walks in per_start {
                for (n, walk) in walks.into_iter().enumerate().skip(len) {
                    let Some((cost, keys)) = walk else { continue };
                    let better = loops[n].as_ref().is_none_or(|l| cost < l.cost);
                    if better {
                        loops[n] = Some(realise(map, blend, &keys, cost));
                    }
                }
            }
            len = last + 1;
        }
        Ok(Self {
            cell,
            core_frames: core.len(),
            blend_max,
            loops,
        })
    }

    /// The cell the loops play in.
    pub fn cell(&self) -> usize {
        self.cell
    }

    /// Core frames of the cell.
    pub fn core_frames(&self) -> usize {
        self.core_frames
    }

    /// R(n): the shortest stretch of natural play its loop of `len` frames may have
    /// ([`min_run`] with this cell's core and longest candidate blend).
    pub fn min_run(&self, len: usize) -> usize {
        min_run(len, self.core_frames, self.blend_max)
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
    /// The natural step i → i + 1 (cost 0, one frame); every other edge is a jump.
    natural: bool,
    len: usize,
    cost: f64,
}

/// The shortest stretch of natural play a loop of `len` frames may have between two jumps,
/// in a cell of `core` core frames with blends of at most `blend` frames:
/// R(n) = max(min(⌈n/4⌉, ⌈core/4⌉), b + 1, min([`MIN_STRETCH`], ⌈core/2⌉)) (see the
/// [module docs](self)).
pub fn min_run(len: usize, core: usize, blend: usize) -> usize {
    len.div_ceil(4)
        .min(core.div_ceil(4))
        .max(blend + 1)
        .max(MIN_STRETCH.min(core.div_ceil(2)))
}

/// The fewest key frames of natural play between two jumps of any loop (a quarter second at
/// 30 fps), unless the cell's core has fewer than twice as many.
pub const MIN_STRETCH: usize = 8;

/// The dynamic program of the [module docs](self) for one run length R, lengths ≤ `max_len`.
struct Program<'a> {
    edges: &'a [Vec<Edge>],
    first: usize,
    run: usize,
    max_len: usize,
}

/// Where a state's cost came from, for walking a loop back.
#[derive(Clone, Copy)]
enum From {
    None,
    /// Landed by a jump from the free state (time, frame).
    Jump(u32, u32),
    /// Free after R frames of natural play from a landing R − 1 frames earlier.
    Landing,
    /// Free, one natural step on from the free state one frame earlier.
    Step,
}

impl Program<'_> {
    /// For each length t ≤ `max_len`, the cheapest loop that starts where a jump lands at `s`
    /// and lands nowhere below it, as (cost, key frames from s).
    fn closed_walks(&self, s: usize) -> Vec<Option<Walk>> {
        let (edges, first, r, max_len) = (self.edges, self.first, self.run, self.max_len);
        let n = edges.len();
        let ls = s - first;
        // natural[v]: key frames of natural play ending at v (1 where v is not reached by a
        // natural step from a core frame).
        let mut natural = vec![1usize; n];
        for v in 1..n {
            if edges[v - 1].iter().any(|e| e.natural) {
                natural[v] = natural[v - 1] + 1;
            }
        }
        let size = (max_len + 1) * n;
        let mut landed = vec![f64::INFINITY; size];
        let mut free = vec![f64::INFINITY; size];
        let mut landed_from = vec![From::None; size];
        let mut free_from = vec![From::None; size];
        landed[ls] = 0.0;
        for t in 0..=max_len {
            for v in ls..n {
                let at = t * n + v;
                // Free at (t, v): R frames of play from a landing, or one more step.
                if natural[v] >= r && t + 1 >= r {
                    let from = (t + 1 - r) * n + v + 1 - r;
                    if v + 1 - r >= ls && landed[from] < free[at] {
                        free[at] = landed[from];
                        free_from[at] = From::Landing;
                    }
                }
                if t > 0 && v > ls && natural[v] >= 2 {
                    let from = (t - 1) * n + v - 1;
                    if free[from] < free[at] {
                        free[at] = free[from];
                        free_from[at] = From::Step;
                    }
                }
                let c = free[at];
                if !c.is_finite() {
                    continue;
                }
                for e in edges[v].iter().filter(|e| !e.natural) {
                    let w = e.to - first;
                    let tt = t + e.len;
                    if w < ls || tt > max_len {
                        continue;
                    }
                    let to = tt * n + w;
                    if c + e.cost < landed[to] {
                        landed[to] = c + e.cost;
                        landed_from[to] = From::Jump(t as u32, v as u32);
                    }
                }
            }
        }
        (0..=max_len)
            .map(|t| {
                if t < 2 || !landed[t * n + ls].is_finite() {
                    return None;
                }
                // Walk back from landing at (t, s) to the start: runs of key frames, reversed.
                let mut keys = Vec::new();
                let (mut tt, mut v) = (t, ls);
                // Until (0, s), the start, which no jump reached.
                while let From::Jump(jt, jv) = landed_from[tt * n + v] {
                    let (mut ft, mut fv) = (jt as usize, jv as usize);
                    loop {
                        keys.push(fv + first);
                        match free_from[ft * n + fv] {
                            From::Step => {
                                ft -= 1;
                                fv -= 1;
                            }
                            _ => {
                                // From::Landing: the run's remaining R − 1 frames down to it.
                                for k in 1..r {
                                    keys.push(fv - k + first);
                                }
                                tt = ft + 1 - r;
                                v = fv + 1 - r;
                                break;
                            }
                        }
                    }
                }
                keys.reverse();
                Some((landed[t * n + ls], keys))
            })
            .collect()
    }
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
