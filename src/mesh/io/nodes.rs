//! Selecting glTF nodes by name: [`NodeFilter`], the `--nodes` option of `pleat lod`/`pleat cage`.
//!
//! A pattern selects every node whose name it matches (`*` any run of characters, `?` one
//! character, everything else literal and case-sensitive), or the node of index `N` when it is
//! `#N`. A selected node selects its whole subtree: naming a character's root node takes its
//! body, its clothes and its props. The merged reader ([`super::gltf::read_gltf_selected`],
//! `bake::read_gltf_appearance_selected`) fuses only the selected subtrees; per-mesh chains
//! (`bake::scene`) are made only for meshes that a selected node instances.

use crate::{Error, Result};

/// Glob patterns over node names (see the [module docs](self)). Never empty.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct NodeFilter {
    patterns: Vec<String>,
}

impl NodeFilter {
    /// A filter from patterns. Errors (`InvalidArgument`) when there is none, one is empty, or
    /// a `#N` pattern's index is not a number.
    pub fn new<S: Into<String>>(patterns: impl IntoIterator<Item = S>) -> Result<NodeFilter> {
        let patterns: Vec<String> = patterns.into_iter().map(Into::into).collect();
        if patterns.is_empty() {
            return Err(Error::InvalidArgument(
                "a node filter needs at least one node name or pattern".into(),
            ));
        }
        for p in &patterns {
            if p.is_empty() {
                return Err(Error::InvalidArgument(
                    "a node name pattern is empty".into(),
                ));
            }
            if let Some(i) = p.strip_prefix('#') {
                if i.parse::<usize>().is_err() {
                    return Err(Error::InvalidArgument(format!(
                        "'{p}': a node index is '#' and a number, such as #0"
                    )));
                }
            }
        }
        Ok(NodeFilter { patterns })
    }

    /// A filter from a comma-separated list (the CLI's form), spaces around names trimmed.
    pub fn parse(list: &str) -> Result<NodeFilter> {
        NodeFilter::new(list.split(',').map(str::trim))
    }

    /// The patterns, as given.
    pub fn patterns(&self) -> &[String] {
        &self.patterns
    }

    /// Whether node `index` named `name` is matched by a pattern itself (not through a parent).
    pub fn matches(&self, index: usize, name: Option<&str>) -> bool {
        self.patterns.iter().any(|p| match p.strip_prefix('#') {
            Some(i) => i.parse::<usize>() == Ok(index),
            None => name.is_some_and(|n| glob(p.as_bytes(), n.as_bytes())),
        })
    }

    /// The selected nodes of a document with `names[i]` and `children[i]` per node: the
    /// matched nodes and everything below them. Children indices out of range are ignored and
    /// a node reached twice is visited once, so a malformed hierarchy cannot loop. Errors
    /// (`InvalidArgument`) when no node matches, listing the node names there are.
    pub fn select(&self, names: &[Option<&str>], children: &[Vec<usize>]) -> Result<Vec<bool>> {
        let n = names.len();
        let mut selected = vec![false; n];
        let mut stack: Vec<usize> = (0..n).filter(|&i| self.matches(i, names[i])).collect();
        if stack.is_empty() {
            return Err(Error::InvalidArgument(self.no_match(names)));
        }
        while let Some(i) = stack.pop() {
            if std::mem::replace(&mut selected[i], true) {
                continue;
            }
            let kids = children.get(i).map_or(&[][..], Vec::as_slice);
            stack.extend(kids.iter().copied().filter(|&c| c < n && !selected[c]));
        }
        Ok(selected)
    }

    /// The message of a filter that matches no node: the patterns and (some of) the names.
    fn no_match(&self, names: &[Option<&str>]) -> String {
        const SHOWN: usize = 20;
        let named: Vec<&str> = names.iter().flatten().copied().collect();
        let mut list = named
            .iter()
            .take(SHOWN)
            .map(|s| format!("'{s}'"))
            .collect::<Vec<_>>()
            .join(", ");
        if named.len() > SHOWN {
            list.push_str(&format!(" and {} more", named.len() - SHOWN));
        }
        if named.is_empty() {
            list = "none has a name; select by index (#0 ..)".into();
        }
        format!(
            "no node matches {}; the document has {} node(s): {list}",
            self.patterns.join(", "),
            names.len()
        )
    }
}

/// Whether `text` matches the glob `pat` (`*`, `?`, literal bytes elsewhere). Iterative with
/// one backtrack point: linear-times-pattern in the worst case, no recursion.
fn glob(pat: &[u8], text: &[u8]) -> bool {
    let (mut p, mut t) = (0, 0);
    let mut star: Option<(usize, usize)> = None;
    while t < text.len() {
        if p < pat.len() && (pat[p] == b'?' || pat[p] == text[t]) {
            p += 1;
            t += 1;
        } else if p < pat.len() && pat[p] == b'*' {
            star = Some((p, t));
            p += 1;
        } else if let Some((sp, st)) = star {
            p = sp + 1;
            t = st + 1;
            star = Some((sp, st + 1));
        } else {
            return false;
        }
    }
    pat[p..].iter().all(|&c| c == b'*')
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn globs_match_names() {
        assert!(glob(b"Body", b"Body"));
        assert!(!glob(b"Body", b"body"));
        assert!(glob(b"Tree*", b"Tree_01"));
        assert!(glob(b"*_LOD?", b"rock_LOD1"));
        assert!(!glob(b"*_LOD?", b"rock_LOD12"));
        assert!(glob(b"*", b""));
        assert!(glob(b"a*b*c", b"axxbyyc"));
        assert!(!glob(b"a*b*c", b"axxbyy"));
    }

    #[test]
    fn a_selected_node_selects_its_subtree() {
        // 0 → 1 → 2, 3 alone; a cycle 2 → 1 must not loop.
        let names = [Some("Root"), Some("Arm"), None, Some("Prop")];
        let children = vec![vec![1], vec![2], vec![1, 99], vec![]];
        let f = NodeFilter::parse("Arm").unwrap();
        assert_eq!(
            f.select(&names, &children).unwrap(),
            vec![false, true, true, false]
        );
        let f = NodeFilter::parse("Prop, #0").unwrap();
        assert_eq!(
            f.select(&names, &children).unwrap(),
            vec![true, true, true, true]
        );
    }

    #[test]
    fn bad_filters_are_refused_with_the_names() {
        assert!(NodeFilter::parse("").is_err());
        assert!(NodeFilter::parse("a,,b").is_err());
        assert!(NodeFilter::parse("#x").is_err());
        let e = NodeFilter::parse("Leg")
            .unwrap()
            .select(&[Some("Body"), Some("Prop")], &[vec![], vec![]])
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("no node matches Leg") && e.contains("'Prop'"),
            "{e}"
        );
    }
}
