//! Issue 13 class 7, end to end with the built binary: the command line protects the
//! user's files (no overwriting an input, a usable --name) and refuses inputs that are
//! not what they claim (devices, FIFOs, compressed files, files far larger than their
//! header can need) at once, with exit code 2 and a message naming the file.

use super::{run, scratch};
use std::path::PathBuf;
use std::process::{Command, Output};
use std::time::{Duration, Instant};

use crate::common::root;

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn data(name: &str) -> PathBuf {
    root().join("tests/data").join(name)
}

#[test]
fn info_refuses_a_device_at_once() {
    let t = Instant::now();
    let out = run(&["info", "/dev/zero"]);
    assert_eq!(out.status.code(), Some(2));
    assert_eq!(
        stderr(&out).trim(),
        "fxbody: /dev/zero: cannot read the body file: expected a regular file, found a character device"
    );
    assert!(t.elapsed() < Duration::from_secs(20), "{:?}", t.elapsed());
}

#[test]
fn info_refuses_a_fifo_and_a_directory() {
    let d = scratch("inputs_fifo");
    let fifo = d.join("pipe.fxb");
    assert!(
        Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .unwrap()
            .success()
    );
    let out = run(&["info", fifo.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
    assert!(
        stderr(&out).contains("found a FIFO (named pipe)"),
        "{}",
        stderr(&out)
    );
    let out = run(&["info", d.to_str().unwrap()]);
    assert!(
        stderr(&out).contains("found a directory"),
        "{}",
        stderr(&out)
    );
    std::fs::remove_dir_all(&d).ok();
}

#[test]
fn compressed_files_are_named_as_such() {
    let d = scratch("inputs_gz");
    let gz = d.join("body.fxb.gz");
    std::fs::write(&gz, b"\x1f\x8b\x08\x00\x00\x00\x00\x00\x00\x03garbage").unwrap();
    let out = run(&["info", gz.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
    assert!(
        stderr(&out).contains("this is a gzip-compressed file"),
        "{}",
        stderr(&out)
    );
    let zip = d.join("body.fmu");
    std::fs::write(&zip, b"PK\x03\x04\x14\x00rest").unwrap();
    let out = run(&["info", zip.to_str().unwrap()]);
    assert!(
        stderr(&out).contains("this is a zip archive"),
        "{}",
        stderr(&out)
    );
    std::fs::remove_dir_all(&d).ok();
}

#[test]
fn a_file_far_larger_than_its_header_needs_is_refused_before_reading() {
    // Header: one node, no local modes, blocked: a few values; the bound is 16 MiB plus
    // 80 bytes per value. 17 MiB of comment after it is refused by size alone.
    let d = scratch("inputs_big");
    let p = d.join("big.fxb");
    let mut text = b"       0       0       1       0       0       1       0\n".to_vec();
    let line = format!("#{}\n", "x".repeat(1023));
    while text.len() < 17 * 1024 * 1024 {
        text.extend_from_slice(line.as_bytes());
    }
    std::fs::write(&p, &text).unwrap();
    let out = run(&["info", p.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
    let e = stderr(&out);
    assert!(
        e.contains(&format!("the file has {} bytes, more than the", text.len())),
        "{e}"
    );
    assert!(e.contains("Nbmod 0 Nbstat 0 Nbnod 1"), "{e}");
    std::fs::remove_dir_all(&d).ok();
}

#[test]
fn pack_refuses_to_overwrite_its_inputs() {
    let d = scratch("inputs_over");
    let body = d.join("a.fxb");
    std::fs::copy(data("body_b1_r0_d0.fxb"), &body).unwrap();
    let coords = d.join("nodes.csv");
    std::fs::copy(data("nodes.csv"), &coords).unwrap();
    let link = d.join("link.fmu");
    std::os::unix::fs::symlink(&body, &link).unwrap();
    let before = std::fs::read(&body).unwrap();
    let dotted = format!("{}/./a.fxb", d.display());
    let b = body.to_str().unwrap();
    let c = coords.to_str().unwrap();
    for (out, what) in [
        (b, "body file"),
        (dotted.as_str(), "body file"),
        (link.to_str().unwrap(), "body file"),
        (c, "coordinate file"),
    ] {
        let o = run(&["pack", b, "--coords", c, "-o", out, "--lib", "Cargo.toml"]);
        assert_eq!(o.status.code(), Some(2), "{out}");
        let e = stderr(&o);
        assert!(
            e.contains(&format!("is the same file as the {what}")),
            "{e}"
        );
        assert!(e.contains("refusing to overwrite an input"), "{e}");
    }
    assert_eq!(std::fs::read(&body).unwrap(), before);
    let nodes = d.join("n.txt");
    std::fs::write(&nodes, "11\n").unwrap();
    let n = nodes.to_str().unwrap();
    let o = run(&[
        "pack",
        b,
        "--coords",
        c,
        "--nodes-file",
        n,
        "-o",
        n,
        "--lib",
        "Cargo.toml",
    ]);
    assert!(
        stderr(&o).contains("is the same file as the nodes file"),
        "{}",
        stderr(&o)
    );
    assert_eq!(std::fs::read_to_string(&nodes).unwrap(), "11\n");
    std::fs::remove_dir_all(&d).ok();
}

#[test]
fn pack_checks_the_model_name() {
    let d = scratch("inputs_name");
    let out = d.join("x.fmu");
    let long = "a".repeat(300);
    for (name, want) in [
        (
            long.as_str(),
            "--name: expected 1 to 64 characters, found 'aaaa",
        ),
        ("my body", "--name: expected letters, digits and '_' only"),
        ("../evil", "found '.' in '../evil'"),
        ("9lives", "--name: expected a letter or '_' first"),
    ] {
        let o = run(&[
            "pack",
            data("body_b1_r0_d0.fxb").to_str().unwrap(),
            "--coords",
            data("nodes.csv").to_str().unwrap(),
            "--name",
            name,
            "-o",
            out.to_str().unwrap(),
            "--lib",
            "Cargo.toml",
        ]);
        assert_eq!(o.status.code(), Some(2), "{name}");
        assert!(stderr(&o).contains(want), "{name}: {}", stderr(&o));
        assert!(!out.exists());
    }
    // Without --name the file stem is the name: a 100-character stem is refused too.
    let long_body = d.join(format!("{}.fxb", "b".repeat(100)));
    std::fs::copy(data("body_b1_r0_d0.fxb"), &long_body).unwrap();
    let o = run(&[
        "pack",
        long_body.to_str().unwrap(),
        "--coords",
        data("nodes.csv").to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--lib",
        "Cargo.toml",
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("the file name's 100 characters, more than 64: give --name"),
        "{}",
        stderr(&o)
    );
    std::fs::remove_dir_all(&d).ok();
}
