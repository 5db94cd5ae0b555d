//! The reader's fast path against the full two-way reading (`Reading::exact`): the same
//! numbers bit for bit, or the same error message, over every body file (tests/data,
//! fixtures/, and the generated benchmark bodies fixtures/large*.fxb when they have been
//! generated), over thousands of damaged copies of two of them, and over a body written
//! with values of every size; reading a file as it is read against parsing its bytes;
//! and the progress callback the commands draw their bar from.

use fxbody_testkit::Rng;
use std::path::{Path, PathBuf};

use crate::common::fxb_files::fxb_files;
use fxbody::fxb::{self, FxbFile, Reading};

/// Every number of a file as bits, with the counts and flags (`==` on f64 would let
/// -0.0 equal 0.0).
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
    match f.damping {
        Some((a, b)) => v.extend([1, a.to_bits(), b.to_bits()]),
        None => v.push(0),
    }
    for block in [
        &f.p0[..],
        &[f.freq],
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

/// What a reading gives, comparable: the bits, or the error's full message.
fn outcome(text: &[u8], exact: bool) -> Result<Vec<u64>, String> {
    let how = Reading {
        exact,
        ..Reading::default()
    };
    fxb::parse_with(text, "t.fxb", how)
        .map(|f| bits(&f))
        .map_err(|e| e.to_string())
}

fn assert_same(text: &[u8], what: &str) -> bool {
    let fast = outcome(text, false);
    let exact = outcome(text, true);
    assert!(
        fast == exact,
        "{what}: fast {:?}\nexact {:?}",
        fast.as_ref().err(),
        exact.as_ref().err()
    );
    fast.is_ok()
}

fn large_bodies() -> Vec<PathBuf> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures");
    ["large.fxb", "large_free.fxb"]
        .iter()
        .map(|n| root.join(n))
        .filter(|p| p.is_file())
        .collect()
}

#[test]
fn fast_and_exact_readings_agree_on_every_body_file() {
    let mut files = fxb_files();
    assert!(files.len() >= 17, "{} files", files.len());
    files.extend(large_bodies());
    let mut read = 0;
    for path in files {
        let text = std::fs::read(&path).unwrap();
        read += usize::from(assert_same(&text, &path.display().to_string()));
    }
    // The labelled files fail the body checks, not the reading: every file reads.
    assert!(read >= 17, "{read}");
}

/// One damage to one line, of the kinds that send a line off the fast path or make it
/// an error: other exponent letters, tabs, glued or split numbers, a blank field, text
/// past column 100, a stray character, a lost or doubled line.
fn damage(lines: &mut Vec<Vec<u8>>, rng: &mut Rng) {
    let k = rng.below(lines.len());
    let line = &mut lines[k];
    let at = if line.is_empty() {
        0
    } else {
        rng.below(line.len())
    };
    match rng.below(11) {
        0 => {
            if let Some(e) = line.iter().position(|&c| c == b'E') {
                line[e] = [b'D', b'd', b'e'][rng.below(3)];
            }
        }
        1 => line.insert(at, b'\t'),
        2 => {
            if !line.is_empty() {
                line.remove(at);
            }
        }
        3 => line.insert(at, b' '),
        4 => line[..]
            .get_mut(at)
            .into_iter()
            .for_each(|c| *c = b"x-+.E 09\r"[rng.below(9)]),
        5 => line.extend_from_slice(&b" "[..].repeat(20 + rng.below(30))),
        6 => line.extend_from_slice(b"                                        7.0"),
        7 => {
            let copy = line.clone();
            lines.insert(k, copy);
        }
        8 => {
            lines.remove(k);
        }
        9 => {
            // A blank 16-column field in the middle of the line.
            let cut = (at / 16) * 16;
            if cut + 16 <= line.len() {
                line[cut..cut + 16].fill(b' ');
            }
        }
        _ => {
            // Turn a fixed-column line into blank-separated values.
            let tokens: Vec<Vec<u8>> = line
                .split(|&c| c == b' ')
                .filter(|t| !t.is_empty())
                .map(<[u8]>::to_vec)
                .collect();
            *line = tokens.join(&b' ');
        }
    }
}

#[test]
fn fast_and_exact_readings_agree_on_damaged_files() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut rng = Rng::new(0x5eed_1234_abcd_0001);
    let (mut ok, mut failed) = (0, 0);
    for name in [
        "fixtures/cantilever_damped.fxb",
        "tests/data/body_b0_r1_d1.fxb",
    ] {
        let text = std::fs::read(root.join(name)).unwrap();
        let lines: Vec<Vec<u8>> = text.split(|&c| c == b'\n').map(<[u8]>::to_vec).collect();
        for trial in 0..1500 {
            let mut copy = lines.clone();
            for _ in 0..1 + rng.below(3) {
                damage(&mut copy, &mut rng);
            }
            let damaged = copy.join(&b'\n');
            if assert_same(&damaged, &format!("{name}, damage {trial}")) {
                ok += 1;
            } else {
                failed += 1;
            }
        }
    }
    // Both outcomes are reached often: the damages do not all fail, nor all pass.
    assert!(ok > 300 && failed > 300, "{ok} read, {failed} refused");
}

/// What reading the file at `path` as it is read gives (`fxb::read_path`: a window at
/// a time, never whole in memory), comparable with [`outcome`] of its bytes.
fn streamed(path: &Path) -> Result<Vec<u64>, String> {
    fxb::read_path(path)
        .map(|f| bits(&f))
        .map_err(|e| e.to_string().replace(&path.display().to_string(), "t.fxb"))
}

/// Reading a file as it is read gives what parsing its bytes in memory gives: the same
/// bits or the same message, over every body file, damaged copies, a byte-order mark,
/// CR-LF line ends and a last line without its line end.
#[test]
fn reading_a_file_as_it_is_read_equals_parsing_its_bytes() {
    let dir = std::env::temp_dir().join(format!("fxbody_streamed_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("t.fxb");
    let check = |text: &[u8], what: &str| {
        std::fs::write(&path, text).unwrap();
        let memory = outcome(text, false);
        assert!(streamed(&path) == memory, "{what}: {:?}", memory.err());
        memory.is_ok()
    };
    let mut files = fxb_files();
    files.extend(large_bodies());
    for file in &files {
        let same = fxb::read_path(file).map(|f| bits(&f)).ok();
        let text = std::fs::read(file).unwrap();
        let name = file.display().to_string();
        let memory = fxb::parse(&text, &name).map(|f| bits(&f)).ok();
        assert!(same.is_some() && same == memory, "{name}");
    }
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read(root.join("fixtures/cantilever_damped.fxb")).unwrap();
    assert!(check(
        &[&b"\xEF\xBB\xBF"[..], &text].concat(),
        "byte-order mark"
    ));
    let crlf: Vec<u8> = text
        .split(|&c| c == b'\n')
        .flat_map(|l| [l, b"\r\n"].concat())
        .collect();
    assert!(check(&crlf, "CR-LF"));
    assert!(check(text.strip_suffix(b"\n").unwrap(), "no last line end"));
    let lines: Vec<Vec<u8>> = text.split(|&c| c == b'\n').map(<[u8]>::to_vec).collect();
    let mut rng = Rng::new(0x5eed_1234_abcd_0002);
    let (mut ok, mut failed) = (0, 0);
    for trial in 0..400 {
        let mut copy = lines.clone();
        for _ in 0..1 + rng.below(3) {
            damage(&mut copy, &mut rng);
        }
        if check(&copy.join(&b'\n'), &format!("damage {trial}")) {
            ok += 1;
        } else {
            failed += 1;
        }
    }
    assert!(ok > 50 && failed > 50, "{ok} read, {failed} refused");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A free body (15 rigid modes, damping) of `n` nodes and `nl` modes, 2 of them static,
/// with the numbers `value` gives, in file order.
fn body(n: usize, nl: usize, mut value: impl FnMut() -> f64) -> FxbFile {
    let mut values = |count: usize| -> Vec<f64> { (0..count).map(|_| value()).collect() };
    FxbFile {
        nbmod: nl,
        nbstat: 2,
        nbnod: n,
        irot: true,
        idamp: true,
        iblo: false,
        ifile: false,
        node_ids: (1..=n as i64).map(|i| i * 1009).collect(),
        p0: values(9).try_into().unwrap(),
        freq: values(1)[0],
        damping: Some((values(1)[0], values(1)[0])),
        rigid_modes: values(15 * n * 6),
        local_modes: values(nl * n * 6),
        m_l: values(nl),
        k_full: values(2 * (2 * nl - 2 + 1) / 2),
        k_diag: values(nl - 2),
        m_r: values(15 * 16 / 2),
        m_c: values(9 * 15 * nl),
        k_c: values(9 * 15 * nl),
    }
}

/// A body written by our writer with values of every magnitude and sign (subnormal,
/// -0.0, huge), read both ways.
#[test]
fn fast_and_exact_readings_agree_on_values_of_every_size() {
    let mut rng = Rng::new(0x0dd_ba11_cafe_f00d);
    let f = body(23, 7, || {
        let r = rng.next_u64();
        match r % 9 {
            0 => 0.0,
            1 => -0.0,
            2 => f64::MIN_POSITIVE / 4.0,
            3 => -1.7e308,
            _ => {
                let m = (r >> 11) as f64 / (1u64 << 53) as f64 - 0.5;
                m * 10f64.powi(((r >> 4) % 600) as i32 - 300)
            }
        }
    });
    let text = fxb::write(&f);
    assert!(
        assert_same(text.as_bytes(), "written body"),
        "{:?}",
        outcome(text.as_bytes(), false).err()
    );
}

/// The callback hears a rising byte count, about every MiB, ending at the file's size;
/// the reading is the same with and without it.
#[test]
fn progress_is_reported_up_to_the_whole_file() {
    let mut x = 0.0;
    let big = fxb::write(&body(1200, 20, || {
        x += 0.25;
        x
    }));
    let big = big.as_bytes();
    assert!(big.len() > 4 << 20, "{}", big.len());
    let mut seen: Vec<(u64, u64)> = Vec::new();
    let mut tell = |done, total| seen.push((done, total));
    let how = Reading {
        progress: Some(&mut tell),
        ..Reading::default()
    };
    let with = fxb::parse_with(big, "big.fxb", how).unwrap();
    assert_eq!(bits(&with), bits(&fxb::parse(big, "big.fxb").unwrap()));
    let size = big.len() as u64;
    assert!(seen.iter().all(|&(_, t)| t == size), "{seen:?}");
    assert_eq!(seen.last().map(|s| s.0), Some(size));
    let steps: Vec<u64> = seen.windows(2).map(|w| w[1].0 - w[0].0).collect();
    // A report after the first line, then one per MiB (at the end of the line that
    // crosses it), and the last at the end.
    assert!(seen.len() >= 5, "{seen:?}");
    assert!(steps.iter().all(|&s| s <= (1 << 20) + 100), "{steps:?}");
    // Reading the file as it is read (what `info` and `pack` do) tells the same.
    let path = std::env::temp_dir().join(format!("fxbody_progress_{}.fxb", std::process::id()));
    std::fs::write(&path, big).unwrap();
    let mut streamed: Vec<(u64, u64)> = Vec::new();
    let mut tell = |done, total| streamed.push((done, total));
    let how = Reading {
        progress: Some(&mut tell),
        ..Reading::default()
    };
    let read = fxb::read_path_with(&path, how).unwrap();
    std::fs::remove_file(&path).unwrap();
    assert_eq!(bits(&read), bits(&with));
    assert_eq!(streamed, seen);
}
