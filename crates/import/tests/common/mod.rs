//! The real models the tests and the bench run on: the L-bracket of
//! `tests/fe_models/bracket.py` (gmsh mesh of second-order tetrahedra, two CalculiX
//! spiders), generated on first use into `target/fe_models/` with ccx's matrices and its
//! own reference results, and read back here; and the process's peak memory and CPU time
//! for the bench and the example.

#![allow(dead_code)]

use std::collections::{HashMap, HashSet};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::Mutex;

/// The workspace root.
pub fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .ancestors()
        .nth(2)
        .expect("crates/import lies two folders below the workspace root")
        .to_path_buf()
}

/// Python with gmsh: `FXBODY_PYTHON` (set by scripts/test.sh), else `.venv/bin/python`.
pub fn python() -> PathBuf {
    std::env::var_os("FXBODY_PYTHON").map_or_else(|| root().join(".venv/bin/python"), PathBuf::from)
}

static GENERATE: Mutex<()> = Mutex::new(());

/// The bracket meshed with largest edge `size` mm, in `target/fe_models/bracket-SIZE`
/// (generated once; the script skips a folder whose parameters match). `reference` also
/// runs ccx's own `*FREQUENCY` and `*STATIC`.
pub fn bracket(size: f64, reference: bool) -> PathBuf {
    let _one_at_a_time = GENERATE.lock().unwrap_or_else(|e| e.into_inner());
    let target =
        std::env::var_os("CARGO_TARGET_DIR").map_or_else(|| root().join("target"), PathBuf::from);
    let dir = target.join("fe_models").join(format!("bracket-{size}"));
    let ccx = Command::new("ccx").arg("-v").output();
    assert!(
        ccx.is_ok(),
        "ccx (CalculiX) is not installed: run scripts/setup-fe.sh (apt-get install calculix-ccx)"
    );
    let mut cmd = Command::new(python());
    cmd.arg(root().join("tests/fe_models/bracket.py"))
        .arg(&dir)
        .arg("--size")
        .arg(size.to_string())
        .arg("--modes")
        .arg("24");
    if !reference {
        cmd.arg("--no-reference");
    }
    let out = cmd
        .output()
        .unwrap_or_else(|e| panic!("cannot run {}: {e}", python().display()));
    assert!(
        out.status.success(),
        "bracket.py failed: {}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    dir
}

/// `id,x,y,z` lines of the model's `nodes.csv`.
pub fn nodes(dir: &Path) -> HashMap<i64, [f64; 3]> {
    read_nodes(&dir.join("nodes.csv"))
}

/// `id,x,y,z` lines of a CSV file.
pub fn read_nodes(path: &Path) -> HashMap<i64, [f64; 3]> {
    let text = std::fs::read_to_string(path)
        .unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()));
    text.lines()
        .filter(|l| !l.trim().is_empty())
        .map(|l| {
            let f: Vec<f64> = l
                .split(',')
                .map(|t| t.trim().parse().expect("number"))
                .collect();
            (f[0] as i64, [f[1], f[2], f[3]])
        })
        .collect()
}

/// A spider's REF and ROT node numbers and centre, from `done.json`.
pub struct Spider {
    pub reference: i64,
    pub rotation: i64,
    pub centre: [f64; 3],
}

/// Spiders "A" and "B".
pub fn spiders(dir: &Path) -> (Spider, Spider) {
    let info: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("done.json")).expect("done.json"))
            .expect("json");
    let one = |k: &str| {
        let s = &info["spiders"][k];
        let c = &s["centre"];
        Spider {
            reference: s["ref"].as_i64().expect("ref"),
            rotation: s["rot"].as_i64().expect("rot"),
            centre: [0, 1, 2].map(|i| c[i].as_f64().expect("centre")),
        }
    };
    (one("A"), one("B"))
}

/// The ROT nodes of both spiders.
pub fn rot_nodes(dir: &Path) -> HashSet<i64> {
    let (a, b) = spiders(dir);
    HashSet::from([a.rotation, b.rotation])
}

/// The mean of the node coordinates: the rigid motions' rotation centre.
pub fn centroid(nodes: &HashMap<i64, [f64; 3]>) -> [f64; 3] {
    let mut o = [0.0; 3];
    for x in nodes.values() {
        for k in 0..3 {
            o[k] += x[k] / nodes.len() as f64;
        }
    }
    o
}

/// `reference.json`.
pub fn reference(dir: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(dir.join("reference.json")).expect("reference"))
        .expect("json")
}

/// A number as ccx printed it, and half a unit of its last printed digit.
pub fn printed(text: &str) -> (f64, f64) {
    let v: f64 = text.parse().expect("printed number");
    let (mantissa, exp) = text.split_once(['E', 'e']).expect("E format");
    let decimals = mantissa.split_once('.').map_or(0, |(_, d)| d.len()) as i32;
    let exp: i32 = exp.parse().expect("exponent");
    (v, 0.5 * 10f64.powi(exp - decimals))
}

/// Peak resident memory of this process (VmHWM), in MB.
pub fn peak_mb() -> f64 {
    let s = std::fs::read_to_string("/proc/self/status").unwrap_or_default();
    s.lines()
        .find_map(|l| l.strip_prefix("VmHWM:"))
        .and_then(|v| v.trim().trim_end_matches("kB").trim().parse::<f64>().ok())
        .map_or(0.0, |kb| kb / 1024.0)
}

/// CPU seconds (user + system) this process has used, from /proc/self/stat.
pub fn cpu_seconds() -> f64 {
    let stat = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    let after = stat.rsplit(')').next().unwrap_or("");
    let f: Vec<&str> = after.split_whitespace().collect();
    // Fields 14 and 15 of the line (utime, stime; the 12th and 13th after the name), in
    // clock ticks of 1/100 s.
    let tick = |k: usize| f.get(k).and_then(|t| t.parse::<f64>().ok()).unwrap_or(0.0);
    (tick(11) + tick(12)) / 100.0
}
