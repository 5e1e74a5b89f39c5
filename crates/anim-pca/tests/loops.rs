//! The loop table (thesis §3.2, Fig. 3.2): exact lengths, zero cost where the clip repeats
//! itself, optimality against a brute-force enumeration of closed walks.

mod common;

use anim_pca::jumpmap::loops::LOOP_CANDIDATES;
use anim_pca::{AnimPcaError, Blend, JumpMap, JumpMapParams, LoopTable};
use common::{assert_acceptable, assert_close, wave_clip, wave_with_tail};

const PERIOD: usize = 12;

#[test]
fn every_loop_plays_exactly_its_length_and_repeats() {
    let clip = wave_clip(8, 50, PERIOD as f32, 0.2);
    let map = JumpMap::analyze(&clip, &JumpMapParams::default()).unwrap();
    for blend in [Blend::None, Blend::Fixed(3), Blend::Smoothness(1.0)] {
        let table = LoopTable::build(&map, 0, 60, blend).unwrap();
        assert!(table.iter().count() > 30, "{blend:?}: too few loop lengths");
        for len in 2..=60 {
            let Some(lp) = table.get(len) else { continue };
            assert_eq!(lp.len(), len, "{blend:?}");
            assert!(lp.frames[0].is_key());
            assert!(!lp.transitions.is_empty(), "a loop needs a jump");
            // Between transitions the keys advance naturally; a transition lands on its target
            // after its blend frames; the last one closes onto frames[0].
            for (k, t) in lp.transitions.iter().enumerate() {
                assert_eq!(lp.frames[t.index].from, t.from);
                let landing = (t.index + t.blend_frames + 1) % len;
                assert_eq!(lp.frames[landing], anim_pca::GeneratedFrame::key(t.to));
                let next = lp
                    .transitions
                    .get(k + 1)
                    .map_or(len + lp.transitions[0].index, |n| n.index);
                let mut key = t.to;
                let mut at = t.index + t.blend_frames + 1;
                while at < next {
                    assert_eq!(lp.frames[at % len], anim_pca::GeneratedFrame::key(key));
                    key += 1;
                    at += 1;
                }
            }
            // The cost is the sum of −ln s_ij over its jumps.
            let cost: f64 = lp
                .transitions
                .iter()
                .map(|t| -map.transition_score(t.from, t.to).ln())
                .sum();
            assert_close(lp.cost, cost, 1e-9 * (1.0 + cost));
            let run = lp.play(3 * len + 1);
            for t in 0..2 * len + 1 {
                assert_eq!(run.frames[t], run.frames[t + len]);
            }
        }
    }
}

#[test]
fn the_period_loops_for_free() {
    let clip = wave_clip(8, 50, PERIOD as f32, 0.0);
    let map = JumpMap::analyze(&clip, &JumpMapParams::default()).unwrap();
    let table = LoopTable::build(&map, 0, 40, Blend::None).unwrap();
    for len in [PERIOD, 2 * PERIOD, 3 * PERIOD] {
        let lp = table.get(len).unwrap();
        assert!(lp.cost < 1e-3, "length {len}: cost {}", lp.cost); // f32 rounding of the frames
    }
    // Off the period the cheapest loop must pay for an imperfect jump.
    let mut off_period = 0;
    for len in (2..=40).filter(|l| l % PERIOD != 0) {
        if let Some(lp) = table.get(len) {
            assert!(lp.cost > 0.1, "length {len}: cost {}", lp.cost);
            off_period += 1;
        }
    }
    assert!(off_period >= 5, "{off_period} off-period loops");
}

/// Edges of the loop graph rebuilt from the public API, exactly as the module docs define it:
/// (target, cost, natural step?).
fn edges(map: &JumpMap) -> Vec<Vec<(usize, f64, bool)>> {
    let l = map.n_frames();
    (0..l)
        .map(|i| {
            if !map.core()[i] {
                return Vec::new();
            }
            let mut out = Vec::new();
            if let Some(s) = map.successor(i).filter(|&s| map.core()[s]) {
                out.push((s, 0.0, true));
            }
            let mut jumps: Vec<(f64, usize)> = (0..l)
                .filter(|&j| map.core()[j] && j != i && j != i + 1 && j + 1 != i)
                .filter(|&j| i + 1 < l || (1..=l - 2).contains(&j))
                .map(|j| (map.transition_score(i, j), j))
                .filter(|(s, _)| *s > 0.0)
                .collect();
            jumps.sort_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)));
            jumps.truncate(LOOP_CANDIDATES);
            out.extend(jumps.into_iter().map(|(s, j)| (j, -s.ln(), false)));
            out
        })
        .collect()
}

/// The cheapest acceptable loop of each length ≤ max, by exhaustive search: closed walks from
/// every start, entered by a jump and closed by a jump back onto it, whose every stretch of
/// natural play lasts at least R(n) key frames.
fn brute_force(
    edges: &[Vec<(usize, f64, bool)>],
    max: usize,
    rule: impl Fn(usize) -> usize,
) -> Vec<f64> {
    struct Search<'a> {
        edges: &'a [Vec<(usize, f64, bool)>],
        start: usize,
        len: usize,
        run: usize,
        best: f64,
    }
    impl Search<'_> {
        fn walk(&mut self, at: usize, t: usize, run: usize, cost: f64) {
            for &(to, c, natural) in &self.edges[at] {
                let (nt, nc) = (t + 1, cost + c);
                if nt > self.len {
                    continue;
                }
                if natural {
                    self.walk(to, nt, run + 1, nc);
                } else if run >= self.run {
                    if to == self.start && nt == self.len {
                        self.best = self.best.min(nc);
                    } else {
                        self.walk(to, nt, 1, nc);
                    }
                }
            }
        }
    }
    let mut best = vec![f64::INFINITY; max + 1];
    for (len, b) in best.iter_mut().enumerate().skip(2) {
        for start in 0..edges.len() {
            let mut search = Search {
                edges,
                start,
                len,
                run: rule(len),
                best: f64::INFINITY,
            };
            search.walk(start, 0, 1, 0.0);
            *b = b.min(search.best);
        }
    }
    best
}

#[test]
fn table_equals_exhaustive_search() {
    // A short aperiodic clip with a tail: many imperfect loops to choose from.
    let clip = wave_with_tail(4, 18, 5.0, 3);
    let params = JumpMapParams {
        sigma: 0.3,
        sigma_velocity: 0.3,
        ..JumpMapParams::default()
    };
    let map = JumpMap::analyze(&clip, &params).unwrap();
    let max = 16;
    let table = LoopTable::build(&map, 0, max, Blend::None).unwrap();
    let best = brute_force(&edges(&map), max, |n| table.min_run(n));
    for (len, &b) in best.iter().enumerate().skip(2) {
        match table.get(len) {
            Some(lp) => {
                assert_close(lp.cost, b, 1e-9 * (1.0 + b));
                assert!(lp.shortest_run() >= table.min_run(len), "length {len}");
            }
            None => assert!(b.is_infinite(), "length {len}: brute force found {b}"),
        }
    }
    assert!(table.iter().count() >= 3, "{} loops", table.iter().count());
}

#[test]
fn bad_parameters_are_named() {
    let clip = wave_clip(4, 20, 6.0, 0.0);
    let map = JumpMap::analyze(&clip, &JumpMapParams::default()).unwrap();
    for (max, name) in [(1, "max_len"), (200_000, "max_len")] {
        match LoopTable::build(&map, 0, max, Blend::None) {
            Err(AnimPcaError::InvalidParameter { name: n, .. }) => assert_eq!(n, name),
            other => panic!("max_len {max}: {other:?}"),
        }
    }
    assert!(matches!(
        LoopTable::build(&map, 1, 10, Blend::None),
        Err(AnimPcaError::InvalidCell { cell: 1, .. })
    ));
    assert!(matches!(
        LoopTable::build(&map, 0, 10, Blend::Smoothness(f64::NAN)),
        Err(AnimPcaError::InvalidParameter { .. })
    ));
}

#[test]
fn a_pause_in_the_clip_does_not_become_a_ping_pong() {
    // A wave that stops for six nearly identical frames halfway: jumps inside the pause are
    // almost free, so the cheapest closed walk of most lengths bounces there (the chicken's
    // 6-frame ping-pong). The table must play real stretches of the clip instead.
    let wave = wave_clip(6, 80, 17.0, 0.0);
    let clip: Vec<_> = (0..80)
        .map(|t| {
            let held = if (40..=46).contains(&t) { 40 } else { t };
            wave[held]
                .iter()
                .map(|p| *p + glam::Vec3::Z * (1e-4 * t as f32))
                .collect::<Vec<_>>()
        })
        .collect();
    let map = JumpMap::analyze(&clip, &JumpMapParams::default()).unwrap();
    let table = LoopTable::build(&map, 0, 60, Blend::Fixed(3)).unwrap();
    let found = assert_acceptable("paused wave", &table);
    assert!(found > 20, "{found} loop lengths");
    for n in [24, 34, 48] {
        let lp = table.get(n).unwrap_or_else(|| panic!("a {n}-frame loop"));
        // No stretch inside the pause alone: each run reaches beyond its seven frames.
        assert!(
            lp.shortest_run() >= n / 4,
            "{n}: shortest run {}",
            lp.shortest_run()
        );
        let inside = lp
            .frames
            .iter()
            .filter(|f| f.is_key() && (40..=46).contains(&f.from))
            .count();
        assert!(inside < n / 2, "{n}: {inside} of its frames are the pause");
    }
}
