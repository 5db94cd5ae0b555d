//! Exponential of the small per-mode matrix that advances one damped mode under a load
//! varying linearly over a step. Computed by scaling and squaring of a Taylor series,
//! in balanced units so that under-, critically and over-damped modes and zero-frequency
//! modes all come out to full precision without special cases.

/// A 4x4 matrix, row-major.
pub type M4 = [[f64; 4]; 4];

fn mul(a: &M4, b: &M4) -> M4 {
    let mut c = [[0.0; 4]; 4];
    for i in 0..4 {
        for k in 0..4 {
            let aik = a[i][k];
            if aik == 0.0 {
                continue;
            }
            for j in 0..4 {
                c[i][j] += aik * b[k][j];
            }
        }
    }
    c
}

/// `exp(a)`: scale so that the 1-norm is at most 1/2, sum the Taylor series to 18 terms
/// (truncation below 1e-22 relative), square back.
pub fn expm(a: &M4) -> M4 {
    let norm = (0..4)
        .map(|j| (0..4).map(|i| a[i][j].abs()).sum::<f64>())
        .fold(0.0, f64::max);
    let mut s = 0i32;
    if norm > 0.5 {
        // log2(norm) + 1, not log2(norm / 0.5): the quotient overflows for a norm near
        // f64::MAX (a strongly damped mode over a long step), which took the matrix to
        // zero and left its velocity undamped. At most 1100 squarings (2^1100 exceeds
        // f64::MAX): an infinite norm must not turn into 2^31 of them.
        s = ((norm.log2() + 1.0).ceil() as i32).min(1100);
    }
    let scale = 0.5f64.powi(s);
    let mut b = *a;
    for row in b.iter_mut() {
        for v in row.iter_mut() {
            *v *= scale;
        }
    }
    // Horner: I + b (I + b/2 (I + b/3 (...))).
    let mut e: M4 = [[0.0; 4]; 4];
    for (i, row) in e.iter_mut().enumerate() {
        row[i] = 1.0;
    }
    for k in (1..=18).rev() {
        let mut t = mul(&b, &e);
        for (i, row) in t.iter_mut().enumerate() {
            for v in row.iter_mut() {
                *v /= k as f64;
            }
            row[i] += 1.0;
        }
        e = t;
    }
    for _ in 0..s {
        e = mul(&e, &e);
    }
    e
}

/// Transition coefficients of one mode `y'' + d y' + w^2 y = f0 + f1 s` over a step `h`
/// (s the time from the start of the step): the new `y` is
/// `c[0] y + c[1] y' + c[2] f0 + c[3] f1` and the new `y'` is
/// `c[4] y + c[5] y' + c[6] f0 + c[7] f1`.
///
/// Undamped modes stepping more than a radian use the closed form. Otherwise the state
/// `(y, y', f, f')` obeys a constant 4x4 system; its exponential is taken in
/// units scaled by `sigma = max(w, 1/h)`, which keeps every entry of the scaled matrix
/// and the scaled step `sigma h >= 1` of order one whatever the damping regime.
pub fn mode_coefficients(w: f64, d: f64, h: f64) -> [f64; 8] {
    if d == 0.0 && w * h > 1.0 {
        // Undamped and at least a radian per step: squaring a rotation many times would
        // let its determinant drift (2^k eps), so take the closed form, free of
        // cancellation in this range (1 - cos x = 2 sin^2(x/2)).
        let x = w * h;
        let (sn, cs) = x.sin_cos();
        let half = (0.5 * x).sin();
        let one_minus_cos = 2.0 * half * half;
        let w2 = w * w;
        return [
            cs,
            sn / w,
            one_minus_cos / w2,
            (h - sn / w) / w2,
            -w * sn,
            cs,
            sn / w,
            one_minus_cos / w2,
        ];
    }
    // 1/h overflows for a subnormal h: cap it, tau = sigma h is then merely small.
    let sigma = w.max((1.0 / h).min(f64::MAX));
    let tau = sigma * h;
    let r = w / sigma;
    let a: M4 = [
        [0.0, tau, 0.0, 0.0],
        [-r * r * tau, -d / sigma * tau, tau, 0.0],
        [0.0, 0.0, 0.0, tau],
        [0.0, 0.0, 0.0, 0.0],
    ];
    let e = expm(&a);
    // E_ij = Ê_ij sigma^(i-j).
    let s1 = 1.0 / sigma;
    let s2 = s1 * s1;
    let s3 = s2 * s1;
    [
        e[0][0],
        e[0][1] * s1,
        e[0][2] * s2,
        e[0][3] * s3,
        e[1][0] * sigma,
        e[1][1],
        e[1][2] * s1,
        e[1][3] * s2,
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn undamped_mode_matches_closed_form() {
        // y = cos(wh) y0 + sin(wh)/w v0 + (1 - cos wh)/w^2 f0 + (h - sin(wh)/w)/w^2 f1,
        // each entry compared relative to its natural size, tolerance 1e-12.
        for &(w, h) in &[(1.0, 0.1), (3.0, 7.0), (2.0e4, 0.5), (0.05, 2.0)] {
            let c = mode_coefficients(w, 0.0, h);
            let (sn, cs) = (w * h).sin_cos();
            let w2 = w * w;
            let want = [
                cs,
                sn / w,
                (1.0 - cs) / w2,
                (h - sn / w) / w2,
                -w * sn,
                cs,
                sn / w,
                (1.0 - cs) / w2,
            ];
            let wh = w * h;
            let scale = [
                1.0,
                1.0 / w,
                (1.0 / w2).min(h * h),
                (h / w2).min(h * h * h),
                w.min(w * wh),
                1.0,
                (1.0 / w).min(h),
                (1.0 / w2).min(h * h),
            ];
            for k in 0..8 {
                let err = (c[k] - want[k]).abs() / scale[k];
                assert!(err < 1e-12, "w={w} h={h} k={k}: {} vs {}", c[k], want[k]);
            }
        }
    }
}
