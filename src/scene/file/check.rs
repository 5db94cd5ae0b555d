//! The physical checks of a scene read back from its file, beyond the format: a scene
//! file whose checksum holds may still have been edited (and its checksum recomputed),
//! or written by something else than `pack`. fmi2Instantiate runs on it what `pack` runs
//! on a body: the body's own checks (run as the reader builds the body,
//! [`crate::body::check_scene_body`]: the same functions the `.fxb` load runs, with the
//! stored modes checked against K_L and m_L instead of solved again), the placement of a free body's nodes against its rigid
//! modes ([`crate::body::placement::check_coords`], as `pack --coords` does), at least
//! one exposed node (as `pack` requires), and a residual flexibility that is a
//! flexibility: symmetric, positive semi-definite, and not absurdly larger than the kept
//! modes'. Each refusal names the section and the value.

use std::collections::HashMap;

use nalgebra::DMatrix;

use super::SceneFileError;
use crate::num::num;
use crate::scene::Scene;

/// Relative asymmetry a residual flexibility may have: `pack` forms it as `G F G^T`,
/// symmetric to a few ulps.
const RESIDUAL_SYMMETRY: f64 = 1e-10;

/// Relative negative eigenvalue a residual flexibility may have (round-off of `G F G^T`).
const RESIDUAL_PSD: f64 = 1e-9;

/// How many times the kept modes' static flexibility at the exposed nodes (largest
/// eigenvalue) the dropped modes' may be. The dropped modes lie above every kept one, so
/// their share is usually a small fraction of the kept share (3 % at the cantilever's tip
/// with one mode kept, measured 0.39 at worst over the fixtures' nodes and cut-offs); a
/// node the kept modes hardly move can raise the ratio by a few orders, never by twelve.
const RESIDUAL_SCALE: f64 = 1e12;

/// Check the scene read from `file` (see the module notes).
pub(super) fn check_scene(scene: &Scene, file: &str) -> Result<(), SceneFileError> {
    let bad = |section: &str, what: String| SceneFileError::Section {
        file: file.to_string(),
        section: section.to_string(),
        what,
    };
    let body = &scene.body;
    if scene.nodes.is_empty() {
        return Err(bad(
            "NODE",
            "no exposed node: a scene exposes at least one (pack refuses an empty node list)"
                .into(),
        ));
    }
    // Placement needs two nodes: one node alone places L0 and contradicts nothing.
    if !body.is_blocked() && scene.nodes.len() >= 2 {
        let xyz: HashMap<i64, [f64; 3]> = body
            .node_ids
            .iter()
            .copied()
            .zip(scene.x0.iter().copied())
            .collect();
        crate::body::placement::check_coords(
            body,
            &xyz,
            &format!("{file}: section NODE"),
            "section PHIR",
        )
        .map_err(|e| SceneFileError::Physics(e.to_string()))?;
    }
    if let Some(res) = &scene.residual {
        check_residual(&res.r, scene).map_err(|what| bad("RESI", what))?;
    }
    Ok(())
}

/// A residual flexibility `r` (6m x 6m, local frame) must be symmetric, positive
/// semi-definite and within [`RESIDUAL_SCALE`] of the kept modes' flexibility at the
/// same rows (when modes are kept).
fn check_residual(r: &DMatrix<f64>, scene: &Scene) -> Result<(), String> {
    let big = r.amax();
    let asym = (r - r.transpose()).amax();
    if asym.is_nan() || asym > RESIDUAL_SYMMETRY * big {
        return Err(format!(
            "the residual flexibility is not symmetric: max |R - R^T| = {} against max |R| = {}",
            num(asym),
            num(big)
        ));
    }
    let eig = r.clone().symmetric_eigenvalues();
    let (min, max) = (eig.min(), eig.max());
    if min < -RESIDUAL_PSD * max.abs() || !min.is_finite() {
        return Err(format!(
            "the residual flexibility is not positive semi-definite: eigenvalue {} (largest {}); a flexibility never moves a node against its load",
            num(min),
            num(max)
        ));
    }
    let kept = kept_flexibility(scene);
    if kept > 0.0 && max > RESIDUAL_SCALE * kept {
        return Err(format!(
            "the residual flexibility's largest eigenvalue {} is {} times the kept modes' static flexibility at the same nodes ({}), more than {}: absurdly scaled",
            num(max),
            num(max / kept),
            num(kept),
            num(RESIDUAL_SCALE)
        ));
    }
    Ok(())
}

/// The largest eigenvalue of the kept modes' static flexibility at the exposed nodes,
/// `G S Lambda^-1 S^T G^T` over the modes with a positive eigenvalue (0 without one).
fn kept_flexibility(scene: &Scene) -> f64 {
    let body = &scene.body;
    let modal = &body.modal;
    let rows = body.phi_l.nrows();
    let mut g = DMatrix::zeros(rows, modal.lambda.len());
    let gs = &body.phi_l * &modal.shapes;
    for (j, &l) in modal.lambda.iter().enumerate() {
        if l > 0.0 {
            g.set_column(j, &(gs.column(j) / l.sqrt()));
        }
    }
    let f = &g * g.transpose();
    f.symmetric_eigenvalues().max().max(0.0)
}
