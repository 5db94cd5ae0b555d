//! The sparse path against CalculiX itself, on a real part: the L-bracket of
//! `tests/fe_models/bracket.py` (second-order tetrahedra, 18,690 DOFs blocked, 18,696
//! free), its matrices written by ccx (`*FREQUENCY, SOLVER=MATRIXSTORAGE`), checked
//! against ccx's own `*FREQUENCY` and `*STATIC` results (independent: ccx factors with
//! SPOOLES and iterates with ARPACK).
//!
//! Needs ccx (scripts/setup-fe.sh) and gmsh in the test venv (requirements-test.txt); the
//! model is generated once into target/fe_models/ (about two minutes).

use std::collections::HashSet;

use faer::Mat;
use fxbody_import::fe::Dof;
use fxbody_import::sparse::dense::{ab, at_b, sym_eigen};
use fxbody_import::sparse::eigen::{Modes, Options, Solver, Support, hz, lambda};
use fxbody_import::sparse::rigid::{null_residual, rigid_motions};
use fxbody_import::sparse::{MatrixStorage, SymCsc, TermStream, read_job, statics};

use crate::common::{bracket, centroid, nodes, printed, reference, rot_nodes, spiders};

/// Largest element edge of the test mesh, mm.
const SIZE: f64 = 6.0;
/// The frequency limit: 19 blocked and 14 elastic free modes lie below it.
const FMAX: f64 = 20_000.0;

fn job(case: &str) -> (std::path::PathBuf, MatrixStorage) {
    let dir = bracket(SIZE, true);
    let model = read_job(&dir.join(case)).unwrap_or_else(|e| panic!("{e}"));
    (dir, model)
}

/// ccx's own machine-to-machine spread, relative (see `assert_frequencies`).
const CCX_SPREAD: f64 = 1e-6;

/// Our frequencies against ccx's printed ones (7 digits): each within half a unit of the
/// last printed digit, plus 1e-6 relative for ccx's own solver. ccx's ARPACK and SPOOLES
/// round differently per machine, and that shows in the 7th digit: the free bracket's
/// mode 3 prints 4.184974e3 Hz on one machine and 4.184973e3 on another, ours 4.1849736e3
/// between them. A wrong mass, spider or index moves a frequency by far more than 1e-6.
fn assert_frequencies(ours: &[f64], printed_hz: &[serde_json::Value]) -> f64 {
    let theirs: Vec<(f64, f64)> = printed_hz
        .iter()
        .map(|v| printed(v.as_str().expect("string")))
        .filter(|&(f, _)| f < FMAX)
        .collect();
    assert_eq!(ours.len(), theirs.len(), "ours {ours:?} ccx {theirs:?}");
    let mut worst = 0.0f64;
    for (k, (&f, &(g, half))) in ours.iter().zip(&theirs).enumerate() {
        let diff = (f - g).abs();
        worst = worst.max(diff / g);
        assert!(
            diff <= half + CCX_SPREAD * g,
            "mode {k}: ours {f:.9e} Hz, ccx {g:e} +- {half:e}"
        );
    }
    worst
}

#[test]
fn blocked_frequencies_equal_ccx() {
    let (dir, model) = job("blocked");
    let lmax = lambda(FMAX);
    let solver = Solver::new(&model.k, &model.m, &Support::Blocked, lmax).unwrap();
    let modes = solver.modes(&Options::default()).unwrap();
    let f: Vec<f64> = modes.lambda.iter().map(|&l| hz(l)).collect();
    let worst = assert_frequencies(&f, reference(&dir)["blocked_hz"].as_array().unwrap());
    println!(
        "blocked: {} modes below {FMAX} Hz, worst relative difference {worst:.1e}",
        f.len()
    );
    assert_eq!(modes.count, 19);
    let worst = modes.residual.iter().fold(0.0f64, |a, &b| a.max(b));
    assert!(worst < 1e-8, "backward error {worst:e}");
}

/// The free body with its rigid motions locked out: the elastic modes are ccx's 7th
/// onwards.
#[test]
fn free_frequencies_equal_ccx() {
    let (dir, model) = job("free");
    let xyz = nodes(&dir);
    let r = rigid_motions(&model.dofs, &xyz, &rot_nodes(&dir), centroid(&xyz)).unwrap();
    let support = Support::Free { rigid: Some(r) };
    let solver = Solver::new(&model.k, &model.m, &support, lambda(FMAX)).unwrap();
    let modes = solver.modes(&Options::default()).unwrap();
    assert_eq!((modes.count, modes.rigid_locked), (20, 6));
    let worst = modes.residual.iter().fold(0.0f64, |a, &b| a.max(b));
    assert!(worst < 1e-8, "backward error {worst:e}");
    let f: Vec<f64> = modes.lambda.iter().map(|&l| hz(l)).collect();
    let ccx = reference(&dir)["free_hz"].as_array().unwrap()[6..].to_vec();
    let worst = assert_frequencies(&f, &ccx);
    println!(
        "free: {} elastic modes below {FMAX} Hz, worst relative difference {worst:.1e}",
        f.len()
    );
    // The elastic modes are M-orthonormal and M-orthogonal to the rigid motions.
    let rigid = solver.rigid().unwrap();
    let c = at_b(rigid.mx.as_ref(), modes.vectors.as_ref()).norm_max();
    assert!(c < 1e-10, "{c:e}");
    let g = model.m.project(modes.vectors.as_ref());
    let off = (0..g.nrows())
        .flat_map(|i| (0..g.ncols()).map(move |j| (i, j)))
        .map(|(i, j)| (g[(i, j)] - if i == j { 1.0 } else { 0.0 }).abs())
        .fold(0.0f64, f64::max);
    assert!(off < 1e-10, "{off:e}");
}

/// Without the rigid motions, the solver finds them as six modes near zero (ccx prints
/// at most 2e-3 Hz for them) and the elastic ones as before.
#[test]
fn free_without_rigid_motions_finds_six_near_zero() {
    let (dir, model) = job("free");
    let support = Support::Free { rigid: None };
    let solver = Solver::new(&model.k, &model.m, &support, lambda(FMAX)).unwrap();
    let modes = solver.modes(&Options::default()).unwrap();
    let f: Vec<f64> = modes.lambda.iter().map(|&l| hz(l)).collect();
    assert_eq!(f.len(), 20);
    assert!(f[..6].iter().all(|&x| x < 1.0), "{f:?}");
    let ccx = reference(&dir)["free_hz"].as_array().unwrap()[6..].to_vec();
    assert_frequencies(&f[6..], &ccx);
}

/// Read with the spider reading (ROT node translations are rotations), the six rigid
/// motions lie in the free K's null space to rounding; read as an ordinary node, the ROT
/// node breaks it.
#[test]
fn rigid_motions_lie_in_the_null_space_with_the_spider_reading() {
    let (dir, model) = job("free");
    let xyz = nodes(&dir);
    let o = centroid(&xyz);
    let r = rigid_motions(&model.dofs, &xyz, &rot_nodes(&dir), o).unwrap();
    let good = null_residual(&model.k, &r);
    println!("spider reading: |K r| / (|K| |r|) = {:.1e}", good.residual);
    assert!(good.residual < 1e-13, "{good:?}");
    let naive = rigid_motions(&model.dofs, &xyz, &HashSet::new(), o).unwrap();
    let bad = null_residual(&model.k, &naive);
    assert!(bad.residual > 1e-3, "{bad:?}");
}

/// Equation indices of a node's directions 1-3.
fn dofs_of(dofs: &[Dof], node: i64) -> Vec<usize> {
    (1..=3)
        .map(|c| {
            dofs.iter()
                .position(|&d| d == Dof::new(node, c))
                .expect("DOF")
        })
        .collect()
}

/// `V (V^T K V)^-1 V^T f` with V = [modes, statics], each column scaled to a unit
/// M-norm (a static mode of a rotation DOF is 1e-10 the size of an M-normalised mode), then
/// M-orthonormalised with directions below 1e-10 of the largest dropped: the reduced
/// model's static response.
fn reduced_solve(
    k: &SymCsc,
    m: &SymCsc,
    modes: &Modes,
    statics: &Mat<f64>,
    f: &Mat<f64>,
) -> Mat<f64> {
    let (n, p, c) = (k.n(), modes.vectors.ncols(), statics.ncols());
    let mut v = Mat::from_fn(n, p + c, |i, j| {
        if j < p {
            modes.vectors[(i, j)]
        } else {
            statics[(i, j - p)]
        }
    });
    let g = m.project(v.as_ref());
    for j in 0..p + c {
        let norm = g[(j, j)].sqrt();
        for i in 0..n {
            v[(i, j)] /= norm;
        }
    }
    let g = m.project(v.as_ref());
    let (s, u) = sym_eigen(g.as_ref()).unwrap();
    let top = s[s.len() - 1];
    let keep: Vec<usize> = (0..s.len()).filter(|&k| s[k] > 1e-20 * top).collect();
    assert_eq!(keep.len(), p + c, "dependent basis");
    let scale = Mat::from_fn(p + c, keep.len(), |i, j| {
        u[(i, keep[j])] / s[keep[j]].sqrt()
    });
    let w = ab(v.as_ref(), scale.as_ref());
    let kr = k.project(w.as_ref());
    let (d, y) = sym_eigen(kr.as_ref()).unwrap();
    let rhs = at_b(y.as_ref(), at_b(w.as_ref(), f.as_ref()).as_ref());
    let q = Mat::from_fn(d.len(), 1, |i, _| rhs[(i, 0)] / d[i]);
    ab(w.as_ref(), ab(y.as_ref(), q.as_ref()).as_ref())
}

/// ccx's static displacement of spider B (REF translations, then ROT "translations" =
/// rotations) and half a unit of each printed last digit.
fn ccx_static(dir: &std::path::Path) -> (Vec<f64>, Vec<f64>, [f64; 3], [f64; 3]) {
    let st = reference(dir)["static"].clone();
    let (mut u, mut half) = (Vec::new(), Vec::new());
    for key in ["ref", "rot"] {
        for v in st[key].as_array().unwrap() {
            let (x, h) = printed(v.as_str().unwrap());
            u.push(x);
            half.push(h);
        }
    }
    let vec3 = |key: &str| [0, 1, 2].map(|i| st[key][i].as_f64().unwrap());
    (u, half, vec3("force"), vec3("moment"))
}

/// Each of our six connection values against ccx's: within 1e-6 of the largest of its
/// kind (translation or rotation), and within the printed precision plus 1e-8 of that
/// largest value (ccx's own SPOOLES solve rounds per machine, and a value near a rounding
/// boundary may print on either side of it).
fn assert_static(ours: &[f64], ccx: &[f64], half: &[f64]) -> f64 {
    let mut worst = 0.0f64;
    for kind in [0..3, 3..6] {
        let scale = ccx[kind.clone()].iter().fold(0.0f64, |a, b| a.max(b.abs()));
        for i in kind {
            let diff = (ours[i] - ccx[i]).abs();
            worst = worst.max(diff / scale);
            assert!(
                diff <= 1e-6 * scale,
                "{i}: ours {:e} ccx {:e}",
                ours[i],
                ccx[i]
            );
            assert!(
                diff <= half[i] + 1e-8 * scale,
                "{i}: ours {:e} ccx {:e}",
                ours[i],
                ccx[i]
            );
        }
    }
    worst
}

/// Blocked at spider A, a force and a moment at spider B: the reduced model (the modes
/// below FMAX plus the static modes of B's six DOFs) gives ccx's `*STATIC` displacement
/// and rotation of B.
#[test]
fn blocked_statics_at_a_connection_equal_ccx() {
    let (dir, model) = job("blocked");
    let (_, b) = spiders(&dir);
    let solver = Solver::new(&model.k, &model.m, &Support::Blocked, lambda(FMAX)).unwrap();
    let modes = solver.modes(&Options::default()).unwrap();
    let conn: Vec<usize> = [
        dofs_of(&model.dofs, b.reference),
        dofs_of(&model.dofs, b.rotation),
    ]
    .concat();
    let psi = statics::static_modes(&solver, &conn, &modes).unwrap();
    let (ccx, half, force, moment) = ccx_static(&dir);
    let mut f = Mat::zeros(model.dofs.len(), 1);
    for i in 0..3 {
        f[(conn[i], 0)] = force[i];
        f[(conn[3 + i], 0)] = moment[i];
    }
    let u = reduced_solve(&model.k, &model.m, &modes, &psi, &f);
    let ours: Vec<f64> = conn.iter().map(|&j| u[(j, 0)]).collect();
    let worst = assert_static(&ours, &ccx, &half);
    println!("blocked statics: worst difference {worst:.1e} of the largest value");
}

/// The free body under a self-equilibrated load (force and moment at B, their reaction
/// at A): B's motion relative to A's rigid frame, from the reduced model (elastic modes
/// plus inertia-relief modes of both spiders' twelve DOFs), equals ccx's `*STATIC` of the
/// body clamped at A.
#[test]
fn free_statics_relative_to_a_equal_ccx_clamped_at_a() {
    let (dir, model) = job("free");
    let (a, b) = spiders(&dir);
    let xyz = nodes(&dir);
    let r = rigid_motions(&model.dofs, &xyz, &rot_nodes(&dir), centroid(&xyz)).unwrap();
    let support = Support::Free { rigid: Some(r) };
    let solver = Solver::new(&model.k, &model.m, &support, lambda(FMAX)).unwrap();
    let modes = solver.modes(&Options::default()).unwrap();
    let conn: Vec<usize> = [
        dofs_of(&model.dofs, a.reference),
        dofs_of(&model.dofs, a.rotation),
        dofs_of(&model.dofs, b.reference),
        dofs_of(&model.dofs, b.rotation),
    ]
    .concat();
    let psi = statics::static_modes(&solver, &conn, &modes).unwrap();
    // Each is an inertia-relief mode: no rigid part (R^T M psi = 0), and
    // K psi_j = P e_j = e_j - M R R^T e_j (R M-orthonormal), to 1e-9 of |P e_j|.
    let rigid = solver.rigid().unwrap();
    let rigid_part = at_b(rigid.mx.as_ref(), psi.as_ref()).norm_max() / psi.norm_max();
    assert!(rigid_part < 1e-12, "rigid part {rigid_part:e}");
    let mut kpsi = Mat::zeros(model.dofs.len(), conn.len());
    model.k.mul(psi.as_ref(), kpsi.as_mut());
    for (j, &e) in conn.iter().enumerate() {
        let pe = Mat::from_fn(model.dofs.len(), 1, |i, _| {
            let unit = if i == e { 1.0 } else { 0.0 };
            unit - (0..6)
                .map(|k| rigid.mx[(i, k)] * rigid.x[(e, k)])
                .sum::<f64>()
        });
        let err = (0..model.dofs.len())
            .map(|i| (kpsi[(i, j)] - pe[(i, 0)]).abs())
            .fold(0.0f64, f64::max);
        assert!(
            err < 1e-9 * pe.norm_max(),
            "mode {j}: |K psi - P e| = {err:e}"
        );
    }
    let (ccx, half, force, moment) = ccx_static(&dir);
    let d = [0, 1, 2].map(|i| b.centre[i] - a.centre[i]);
    let d_x_f = [
        d[1] * force[2] - d[2] * force[1],
        d[2] * force[0] - d[0] * force[2],
        d[0] * force[1] - d[1] * force[0],
    ];
    let mut f = Mat::zeros(model.dofs.len(), 1);
    for i in 0..3 {
        f[(conn[i], 0)] = -force[i];
        f[(conn[3 + i], 0)] = -moment[i] - d_x_f[i];
        f[(conn[6 + i], 0)] = force[i];
        f[(conn[9 + i], 0)] = moment[i];
    }
    let u = reduced_solve(&model.k, &model.m, &modes, &psi, &f);
    let at = |k: usize| u[(conn[k], 0)];
    let (va, wa) = ([0, 1, 2].map(at), [3, 4, 5].map(at));
    let w_x_d = [
        wa[1] * d[2] - wa[2] * d[1],
        wa[2] * d[0] - wa[0] * d[2],
        wa[0] * d[1] - wa[1] * d[0],
    ];
    let ours: Vec<f64> = (0..3)
        .map(|i| at(6 + i) - va[i] - w_x_d[i])
        .chain((0..3).map(|i| at(9 + i) - wa[i]))
        .collect();
    let worst = assert_static(&ours, &ccx, &half);
    println!("free statics: worst difference {worst:.1e} of the largest value");
}

/// The term-stream entry (what the Abaqus and DMIG readers feed) builds, from the same
/// terms keyed by DOF in reverse order and mirrored, the matrix the CalculiX reader built
/// (rows and columns in sorted DOF order).
#[test]
fn term_stream_gives_the_calculix_matrix() {
    let (_, model) = job("blocked");
    let k = &model.k;
    let mut stream = TermStream::new("k.mtx");
    let mut line = 0;
    for j in (0..k.n()).rev() {
        for p in (k.col_ptr()[j]..k.col_ptr()[j + 1]).rev() {
            line += 1;
            let i = k.row_idx()[p];
            // Lower triangle: (col, row).
            stream
                .push(model.dofs[j], model.dofs[i], k.values()[p], line)
                .unwrap();
        }
    }
    let sorted = stream.finish().unwrap();
    assert_eq!(sorted.matrix.nnz(), k.nnz());
    let pos: Vec<usize> = model
        .dofs
        .iter()
        .map(|d| sorted.dofs.binary_search(d).expect("DOF"))
        .collect();
    for j in 0..k.n() {
        for p in k.col_ptr()[j]..k.col_ptr()[j + 1] {
            let i = k.row_idx()[p];
            assert_eq!(sorted.matrix.get(pos[i], pos[j]), k.values()[p]);
        }
    }
}

/// The same bits for any pool size: eigenvalues, eigenvectors and static modes computed
/// in rayon pools of 1, 2 and 3 threads.
#[test]
fn same_bits_for_any_thread_count() {
    let (dir, model) = job("blocked");
    let (_, b) = spiders(&dir);
    let conn = dofs_of(&model.dofs, b.reference);
    let run = |threads: usize| {
        fxbody_testkit::in_pool(threads, || {
            let solver =
                Solver::new(&model.k, &model.m, &Support::Blocked, lambda(8_000.0)).unwrap();
            let modes = solver.modes(&Options::default()).unwrap();
            let psi = statics::static_modes(&solver, &conn, &modes).unwrap();
            let bits = |m: &Mat<f64>| -> Vec<u64> {
                (0..m.ncols())
                    .flat_map(|j| (0..m.nrows()).map(move |i| m[(i, j)].to_bits()))
                    .collect()
            };
            let l: Vec<u64> = modes.lambda.iter().map(|x| x.to_bits()).collect();
            (l, bits(&modes.vectors), bits(&psi))
        })
    };
    let one = run(1);
    assert_eq!(one.0.len(), 7);
    for threads in [2, 3] {
        assert!(run(threads) == one, "{threads} threads differ from 1");
    }
}
