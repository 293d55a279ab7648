//! ROS 2 name resolution: private (`~`), relative and absolute names, and remapping.
//!
//! Follows the ROS 2 design article "Topic and Service name mapping to DDS" and rcl's
//! expansion rules: `~/x` → `/<namespace>/<node>/x`, `x` → `/<namespace>/x`, `/x` → `/x`.
//! Remap rules are matched against the fully qualified name and the first match wins (rcl).

use crate::RosError;

fn check_token(token: &str, whole: &str) -> Result<(), RosError> {
    let bad = |reason: &str| RosError::Name {
        name: whole.to_string(),
        reason: reason.to_string(),
    };
    if token.is_empty() {
        return Err(bad("empty token (double slash, or trailing slash)"));
    }
    if token.contains("__") {
        return Err(bad("contains '__'"));
    }
    let mut chars = token.chars();
    match chars.next() {
        Some(c) if c.is_ascii_alphabetic() || c == '_' => {}
        _ => return Err(bad("a token must start with a letter or '_'")),
    }
    if let Some(c) = token
        .chars()
        .find(|c| !(c.is_ascii_alphanumeric() || *c == '_'))
    {
        return Err(bad(&format!("character {c:?} is not allowed")));
    }
    Ok(())
}

/// Checks a node base name (one token).
pub fn validate_node_name(name: &str) -> Result<(), RosError> {
    check_token(name, name)
}

/// Normalizes and checks a namespace: absolute, no trailing slash except for `/` itself.
///
/// # Returns
/// The namespace in canonical form (`""` and `"/"` both give `"/"`; `"cell"` gives `"/cell"`).
pub fn normalize_namespace(ns: &str) -> Result<String, RosError> {
    let trimmed = ns.trim_end_matches('/');
    if trimmed.is_empty() {
        return Ok("/".into());
    }
    let abs = if trimmed.starts_with('/') {
        trimmed.to_string()
    } else {
        format!("/{trimmed}")
    };
    for tok in abs[1..].split('/') {
        check_token(tok, ns)?;
    }
    Ok(abs)
}

/// Expands a topic or service name to its fully qualified form.
///
/// # Arguments
/// * `name` – the name as written by the node or user (`~/x`, `x`, `a/b`, `/x`).
/// * `namespace` – the node's normalized namespace.
/// * `node` – the node's base name.
pub fn expand(name: &str, namespace: &str, node: &str) -> Result<String, RosError> {
    let ns = if namespace == "/" { "" } else { namespace };
    let full = if name == "~" {
        format!("{ns}/{node}")
    } else if let Some(rest) = name.strip_prefix("~/") {
        format!("{ns}/{node}/{rest}")
    } else if name.starts_with('~') {
        return Err(RosError::Name {
            name: name.into(),
            reason: "'~' must be followed by '/'".into(),
        });
    } else if name.starts_with('/') {
        name.to_string()
    } else {
        format!("{ns}/{name}")
    };
    for tok in full[1..].split('/') {
        check_token(tok, name)?;
    }
    Ok(full)
}

/// A remapping rule `from:=to`, optionally restricted to one node (`node:from:=to`).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Remap {
    /// Node base name the rule applies to; `None` applies to every node.
    pub node: Option<String>,
    /// Name to match (expanded against the node before matching).
    pub from: String,
    /// Replacement name (expanded against the node).
    pub to: String,
}

impl Remap {
    /// Parses `[node:]from:=to`.
    pub fn parse(rule: &str) -> Result<Self, RosError> {
        let (lhs, to) = rule.split_once(":=").ok_or_else(|| RosError::Args {
            arg: rule.into(),
            reason: "a remap rule has the form [node:]from:=to".into(),
        })?;
        let (node, from) = match lhs.split_once(':') {
            Some((n, f)) => (Some(n.to_string()), f.to_string()),
            None => (None, lhs.to_string()),
        };
        if from.is_empty() || to.is_empty() {
            return Err(RosError::Args {
                arg: rule.into(),
                reason: "both sides of ':=' must be non-empty".into(),
            });
        }
        Ok(Self {
            node,
            from,
            to: to.to_string(),
        })
    }

    /// Whether the rule applies to the node with this (original or remapped) base name.
    pub fn applies_to(&self, node: &str) -> bool {
        self.node.as_deref().is_none_or(|n| n == node)
    }
}

/// Resolves a name used by a node: expands it, then applies the first matching topic remap.
///
/// Rules whose `from` is `__ns`, `__node` or `__name` are node-level rules and are skipped here.
pub fn resolve(
    name: &str,
    namespace: &str,
    node: &str,
    remaps: &[Remap],
) -> Result<String, RosError> {
    let full = expand(name, namespace, node)?;
    for r in remaps
        .iter()
        .filter(|r| r.applies_to(node) && !r.from.starts_with("__"))
    {
        if expand(&r.from, namespace, node)? == full {
            return expand(&r.to, namespace, node);
        }
    }
    Ok(full)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn expands_private_relative_absolute() {
        assert_eq!(
            expand("~/joint_trajectory", "/", "exec").unwrap(),
            "/exec/joint_trajectory"
        );
        assert_eq!(expand("~/a", "/cell", "exec").unwrap(), "/cell/exec/a");
        assert_eq!(
            expand("joint_states", "/cell", "exec").unwrap(),
            "/cell/joint_states"
        );
        assert_eq!(
            expand("/joint_states", "/cell", "exec").unwrap(),
            "/joint_states"
        );
        assert!(expand("~x", "/", "n").is_err());
        assert!(expand("a//b", "/", "n").is_err());
        assert!(expand("9a", "/", "n").is_err());
        assert!(expand("a__b", "/", "n").is_err());
    }

    #[test]
    fn namespaces_normalize() {
        assert_eq!(normalize_namespace("").unwrap(), "/");
        assert_eq!(normalize_namespace("/").unwrap(), "/");
        assert_eq!(normalize_namespace("cell/").unwrap(), "/cell");
        assert_eq!(normalize_namespace("/a/b").unwrap(), "/a/b");
        assert!(normalize_namespace("/a b").is_err());
    }

    #[test]
    fn remaps_match_on_full_names_first_wins() {
        let rules = vec![
            Remap::parse("other:~/in:=/nope").unwrap(),
            Remap::parse("~/in:=/cell/trajectory").unwrap(),
            Remap::parse("/exec/in:=/second").unwrap(),
        ];
        assert_eq!(
            resolve("~/in", "/", "exec", &rules).unwrap(),
            "/cell/trajectory"
        );
        assert_eq!(resolve("~/out", "/", "exec", &rules).unwrap(), "/exec/out");
        assert!(Remap::parse("nothing").is_err());
        assert!(Remap::parse(":=x").is_err());
    }
}
