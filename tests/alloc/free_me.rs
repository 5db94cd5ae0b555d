//! Issue 26.2, free bodies: Model Exchange's per-evaluation calls on a free body (set
//! time, set states, state derivatives, a completed integrator step that normalises the
//! quaternion, one position read, a load set) allocate nothing once the solver is built,
//! on the free-free beam and on the beam truncated with the static correction.

use crate::common::fixture_scene;
use crate::me::evaluations_do_not_allocate;

/// The states are moved by up to 1e-6 from the start, the quaternion's norm with them:
/// completed steps normalise it (and must, at least once).
#[test]
fn free_model_exchange_evaluations_do_not_allocate() {
    let full = fixture_scene("freefree", &[521, 511]);
    let truncated = full.truncated(300.0).unwrap().0;
    let normalised = evaluations_do_not_allocate([full, truncated], 4);
    assert!(
        normalised > 0,
        "no completed step normalised the quaternion"
    );
}
