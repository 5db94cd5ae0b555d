//! Shared helpers of the free-body tests: a small generator of lumped-mass spring bodies
//! that writes the raw file blocks from the definitions of FORMULATION.md section 1
//! (independent of the solver), and the physical quantities the tests check (momentum,
//! angular momentum, centre of mass) computed from node outputs and nodal masses.
#![allow(dead_code)]

use std::sync::Arc;

use fxbody::body::Body;
use fxbody::fxb::FxbFile;
use fxbody::scene::Scene;
use fxbody::solver::Solver;
use nalgebra::{DMatrix, Matrix3, Vector3};

/// A generated body with the data the generator knows and the solver does not.
pub struct SpringBody {
    pub file: FxbFile,
    /// Global node coordinates.
    pub x: Vec<[f64; 3]>,
    /// Nodal masses.
    pub mass: Vec<f64>,
    /// Nodal rotational inertia (isotropic; zeros without rotational DOFs).
    pub jrot: Vec<f64>,
}

impl SpringBody {
    pub fn body(&self) -> Arc<Body> {
        // Through the validated constructor: a generated body passes every check.
        Arc::new(Body::from_fxb(&self.file, "spring body").unwrap_or_else(|e| panic!("{e}")))
    }

    /// A scene exposing every node.
    pub fn scene(&self) -> Scene {
        let body = self.body();
        Scene::new(body, (0..self.x.len()).collect(), self.x.clone())
    }

    pub fn total_mass(&self) -> f64 {
        self.mass.iter().sum()
    }
}

/// Rotation from three angles.
pub fn rotation(ax: f64, ay: f64, az: f64) -> Matrix3<f64> {
    let rx = Matrix3::new(
        1.0,
        0.0,
        0.0,
        0.0,
        ax.cos(),
        -ax.sin(),
        0.0,
        ax.sin(),
        ax.cos(),
    );
    let ry = Matrix3::new(
        ay.cos(),
        0.0,
        ay.sin(),
        0.0,
        1.0,
        0.0,
        -ay.sin(),
        0.0,
        ay.cos(),
    );
    let rz = Matrix3::new(
        az.cos(),
        -az.sin(),
        0.0,
        az.sin(),
        az.cos(),
        0.0,
        0.0,
        0.0,
        1.0,
    );
    rz * ry * rx
}

/// Raw file of a lumped-mass body with axial springs. The frame origin L0 is the centre
/// of mass, the frame P0; local modes are the lowest `nl` deformation modes of the
/// translational stiffness (local frame), scaled by `mode_scale` after mass
/// normalisation. `jrot` gives rotational DOFs (Irot = 1) with isotropic inertia.
pub fn spring_body(
    x: &[[f64; 3]],
    mass: &[f64],
    jrot: Option<&[f64]>,
    springs: &[(usize, usize, f64)],
    p0: Matrix3<f64>,
    nl: usize,
    mode_scale: f64,
) -> SpringBody {
    let n = x.len();
    let nd = 6 * n;
    let irot = jrot.is_some();
    let xs: Vec<Vector3<f64>> = x.iter().map(|v| Vector3::from(*v)).collect();
    let mt: f64 = mass.iter().sum();
    let com = xs
        .iter()
        .zip(mass)
        .map(|(v, m)| v * *m)
        .sum::<Vector3<f64>>()
        / mt;
    let local: Vec<Vector3<f64>> = xs.iter().map(|v| p0.transpose() * (v - com)).collect();
    let mut mm = DMatrix::zeros(nd, nd);
    for i in 0..n {
        for c in 0..3 {
            mm[(6 * i + c, 6 * i + c)] = mass[i];
            if let Some(j) = jrot {
                mm[(6 * i + 3 + c, 6 * i + 3 + c)] = j[i];
            }
        }
    }
    let mut kg = DMatrix::zeros(nd, nd);
    for &(a, b, k) in springs {
        let e = (xs[b] - xs[a]).normalize();
        let kk = e * e.transpose() * k;
        for (i, si) in [(a, 1.0), (b, -1.0)] {
            for (j, sj) in [(a, 1.0), (b, -1.0)] {
                for r in 0..3 {
                    for c in 0..3 {
                        kg[(6 * i + r, 6 * j + c)] += si * sj * kk[(r, c)];
                    }
                }
            }
        }
    }
    let mut rot = DMatrix::zeros(nd, nd);
    for i in 0..n {
        for blk in [0, 3] {
            for r in 0..3 {
                for c in 0..3 {
                    rot[(6 * i + blk + r, 6 * i + blk + c)] = p0[(r, c)];
                }
            }
        }
    }
    let kloc = rot.transpose() * &kg * &rot;
    // Deformation modes of the translational part.
    let tr: Vec<usize> = (0..n)
        .flat_map(|i| (0..3).map(move |c| 6 * i + c))
        .collect();
    let s: Vec<f64> = tr.iter().map(|&d| 1.0 / mm[(d, d)].sqrt()).collect();
    let kt = DMatrix::from_fn(tr.len(), tr.len(), |i, j| {
        kloc[(tr[i], tr[j])] * s[i] * s[j]
    });
    let eig = kt.symmetric_eigen();
    let lmax = eig.eigenvalues.max();
    let mut order: Vec<usize> = (0..tr.len())
        .filter(|&i| eig.eigenvalues[i] > 1e-8 * lmax)
        .collect();
    order.sort_by(|&a, &b| eig.eigenvalues[a].total_cmp(&eig.eigenvalues[b]));
    assert!(
        order.len() >= nl,
        "body has fewer deformation modes than asked"
    );
    let mut phil = DMatrix::zeros(nd, nl);
    for (j, &o) in order.iter().take(nl).enumerate() {
        for (i, &d) in tr.iter().enumerate() {
            phil[(d, j)] = eig.eigenvectors[(i, o)] * s[i] * mode_scale;
        }
    }
    let nr = if irot { 15 } else { 12 };
    let mut phir = DMatrix::zeros(nd, nr);
    for i in 0..n {
        let l = local[i];
        for j in 0..3 {
            for c in 0..3 {
                phir[(6 * i + c, 3 * j + c)] = l[j];
            }
        }
        for c in 0..3 {
            phir[(6 * i + c, 9 + c)] = 1.0 - l[0] - l[1] - l[2];
            if irot {
                phir[(6 * i + 3 + c, 12 + c)] = 1.0;
            }
        }
    }
    let mlm = phil.transpose() * &mm * &phil;
    let klm = phil.transpose() * &kloc * &phil;
    let mr = phir.transpose() * &mm * &phir;
    let t_kl = |k: usize, l: usize, v: &DMatrix<f64>, col: usize| -> DMatrix<f64> {
        let mut out = DMatrix::zeros(nd, 1);
        for i in 0..n {
            out[(6 * i + k, 0)] = v[(6 * i + l, col)];
            out[(6 * i + 3 + k, 0)] = v[(6 * i + 3 + l, col)];
        }
        out
    };
    let mut m_c = Vec::new();
    let mut k_c = Vec::new();
    for k in 0..3 {
        for l in 0..3 {
            let mut mcb = vec![0.0; nr * nl];
            let mut kcb = vec![0.0; nr * nl];
            for i in 0..nr {
                let tr_i = t_kl(k, l, &phir, i);
                let kt_i = &kloc * &tr_i;
                for j in 0..nl {
                    let tl = t_kl(k, l, &phil, j);
                    mcb[i * nl + j] = (tl.transpose() * &mm * phir.column(i))[(0, 0)];
                    kcb[i * nl + j] = (phil.column(j).transpose() * &kt_i)[(0, 0)];
                }
            }
            m_c.extend(mcb);
            k_c.extend(kcb);
        }
    }
    let m_l: Vec<f64> = (0..nl).map(|j| mlm[(j, j)]).collect();
    let mut m_r = Vec::new();
    for i in 0..nr {
        for j in i..nr {
            m_r.push(mr[(i, j)]);
        }
    }
    // Full K_L written as static rows (nS = nL): no assumption on its structure.
    let mut k_full = Vec::new();
    for r in 0..nl {
        for c in r..nl {
            k_full.push(klm[(r, c)]);
        }
    }
    let freq = fxbody::body::eigenfrequencies_hz(&klm, &nalgebra::DVector::from_vec(m_l.clone()))
        .last()
        .cloned()
        .unwrap_or(0.0);
    let mode_data = |phi: &DMatrix<f64>| -> Vec<f64> {
        (0..phi.ncols())
            .flat_map(|j| (0..nd).map(move |r| (j, r)))
            .map(|(j, r)| phi[(r, j)])
            .collect()
    };
    let p = p0;
    let file = FxbFile {
        nbmod: nl,
        nbstat: nl,
        nbnod: n,
        irot,
        idamp: false,
        iblo: false,
        ifile: false,
        node_ids: (1..=n as i64).collect(),
        p0: [
            p[(0, 0)],
            p[(0, 1)],
            p[(0, 2)],
            p[(1, 0)],
            p[(1, 1)],
            p[(1, 2)],
            p[(2, 0)],
            p[(2, 1)],
            p[(2, 2)],
        ],
        freq,
        damping: None,
        rigid_modes: mode_data(&phir),
        local_modes: mode_data(&phil),
        m_l,
        k_full,
        k_diag: vec![],
        m_r,
        m_c,
        k_c,
    };
    SpringBody {
        file,
        x: x.to_vec(),
        mass: mass.to_vec(),
        jrot: jrot.map(|j| j.to_vec()).unwrap_or_else(|| vec![0.0; n]),
    }
}

/// An irregular "cube" of eight nodes, every pair joined by a spring, unequal masses.
pub fn cube_body(irot: bool, nl: usize, stiffness: f64) -> SpringBody {
    let x = [
        [0.0, 0.0, 0.0],
        [1.1, 0.0, 0.1],
        [1.0, 0.9, 0.0],
        [0.1, 1.0, -0.1],
        [0.0, 0.1, 1.2],
        [1.0, 0.0, 1.0],
        [1.1, 1.0, 1.1],
        [-0.1, 0.9, 1.0],
    ];
    let mass = [1.0, 1.5, 0.8, 1.2, 2.0, 0.9, 1.1, 1.3];
    let jrot = [0.02, 0.01, 0.03, 0.015, 0.02, 0.01, 0.025, 0.012];
    let mut springs = Vec::new();
    for a in 0..8 {
        for b in a + 1..8 {
            springs.push((a, b, stiffness * (1.0 + 0.1 * ((a + 2 * b) % 5) as f64)));
        }
    }
    spring_body(
        &x,
        &mass,
        irot.then_some(&jrot[..]),
        &springs,
        rotation(0.2, -0.4, 0.7),
        nl,
        1.7,
    )
}

/// Node positions and velocities of every exposed node (all nodes in these tests).
pub fn node_states(s: &dyn Solver, n: usize) -> (Vec<Vector3<f64>>, Vec<Vector3<f64>>) {
    let mut x = vec![0.0; 3 * n];
    let mut v = vec![0.0; 3 * n];
    s.positions(&mut x);
    s.velocities(&mut v);
    let to = |a: &[f64]| {
        (0..n)
            .map(|k| Vector3::new(a[3 * k], a[3 * k + 1], a[3 * k + 2]))
            .collect()
    };
    (to(&x), to(&v))
}

/// Linear momentum `sum m v`.
pub fn momentum(b: &SpringBody, s: &dyn Solver) -> Vector3<f64> {
    let (_, v) = node_states(s, b.x.len());
    v.iter().zip(&b.mass).map(|(v, m)| v * *m).sum()
}

/// Centre of mass.
pub fn centre_of_mass(b: &SpringBody, s: &dyn Solver) -> Vector3<f64> {
    let (x, _) = node_states(s, b.x.len());
    x.iter()
        .zip(&b.mass)
        .map(|(x, m)| x * *m)
        .sum::<Vector3<f64>>()
        / b.total_mass()
}

/// Angular momentum about the origin `sum m x x v + J omega_n`.
pub fn angular_momentum(b: &SpringBody, s: &dyn Solver) -> Vector3<f64> {
    let n = b.x.len();
    let (x, v) = node_states(s, n);
    let mut w = vec![0.0; 3 * n];
    s.rotation_rates(&mut w);
    let mut l = Vector3::zeros();
    for k in 0..n {
        l += b.mass[k] * x[k].cross(&v[k]);
        l += b.jrot[k] * Vector3::new(w[3 * k], w[3 * k + 1], w[3 * k + 2]);
    }
    l
}

/// Largest entry of `P^T P - I`.
pub fn frame_error(s: &dyn Solver) -> f64 {
    let f = s.frame().expect("free body has a frame");
    let p = Matrix3::from_row_slice(&f.p);
    (p.transpose() * p - Matrix3::identity()).abs().max()
}
