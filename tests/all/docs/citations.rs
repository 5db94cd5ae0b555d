//! The repository's documentation stands alone: every "FORMULATION.md section N" cited in
//! the code, tests, docs or fixtures names a section that exists in docs/FORMULATION.md,
//! and no file points outside the repository (to a shared design folder, or by a relative
//! Markdown link that climbs out of it).

use crate::common::root;
use std::path::{Path, PathBuf};

/// Directories of the repository that are not its own text (the two venvs that
/// scripts/test.sh makes among them).
const SKIP_DIRS: [&str; 6] = [
    "target",
    ".venv",
    ".venv-nastran",
    ".git",
    "out",
    "__pycache__",
];
/// Text files that may cite the formulation or link to other files.
const EXTENSIONS: [&str; 8] = ["rs", "md", "py", "toml", "txt", "sh", "h", "c"];

/// Every text file of the repository (symbolic links not followed).
fn text_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let mut entries: Vec<_> = std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| e.unwrap())
        .collect();
    entries.sort_by_key(|e| e.file_name());
    for e in entries {
        let kind = e.file_type().unwrap();
        let path = e.path();
        let name = e.file_name().to_string_lossy().into_owned();
        if kind.is_dir() && !SKIP_DIRS.contains(&name.as_str()) {
            text_files(&path, out);
        } else if kind.is_file()
            && path
                .extension()
                .is_some_and(|x| EXTENSIONS.contains(&x.to_string_lossy().as_ref()))
        {
            out.push(path);
        }
    }
}

/// The section numbers that exist: "## N." and "### N.M" headings of docs/FORMULATION.md.
fn sections() -> Vec<String> {
    let text = std::fs::read_to_string(root().join("docs/FORMULATION.md"))
        .expect("docs/FORMULATION.md exists");
    let mut out = Vec::new();
    for line in text.lines() {
        let Some(rest) = line
            .strip_prefix("## ")
            .or_else(|| line.strip_prefix("### "))
        else {
            continue;
        };
        let num: String = rest
            .chars()
            .take_while(|c| c.is_ascii_digit() || *c == '.')
            .collect();
        let num = num.trim_end_matches('.');
        if !num.is_empty() {
            out.push(num.to_string());
        }
    }
    out
}

/// The text after a citation with line breaks and comment markers (`//!`, `///`, `//`,
/// `#`, `*`) folded into single blanks, so a citation broken across comment lines reads
/// as one.
fn fold(after: &str) -> String {
    let mut out = String::new();
    for (i, line) in after.lines().take(3).enumerate() {
        let line = if i == 0 {
            line
        } else {
            line.trim_start()
                .trim_start_matches("//!")
                .trim_start_matches("///")
                .trim_start_matches("//")
                .trim_start_matches('#')
                .trim_start_matches('*')
        };
        out.push(' ');
        out.push_str(line.trim());
    }
    out
}

/// The section numbers a citation names: "section 4", "sections 2 and 3",
/// "section 1, last paragraph", "section 10.3", "sections 1-4". Empty when the mention
/// names no section.
fn cited(after: &str) -> Vec<String> {
    let text = fold(after);
    let text = text.trim_start_matches(|c: char| c == '`' || c == ')' || c.is_whitespace());
    let text = text.strip_prefix(',').unwrap_or(text).trim_start();
    let rest = if let Some(r) = text.strip_prefix("sections ") {
        r
    } else if let Some(r) = text.strip_prefix("section ") {
        r
    } else {
        return Vec::new();
    };
    let mut nums = Vec::new();
    let mut words = rest.split_whitespace();
    while let Some(w) = words.next() {
        let num: String = w
            .chars()
            .take_while(|c| c.is_ascii_digit() || *c == '.' || *c == '-')
            .collect();
        let num = num.trim_end_matches('.');
        if num.is_empty() {
            break;
        }
        for part in num.split('-') {
            nums.push(part.to_string());
        }
        // A list goes on after "N," or "N and".
        if w.ends_with(',') {
            continue;
        }
        match words.clone().next() {
            Some("and") => {
                words.next();
            }
            _ => break,
        }
    }
    nums
}

#[test]
fn formulation_citations_name_existing_sections() {
    let have = sections();
    assert!(
        (1..=10).all(|n| have.contains(&n.to_string())),
        "docs/FORMULATION.md must keep sections 1-10, found {have:?}"
    );
    let mut files = Vec::new();
    text_files(&root(), &mut files);
    let mut count = 0;
    let mut bad = Vec::new();
    for f in &files {
        let Ok(text) = std::fs::read_to_string(f) else {
            continue;
        };
        for (pos, _) in text.match_indices("FORMULATION.md") {
            let line = text[..pos].lines().count().max(1);
            for n in cited(&text[pos + "FORMULATION.md".len()..]) {
                count += 1;
                if !have.contains(&n) {
                    bad.push(format!(
                        "{}:{line}: section {n}",
                        f.strip_prefix(root()).unwrap().display()
                    ));
                }
            }
        }
    }
    println!("{count} section citations checked in {} files", files.len());
    assert!(
        count >= 30,
        "only {count} citations found: is the scan broken?"
    );
    assert!(
        bad.is_empty(),
        "citations of sections docs/FORMULATION.md does not have:\n{}",
        bad.join("\n")
    );
}

/// The parser reads the forms the repository uses.
#[test]
fn citation_forms() {
    assert_eq!(cited(" section 1). More"), ["1"]);
    assert_eq!(cited(" sections 2 and 3)."), ["2", "3"]);
    assert_eq!(cited(" section 1, last paragraph"), ["1"]);
    assert_eq!(cited("\n//! section 4 sub-cycled"), ["4"]);
    assert_eq!(cited("` section 10.3."), ["10.3"]);
    assert_eq!(cited(" sections 1-4, 7"), ["1", "4", "7"]);
    assert_eq!(cited("` defines"), Vec::<String>::new());
}

#[test]
fn nothing_points_outside_the_repository() {
    // Built from pieces so that this file does not match itself.
    let forbidden = [
        concat!("../", "shared"),
        concat!("/work", "/shared"),
        concat!("shared/", "design/"),
        concat!("shared/", "reference/"),
    ];
    let mut files = Vec::new();
    text_files(&root(), &mut files);
    let mut bad = Vec::new();
    for f in &files {
        let Ok(text) = std::fs::read_to_string(f) else {
            continue;
        };
        let rel = f.strip_prefix(root()).unwrap();
        for (i, line) in text.lines().enumerate() {
            for s in forbidden {
                if line.contains(s) {
                    bad.push(format!("{}:{}: {s}", rel.display(), i + 1));
                }
            }
        }
        if f.extension().is_some_and(|x| x == "md") {
            // Relative Markdown links must stay inside the repository and exist.
            for (pos, _) in text.match_indices("](") {
                let target: String = text[pos + 2..]
                    .chars()
                    .take_while(|&c| c != ')' && c != ' ')
                    .collect();
                let target = target.split('#').next().unwrap_or("");
                if target.is_empty() || target.contains("://") || target.starts_with("mailto:") {
                    continue;
                }
                let line = text[..pos].lines().count().max(1);
                let mut depth: i64 = rel.components().count() as i64 - 1;
                let mut outside = target.starts_with('/');
                for part in target.split('/') {
                    match part {
                        ".." => depth -= 1,
                        "." | "" => {}
                        _ => depth += 1,
                    }
                    outside |= depth < 0;
                }
                let exists = f.parent().unwrap().join(target).exists();
                if outside || !exists {
                    bad.push(format!(
                        "{}:{line}: link to {target} ({})",
                        rel.display(),
                        if outside {
                            "outside the repository"
                        } else {
                            "missing"
                        }
                    ));
                }
            }
        }
    }
    assert!(
        bad.is_empty(),
        "references outside the repository or to missing files:\n{}",
        bad.join("\n")
    );
}
