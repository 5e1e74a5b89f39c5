//! Cast shadows: per-light visibility tables shared by all views.
//!
//! Whether a surface point sees a directional light depends only on the point and the
//! light, not on the view. A full BTF shades the hits of 81 views with the same 81 lights,
//! so visibility is computed once per light on a lattice aligned with the light's azimuth
//! and every view looks it up.
//!
//! **Building (a horizon sweep).** Let d be the light's horizontal direction and k =
//! l_z / |l_xy| the rise of its ray per unit of horizontal travel. Lattice lines run along
//! d, [`NODE_SPACING`] sub-samples apart, through the tile (extended by a margin). Along a
//! line the surface profile h(u) is sampled every fine march step δ, and a point u is in
//! shadow exactly when `g(u') ≥ g(u) + bias` for some later sample u' (within
//! [`MAX_SHADOW_TRAVEL`]), where `g(u) = h(u) − k u`: the ray from u rises as k u, so the
//! surface at u' is above it by `g(u') − g(u)`. Sweeping each line backwards with a sliding
//! window maximum answers every sample in O(1): one height evaluation per fine step per
//! line, instead of a ray march per node. This is the same test, with the same fine step,
//! as the exact shadow ray ([`Tracer::occluded`](super::march::Tracer::occluded)).
//!
//! **Looking up.** A hit takes the answer of the (up to four) lattice nodes around it —
//! the two nearest nodes on each of the two nearest lines — that lie on a yarn of its
//! class (family and index parity) and face the light, provided they agree. Otherwise (a
//! shadow boundary, a terminator or a yarn edge runs between them: about 2% of the look-ups
//! at 64² × 2², 0.5% at 256² × 2²), and always for a hit on the vertical face below a
//! yarn's edge, which no node represents, its own shadow ray is traced. Only a shadow
//! sliver narrower than the node spacing that passes between four agreeing nodes is
//! missed (the tests measure ≤ 0.2% of the hits).
//!
//! Tables are built on first use, one per distinct light direction (bit-exact after
//! normalisation), at most [`MAX_CACHED_TABLES`] of them; beyond that a table is built for
//! the call and dropped, so results never depend on what was shaded before. A table is
//! built by plain OS threads, never rayon: a rayon worker waiting for its own parallel
//! loop could steal a task that waits for the same table, and deadlock.

use super::march::{MAX_SHADOW_TRAVEL, SHADOW_BIAS};
use super::weave::floor_i32;
use super::{Inner, SurfacePoint, Yarn};
use glam::{DVec2, Vec2, Vec3};
use std::collections::{HashMap, VecDeque};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Arc, Mutex, OnceLock, PoisonError};

/// Most light directions whose tables are kept. A table holds half a byte per node, about
/// `0.6 · (2 · res · supersample)²` bytes (0.6 MB at 256² × 2²); the UBO2003 layout needs 81.
pub(crate) const MAX_CACHED_TABLES: usize = 128;
/// Spacing of the lattice lines and of the nodes along them, in sub-samples. Half a
/// sub-sample halves the hits that need their own shadow ray compared with a whole one
/// (measured on the default weave at 64² × 2²: 1.9% instead of 3.5% of the lookups), for
/// 4× the (cheap) sweep and memory.
const NODE_SPACING: f32 = 0.5;
/// Lines handed to a table-building thread at a time.
const LINES_PER_CHUNK: usize = 16;
/// Below this horizontal length a light is straight overhead: nothing casts a shadow.
const VERTICAL_EPSILON: f32 = 1e-7;

/// Node states: facing away from the light (not voted with), facing it and lit, facing it
/// and in a cast shadow. A node is the 4-bit value `3 · yarn class + state` (see
/// [`yarn_class`]), two per byte: the table of a 256² × 2² BTF (1.2 M nodes) takes
/// 0.6 MB.
const FACING_AWAY: u8 = 0;
const LIT: u8 = 1;
const SHADOWED: u8 = 2;
/// Yarn classes (5) × states (3) fit in a nibble.
const STATES: u8 = 3;

/// One line of the lattice: nodes `first ..= first + len − 1` stored from nibble `offset`.
#[derive(Debug, Clone, Copy, Default)]
struct Line {
    first: i32,
    len: u32,
    offset: u32,
}

/// One light's visibility on its lattice. Node (j, i) lies at `j·spacing·across +
/// i·spacing·along` (along = the light's horizontal direction, across = along rotated by
/// +90°).
pub(crate) struct ShadowTable {
    /// `along / spacing` and `across / spacing`: a point's node coordinates are its dot
    /// products with them.
    along_per_node: Vec2,
    across_per_node: Vec2,
    first_line: i32,
    lines: Vec<Line>,
    /// Nibbles, two per byte, low nibble first.
    nodes: Vec<u8>,
    /// With no lines: trace every hit (the lattice would be too coarse for the yarn
    /// classes) instead of answering "lit" (a light straight overhead).
    trace_all: bool,
}

impl ShadowTable {
    /// A table without nodes: every hit is lit (`trace_all` false: a light straight
    /// overhead) or traced.
    fn without_nodes(trace_all: bool) -> Self {
        Self {
            along_per_node: Vec2::X,
            across_per_node: Vec2::Y,
            first_line: 0,
            lines: Vec::new(),
            nodes: Vec::new(),
            trace_all,
        }
    }

    #[inline]
    fn nibble(&self, index: usize) -> u8 {
        (self.nodes[index >> 1] >> ((index & 1) << 2)) & 15
    }

    /// What the nodes around `position` that belong to yarn class `class` and face the
    /// light say (without data-dependent branches: sentinel lines and clamped reads).
    #[inline]
    pub(crate) fn vote(&self, position: Vec3, class: u8) -> Vote {
        if self.lines.is_empty() {
            return if self.trace_all {
                Vote::Undecided
            } else {
                Vote::Lit
            };
        }
        let xy = position.truncate();
        let i0 = floor_i32(xy.dot(self.along_per_node));
        let j0 = floor_i32(xy.dot(self.across_per_node));
        let lit = class * STATES + LIT;
        // Bit 0: a matching node is lit; bit 1: one is shadowed.
        let mut votes = 0u8;
        let last_line = self.lines.len() as i64 - 1;
        for j in [j0, j0 + 1] {
            // `lines` starts and ends with an empty sentinel, so clamping is harmless.
            let index = (i64::from(j) - i64::from(self.first_line)).clamp(0, last_line);
            let line = self.lines[index as usize];
            for i in [i0, i0 + 1] {
                let k = i.wrapping_sub(line.first) as u32;
                let inside = k < line.len;
                let node = self.nibble(if inside {
                    (line.offset + k) as usize
                } else {
                    0
                });
                let node = if inside { node } else { FACING_AWAY };
                votes |= u8::from(node == lit) | (u8::from(node == lit + 1) << 1);
            }
        }
        match votes {
            1 => Vote::Lit,
            2 => Vote::Shadowed,
            _ => Vote::Undecided,
        }
    }
}

/// The answer of a shadow table for one hit.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Vote {
    Lit,
    Shadowed,
    /// The nodes disagree or none applies: trace the hit's own shadow ray.
    Undecided,
}

type Slot = Arc<OnceLock<Arc<ShadowTable>>>;

/// The tables of one [`Inner`], keyed by the bits of the normalised light direction.
#[derive(Default)]
pub(crate) struct ShadowCache {
    tables: Mutex<HashMap<[u32; 3], Slot>>,
    /// Tables being built right now; their builders share the cores.
    building: AtomicUsize,
}

/// A yarn's class: the gap, or its family and index parity (0 ..= 4). Two yarns of one
/// class are two pitches apart; [`Inner::build_table`] makes the node spacing at most a
/// quarter pitch, so they are never both among the nodes around a hit.
fn yarn_class(yarn: Yarn) -> u8 {
    match yarn {
        Yarn::Gap => 0,
        Yarn::Warp(k) => 1 + (k & 1) as u8,
        Yarn::Weft(m) => 3 + (m & 1) as u8,
    }
}

/// The class of a hit that no node represents: one on the vertical face between a yarn's
/// edge and the floor (the nodes lie on the height field, above it). Its shadow ray is
/// always traced.
const WALL_CLASS: u8 = 5;

impl Inner {
    /// The class a hit looks up in the shadow tables: its yarn's, or [`WALL_CLASS`] where
    /// it lies more than a fine step below the height field (on a wall; a hit on the
    /// height field lies below it only by the bisection's last bracket, 2⁻⁸ of a step).
    pub(crate) fn shadow_class(&self, hit: &SurfacePoint) -> u8 {
        let surface = self.tracer.weave.height(hit.position.x, hit.position.y);
        if hit.position.z < surface - self.tracer.step {
            WALL_CLASS
        } else {
            yarn_class(hit.yarn)
        }
    }

    /// The shadow table of `light` (unit, `light.z > 0`), built on first use.
    pub(crate) fn shadow_table(&self, light: Vec3) -> Arc<ShadowTable> {
        let key = light.to_array().map(f32::to_bits);
        let slot = {
            let mut tables = self
                .shadows
                .tables
                .lock()
                .unwrap_or_else(PoisonError::into_inner);
            match tables.get(&key) {
                Some(slot) => Some(Arc::clone(slot)),
                None if tables.len() < MAX_CACHED_TABLES => {
                    let slot = Slot::default();
                    tables.insert(key, Arc::clone(&slot));
                    Some(slot)
                }
                None => None,
            }
        };
        match slot {
            Some(slot) => Arc::clone(slot.get_or_init(|| Arc::new(self.build_table(light)))),
            None => Arc::new(self.build_table(light)),
        }
    }

    /// Lays out the lattice for `light` and sweeps every line.
    fn build_table(&self, light: Vec3) -> ShadowTable {
        let horizontal = light.truncate().length();
        if horizontal < VERTICAL_EPSILON {
            return ShadowTable::without_nodes(false);
        }
        let along = light.truncate() / horizontal;
        let across = along.perp();
        let spacing = NODE_SPACING / (self.params.res * self.params.supersample) as f32;
        // Nodes lie on the fine sampling positions of their line: every `stride` steps.
        let step = self.tracer.step;
        let stride = (spacing / step).round().max(1.0) as i64;
        let spacing = stride as f32 * step;
        let pitch = 1.0 / self.params.warp_count.max(self.params.weft_count) as f32;
        if spacing > 0.25 * pitch {
            // Fewer than 4 nodes per yarn pitch: too coarse to tell yarns apart by class
            // (and a cheap image to trace).
            return ShadowTable::without_nodes(true);
        }
        let layout = Layout::new(along, across, spacing);
        let sweep = Sweep {
            inner: self,
            light,
            along: along.as_dvec2(),
            across: across.as_dvec2(),
            rise: f64::from(light.z / horizontal),
            step: f64::from(step),
            stride,
            spacing: f64::from(spacing),
        };
        let lines = self.in_threads(layout.spans.len(), |j| {
            let (first, last) = layout.spans[j];
            sweep.line(layout.first_line + j as i32, first, last)
        });
        // An empty sentinel line before and after the layout's lines.
        let lines: Vec<Vec<u8>> = std::iter::once(Vec::new())
            .chain(lines)
            .chain(std::iter::once(Vec::new()))
            .collect();
        let spans: Vec<(i32, i32)> = std::iter::once((1, 0))
            .chain(layout.spans.iter().copied())
            .chain(std::iter::once((1, 0)))
            .collect();
        let mut table = ShadowTable {
            along_per_node: along / spacing,
            across_per_node: across / spacing,
            first_line: layout.first_line - 1,
            lines: vec![Line::default(); lines.len()],
            nodes: Vec::new(),
            trace_all: false,
        };
        let mut offset = 0;
        for (j, nodes) in lines.iter().enumerate() {
            table.lines[j] = Line {
                first: spans[j].0,
                len: nodes.len() as u32,
                offset: offset as u32,
            };
            // Lines start on a byte.
            offset += nodes.len() + nodes.len() % 2;
        }
        // At least one byte: an empty line's clamped read lands on byte 0.
        table.nodes = vec![0; (offset / 2).max(1)];
        for (line, nodes) in table.lines.iter().zip(&lines) {
            for (k, &nibble) in nodes.iter().enumerate() {
                let index = line.offset as usize + k;
                table.nodes[index >> 1] |= nibble << ((index & 1) << 2);
            }
        }
        table
    }

    /// `(0..count).map(work)` on OS threads (see the module documentation for why not
    /// rayon), in order.
    fn in_threads(&self, count: usize, work: impl Fn(usize) -> Vec<u8> + Sync) -> Vec<Vec<u8>> {
        let building = self.shadows.building.fetch_add(1, Ordering::Relaxed) + 1;
        let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
        let chunks = count.div_ceil(LINES_PER_CHUNK);
        let threads = (cores / building).clamp(1, chunks.max(1));
        let next = AtomicUsize::new(0);
        let worker = || {
            let mut done = Vec::new();
            loop {
                let chunk = next.fetch_add(1, Ordering::Relaxed);
                if chunk >= chunks {
                    return done;
                }
                let start = chunk * LINES_PER_CHUNK;
                for j in start..(start + LINES_PER_CHUNK).min(count) {
                    done.push((j, work(j)));
                }
            }
        };
        let parts: Vec<(usize, Vec<u8>)> = if threads == 1 {
            worker()
        } else {
            std::thread::scope(|scope| {
                let handles: Vec<_> = (0..threads).map(|_| scope.spawn(worker)).collect();
                handles
                    .into_iter()
                    .flat_map(|handle| match handle.join() {
                        Ok(part) => part,
                        Err(panic) => std::panic::resume_unwind(panic),
                    })
                    .collect()
            })
        };
        self.shadows.building.fetch_sub(1, Ordering::Relaxed);
        let mut results = vec![Vec::new(); count];
        for (j, nodes) in parts {
            results[j] = nodes;
        }
        results
    }

    /// Whether the surface point `position` on a yarn of class `class` ([`yarn_class`]),
    /// facing `light`, is in a cast shadow: answered from `table` where its neighbouring
    /// nodes of the same class that face the light agree, traced otherwise.
    #[inline]
    pub(crate) fn in_shadow(
        &self,
        table: &ShadowTable,
        position: Vec3,
        class: u8,
        light: Vec3,
    ) -> bool {
        match table.vote(position, class) {
            Vote::Lit => false,
            Vote::Shadowed => true,
            Vote::Undecided => self.traced_shadow(position, light),
        }
    }

    /// The exact answer for a hit the table cannot decide (out of line: rare).
    #[cold]
    #[inline(never)]
    fn traced_shadow(&self, position: Vec3, light: Vec3) -> bool {
        self.tracer.occluded(position, light)
    }
}

/// Which lines cover the tile and which nodes of each.
struct Layout {
    first_line: i32,
    /// Per line, its first and last node index (`first > last` when empty).
    spans: Vec<(i32, i32)>,
}

impl Layout {
    /// Lines `j` at `w = j·spacing` along `across`, nodes `i` at `u = i·spacing` along
    /// `along`, covering the tile extended by two spacings (a hit reads the nodes up to one
    /// spacing beyond it).
    fn new(along: Vec2, across: Vec2, spacing: f32) -> Self {
        let margin = 2.0 * f64::from(spacing);
        let (lo, hi) = (-margin, 1.0 + margin);
        let corners = [(lo, lo), (hi, lo), (lo, hi), (hi, hi)].map(|(x, y)| DVec2::new(x, y));
        let (along, across) = (along.as_dvec2(), across.as_dvec2());
        let spacing = f64::from(spacing);
        let w: Vec<f64> = corners.iter().map(|c| c.dot(across) / spacing).collect();
        let first_line = w.iter().copied().fold(f64::INFINITY, f64::min).floor() as i32;
        let last_line = w.iter().copied().fold(f64::NEG_INFINITY, f64::max).ceil() as i32;
        let spans = (first_line..=last_line)
            .map(|j| {
                // The part of the line inside [lo, hi]², as an interval of u.
                let base = across * (f64::from(j) * spacing);
                let mut range = (f64::NEG_INFINITY, f64::INFINITY);
                for (b, d) in [(base.x, along.x), (base.y, along.y)] {
                    if d.abs() < 1e-12 {
                        if !(lo..=hi).contains(&b) {
                            range = (1.0, 0.0);
                        }
                    } else {
                        let (t0, t1) = ((lo - b) / d, (hi - b) / d);
                        range = (range.0.max(t0.min(t1)), range.1.min(t0.max(t1)));
                    }
                }
                if range.0 > range.1 {
                    (1, 0)
                } else {
                    (
                        (range.0 / spacing).floor() as i32,
                        (range.1 / spacing).ceil() as i32,
                    )
                }
            })
            .collect();
        Self { first_line, spans }
    }
}

/// The horizon sweep of one light's lines (see the module documentation).
struct Sweep<'a> {
    inner: &'a Inner,
    light: Vec3,
    along: DVec2,
    across: DVec2,
    /// Rise k of the light's ray per unit of horizontal travel.
    rise: f64,
    /// Fine step δ, tile units.
    step: f64,
    /// Fine steps per node.
    stride: i64,
    /// Node spacing = stride · δ.
    spacing: f64,
}

impl Sweep<'_> {
    /// The nodes of line j, `first ..= last`, one nibble value per byte.
    fn line(&self, j: i32, first: i32, last: i32) -> Vec<u8> {
        if first > last {
            return Vec::new();
        }
        let weave = &self.inner.tracer.weave;
        let base = self.across * (f64::from(j) * self.spacing);
        // A shadow ray needs at most `window` fine steps to clear the top of the tile (or
        // to reach MAX_SHADOW_TRAVEL, as the traced ray).
        let reach =
            (f64::from(weave.z_top - weave.z_floor) / self.rise).min(f64::from(MAX_SHADOW_TRAVEL));
        let window = (reach / self.step).ceil() as i64;
        let (t_first, t_last) = (
            i64::from(first) * self.stride,
            i64::from(last) * self.stride,
        );
        let mut nodes = vec![0u8; (last - first + 1) as usize];
        // Samples ahead of the current one, (index, g), g strictly decreasing from the
        // front: the front is the maximum of g over the window.
        let mut ahead: VecDeque<(i64, f64)> = VecDeque::new();
        for t in (t_first..=t_last + window).rev() {
            let u = t as f64 * self.step;
            let p = (base + self.along * u).as_vec2();
            let is_node = t <= t_last && t % self.stride == 0;
            let (height, point) = if is_node {
                let point = weave.point(p.x, p.y);
                (point.height, Some(point))
            } else {
                (weave.height(p.x, p.y), None)
            };
            // Relative to t_first to keep the magnitudes (and f64 rounding) small.
            let g = f64::from(height) - self.rise * (t - t_first) as f64 * self.step;
            if let Some(point) = point {
                while ahead.front().is_some_and(|&(index, _)| index > t + window) {
                    ahead.pop_front();
                }
                let state = if point.normal.dot(self.light) <= 0.0 {
                    FACING_AWAY
                } else if ahead
                    .front()
                    .is_some_and(|&(_, highest)| highest >= g + f64::from(SHADOW_BIAS))
                {
                    SHADOWED
                } else {
                    LIT
                };
                let k = (t / self.stride - i64::from(first)) as usize;
                nodes[k] = yarn_class(point.yarn) * STATES + state;
            }
            while ahead.back().is_some_and(|&(_, back)| back <= g) {
                ahead.pop_back();
            }
            ahead.push_back((t, g));
        }
        nodes
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::btf::{WovenBtf, WovenBtfParams};

    /// The sweep and the traced shadow ray answer the same question with the same step:
    /// at the lattice nodes they agree (up to f32 rounding of a sample landing exactly on
    /// the surface).
    #[test]
    fn sweep_matches_traced_rays_at_the_nodes() {
        let btf = WovenBtf::new(&WovenBtfParams {
            res: 24,
            ..Default::default()
        })
        .expect("valid");
        let inner = &*btf.inner;
        for (theta, phi) in [
            (30.0f32, 10.0f32),
            (68.0, 0.0),
            (80.0, 125.0),
            (85.0, 270.0),
        ] {
            let (t, p) = (theta.to_radians(), phi.to_radians());
            let light = Vec3::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos());
            let table = inner.build_table(light);
            let (mut compared, mut differ, mut shadowed) = (0, 0, 0);
            for (j, line) in table.lines.iter().enumerate() {
                for k in 0..line.len as usize {
                    let state = table.nibble(line.offset as usize + k) % STATES;
                    if state == FACING_AWAY {
                        continue;
                    }
                    let (j, i) = (table.first_line + j as i32, line.first + k as i32);
                    let spacing = 1.0 / f64::from(table.along_per_node.length());
                    let along = table.along_per_node.as_dvec2().normalize();
                    let p = (along.perp() * (f64::from(j) * spacing)
                        + along * (f64::from(i) * spacing))
                        .as_vec2();
                    let height = inner.tracer.weave.height(p.x, p.y);
                    let traced = inner.tracer.occluded(p.extend(height), light);
                    compared += 1;
                    shadowed += usize::from(traced);
                    differ += usize::from(traced != (state == SHADOWED));
                }
            }
            assert!(compared > 1000);
            assert!(
                differ * 1000 <= compared,
                "θ {theta}: sweep and traced rays differ at {differ} of {compared} nodes"
            );
            if theta >= 68.0 {
                assert!(
                    shadowed * 20 > compared,
                    "θ {theta}: only {shadowed} shadowed"
                );
            }
        }
    }
}
