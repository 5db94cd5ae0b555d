//! The numpy hand computation of two explicit steps on a three-node free body
//! (tests/reference/free_hand_step.py, written to tests/data/free_hand_step.json): the
//! raw file blocks of the body, the steps, and the coordinates after each case.

use serde_json::Value;

use super::{nums, root};

/// One body of the hand computation (Irot 0 or 1) and its results.
pub struct HandStep {
    pub p0: [f64; 9],
    pub freq: f64,
    pub damping: (f64, f64),
    pub rigid_modes: Vec<f64>,
    pub local_modes: Vec<f64>,
    pub m_l: Vec<f64>,
    pub k_full: Vec<f64>,
    pub k_diag: Vec<f64>,
    pub m_r: Vec<f64>,
    pub m_c: Vec<f64>,
    pub k_c: Vec<f64>,
    /// Node coordinates, 3 per node.
    pub x0: [f64; 9],
    /// Case A: one communication step of two internal steps.
    pub ha: f64,
    /// Cases B and C: two communication steps of one internal step each.
    pub hb: [f64; 2],
    /// Case C: the loads set before the second step.
    pub jump: [f64; 12],
    /// Coordinates q (rigid then local), velocities v and frame P (row-major) after
    /// case A, B and C; exposed node positions after case B.
    pub qa: Vec<f64>,
    pub va: Vec<f64>,
    pub pa: Vec<f64>,
    pub qb: Vec<f64>,
    pub vb: Vec<f64>,
    pub pb: Vec<f64>,
    pub posb: Vec<f64>,
    pub qc: Vec<f64>,
    pub vc: Vec<f64>,
    pub pc: Vec<f64>,
}

/// The body with (`irot`) or without rotational DOFs.
pub fn load(irot: bool) -> HandStep {
    let path = root().join("tests/data/free_hand_step.json");
    let text = std::fs::read_to_string(&path).unwrap();
    let all: Value = serde_json::from_str(&text).unwrap();
    let h = &all[if irot { "rot" } else { "norot" }];
    let v = |key: &str| {
        assert!(!h[key].is_null(), "{}: no {key}", path.display());
        nums(&h[key])
    };
    let damping = v("damping");
    HandStep {
        p0: v("p0").try_into().unwrap(),
        freq: h["freq"].as_f64().unwrap(),
        damping: (damping[0], damping[1]),
        rigid_modes: v("rigid_modes"),
        local_modes: v("local_modes"),
        m_l: v("m_l"),
        k_full: v("k_full"),
        k_diag: v("k_diag"),
        m_r: v("m_r"),
        m_c: v("m_c"),
        k_c: v("k_c"),
        x0: v("x0").try_into().unwrap(),
        ha: h["ha"].as_f64().unwrap(),
        hb: v("hb").try_into().unwrap(),
        jump: v("jump").try_into().unwrap(),
        qa: v("qa"),
        va: v("va"),
        pa: v("pa"),
        qb: v("qb"),
        vb: v("vb"),
        pb: v("pb"),
        posb: v("posb"),
        qc: v("qc"),
        vc: v("vc"),
        pc: v("pc"),
    }
}
