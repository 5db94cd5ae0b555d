//! How long the FE readers take on a dense 3000-DOF matrix (500 grids x 6 components,
//! upper triangle: 4,501,500 terms), written to a temporary folder in the Nastran punch
//! layout and as Abaqus MATRIX INPUT lines, against two references timed in the same run
//! on the same file: `wc -c` (the size, as a shell user would check it) and one plain
//! read of all its bytes (`std::fs::read`), the least any reader must spend.
//! Run with `cargo bench -p fxbody-import --bench fe_read`; the files are removed afterwards.

use std::fmt::Write as _;
use std::path::Path;
use std::time::Instant;

use fxbody_import::fe;

const GRIDS: i64 = 500;

/// A deterministic, varied value for term (i, j).
fn value(i: usize, j: usize) -> f64 {
    let x = ((i * 7919 + j * 104_729) % 10_007) as f64 / 10_007.0;
    if i == j {
        1e8 * (1.0 + x)
    } else {
        (x - 0.5) * 10f64.powi((i + j) as i32 % 7)
    }
}

fn dof(k: usize) -> (i64, usize) {
    (k as i64 / 6 + 1, k % 6 + 1)
}

fn write_punch(path: &Path) {
    let n = (GRIDS * 6) as usize;
    let mut s = String::with_capacity(n * n / 2 * 74);
    writeln!(
        s,
        "DMIG    KAAX           0       6       2       0{:>24}",
        n
    )
    .unwrap();
    for j in 0..n {
        let (gj, cj) = dof(j);
        writeln!(s, "DMIG*   {:<16}{:>16}{:>16}", "KAAX", gj, cj).unwrap();
        for i in 0..=j {
            let (gi, ci) = dof(i);
            let v = value(i, j);
            // %16.9E: Rust has no such format; build it from {:.9E} and pad to 16.
            let t = format!("{v:.9E}");
            let (m, e) = t.split_once('E').unwrap();
            let e: i32 = e.parse().unwrap();
            let t = format!("{m}E{}{:02}", if e < 0 { '-' } else { '+' }, e.abs());
            writeln!(s, "*       {gi:>16}{ci:>16}{t:>16}").unwrap();
        }
    }
    std::fs::write(path, s).unwrap();
}

fn write_abaqus(path: &Path) {
    let n = (GRIDS * 6) as usize;
    let mut s = String::with_capacity(n * n / 2 * 40);
    for j in 0..n {
        let (gj, cj) = dof(j);
        for i in j..n {
            let (gi, ci) = dof(i);
            writeln!(s, "{gi},{ci}, {gj},{cj},  {:.16e}", value(j, i)).unwrap();
        }
    }
    std::fs::write(path, s).unwrap();
}

/// This process's CPU time so far (s), from /proc/self/schedstat (Linux; 0 elsewhere):
/// on a shared machine the wall time also counts other processes' turns.
fn cpu() -> f64 {
    std::fs::read_to_string("/proc/self/schedstat")
        .ok()
        .and_then(|s| s.split_whitespace().next()?.parse::<f64>().ok())
        .map_or(0.0, |ns| ns * 1e-9)
}

/// Wall and CPU time (s) of `f`, and its result.
fn time<T>(f: impl FnOnce() -> T) -> ((f64, f64), T) {
    let (t, c) = (Instant::now(), cpu());
    let r = f();
    ((t.elapsed().as_secs_f64(), cpu() - c), r)
}

fn report(what: &str, path: &Path, read: impl Fn(&Path) -> fe::SymMatrix) {
    let (t_wc, out) = time(|| {
        std::process::Command::new("wc")
            .arg("-c")
            .arg(path)
            .output()
            .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_string())
            .unwrap_or_else(|e| format!("wc failed: {e}"))
    });
    let (t_bytes, bytes) = time(|| std::fs::read(path).unwrap().len());
    let (t_read, m) = time(|| read(path));
    println!("{what}: {out} ({:.0} MB)", bytes as f64 / 1e6);
    println!(
        "  wall (cpu) s: wc -c {:.4} | read all bytes {:.3} ({:.3}) | fe reader {:.3} ({:.3}): \
         {} DOFs, {} terms; reader / byte read = {:.1} (cpu {:.1}), {:.0} MB/s cpu",
        t_wc.0,
        t_bytes.0,
        t_bytes.1,
        t_read.0,
        t_read.1,
        m.dofs.len(),
        m.terms.len(),
        t_read.0 / t_bytes.0,
        t_read.1 / t_bytes.1,
        bytes as f64 / 1e6 / t_read.1
    );
}

fn main() {
    let dir = std::env::temp_dir().join(format!("fxbody_fe_read_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let pch = dir.join("dense3000.pch");
    let mtx = dir.join("dense3000_STIF1.mtx");
    write_punch(&pch);
    write_abaqus(&mtx);
    report("Nastran punch, 3000 DOFs dense", &pch, |p| {
        fe::read_dmig(p, "KAAX").unwrap()
    });
    report("Abaqus MATRIX INPUT, 3000 DOFs dense", &mtx, |p| {
        fe::read_abaqus(p).unwrap()
    });
    if std::env::var_os("FE_READ_KEEP").is_none() {
        std::fs::remove_dir_all(&dir).unwrap();
    } else {
        println!("kept {}", dir.display());
    }
}
