//! How fast a `.fxb` file is read and packed, on the large grillage (5151 nodes, 200
//! modes, 101 MB; `python fixtures/generate.py --large`, not committed), against the
//! references for raw reading speed timed in the same run on the same file:
//! - `wc -c FILE`, as a shell user would check the size (GNU wc answers from the file's
//!   size without reading it, so it is nearly free);
//! - `cat FILE | wc -c`, which does push every byte through a pipe: the raw reading
//!   speed the commands are compared with;
//! - one plain read of all its bytes (`std::fs::read`).
//!
//! Then the readers: `fxb::parse` (the fast path, on bytes in memory), `fxb::parse_with`
//! with `exact` (every line read both ways in full: the reference the fast path must
//! equal, and what reading cost before it), `fxb::read_path` (reading the file as it is
//! read, a window at a time), `body::load` (what `fxbody info` does: read, parse,
//! validate), and, when target/release/fxbody is built, the commands themselves: `fxbody
//! info` and `fxbody pack` of the 2-node scene (tip and corner, [`large_scene`]). Each is
//! timed three times, best kept, wall and CPU (the machine is shared: CPU time says what
//! the reader costs, wall time what a user waits). The fast and exact readings are
//! checked equal bit for bit. Run with `cargo bench --bench fxb_read`;
//! `FXB_READ_BEFORE=/path/to/fxbody` also times that build's `info` and `pack` in the
//! same run.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::Instant;

use fxbody::fxb::{self, FxbFile, Reading};

#[path = "common/large_scene.rs"]
mod large_scene;

/// This process's CPU time so far (s), from /proc/self/schedstat (Linux; 0 elsewhere).
fn cpu() -> f64 {
    std::fs::read_to_string("/proc/self/schedstat")
        .ok()
        .and_then(|s| s.split_whitespace().next()?.parse::<f64>().ok())
        .map_or(0.0, |ns| ns * 1e-9)
}

/// CPU time (s) of this process's waited-for children, from /proc/self/stat (clock
/// ticks of 1/100 s, as Linux reports them).
fn children_cpu() -> f64 {
    std::fs::read_to_string("/proc/self/stat")
        .ok()
        .and_then(|s| {
            // Fields after the command name in parentheses; cutime and cstime are the
            // 16th and 17th fields of the line.
            let rest = &s[s.rfind(')')? + 2..];
            let f: Vec<&str> = rest.split_whitespace().collect();
            Some(f.get(13)?.parse::<f64>().ok()? + f.get(14)?.parse::<f64>().ok()?)
        })
        .map_or(0.0, |ticks| ticks / 100.0)
}

/// Best wall and CPU time (s) of three runs of `f`, and its last result.
fn best<T>(mut f: impl FnMut() -> T) -> ((f64, f64), T) {
    let mut wall = f64::INFINITY;
    let mut used = f64::INFINITY;
    let mut out = None;
    for _ in 0..3 {
        let (t, c, cc) = (Instant::now(), cpu(), children_cpu());
        let r = f();
        wall = wall.min(t.elapsed().as_secs_f64());
        used = used.min(cpu() - c + children_cpu() - cc);
        out = Some(r);
    }
    ((wall, used), out.expect("three runs"))
}

/// Run a shell pipeline; its standard output, trimmed.
fn shell(script: &str, file: &Path) -> String {
    let out = Command::new("sh")
        .arg("-c")
        .arg(script)
        .arg("sh")
        .arg(file)
        .output()
        .expect("sh runs");
    String::from_utf8_lossy(&out.stdout).trim().to_string()
}

/// Every number of a parsed file, as bits, with the counts and flags: two readings
/// are the same exactly when these are equal (`==` on f64 would let -0.0 equal 0.0).
fn bits(f: &FxbFile) -> Vec<u64> {
    let mut v = vec![
        f.nbmod as u64,
        f.nbstat as u64,
        f.nbnod as u64,
        u64::from(f.irot),
        u64::from(f.idamp),
        u64::from(f.iblo),
        u64::from(f.ifile),
    ];
    v.extend(f.node_ids.iter().map(|&i| i as u64));
    let (a, b) = f.damping.unwrap_or((f64::NAN, f64::NAN));
    for block in [
        &f.p0[..],
        &[f.freq, a, b],
        &f.rigid_modes,
        &f.local_modes,
        &f.m_l,
        &f.k_full,
        &f.k_diag,
        &f.m_r,
        &f.m_c,
        &f.k_c,
    ] {
        v.push(block.len() as u64);
        v.extend(block.iter().map(|x| x.to_bits()));
    }
    v
}

fn run(path: &Path) {
    let size = std::fs::metadata(path).expect("file").len() as f64;
    let mb = size / 1e6;
    let rate = |t: f64| mb / t;
    println!("{}: {mb:.1} MB", path.display());
    println!(
        "  {:<38} {:>9} {:>9} {:>10} {:>10}",
        "", "wall s", "cpu s", "MB/s wall", "MB/s cpu"
    );
    let line = |what: &str, (w, c): (f64, f64)| {
        println!(
            "  {what:<38} {w:>9.3} {c:>9.3} {:>10.0} {:>10.0}",
            rate(w),
            rate(c)
        );
    };
    let (t_wc, wc) = best(|| shell("wc -c \"$1\"", path));
    line(
        &format!(
            "wc -c (says {})",
            wc.split_whitespace().next().unwrap_or("?")
        ),
        t_wc,
    );
    let (t_cat, n) = best(|| shell("cat \"$1\" | wc -c", path));
    assert_eq!(n.parse::<f64>().ok(), Some(size), "cat | wc -c");
    line("cat FILE | wc -c", t_cat);
    let (t_bytes, bytes) = best(|| std::fs::read(path).expect("read"));
    line("std::fs::read (all bytes)", t_bytes);
    let name = path.display().to_string();
    let (t_exact, exact) = best(|| {
        let how = Reading {
            exact: true,
            ..Reading::default()
        };
        fxb::parse_with(&bytes, &name, how).expect("exact reading")
    });
    line("fxb::parse_with exact (before)", t_exact);
    let (t_fast, fast) = best(|| fxb::parse(&bytes, &name).expect("fast reading"));
    line("fxb::parse (fast path)", t_fast);
    assert!(
        bits(&fast) == bits(&exact),
        "the fast and exact readings differ"
    );
    let (t_load, body) = best(|| fxbody::body::load(path, Default::default()).expect("load"));
    line("body::load (what info does)", t_load);
    let (t_stream, _) = best(|| fxb::read_path(path).expect("read_path"));
    line("fxb::read_path (as it is read)", t_stream);
    let exe = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("target/release/fxbody");
    let before = std::env::var_os("FXB_READ_BEFORE").map(PathBuf::from);
    // The body's own deck for its coordinates; the blocked body's deck names the nodes.
    let deck = path.with_extension("nodes.rad");
    let grid = path.with_file_name("large.nodes.rad");
    let scene = (deck.is_file() && grid.is_file()).then(|| large_scene::two_nodes(&grid));
    let out = std::env::temp_dir().join(format!("fxbody_bench_read_{}", std::process::id()));
    std::fs::create_dir_all(&out).expect("temp dir");
    // The commands, this build's and FXB_READ_BEFORE's (another build of the command,
    // e.g. one built from an older commit, for a before/after figure in the same run).
    let mut commands = Vec::new();
    for (who, exe) in [
        ("fxbody", Some(exe).filter(|e| e.is_file())),
        ("FXB_READ_BEFORE", before),
    ] {
        let Some(exe) = exe else { continue };
        let (t, ok) = best(|| run_quiet(Command::new(&exe).arg("info").arg(path)));
        assert!(ok, "{who} info failed");
        line(&format!("{who} info (the command)"), t);
        commands.push((format!("{who} info"), t));
        if let Some(nodes) = &scene {
            let fmu = out.join("large2.fmu");
            let ids: Vec<String> = nodes.iter().map(i64::to_string).collect();
            let (t, ok) = best(|| {
                let _ = std::fs::remove_file(&fmu);
                run_quiet(
                    Command::new(&exe)
                        .arg("pack")
                        .arg(path)
                        .arg("--coords")
                        .arg(&deck)
                        .arg("--nodes")
                        .arg(ids.join(","))
                        .arg("-o")
                        .arg(&fmu),
                )
            });
            assert!(ok, "{who} pack failed");
            let size = std::fs::metadata(&fmu).map_or(0, |m| m.len());
            line(
                &format!(
                    "{who} pack ({} nodes, {:.2} MB .fmu)",
                    nodes.len(),
                    size as f64 / 1e6
                ),
                t,
            );
            commands.push((format!("{who} pack"), t));
        }
    }
    let _ = std::fs::remove_dir_all(&out);
    println!(
        "  {} nodes, {} modes; identical bits fast vs exact: yes{}",
        body.node_ids().len(),
        body.nl(),
        scene.map_or(String::new(), |n| format!("; pack exposes nodes {n:?}"))
    );
    println!(
        "  ratios (time over std::fs::read's, cpu): exact {:.1}, fast {:.1}, load {:.1}; \
         fast path speed-up over exact {:.1}x (cpu), {:.1}x (wall)",
        t_exact.1 / t_bytes.1,
        t_fast.1 / t_bytes.1,
        t_load.1 / t_bytes.1,
        t_exact.1 / t_fast.1,
        t_exact.0 / t_fast.0
    );
    println!(
        "  ratios over wc -c (wall): cat|wc {:.1}, body::load {:.1}",
        t_cat.0 / t_wc.0,
        t_load.0 / t_wc.0,
    );
    // The figure the issue asks for: each command's reading speed beside the raw
    // reading speed of the same file in the same run.
    println!(
        "  {size:.0} bytes; raw read (cat | wc -c) {:.3} s = {:.0} MB/s wall",
        t_cat.0,
        rate(t_cat.0)
    );
    for (what, t) in commands {
        println!(
            "  {what:<22} {:.3} s = {:>4.0} MB/s wall ({:.0} MB/s cpu), {:.1}x the raw read's time",
            t.0,
            rate(t.0),
            rate(t.1),
            t.0 / t_cat.0
        );
    }
}

/// Run a command with its output discarded; whether it succeeded.
fn run_quiet(cmd: &mut Command) -> bool {
    cmd.stdout(Stdio::null())
        .stderr(Stdio::null())
        .status()
        .is_ok_and(|s| s.success())
}

fn main() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("fixtures");
    let mut any = false;
    for name in ["large", "large_free"] {
        let fxb = root.join(format!("{name}.fxb"));
        if fxb.is_file() {
            run(&fxb);
            any = true;
        } else {
            println!(
                "{name}: {} absent, run `python fixtures/generate.py --large`",
                fxb.display()
            );
        }
    }
    if !any {
        // Still measure something: the largest committed fixture.
        run(&root.join("truss.fxb"));
    }
}
