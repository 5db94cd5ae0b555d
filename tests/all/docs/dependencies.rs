//! README lists each package's dependencies (issue 27.1): every external crate a
//! workspace package depends on (normal, target-specific and build dependencies; the
//! workspace's own packages and dev-dependencies aside) is named in that package's entry
//! of README's package list (`` `name` (...) ``), and the entry names nothing the package
//! does not depend on. A dependency added or dropped without README following fails here.

use crate::common::root;

/// The workspace packages: manifest path and package name.
const PACKAGES: [(&str, &str); 7] = [
    ("Cargo.toml", "fxbody"),
    ("crates/import/Cargo.toml", "fxbody-import"),
    ("crates/cli/Cargo.toml", "fxbody-cli"),
    ("crates/host/Cargo.toml", "fxbody-host"),
    ("crates/study/Cargo.toml", "fxbody-study"),
    ("crates/chart/Cargo.toml", "fxbody-chart"),
    ("crates/testkit/Cargo.toml", "fxbody-testkit"),
];

/// Every external dependency of a manifest: the keys of its `[dependencies]`,
/// `[target.'...'.dependencies]` and `[build-dependencies]` tables, our own packages left
/// out.
fn dependencies(manifest: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut inside = false;
    for line in manifest.lines().map(str::trim) {
        if line.starts_with('[') {
            inside = line == "[dependencies]"
                || line == "[build-dependencies]"
                || (line.starts_with("[target.") && line.ends_with(".dependencies]"));
            continue;
        }
        if !inside || line.is_empty() || line.starts_with('#') {
            continue;
        }
        if let Some((key, _)) = line.split_once('=') {
            let key = key.trim();
            if !key.starts_with("fxbody") {
                out.push(key.to_string());
            }
        }
    }
    out
}

/// The words of README's entry for `package`: the text in the parentheses after its
/// name in the package list.
fn entry<'a>(readme: &'a str, package: &str) -> &'a str {
    let list = &readme[readme
        .find("the packages, each dependency and why")
        .expect("README's package list")..];
    let head = format!("`{package}` (");
    let start = list
        .find(&head)
        .unwrap_or_else(|| panic!("README's package list has no entry for {package}"))
        + head.len();
    let end = start
        + list[start..]
            .find(')')
            .expect("the entry's closing parenthesis");
    &list[start..end]
}

/// The crate names among an entry's words (the words with a `-` or `_`, or plain ones
/// that are a known dependency of some package).
fn named(entry: &str, known: &[String]) -> Vec<String> {
    entry
        .split(|c: char| !(c.is_ascii_alphanumeric() || c == '-' || c == '_'))
        .filter(|w| known.iter().any(|k| k == w))
        .map(str::to_string)
        .collect()
}

#[test]
fn readme_lists_each_packages_dependencies() {
    let readme = std::fs::read_to_string(root().join("README.md")).unwrap();
    let deps: Vec<(&str, Vec<String>)> = PACKAGES
        .iter()
        .map(|&(path, name)| {
            let text = std::fs::read_to_string(root().join(path)).unwrap();
            assert!(text.contains(&format!("name = \"{name}\"")), "{path}");
            (name, dependencies(&text))
        })
        .collect();
    let known: Vec<String> = deps.iter().flat_map(|(_, d)| d.clone()).collect();
    assert!(known.len() >= 20, "{known:?}");
    for (name, wanted) in &deps {
        let e = entry(&readme, name);
        let said = named(e, &known);
        for d in wanted {
            assert!(
                said.contains(d),
                "README's entry for {name} does not name {d}: '{e}'"
            );
        }
        for d in &said {
            assert!(
                wanted.contains(d),
                "README's entry for {name} names {d}, which it does not depend on"
            );
        }
    }
}
