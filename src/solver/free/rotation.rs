//! The rotation vector of a rotation matrix, for the node rotation outputs of the free
//! methods ([`super::FreeScene::rotations`]).

use nalgebra::{Matrix3, Vector3};

/// The rotation vector (axis times angle, angle in [0, pi]) of a rotation matrix, by
/// way of its unit quaternion `(w, v)`: `2 atan2(|v|, w) v / |v|`, accurate at small
/// angles (where `acos` of the trace loses half the digits) and near pi. The quaternion
/// is Shepperd's (from the largest of the trace and the diagonal, so no square root of a
/// small difference) normalised, which absorbs the frame's drift from a rotation (1e-13,
/// the constraints' tolerance) to the same order. No iteration: whatever the matrix
/// (a state far outside what any step leaves), the call returns, finite for finite
/// entries. (nalgebra's nearest-rotation search, used until issue 28, looped for ever on
/// a NaN and on some large matrices.)
pub(crate) fn rotation_vector(r: &Matrix3<f64>) -> Vector3<f64> {
    let (r00, r11, r22) = (r[(0, 0)], r[(1, 1)], r[(2, 2)]);
    let tr = r00 + r11 + r22;
    let (w, x, y, z);
    if tr >= r00.max(r11).max(r22) {
        let s = 2.0 * (1.0 + tr).max(0.0).sqrt();
        (w, x, y, z) = (
            0.25 * s,
            (r[(2, 1)] - r[(1, 2)]) / s,
            (r[(0, 2)] - r[(2, 0)]) / s,
            (r[(1, 0)] - r[(0, 1)]) / s,
        );
    } else if r00 >= r11 && r00 >= r22 {
        let s = 2.0 * (1.0 + r00 - r11 - r22).max(0.0).sqrt();
        (w, x, y, z) = (
            (r[(2, 1)] - r[(1, 2)]) / s,
            0.25 * s,
            (r[(0, 1)] + r[(1, 0)]) / s,
            (r[(0, 2)] + r[(2, 0)]) / s,
        );
    } else if r11 >= r22 {
        let s = 2.0 * (1.0 + r11 - r00 - r22).max(0.0).sqrt();
        (w, x, y, z) = (
            (r[(0, 2)] - r[(2, 0)]) / s,
            (r[(0, 1)] + r[(1, 0)]) / s,
            0.25 * s,
            (r[(1, 2)] + r[(2, 1)]) / s,
        );
    } else {
        let s = 2.0 * (1.0 + r22 - r00 - r11).max(0.0).sqrt();
        (w, x, y, z) = (
            (r[(1, 0)] - r[(0, 1)]) / s,
            (r[(0, 2)] + r[(2, 0)]) / s,
            (r[(1, 2)] + r[(2, 1)]) / s,
            0.25 * s,
        );
    }
    let (mut w, mut v) = (w, Vector3::new(x, y, z));
    if !(w.is_finite() && v.iter().all(|c| c.is_finite())) {
        // Only a matrix far from any rotation (or with a non-finite entry) gets here.
        return if r.iter().all(|c| c.is_finite()) {
            Vector3::zeros()
        } else {
            Vector3::from_element(f64::NAN)
        };
    }
    if w < 0.0 {
        w = -w;
        v = -v;
    }
    let s = v.norm();
    if s == 0.0 {
        return Vector3::zeros();
    }
    // atan2 needs no normalisation of (w, v): only their ratio enters.
    v * (2.0 * s.atan2(w) / s)
}
