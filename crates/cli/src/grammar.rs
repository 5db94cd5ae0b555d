//! One grammar for the values every command takes, in one place: node lists (`--nodes
//! 1,2,5-9`, `--nodes-file`), unit systems (`pack --units`, `import --units`) and number
//! pairs (`import --damping ALPHA,BETA`). Each parser's message names what it expected;
//! clap puts the flag in front (`invalid value 'x' for '--nodes <NODES>': ...`), and
//! the parsers called outside clap name the flag themselves.

use std::ffi::OsString;

use fxbody::units::{FORM, UnitSystem};

/// The node-list form, for messages.
pub const NODES_FORM: &str =
    "node IDs or ranges A-B separated by commas and/or blanks (e.g. 1,2,5-9 or \"121 111\")";

/// The most IDs one range may expand to: a typo such as `1-1000000000` is refused
/// instead of allocating gigabytes.
pub const MAX_RANGE: i64 = 10_000_000;

/// Node IDs given with `--nodes`, parsed by [`node_list`].
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct NodeIds(pub Vec<i64>);

/// clap value parser of every `--nodes`: see [`NODES_FORM`].
pub fn node_list(text: &str) -> Result<NodeIds, String> {
    let mut ids = Vec::new();
    node_tokens(text, &mut ids)?;
    if ids.is_empty() {
        return Err(format!("expected {NODES_FORM}, found no ID"));
    }
    Ok(NodeIds(ids))
}

/// Appends the IDs of `text` (one line of a list) to `ids`.
fn node_tokens(text: &str, ids: &mut Vec<i64>) -> Result<(), String> {
    for tok in text.split([',', ' ', '\t']).filter(|t| !t.is_empty()) {
        let bad = || {
            let shown = fxbody::fxb::fields::shown(tok.as_bytes());
            format!("expected {NODES_FORM}, found '{shown}'")
        };
        let id = |s: &str| s.parse::<i64>().ok().filter(|&v| v > 0).ok_or_else(bad);
        match tok.split_once('-') {
            None => ids.push(id(tok)?),
            Some((a, b)) => {
                let (a, b) = (id(a)?, id(b)?);
                if b < a {
                    return Err(format!("range '{tok}' runs backwards: write {b}-{a}"));
                }
                if b - a >= MAX_RANGE {
                    return Err(format!(
                        "range '{tok}' holds {} IDs, more than {MAX_RANGE}",
                        b - a + 1
                    ));
                }
                ids.extend(a..=b);
            }
        }
    }
    Ok(())
}

/// The text of a `--nodes-file`: the grammar of [`node_list`] on every line, `#` starts
/// a comment. Errors name `name` (the file) and the line.
pub fn node_file_text(text: &str, name: &str) -> Result<Vec<i64>, String> {
    let mut ids = Vec::new();
    for (k, line) in text.lines().enumerate() {
        let line = line.split('#').next().unwrap_or("");
        node_tokens(line, &mut ids).map_err(|e| format!("{name}:{}: {e}", k + 1))?;
    }
    if ids.is_empty() {
        return Err(format!("{name}: no node IDs"));
    }
    Ok(ids)
}

/// clap value parser of `pack --units`: one system of [`fxbody::units`].
pub fn unit_system(text: &str) -> Result<UnitSystem, String> {
    UnitSystem::parse(text).map_err(|_| format!("expected {FORM}, found '{text}'"))
}

/// `import --units`: the matrices' system and the body's.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Conversion {
    /// The system the FE matrices and coordinates are in.
    pub from: UnitSystem,
    /// The system the body is written in.
    pub to: UnitSystem,
}

impl Conversion {
    /// The import's factors from `from` to `to`, exact powers of ten.
    pub fn factors(&self) -> fxbody_import::Units {
        fxbody_import::Units::between(self.from, self.to)
    }
}

/// clap value parser of `import --units`: `FROM:TO` (convert), or one system (the
/// matrices are in it and the body stays in it).
pub fn unit_conversion(text: &str) -> Result<Conversion, String> {
    let bad = || format!("expected FROM:TO or one system, each {FORM}; found '{text}'");
    let (from, to) = text.split_once(':').unwrap_or((text, text));
    Ok(Conversion {
        from: UnitSystem::parse(from).map_err(|_| bad())?,
        to: UnitSystem::parse(to).map_err(|_| bad())?,
    })
}

/// clap value parser of a pair `A,B` (`--damping ALPHA,BETA`): two finite numbers
/// separated by a comma (blanks around it allowed).
pub fn pair(text: &str) -> Result<(f64, f64), String> {
    let bad = || format!("expected two numbers A,B (e.g. 5,1e-5), found '{text}'");
    let (a, b) = text.split_once(',').ok_or_else(bad)?;
    let num = |s: &str| s.trim().parse::<f64>().ok().filter(|v| v.is_finite());
    Ok((num(a).ok_or_else(bad)?, num(b).ok_or_else(bad)?))
}

/// The flags that take a pair ([`pair`]).
const PAIR_FLAGS: [&str; 1] = ["--damping"];

/// The command line with a pair flag's older two-word form (`--damping 5 1e-5`) joined
/// into the documented one (`--damping 5,1e-5`): only when both words are numbers, so a
/// file name after `--damping 5` is never taken for the second value.
pub fn join_pairs(args: impl IntoIterator<Item = OsString>) -> Vec<OsString> {
    let mut args: Vec<OsString> = args.into_iter().collect();
    let number = |s: &OsString| s.to_str().is_some_and(|t| t.parse::<f64>().is_ok());
    let mut k = 0;
    while k + 2 < args.len() {
        if PAIR_FLAGS.iter().any(|f| args[k] == *f) && number(&args[k + 1]) && number(&args[k + 2])
        {
            let mut joined = args[k + 1].clone();
            joined.push(",");
            joined.push(&args[k + 2]);
            args.splice(k + 1..k + 3, [joined]);
        }
        k += 1;
    }
    args
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn node_lists_take_commas_blanks_and_ranges() {
        assert_eq!(node_list("121, 111").unwrap().0, vec![121, 111]);
        assert_eq!(node_list("121,111").unwrap().0, vec![121, 111]);
        assert_eq!(node_list(" 121  111 ,").unwrap().0, vec![121, 111]);
        assert_eq!(node_list("1,2,5-9").unwrap().0, vec![1, 2, 5, 6, 7, 8, 9]);
        assert_eq!(node_list("7-7").unwrap().0, vec![7]);
        for (bad, says) in [
            ("121, x", "found 'x'"),
            (" , ", "found no ID"),
            ("9-5", "runs backwards: write 5-9"),
            ("-5", "found '-5'"),
            ("0", "found '0'"),
            ("5-", "found '5-'"),
            ("1-2-3", "found '1-2-3'"),
            ("1-100000000", "more than 10000000"),
        ] {
            let e = node_list(bad).unwrap_err();
            assert!(e.contains(says), "{bad}: {e}");
        }
        assert!(node_list("x").unwrap_err().contains("e.g. 1,2,5-9"));
    }

    #[test]
    fn node_files_take_the_same_grammar_by_line() {
        let ids = node_file_text(
            "# tip and root\n121, 101\n111 # mid\n\n 105\t106\n3-5\n",
            "n.txt",
        );
        assert_eq!(ids.unwrap(), vec![121, 101, 111, 105, 106, 3, 4, 5]);
        let e = node_file_text("121\n12x\n", "n.txt").unwrap_err();
        assert!(e.starts_with("n.txt:2: expected node IDs"), "{e}");
        assert!(e.ends_with("found '12x'"), "{e}");
        assert_eq!(
            node_file_text("# none\n", "n.txt").unwrap_err(),
            "n.txt: no node IDs"
        );
    }

    #[test]
    fn units_one_system_or_a_conversion() {
        assert_eq!(unit_system("SI"), Ok(UnitSystem::SI));
        assert_eq!(unit_system("m-kg-s"), Ok(UnitSystem::SI));
        assert_eq!(unit_system("mm-kg-ms").unwrap().name(), "mm-kg-ms");
        assert!(
            unit_system("mm-t-s:SI")
                .unwrap_err()
                .contains("e.g. m-kg-s")
        );
        let c = unit_conversion("mm-t-s:mm-kg-ms").unwrap().factors();
        // t -> kg: 1e3; mm -> mm and s -> ms: lengths 1, times 1e3, exactly.
        assert_eq!((c.length, c.mass, c.time), (1.0, 1e3, 1e3));
        let si = unit_conversion("SI:mm-t-s").unwrap().factors();
        assert_eq!((si.length, si.mass, si.time), (1e3, 1e-3, 1.0));
        let same = unit_conversion("mm-kg-ms").unwrap();
        assert_eq!(same.from, same.to);
        assert_eq!(same.factors().energy(), 1.0);
        for bad in ["mm-t-s:", ":SI", "mm-t-s:mm-lb-s", "a:b:c"] {
            assert!(
                unit_conversion(bad).unwrap_err().contains("FROM:TO"),
                "{bad}"
            );
        }
    }

    #[test]
    fn pairs_take_a_comma_and_the_old_two_words_join() {
        assert_eq!(pair("5,1e-5"), Ok((5.0, 1e-5)));
        assert_eq!(pair("5, 1e-5"), Ok((5.0, 1e-5)));
        for bad in ["5", "5,", "5,x", "5;1", "inf,1", "1,2,3"] {
            assert!(pair(bad).unwrap_err().contains("A,B"), "{bad}");
        }
        let os = |v: &[&str]| v.iter().map(OsString::from).collect::<Vec<_>>();
        assert_eq!(
            join_pairs(os(&["fxbody", "import", "--damping", "5", "1e-5", "m.pch"])),
            os(&["fxbody", "import", "--damping", "5,1e-5", "m.pch"])
        );
        // A file name is never taken for the second value.
        let kept = os(&["fxbody", "import", "--damping", "5", "m.pch"]);
        assert_eq!(join_pairs(kept.clone()), kept);
        let kept = os(&["fxbody", "import", "--damping", "5,1e-5", "2"]);
        assert_eq!(join_pairs(kept.clone()), kept);
    }
}
