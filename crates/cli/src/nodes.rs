//! Node ID lists on the command line (`--nodes "121, 111"`) and in `--nodes-file`: IDs
//! separated by commas and/or blanks, so a list typed with spaces works as one without.

/// Node IDs given with `--nodes`, parsed by [`id_list`].
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct NodeIds(pub Vec<i64>);

/// clap value parser of `--nodes`: IDs separated by commas and/or blanks
/// (`121,111`, `"121, 111"`, `"121 111"`).
pub fn id_list(text: &str) -> Result<NodeIds, String> {
    let mut ids = Vec::new();
    for tok in text.split([',', ' ', '\t']).filter(|t| !t.is_empty()) {
        ids.push(tok.parse::<i64>().map_err(|_| {
            format!("expected integer node IDs separated by commas or blanks, found '{tok}'")
        })?);
    }
    if ids.is_empty() {
        return Err("expected at least one node ID".into());
    }
    Ok(NodeIds(ids))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn commas_and_blanks_both_separate() {
        assert_eq!(id_list("121, 111").unwrap().0, vec![121, 111]);
        assert_eq!(id_list("121,111").unwrap().0, vec![121, 111]);
        assert_eq!(id_list(" 121  111 ,").unwrap().0, vec![121, 111]);
        assert!(id_list("121, x").unwrap_err().contains("'x'"));
        assert!(id_list(" , ").is_err());
    }
}
