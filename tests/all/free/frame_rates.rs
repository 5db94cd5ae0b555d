//! The frame's velocity and angular velocity outputs of a free body (issue 25.5:
//! `frame.vx..vz`, `frame.wx..wz`), which users had to derive by differentiating
//! `frame.x` and `frame.P`: at the start they are v0 and w0, and during a loaded tumble
//! they equal the central finite differences of `frame.x` and of `frame.P`
//! (`skew(w) = dP/dt P^T`) for every method, in the table FMI 2.0 and 3.0 share.

use crate::common::root;
use fxbody::fmu::pack::{PackOptions, PackRequest, prepare};
use fxbody::fmu::simulation::{Phase, Simulation};
use fxbody::fmu::vars::{Kind, METHODS};
use nalgebra::Matrix3;

fn vr_of(table: &fxbody::fmu::vars::VarTable, want: Kind) -> u32 {
    table.vars.iter().find(|v| v.kind == want).unwrap().vr
}

#[test]
fn frame_rates_start_at_v0_w0_and_are_the_derivatives_of_frame_x_and_p() {
    let req = PackRequest {
        body: root().join("fixtures/freefree.fxb"),
        nodes: Some(vec![521]),
        ..PackRequest::default()
    };
    let v0 = [0.3, -0.2, 0.1];
    let w0 = [2.0, 5.0, 20.0];
    let h = 1e-4;
    for info in METHODS.iter().filter(|i| i.bodies.includes(true)) {
        let p = prepare(&req, &PackOptions::default(), None).unwrap();
        let t = &p.table;
        let vr = |k: Kind| vr_of(t, k);
        let x: Vec<u32> = (0..3).map(|c| vr(Kind::FrameOrigin(c))).collect();
        let pp: Vec<u32> = (0..9).map(|k| vr(Kind::FrameP(k))).collect();
        let v: Vec<u32> = (0..3).map(|c| vr(Kind::FrameVelocity(c))).collect();
        let w: Vec<u32> = (0..3).map(|c| vr(Kind::FrameAngularVelocity(c))).collect();
        let method = vr(Kind::Method);
        let fy = vr(Kind::Load { node: 0, comp: 1 });
        let mut m = Simulation::new(p.scene, p.guid);
        m.set_integers(&[method], &[info.method as i32], Phase::Configuring)
            .unwrap();
        for c in 0..3 {
            m.set_real(vr(Kind::V0(c)), v0[c], Phase::Configuring)
                .unwrap();
            m.set_real(vr(Kind::W0(c)), w0[c], Phase::Configuring)
                .unwrap();
        }
        m.setup(0.0, None).unwrap();
        // At the start: v0 and w0 (1e-9 relative: the explicit method recovers its
        // velocities from the staggered half-step ones, 9e-11 measured).
        let mut out = [0.0; 3];
        m.get_reals(&v, &mut out).unwrap();
        for c in 0..3 {
            assert!((out[c] - v0[c]).abs() < 1e-9, "{}: {out:?}", info.name);
        }
        m.get_reals(&w, &mut out).unwrap();
        for c in 0..3 {
            assert!(
                (out[c] - w0[c]).abs() < 1e-9 * 20.7,
                "{}: {out:?}",
                info.name
            );
        }
        // A constant transverse tip force makes the frame accelerate and the body bend.
        m.set_real(fy, 5.0, Phase::Running).unwrap();
        let read = |m: &mut Simulation, vrs: &[u32]| -> Vec<f64> {
            let mut o = vec![0.0; vrs.len()];
            m.get_reals(vrs, &mut o).unwrap();
            o
        };
        let mut samples = Vec::new();
        let mut time = 0.0;
        for _ in 0..201 {
            samples.push((
                read(&mut m, &x),
                read(&mut m, &pp),
                read(&mut m, &v),
                read(&mut m, &w),
            ));
            m.do_step(time, h).unwrap();
            time += h;
        }
        let (mut ev, mut ew, mut vmax, mut wmax) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
        for i in 1..samples.len() - 1 {
            let (xa, pa, _, _) = &samples[i - 1];
            let (xb, pb, _, _) = &samples[i + 1];
            let (_, pm, vm, wm) = &samples[i];
            let p_mid = Matrix3::from_row_slice(pm);
            let dp = (Matrix3::from_row_slice(pb) - Matrix3::from_row_slice(pa)) / (2.0 * h);
            let s = dp * p_mid.transpose();
            let w_fd = [s[(2, 1)], s[(0, 2)], s[(1, 0)]];
            for c in 0..3 {
                let v_fd = (xb[c] - xa[c]) / (2.0 * h);
                ev = ev.max((vm[c] - v_fd).abs());
                ew = ew.max((wm[c] - w_fd[c]).abs());
                vmax = vmax.max(vm[c].abs());
                wmax = wmax.max(wm[c].abs());
            }
        }
        println!(
            "{}: frame velocity vs d(frame.x)/dt {:.2e} of {vmax:.3}, angular velocity vs dP/dt P^T {:.2e} of {wmax:.3}",
            info.name,
            ev / vmax,
            ew / wmax
        );
        // The central difference errs by h^2/6 times the third derivative: at
        // |w| = 20.7 rad/s that is (w h)^2/6 = 7e-7 of w; 1e-4 leaves room for the
        // bending, far below the 1 (a wrong axis or sign) to 1e-2 (a half-step lag,
        // w h / 2) a defect would give.
        assert!(ev < 1e-4 * vmax, "{}: {}", info.name, ev / vmax);
        assert!(ew < 1e-4 * wmax, "{}: {}", info.name, ew / wmax);
    }
}
