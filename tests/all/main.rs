//! The integration tests, one module per area of the crate (tests/README.md says where a
//! new test goes). One binary: one link instead of one per file, and libtest runs all
//! of them in one pool of threads. The allocation-counting tests are in `tests/alloc`,
//! a binary of their own because they install a counting global allocator.

#[path = "../common/mod.rs"]
mod common;

mod body;
mod cli;
mod docs;
mod fmi;
mod format;
mod free;
mod scene;
mod solver;

/// With `autotests = false`, a test file that no `[[test]]` target or `mod` line reaches
/// is silently never compiled: every .rs file under tests/ must be a `[[test]]` root of
/// Cargo.toml, or be declared by a `mod` line of its parent module (or by a `#[path]`
/// line of a binary's root, for tests/common).
#[test]
fn every_test_file_is_compiled() {
    let root = common::root();
    let manifest = std::fs::read_to_string(root.join("Cargo.toml")).unwrap();
    let mut missing = Vec::new();
    let mut stack = vec![root.join("tests")];
    while let Some(dir) = stack.pop() {
        for entry in std::fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                stack.push(path);
                continue;
            }
            if path.extension().is_none_or(|e| e != "rs") {
                continue;
            }
            let rel = path
                .strip_prefix(&root)
                .unwrap()
                .to_string_lossy()
                .into_owned();
            if manifest.contains(&format!("path = \"{rel}\"")) {
                continue;
            }
            // Shared by the binaries: `#[path = "../common/mod.rs"]` in their roots.
            let by_path = format!("#[path = \"../{}\"]", rel.trim_start_matches("tests/"));
            if ["all", "alloc"].iter().any(|b| {
                std::fs::read_to_string(root.join("tests").join(b).join("main.rs"))
                    .is_ok_and(|t| t.contains(&by_path))
            }) {
                continue;
            }
            // A module file: dir/name.rs, or dir/name/mod.rs, declared as `mod name;` in
            // dir's main.rs or mod.rs.
            let (parent, name) = match path.file_name().unwrap().to_str().unwrap() {
                "mod.rs" => (
                    dir.parent().unwrap().to_path_buf(),
                    dir.file_name().unwrap().to_string_lossy().into_owned(),
                ),
                file => (dir.clone(), file.trim_end_matches(".rs").to_owned()),
            };
            let declared = ["main.rs", "mod.rs"].iter().any(|f| {
                std::fs::read_to_string(parent.join(f)).is_ok_and(|t| {
                    t.lines().any(|l| {
                        let l = l.trim();
                        l == format!("mod {name};") || l == format!("pub mod {name};")
                    })
                })
            });
            if !declared {
                missing.push(rel);
            }
        }
    }
    missing.sort();
    assert!(
        missing.is_empty(),
        "never compiled (autotests = false): {missing:?}; move each into the module of its \
         area under tests/all and add a `mod` line (tests/README.md)"
    );
}
