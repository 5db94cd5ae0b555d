//! Issue 26.2, free bodies: the split method's equations as a first-order system
//! (`solver::free::continuous`), integrated here by a classical Runge-Kutta of our own
//! through the derivatives only, as a Model Exchange master would.
//!
//! References: the co-simulation split method (a second integration of the same
//! equations: exact modes, the frame on the rotation group), the conservation of
//! angular momentum and energy by the torque-free equations, the rotation the frame
//! output makes, and the node velocity outputs (the kinematics the derivatives must
//! match). Tolerances are stated at each assertion.

use fxbody::fmu::simulation::{Phase, Simulation};
use fxbody::fmu::vars::Kind;
use fxbody::scene::Scene;
use fxbody::solver::continuous::Continuous;
use fxbody::solver::free::Split;
use fxbody::solver::free::continuous::{NORM_TOLERANCE, RIGID_STATES};
use fxbody::solver::{Options, Solver};
use nalgebra::{Matrix3, Vector3};

use crate::common::fixture_scene;

/// The free-free beam exposing its tip (521) and middle (511) nodes.
fn beam() -> Scene {
    fixture_scene("freefree", &[521, 511])
}

/// A model of `scene` on the split method (4), started at 0.
fn model(scene: &Scene) -> Simulation {
    let mut m = Simulation::new(scene.clone(), "me-free".into());
    let vr = m.table.vars.iter().find(|v| v.name == "method").unwrap().vr;
    m.set_integer(vr, 4, Phase::Configuring).unwrap();
    m.setup(0.0, None).unwrap();
    m
}

fn vr(m: &Simulation, kind: Kind) -> u32 {
    m.table.vars.iter().find(|v| v.kind == kind).unwrap().vr
}

/// The value references of every exposed node's position (x, y, z per node).
fn position_vrs(m: &Simulation, nodes: usize) -> Vec<u32> {
    node_vrs(m, nodes, 3, |node, comp| Kind::Position { node, comp })
}

/// The value references of `per` variables of each of `nodes` exposed nodes.
fn node_vrs(m: &Simulation, nodes: usize, per: usize, kind: fn(usize, usize) -> Kind) -> Vec<u32> {
    (0..nodes)
        .flat_map(|node| (0..per).map(move |comp| kind(node, comp)))
        .map(|k| vr(m, k))
        .collect()
}

/// The derivatives `dx` of the states `x` at time `t`.
type Rhs<'a> = dyn FnMut(f64, &[f64], &mut [f64]) + 'a;

/// The beam, two models of it (co-simulation and Model Exchange), the tip's fy load and
/// both nodes' positions (value references).
fn twins() -> (Scene, Simulation, Simulation, u32, Vec<u32>) {
    let scene = beam();
    let (cs, me) = (model(&scene), model(&scene));
    let fy = vr(&cs, Kind::Load { node: 0, comp: 1 });
    let pos = position_vrs(&cs, 2);
    (scene, cs, me, fy, pos)
}

/// One classical Runge-Kutta step of `dt` from `(t, x)` through `eval(t, x, dx)`,
/// `k` holding five state-sized work vectors.
fn rk4(eval: &mut Rhs, t: f64, dt: f64, x: &mut [f64], k: &mut [Vec<f64>; 5]) {
    let [k1, k2, k3, k4, xs] = k;
    let stage = |xs: &mut Vec<f64>, x: &[f64], kk: &[f64], c: f64| {
        for ((o, a), b) in xs.iter_mut().zip(x).zip(kk) {
            *o = a + c * b;
        }
    };
    eval(t, x, k1);
    stage(xs, x, k1, 0.5 * dt);
    eval(t + 0.5 * dt, xs, k2);
    stage(xs, x, k2, 0.5 * dt);
    eval(t + 0.5 * dt, xs, k3);
    stage(xs, x, k3, dt);
    eval(t + dt, xs, k4);
    for (i, xi) in x.iter_mut().enumerate() {
        *xi += dt / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
    }
}

fn work(n: usize) -> [Vec<f64>; 5] {
    std::array::from_fn(|_| vec![0.0; n])
}

/// Tip pulse on the free-free beam (0.1 N on the tip's fy for 2 ms, as the fixture's
/// reference), 20 ms: Model Exchange through the model layer (set time, set states,
/// derivatives; node positions read by `get_reals`, the co-simulation output code),
/// integrated by RK4 at 2.5 us, against the co-simulation split method at 10 us. Both
/// nodes' positions, every 0.1 ms, agree within 1e-5 of the peak displacement (the
/// issue's figure for CVode; measured: printed).
#[test]
fn pulse_matches_the_split_method() {
    let (scene, mut cs, mut me, fy, pos) = twins();
    let (h, sub, n) = (1e-4, 4 * 10, 200);
    let load = |t: f64| if t < 2e-3 - 1e-12 { 0.1 } else { 0.0 };
    let nx = me.state_count().unwrap();
    assert_eq!(nx, RIGID_STATES + 2 * scene.body.nl());
    let mut x = vec![0.0; nx];
    me.states(&mut x).unwrap();
    let mut k = work(nx);
    let (mut a, mut b) = (vec![0.0; 6], vec![0.0; 6]);
    let (mut worst, mut peak) = (0.0f64, 0.0f64);
    let x0: Vec<f64> = scene.x0.iter().flatten().copied().collect();
    for i in 0..n {
        let t = i as f64 * h;
        cs.set_real(fy, load(t), Phase::Running).unwrap();
        for s in 0..10 {
            cs.do_step(t + s as f64 * h / 10.0, h / 10.0).unwrap();
        }
        cs.get_reals(&pos, &mut a).unwrap();
        me.set_real(fy, load(t), Phase::Running).unwrap();
        let dt = h / sub as f64;
        for s in 0..sub {
            let mut eval = |tt: f64, xx: &[f64], dx: &mut [f64]| {
                me.set_time(tt).unwrap();
                me.set_states(xx).unwrap();
                me.derivatives(dx).unwrap();
            };
            rk4(&mut eval, t + s as f64 * dt, dt, &mut x, &mut k);
            me.set_time(t + (s + 1) as f64 * dt).unwrap();
            me.set_states(&x).unwrap();
            if me.completed_step().unwrap() {
                me.states(&mut x).unwrap();
            }
        }
        me.get_reals(&pos, &mut b).unwrap();
        for c in 0..6 {
            peak = peak.max((a[c] - x0[c]).abs());
            worst = worst.max((a[c] - b[c]).abs());
        }
    }
    println!(
        "free-free pulse, Model Exchange (RK4, 2.5 us) against co-simulation split \
         (10 us): {:.2e} of the peak {peak:.3e} m",
        worst / peak
    );
    assert!(peak > 1e-7, "the beam did not move ({peak:.2e} m)");
    assert!(worst < 1e-5 * peak, "{:.2e} of the peak", worst / peak);
}

/// The formulation's angular momentum about the origin (as in `spin.rs`: the
/// generalised momenta `M_R v_R + M_C(P) v_L` of the frame points, at `x_L0 + P e_j`
/// and L0, plus the rotational DOFs'), from the solver's coordinate velocities.
fn angular_momentum(scene: &Scene, s: &Split) -> Vector3<f64> {
    let body = &scene.body;
    let f = s.frame().unwrap();
    let p = Matrix3::from_row_slice(&f.p);
    let v = s.velocity_coordinates();
    let (nr, nl) = (body.nr(), body.nl());
    let mut g = body.m_r() * v.rows(0, nr);
    for (kl, mc) in body.m_c().iter().enumerate() {
        g += (mc * v.rows(nr, nl)) * p[(kl / 3, kl % 3)];
    }
    let at = |o: usize| Vector3::new(g[o], g[o + 1], g[o + 2]);
    let origin = Vector3::from(f.origin);
    let mut l = origin.cross(&at(9));
    for j in 0..3 {
        l += (origin + p.column(j)).cross(&at(3 * j));
    }
    if nr == 15 { l + at(12) } else { l }
}

/// A torque-free spin of the beam at `rate` of its first frequency about
/// `P0 (1, -2, 3)` (not a principal axis), `turns` rad, integrated by RK4 through the
/// trait at `dt = courant / w_max` (w_max the highest local frequency: RK4's stability
/// bound is 2.8), a completed step after each: the largest relative changes of angular
/// momentum and energy, and the largest `|abs(q) - 1|` seen after a completed step.
fn spin(rate: f64, turns: f64, courant: f64) -> (f64, f64, f64) {
    let mut scene = fixture_scene("freefree", &[521]);
    let hz = scene.body.frequencies_hz();
    let w1 = 2.0 * std::f64::consts::PI * hz[0];
    let w_max = 2.0 * std::f64::consts::PI * hz.iter().fold(0.0f64, |m, f| m.max(*f));
    let w = scene.body.p0() * Vector3::new(1.0, -2.0, 3.0).normalize() * (rate * w1);
    scene.w0 = [w[0], w[1], w[2]];
    let mut s = Split::new(&scene, &Options::default()).unwrap();
    let l0 = angular_momentum(&scene, &s);
    let e0 = s.kinetic_energy() + s.strain_energy();
    let nx = s.state_count();
    let mut x = vec![0.0; nx];
    s.states(&mut x);
    let mut k = work(nx);
    let dt = courant / w_max;
    let steps = (turns / (w.norm() * dt)) as usize;
    let (mut dl, mut de, mut dq) = (0.0f64, 0.0f64, 0.0f64);
    for i in 0..steps {
        let t = i as f64 * dt;
        let mut eval = |tt: f64, xx: &[f64], dx: &mut [f64]| {
            s.set_states(tt, xx).unwrap();
            s.derivatives(dx);
        };
        rk4(&mut eval, t, dt, &mut x, &mut k);
        s.set_states(t + dt, &x).unwrap();
        if s.completed_step() {
            s.states(&mut x);
        }
        let q = (x[3] * x[3] + x[4] * x[4] + x[5] * x[5] + x[6] * x[6]).sqrt();
        dq = dq.max((q - 1.0).abs());
        if i % 100 == 0 || i + 1 == steps {
            dl = dl.max((angular_momentum(&scene, &s) - l0).norm() / l0.norm());
            de = de.max((s.kinetic_energy() + s.strain_energy() - e0).abs() / e0);
        }
    }
    (dl, de, dq)
}

/// Torque-free spin about a non-principal axis at 0.018 of the first frequency, 200 rad
/// turned (42 s), RK4 at `dt = 0.5 / w_max` (4.8e-4 rad per step, 4.1e5 steps): angular
/// momentum and energy within 1e-10 of their start (RK4's error on the frame is of
/// order `(|w| dt)^4` per radian, 5e-14 here, and the modes carry only the centrifugal
/// deflection; measured: printed), the quaternion's norm within [`NORM_TOLERANCE`] of 1
/// after every completed step. Release build: about 5 s.
///
/// Not here: the truss (its modes drag rigid motion: FORMULATION.md section 3, it gains
/// energy under the equations themselves), and an imported bracket (none is shipped as
/// an `.fxb` under fixtures/).
#[test]
fn torque_free_spin_keeps_momentum_and_energy() {
    let (dl, de, dq) = spin(0.018, 200.0, 0.5);
    println!(
        "free-free spin, 200 rad, RK4 at 0.5 / w_max: |dL|/|L| {dl:.2e}, |dE|/E {de:.2e}, \
         |abs(q) - 1| at most {dq:.1e}"
    );
    assert!(dl < 1e-10, "angular momentum off by {dl:.2e}");
    assert!(de < 1e-10, "energy off by {de:.2e}");
    assert!(dq <= NORM_TOLERANCE, "quaternion norm off by {dq:.1e}");
}

/// A state of the spinning, deformed beam (from a few co-simulation split steps under a
/// tip load).
fn moving_beam() -> Split {
    let mut scene = beam();
    scene.v0 = [0.1, -0.2, 0.05];
    scene.w0 = [3.0, -1.0, 2.0];
    let mut s = Split::new(&scene, &Options::default()).unwrap();
    s.set_loads(&[0.0, 0.1, 0.05, 0.01, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0])
        .unwrap();
    for _ in 0..30 {
        s.step(1e-4).unwrap();
    }
    s
}

/// The kinematic derivatives against the co-simulation outputs: moving the states
/// along their derivatives by `+-eps` moves every node by `+-eps` times its velocity
/// output (central difference, within 1e-7 of the speed) and turns the frame by `eps`
/// times the frame's angular velocity (within 1e-7). A dropped factor 1/2 in the
/// quaternion rate doubles the turn.
#[test]
fn derivatives_move_the_nodes_at_their_output_velocities() {
    let mut s = moving_beam();
    let nx = s.state_count();
    let (mut x, mut dx) = (vec![0.0; nx], vec![0.0; nx]);
    s.states(&mut x);
    s.derivatives(&mut dx);
    let t = s.time();
    let mut vel = [0.0; 6];
    s.velocities(&mut vel);
    let omega = Vector3::from(s.frame_rates().unwrap().omega);
    let p_of = |s: &Split| Matrix3::from_row_slice(&s.frame().unwrap().p);
    let p0 = p_of(&s);
    let eps = 1e-6;
    let mut moved = |c: f64| {
        let xs: Vec<f64> = x.iter().zip(&dx).map(|(a, b)| a + c * eps * b).collect();
        s.set_states(t, &xs).unwrap();
        let mut pos = [0.0; 6];
        s.positions(&mut pos);
        (pos, p_of(&s))
    };
    let ((pp, rp), (pm, rm)) = (moved(1.0), moved(-1.0));
    // The velocity outputs leave out `P_dot Phi_L alpha` (FORMULATION.md section 2):
    // add `omega x` the elastic displacement, the positions less those of the
    // undeformed body (modal amplitudes zeroed).
    let mut rigid = x.clone();
    let nl = (nx - RIGID_STATES) / 2;
    rigid[RIGID_STATES..RIGID_STATES + nl].fill(0.0);
    let (mut pos, mut pos_rigid) = ([0.0; 6], [0.0; 6]);
    s.set_states(t, &x).unwrap();
    s.positions(&mut pos);
    s.set_states(t, &rigid).unwrap();
    s.positions(&mut pos_rigid);
    let speed = vel.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let mut dv = 0.0f64;
    for k in 0..2 {
        let u = Vector3::from_fn(|c, _| pos[3 * k + c] - pos_rigid[3 * k + c]);
        let expected = Vector3::from_fn(|c, _| vel[3 * k + c]) + omega.cross(&u);
        for c in 0..3 {
            let i = 3 * k + c;
            dv = dv.max(((pp[i] - pm[i]) / (2.0 * eps) - expected[c]).abs());
        }
    }
    // The turn from one to the other, read from the skew part (sin of the angle, exact
    // to the angle's cube) rather than through an arc cosine.
    let r = rp * rm.transpose();
    let turn = Vector3::new(
        r[(2, 1)] - r[(1, 2)],
        r[(0, 2)] - r[(2, 0)],
        r[(1, 0)] - r[(0, 1)],
    ) / (4.0 * eps);
    let dw = (turn - omega).norm() / omega.norm();
    println!(
        "node velocity {:.2e} of the speed, frame turn {dw:.2e} of omega",
        dv / speed
    );
    assert!((p0 - rp).amax() > 0.0, "the frame did not move");
    assert!(
        dv < 1e-7 * speed,
        "node velocity off by {:.2e} of the speed",
        dv / speed
    );
    assert!(dw < 1e-7, "frame turn off by {dw:.2e} of omega");
}

/// Outputs of a state set through the model layer are the co-simulation outputs of that
/// state: a co-simulation split run's states, set into a fresh Model Exchange model at
/// the same time, give the same node positions through `get_reals` (within 1e-15 of
/// the displacement scale: the frame goes through a quaternion and back).
#[test]
fn set_states_give_the_co_simulation_outputs() {
    let (scene, mut cs, mut me, fy, pos) = twins();
    cs.set_real(fy, 0.3, Phase::Running).unwrap();
    me.set_real(fy, 0.3, Phase::Running).unwrap();
    for i in 0..50 {
        cs.do_step(i as f64 * 1e-4, 1e-4).unwrap();
    }
    let n = cs.state_count().unwrap();
    let mut x = vec![0.0; n];
    cs.states(&mut x).unwrap();
    me.set_time(50.0 * 1e-4).unwrap();
    me.set_states(&x).unwrap();
    let (mut a, mut b) = (vec![0.0; 6], vec![0.0; 6]);
    cs.get_reals(&pos, &mut a).unwrap();
    me.get_reals(&pos, &mut b).unwrap();
    let moved = (0..6)
        .map(|c| (a[c] - scene.x0[c / 3][c % 3]).abs())
        .fold(0.0f64, f64::max);
    let diff = (0..6).map(|c| (a[c] - b[c]).abs()).fold(0.0f64, f64::max);
    println!("positions: {diff:.1e} m apart over a motion of {moved:.2e} m");
    assert!(moved > 1e-7, "the beam did not move");
    assert!(
        diff <= 1e-15 * a.iter().fold(1.0f64, |m, v| m.max(v.abs())),
        "{diff:.1e} m"
    );
    let mut y = vec![0.0; n];
    me.states(&mut y).unwrap();
    assert_eq!(x, y, "the states read back differ from those set");
}

/// The quaternion's norm: a state set with a norm 1e-6 off gives the same frame and
/// derivatives as its unit quaternion (the frame reads `q / abs(q)`), the completed
/// step puts it back to 1 and says so (`true`), and a norm within [`NORM_TOLERANCE`] is
/// left as the master set it (`false`). A zero quaternion is refused, the state
/// unchanged.
#[test]
fn completed_step_puts_the_quaternion_back_to_unit_norm() {
    let mut s = moving_beam();
    let nx = s.state_count();
    let t = s.time();
    let mut x = vec![0.0; nx];
    s.states(&mut x);
    let unit = x.clone();
    let mut d_unit = vec![0.0; nx];
    s.derivatives(&mut d_unit);
    for q in &mut x[3..7] {
        *q *= 1.0 + 1e-6;
    }
    s.set_states(t, &x).unwrap();
    let mut d = vec![0.0; nx];
    s.derivatives(&mut d);
    // Each entry against its own size, floored at 1e-6 of its block's largest.
    let nl = (nx - RIGID_STATES) / 2;
    let blocks = [0..3, 7..13, 13..13 + nl, 13 + nl..nx];
    let mut off = 0.0f64;
    for b in blocks {
        let big = d_unit[b.clone()].iter().fold(0.0f64, |m, v| m.max(v.abs()));
        for i in b {
            off = off.max((d[i] - d_unit[i]).abs() / (d_unit[i].abs() + 1e-6 * big));
        }
    }
    assert!(
        off < 1e-12,
        "derivatives change with the quaternion's norm: {off:.1e}"
    );
    assert!(s.completed_step(), "a norm 1e-6 off was left");
    let mut y = vec![0.0; nx];
    s.states(&mut y);
    let norm = y[3..7].iter().map(|v| v * v).sum::<f64>().sqrt();
    assert!(
        (norm - 1.0).abs() < 1e-15,
        "norm after the completed step {norm}"
    );
    for i in 3..7 {
        assert!(
            (y[i] - unit[i]).abs() < 1e-15,
            "quaternion {i}: {} vs {}",
            y[i],
            unit[i]
        );
    }
    assert!(!s.completed_step(), "a unit quaternion was changed");
    for q in &mut x[3..7] {
        *q = 0.0;
    }
    assert!(
        s.set_states(t, &x).is_err(),
        "a zero quaternion was accepted"
    );
    s.states(&mut y);
    assert!(
        (y[3] - unit[3]).abs() < 1e-15,
        "the refused state changed the attitude"
    );
}

/// No closed-form Jacobian: the trait answers `false` for a free body (the FMU's
/// directional derivative differentiates the accelerations numerically, tested below).
#[test]
fn the_jacobian_is_not_claimed() {
    let s = moving_beam();
    let n = s.state_count();
    let (mut a, mut b) = (vec![0.0; n * n], vec![0.0; n * 12]);
    assert!(!s.jacobian(&mut a, &mut b));
}

/// Issue 26.2: a free body's directional derivative (the model-layer call behind
/// fmi2/fmi3GetDirectionalDerivative: a central difference along the seed with the
/// kinematic rows exact) on the tumbling beam, spinning at (3, -1, 2) rad/s, deformed by
/// 30 split steps under tip loads and its modes moved by up to half their nominals,
/// loads on: every column (each state and each load as the known, every state
/// derivative as the unknowns) against an independent Richardson extrapolation of
/// central differences of the derivatives (steps 1e-3 and 5e-4 of the known's nominal,
/// 100 times the FMU's: error O(h^4)). Entry (i, j) is scaled by the known's nominal
/// over row i's largest scaled entry; the worst scaled gap is held to 1e-7 (measured:
/// printed, with the reference's own two-step spread). The kinematic rows are exact:
/// `d der(X) / d V` is the identity bit for bit.
#[test]
fn free_directional_derivative_matches_richardson_differences() {
    let mut scene = beam();
    scene.v0 = [0.1, -0.2, 0.05];
    scene.w0 = [3.0, -1.0, 2.0];
    let mut m = Simulation::new(scene.clone(), "me-free-jacobian".into());
    m.table = m.table.clone().with_states(&scene);
    m.serve_model_exchange();
    m.setup(0.0, None).unwrap();
    let loads = node_vrs(&m, 2, 6, |node, comp| Kind::Load { node, comp });
    let u: Vec<f64> = (0..12).map(|k| 0.05 * (1.0 + k as f64).sin()).collect();
    for (&l, &v) in loads.iter().zip(&u) {
        m.set_real(l, v, Phase::Running).unwrap();
    }
    for i in 0..30 {
        m.do_step(i as f64 * 1e-4, 1e-4).unwrap();
    }
    let n = m.state_count().unwrap();
    let nl = (n - RIGID_STATES) / 2;
    let (mut x, mut nom) = (vec![0.0; n], vec![0.0; n]);
    m.states(&mut x).unwrap();
    m.nominals(&mut nom).unwrap();
    for j in RIGID_STATES..n {
        x[j] += 0.5 * nom[j] * (0.7 * j as f64).sin();
    }
    m.set_time(30.0 * 1e-4).unwrap();
    m.set_states(&x).unwrap();
    let ders: Vec<u32> = (0..n).map(|i| vr(&m, Kind::Derivative(i))).collect();
    let knowns: Vec<(u32, f64)> = (0..n)
        .map(|j| (vr(&m, Kind::State(j)), nom[j]))
        .chain(loads.iter().map(|&l| (l, 0.1)))
        .collect();
    let cols = knowns.len();
    let (mut jac, mut reference, mut spread) = (
        vec![0.0; n * cols],
        vec![0.0; n * cols],
        vec![0.0; n * cols],
    );
    let (mut fp, mut fm) = (vec![0.0; n], vec![0.0; n]);
    for (c, &(known, scale)) in knowns.iter().enumerate() {
        let col = &mut jac[c * n..(c + 1) * n];
        m.directional_derivative(&ders, &[known], &[1.0], col)
            .unwrap();
        // The reference: central differences of the derivatives at two steps.
        let mut d = |h: f64, out: &mut [f64]| {
            for (sign, f) in [(1.0, &mut fp), (-1.0, &mut fm)] {
                let mut xs = x.clone();
                if c < n {
                    xs[c] += sign * h;
                } else {
                    m.set_real(known, u[c - n] + sign * h, Phase::Running)
                        .unwrap();
                }
                m.set_states(&xs).unwrap();
                m.derivatives(f).unwrap();
            }
            if c >= n {
                m.set_real(known, u[c - n], Phase::Running).unwrap();
            }
            for i in 0..n {
                out[i] = (fp[i] - fm[i]) / (2.0 * h);
            }
        };
        let (mut d1, mut d2) = (vec![0.0; n], vec![0.0; n]);
        d(1e-3 * scale, &mut d1);
        d(5e-4 * scale, &mut d2);
        m.set_states(&x).unwrap();
        for i in 0..n {
            reference[c * n + i] = (4.0 * d2[i] - d1[i]) / 3.0;
            spread[c * n + i] = (d2[i] - d1[i]).abs();
        }
    }
    let scale = |c: usize| knowns[c].1;
    let (mut worst, mut worst_spread, mut at) = (0.0f64, 0.0f64, (0, 0));
    for i in 0..n {
        let row = (0..cols)
            .map(|c| reference[c * n + i].abs() * scale(c))
            .fold(0.0f64, f64::max);
        if row == 0.0 {
            continue;
        }
        for c in 0..cols {
            let g = (jac[c * n + i] - reference[c * n + i]).abs() * scale(c) / row;
            if g > worst {
                (worst, at) = (g, (i, c));
            }
            worst_spread = worst_spread.max(spread[c * n + i] * scale(c) / row);
        }
    }
    println!(
        "free directional derivative vs Richardson differences: worst {worst:.2e} \
         (row-scaled; der {} wrt known {}), the reference's two steps differ by \
         {worst_spread:.2e}",
        at.0, at.1
    );
    assert!(worst < 1e-7, "{worst:.2e} at {at:?}");
    // d der(X_k) / d V_l = delta_kl exactly; d der(q_j) / d qd_j = 1.
    for k in 0..3 {
        for l in 0..3 {
            assert_eq!(jac[(7 + l) * n + k], f64::from(u8::from(k == l)));
        }
    }
    assert_eq!(jac[(RIGID_STATES + nl) * n + RIGID_STATES], 1.0);
    // The model is back at the states of the call.
    let mut back = vec![0.0; n];
    m.states(&mut back).unwrap();
    assert_eq!(back, x);
}

/// A free body on the implicit (2) or explicit (1) method has no first-order form:
/// Model Exchange is refused, the message naming the split method (4).
#[test]
fn implicit_and_explicit_are_refused_naming_split() {
    for method in [1, 2] {
        let mut m = Simulation::new(beam(), "me-free-refused".into());
        let vr = m.table.vars.iter().find(|v| v.name == "method").unwrap().vr;
        m.set_integer(vr, method, Phase::Configuring).unwrap();
        m.setup(0.0, None).unwrap();
        let e = m.state_count().unwrap_err().to_string();
        assert!(
            e.contains("4 (split) for a free one"),
            "method {method}: {e}"
        );
    }
}
