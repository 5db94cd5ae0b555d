//! Mutation test: seeded, deterministic damage to every .fxb file in tests/data and
//! fixtures/ (truncations, byte flips, swapped, duplicated and deleted lines, garbage
//! lines, NaN/Inf/huge literals, touching signs), then read + validate + write + read
//! again. No case may panic; each ends in an error or in a valid body whose written text
//! reads back. About 3000 cases in total.

use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::{Path, PathBuf};

use fxbody::body::Body;
use fxbody::fxb;

/// Total number of mutated texts tried, spread over the files.
const CASES: usize = 3000;

/// xorshift64: a small deterministic generator, enough to pick positions.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        let mut x = self.0;
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        self.0 = x;
        x
    }
    fn below(&mut self, n: usize) -> usize {
        if n == 0 {
            0
        } else {
            (self.next() % n as u64) as usize
        }
    }
}

fn fxb_files() -> Vec<PathBuf> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut out = Vec::new();
    // FXBODY_FXB_DIR adds a directory of further files (to try files from elsewhere).
    let extra = std::env::var("FXBODY_FXB_DIR").unwrap_or_default();
    for dir in ["tests/data", "fixtures", extra.as_str()] {
        if dir.is_empty() {
            continue;
        }
        if let Ok(entries) = std::fs::read_dir(root.join(dir)) {
            for e in entries.flatten() {
                if e.path().extension().is_some_and(|x| x == "fxb") {
                    out.push(e.path());
                }
            }
        }
    }
    out.sort();
    out
}

fn split_lines(text: &[u8]) -> Vec<Vec<u8>> {
    text.split(|&c| c == b'\n').map(<[u8]>::to_vec).collect()
}

fn join_lines(lines: &[Vec<u8>]) -> Vec<u8> {
    lines.join(&b'\n')
}

const LITERALS: [&str; 12] = [
    "NaN",
    "Infinity",
    "-Inf",
    "1.0E+999",
    "1.0+400",
    "-9.9D+307",
    "99999999999999999999",
    "-1",
    "2",
    "0",
    "1.0-3",
    "-0.0",
];

/// Apply one random mutation.
fn mutate(rng: &mut Rng, text: &[u8]) -> Vec<u8> {
    let mut lines = split_lines(text);
    match rng.below(9) {
        0 => text[..rng.below(text.len() + 1)].to_vec(),
        1 => {
            let mut t = text.to_vec();
            if !t.is_empty() {
                let p = rng.below(t.len());
                t[p] ^= (1 + rng.below(255)) as u8;
            }
            t
        }
        2 => {
            let (a, b) = (rng.below(lines.len()), rng.below(lines.len()));
            lines.swap(a, b);
            join_lines(&lines)
        }
        3 => {
            let a = rng.below(lines.len());
            let l = lines[a].clone();
            lines.insert(a, l);
            join_lines(&lines)
        }
        4 => {
            let a = rng.below(lines.len());
            lines.remove(a);
            join_lines(&lines)
        }
        5 => {
            let len = rng.below(120);
            let garbage: Vec<u8> = (0..len).map(|_| (rng.next() & 0xff) as u8).collect();
            lines.insert(rng.below(lines.len() + 1), garbage);
            join_lines(&lines)
        }
        6 => {
            // Replace one 16-column field (or 8 in the first lines) with a literal.
            let a = rng.below(lines.len());
            let lit = LITERALS[rng.below(LITERALS.len())];
            let width = if a < 8 { 8 } else { 16 };
            let field = rng.below(6) * width;
            let line = &mut lines[a];
            if line.len() < field + width {
                line.resize(field + width, b' ');
            }
            let padded = format!("{lit:>width$}");
            line[field..field + width].copy_from_slice(&padded.as_bytes()[..width]);
            join_lines(&lines)
        }
        7 => {
            let mut t = text.to_vec();
            if !t.is_empty() {
                let p = rng.below(t.len());
                let pool = b"0123456789+-.\t EeDd#$\r\n";
                t[p] = pool[rng.below(pool.len())];
            }
            t
        }
        _ => {
            let mut t = text.to_vec();
            for _ in 0..2 + rng.below(3) {
                t = mutate(rng, &t);
            }
            t
        }
    }
}

/// Read, validate, write, read again. Returns whether a valid body came out.
fn exercise(text: &[u8]) -> bool {
    let Ok(file) = fxb::parse(text, "mutant.fxb") else {
        return false;
    };
    let written = fxb::write(&file);
    let again = fxb::parse(&written, "mutant-written.fxb").expect("written text must read back");
    assert_eq!(again.node_ids, file.node_ids);
    match Body::from_fxb(&file, "mutant.fxb") {
        Ok(body) => {
            let _ = (body.total_mass(), body.node_has_rotation(0));
            true
        }
        Err(e) => {
            assert!(e.to_string().starts_with("mutant.fxb: block"), "{e}");
            false
        }
    }
}

#[test]
fn mutated_files_never_panic() {
    let files = fxb_files();
    assert!(!files.is_empty());
    // FXBODY_MUTATION_CASES runs more (or fewer) cases than the CI default.
    let total = std::env::var("FXBODY_MUTATION_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(CASES);
    let per_file = total.div_ceil(files.len());
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    let (mut cases, mut valid, mut panics) = (0, 0, Vec::new());
    for path in &files {
        let original = std::fs::read(path).unwrap();
        for k in 0..per_file {
            let text = mutate(&mut rng, &original);
            cases += 1;
            match catch_unwind(AssertUnwindSafe(|| exercise(&text))) {
                Ok(v) => valid += usize::from(v),
                Err(_) => panics.push(format!("{} case {k}", path.display())),
            }
        }
    }
    println!(
        "mutation cases: {cases}, valid bodies: {valid}, errors: {}",
        cases - valid - panics.len()
    );
    assert!(panics.is_empty(), "{} panics: {:?}", panics.len(), panics);
    assert!(cases >= total);
}
