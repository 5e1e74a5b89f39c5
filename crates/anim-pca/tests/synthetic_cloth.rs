//! Jump maps on the synthetic cloth (`synth::simulate_cloth`): a drape that falls onto a
//! sphere, folds, and slides off: a clip with no period at all, whose only self-similar part
//! is the slow middle (frames ≈ 27–79 of 90 at grid 20). The repository's own sequence, so
//! this runs on a fresh clone without ../shared/data.

mod common;

use anim_pca::jumpmap::metrics::{
    clip_max_velocity_change, reconstruction_errors, sequence_stats, transition_velocity_change,
};
use anim_pca::{Blend, JumpMap, JumpMapParams, LoopTable, PlaybackParams, Player};
use common::drape;

#[test]
fn drape_plays_endlessly_and_smoothly() {
    let clip = drape();
    let map = JumpMap::analyze(&clip, &JumpMapParams::default()).unwrap();
    let l = clip.len();
    // The slow middle resembles itself and forms the core; the fall and the slide off the
    // sphere never recur and lie outside it (played once on the way in, or never).
    let core = map.core().iter().filter(|c| **c).count();
    assert!(core >= 20, "core of {core} frames");
    assert!(!map.core()[0], "the flat start never recurs");
    assert!(!map.core()[l - 1], "the slide off the sphere never recurs");
    let params = PlaybackParams {
        blend: Blend::Fixed(3),
        seed: 3,
        ..Default::default()
    };
    let run = Player::new(&map, &params).unwrap().generate(100_000);
    let stats = sequence_stats(&map, &run);
    println!(
        "drape: {stats:?}, core {}/{l}",
        map.core().iter().filter(|c| **c).count()
    );
    assert!(stats.transitions > 1000, "{stats:?}");
    // Once in the core, no key frame outside it again (blend frames may run a few frames
    // past a core frame: the source stream plays on while it fades out).
    let first_core = run.frames.iter().position(|f| map.core()[f.from]).unwrap();
    assert!(first_core < l);
    assert!(
        run.frames[first_core..]
            .iter()
            .filter(|f| f.is_key())
            .all(|f| map.core()[f.from])
    );
    let (reference, at_transitions) = (
        clip_max_velocity_change(&map),
        transition_velocity_change(&map, &run),
    );
    assert!(
        at_transitions <= 2.0 * reference,
        "velocity change at transitions {at_transitions} > 2 × clip's {reference}"
    );
    // The core loops: a one-second loop exists, inside the core.
    let table = LoopTable::build(&map, 0, 40, Blend::Fixed(3)).unwrap();
    let lp = table.get(30).expect("a 30-frame loop of the drape");
    assert!(lp.frames.iter().all(|f| map.core()[f.from]));
}

#[test]
fn drape_reconstruction_error_falls_with_c() {
    let clip = drape();
    let errors = reconstruction_errors(&clip, &[0, 2, 4, 8, 16]).unwrap();
    for w in errors.windows(2) {
        assert!(
            w[1].position <= w[0].position * (1.0 + 1e-9),
            "E({}) = {} > E({}) = {}",
            w[1].components,
            w[1].position,
            w[0].components,
            w[0].position
        );
    }
    // A drape is smooth in time: 16 of 89 possible components keep E below 1 % of the mean-only
    // error.
    assert!(errors[4].position < 0.01 * errors[0].position, "{errors:?}");
}
