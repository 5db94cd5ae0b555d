//! Issue 28 point 6, end to end with the built binary: every path any command reads
//! (the body of `info`, `pack` and `reduce`, `--coords`, `--nodes-file`, `--lib`,
//! `FXBODY_LIB`, `--binary`, `import`'s DMIG file, `--stiffness`, `--mass`, `--dof-map`
//! and `--coords`, `demo --fixtures`) is refused unless it is a regular file no larger
//! than its kind of file can need: `/dev/zero`, a FIFO, a directory, a missing file and
//! a file one byte over the bound (sparse, so it costs no disk) each get exit code 2, at
//! once, and a message naming the option, the path and what the path is. A FIFO or
//! `/dev/zero` read would hang or exhaust memory: every run has a deadline.

use super::scratch;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use fxbody::fxb::input::{MAX_LIBRARY, MAX_NODE_LIST, MAX_TEXT};

use crate::common::root;

/// How long a refusal may take: reading `/dev/zero` or waiting on a FIFO never ends.
const DEADLINE: Duration = Duration::from_secs(30);

/// Run fxbody with `args` (and `env`), killed at the deadline; (exit code, stderr).
/// stderr is drained as it comes, so a long message cannot stall the child.
fn run_bounded(args: &[String], env: &[(&str, &str)]) -> (Option<i32>, String) {
    let mut child = Command::new(fxbody_host::workspace_binary("fxbody"))
        .args(args)
        .envs(env.iter().copied())
        .current_dir(root())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("run fxbody");
    let mut pipe = child.stderr.take().unwrap();
    let reader = std::thread::spawn(move || {
        let mut err = Vec::new();
        std::io::Read::read_to_end(&mut pipe, &mut err).ok();
        String::from_utf8_lossy(&err).into_owned()
    });
    let start = Instant::now();
    loop {
        if let Some(status) = child.try_wait().unwrap() {
            return (status.code(), reader.join().unwrap());
        }
        if start.elapsed() > DEADLINE {
            child.kill().ok();
            child.wait().ok();
            panic!("fxbody {args:?} still running after {DEADLINE:?}: it reads the input");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
}

/// One way a command reads a path: the arguments with `@` where the path goes, the
/// environment likewise, the option the message must name, and the kind's bound.
struct Reader {
    args: Vec<String>,
    env: Option<&'static str>,
    option: &'static str,
    bound: u64,
}

fn reader(args: &[&str], option: &'static str, bound: u64) -> Reader {
    Reader {
        args: args.iter().map(|s| s.to_string()).collect(),
        env: None,
        option,
        bound,
    }
}

/// Every path-reading option of every command.
fn readers(work: &Path) -> Vec<Reader> {
    let cant = "fixtures/cantilever.fxb";
    let deck = "fixtures/cantilever.nodes.rad";
    let out = work.join("out.fmu").display().to_string();
    let fxb_out = work.join("out.fxb").display().to_string();
    let fe = |f: &str| format!("tests/data/fe/{f}");
    let (sti, mas, dof, mtx) = (
        fe("job.sti"),
        fe("job.mas"),
        fe("job.dof"),
        fe("model_STIF1.mtx"),
    );
    let nodes = fe("nodes.csv");
    // The body's own bound comes from its header: tested with a header below.
    let body = u64::MAX;
    let mut v = vec![
        reader(&["info", "@"], "cannot read the body file", body),
        reader(
            &["pack", "@", "--coords", deck, "-o", &out],
            "cannot read the body file",
            body,
        ),
        reader(
            &["reduce", "@", "-o", &fxb_out],
            "cannot read the body file",
            body,
        ),
        reader(
            &["pack", cant, "--coords", "@", "-o", &out],
            "--coords",
            MAX_TEXT,
        ),
        reader(
            &[
                "pack",
                cant,
                "--coords",
                deck,
                "--nodes-file",
                "@",
                "-o",
                &out,
            ],
            "--nodes-file",
            MAX_NODE_LIST,
        ),
        reader(
            &["pack", cant, "--coords", deck, "--lib", "@", "-o", &out],
            "--lib",
            MAX_LIBRARY,
        ),
        reader(
            &[
                "pack", cant, "--coords", deck, "--binary", "win64=@", "-o", &out,
            ],
            "--binary win64=",
            MAX_LIBRARY,
        ),
        reader(
            &["import", "@", "--coords", &nodes, "-o", &fxb_out],
            "DMIG file",
            MAX_TEXT,
        ),
        reader(
            &[
                "import",
                "--stiffness",
                "@",
                "--mass",
                &mtx,
                "--coords",
                &nodes,
                "-o",
                &fxb_out,
            ],
            "--stiffness",
            MAX_TEXT,
        ),
        reader(
            &[
                "import",
                "--stiffness",
                &mtx,
                "--mass",
                "@",
                "--coords",
                &nodes,
                "-o",
                &fxb_out,
            ],
            "--mass",
            MAX_TEXT,
        ),
        reader(
            &[
                "import",
                "--stiffness",
                &sti,
                "--mass",
                &mas,
                "--dof-map",
                "@",
                "-o",
                &fxb_out,
            ],
            "--dof-map",
            MAX_TEXT,
        ),
        reader(
            &[
                "import",
                "--stiffness",
                &sti,
                "--mass",
                &mas,
                "--dof-map",
                &dof,
                "--coords",
                "@",
                "-o",
                &fxb_out,
            ],
            "--coords",
            MAX_TEXT,
        ),
    ];
    let mut env = reader(
        &["pack", cant, "--coords", deck, "-o", &out],
        "FXBODY_LIB=",
        MAX_LIBRARY,
    );
    env.env = Some("FXBODY_LIB");
    v.push(env);
    v
}

/// The paths to try: (what, path, the words the message must hold).
fn bad_paths(work: &Path) -> Vec<(&'static str, PathBuf, &'static str)> {
    let fifo = work.join("pipe");
    let made = Command::new("mkfifo").arg(&fifo).status().unwrap();
    assert!(made.success(), "mkfifo");
    let dir = work.join("folder");
    std::fs::create_dir_all(&dir).unwrap();
    vec![
        (
            "device",
            PathBuf::from("/dev/zero"),
            "expected a regular file, found a character device",
        ),
        (
            "FIFO",
            fifo,
            "expected a regular file, found a FIFO (named pipe)",
        ),
        (
            "directory",
            dir,
            "expected a regular file, found a directory",
        ),
        ("missing", work.join("missing.txt"), "no such file"),
    ]
}

/// `r`'s arguments and environment with `path` in place of `@`.
fn with_path(r: &Reader, path: &Path) -> (Vec<String>, Vec<(&'static str, String)>) {
    let p = path.display().to_string();
    let args = r.args.iter().map(|a| a.replace('@', &p)).collect();
    let env = r.env.map(|name| (name, p.clone())).into_iter().collect();
    (args, env)
}

fn refused_with(r: &Reader, path: &Path, words: &[String]) {
    let (args, env) = with_path(r, path);
    let env: Vec<(&str, &str)> = env.iter().map(|(k, v)| (*k, v.as_str())).collect();
    let (code, err) = run_bounded(&args, &env);
    assert_eq!(code, Some(2), "{args:?}: {err}");
    for w in words {
        assert!(
            err.contains(w.as_str()),
            "{args:?}: expected '{w}' in: {err}"
        );
    }
}

#[test]
fn every_input_path_that_is_no_regular_file_is_refused_naming_the_option() {
    let work = scratch("kinds_kinds");
    let readers = readers(&work);
    let paths = bad_paths(&work);
    for r in &readers {
        for (_, path, what) in &paths {
            let p = path.display().to_string();
            // The option and the path together (the body: the path, then its role).
            let named = if r.option.starts_with("cannot") {
                format!("{p}: {}", r.option)
            } else if r.option.ends_with('=') {
                format!("{}{p}: ", r.option)
            } else {
                format!("{} {p}: ", r.option)
            };
            refused_with(r, path, &[named, what.to_string()]);
        }
    }
    std::fs::remove_dir_all(&work).ok();
}

#[test]
fn every_input_one_byte_over_its_bound_is_refused_before_reading() {
    let work = scratch("kinds_bound");
    for r in readers(&work).iter().filter(|r| r.bound != u64::MAX) {
        // Sparse: the size is there, the disk blocks are not; reading it would take
        // minutes (4 GiB), refusing it takes milliseconds.
        let big = work.join("big.dat");
        let f = std::fs::File::create(&big).unwrap();
        f.set_len(r.bound + 1).unwrap();
        drop(f);
        let t = Instant::now();
        refused_with(
            r,
            &big,
            &[format!(
                "the file has {} bytes, more than the {} bytes",
                r.bound + 1,
                r.bound
            )],
        );
        assert!(
            t.elapsed() < Duration::from_secs(10),
            "{:?}: {:?}",
            r.args,
            t.elapsed()
        );
        // Under the bound the size is no reason to refuse (the content is).
        let f = std::fs::OpenOptions::new().write(true).open(&big).unwrap();
        f.set_len(r.bound.min(1 << 20)).unwrap();
        drop(f);
        let (args, env) = with_path(r, &big);
        let env: Vec<(&str, &str)> = env.iter().map(|(k, v)| (*k, v.as_str())).collect();
        let (_, err) = run_bounded(&args, &env);
        assert!(!err.contains("more than the"), "{args:?}: {err}");
        std::fs::remove_file(&big).unwrap();
    }
    // The body's bound comes from its header: one node, no modes.
    let body = work.join("big.fxb");
    std::fs::write(
        &body,
        b"       0       0       1       0       0       1       0\n",
    )
    .unwrap();
    let bound = fxbody::fxb::input::size_bound(&[0, 0, 1, 0, 0, 1, 0]) as u64;
    std::fs::OpenOptions::new()
        .write(true)
        .open(&body)
        .unwrap()
        .set_len(bound + 1)
        .unwrap();
    for cmd in [&["info"][..], &["reduce", "--output", "/dev/null"][..]] {
        let mut args: Vec<String> = cmd.iter().map(|s| s.to_string()).collect();
        args.insert(1, body.display().to_string());
        let (code, err) = run_bounded(&args, &[]);
        assert_eq!(code, Some(2), "{err}");
        assert!(
            err.contains(&format!(
                "the file has {} bytes, more than the {bound} bytes a body file with this header",
                bound + 1
            )),
            "{err}"
        );
    }
    std::fs::remove_dir_all(&work).ok();
}

#[test]
fn demo_refuses_a_reference_that_is_no_regular_file() {
    let work = scratch("kinds_demo");
    let fixtures = work.join("fixtures");
    std::fs::create_dir_all(&fixtures).unwrap();
    for f in ["cantilever.fxb", "cantilever.nodes.rad"] {
        std::os::unix::fs::symlink(root().join("fixtures").join(f), fixtures.join(f)).unwrap();
    }
    let reference = fixtures.join("cantilever.ref.json");
    assert!(
        Command::new("mkfifo")
            .arg(&reference)
            .status()
            .unwrap()
            .success()
    );
    let args: Vec<String> = ["demo", "--fixtures", fixtures.to_str().unwrap(), "--out"]
        .iter()
        .map(|s| s.to_string())
        .chain([work.join("out").display().to_string()])
        .collect();
    let (code, err) = run_bounded(&args, &[]);
    assert_eq!(code, Some(2), "{err}");
    assert!(
        err.contains(&format!(
            "--fixtures {}: expected a regular file, found a FIFO",
            reference.display()
        )),
        "{err}"
    );
    std::fs::remove_dir_all(&work).ok();
}

#[test]
fn a_library_that_is_no_shared_library_is_refused_before_anything_is_written() {
    let work = scratch("kinds_lib");
    let out = work.join("x.fmu");
    let args: Vec<String> = [
        "pack",
        "fixtures/cantilever.fxb",
        "--coords",
        "fixtures/cantilever.nodes.rad",
        "--lib",
        "Cargo.toml",
        "-o",
        out.to_str().unwrap(),
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    let (code, err) = run_bounded(&args, &[]);
    assert_eq!(code, Some(2), "{err}");
    assert!(
        err.contains("--lib Cargo.toml: expected an ELF 64-bit shared library for linux64, found: not a shared library"),
        "{err}"
    );
    assert!(!out.exists());
    std::fs::remove_dir_all(&work).ok();
}
