//! [`AllowedRoots`]: the directories a request may name files in (issue 11, item 4).

use std::path::{Path, PathBuf};

/// Where files named by requests (meshes, policies, programs) may be: anywhere, or only under
/// a list of directories. The shipped data (the kerf data root, [`crate::data::root`]) is
/// always allowed. Paths are compared after resolving symbolic links and `..`, so a link
/// inside a root that points outside it is refused.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct AllowedRoots {
    /// Canonical directories; `None` = any path.
    roots: Option<Vec<PathBuf>>,
}

impl AllowedRoots {
    /// Any path is allowed (the default).
    pub fn any() -> Self {
        Self::default()
    }

    /// Only files under `roots` (and the shipped data) are allowed.
    ///
    /// # Errors
    /// The reason, naming the root, for a root that does not exist or is not a directory.
    pub fn only(roots: &[PathBuf]) -> Result<Self, String> {
        let mut canonical = Vec::with_capacity(roots.len() + 1);
        for root in roots {
            let c = std::fs::canonicalize(root)
                .map_err(|e| format!("allowed root {}: {e}", root.display()))?;
            if !c.is_dir() {
                return Err(format!(
                    "allowed root {} is not a directory",
                    root.display()
                ));
            }
            canonical.push(c);
        }
        if let Some(data) = crate::data::root()
            .ok()
            .and_then(|r| std::fs::canonicalize(r.path).ok())
        {
            canonical.push(data);
        }
        Ok(Self {
            roots: Some(canonical),
        })
    }

    /// Whether any path is allowed.
    pub fn is_any(&self) -> bool {
        self.roots.is_none()
    }

    /// Checks a file a request names.
    ///
    /// # Returns
    /// The canonical path (links resolved) to read.
    ///
    /// # Errors
    /// The reason, naming the path (never its contents): it cannot be resolved (missing), or
    /// it resolves outside every allowed root.
    pub fn check(&self, path: &Path) -> Result<PathBuf, String> {
        let Some(roots) = &self.roots else {
            return Ok(path.to_path_buf());
        };
        let canonical = std::fs::canonicalize(path)
            .map_err(|e| format!("cannot resolve {}: {e}", path.display()))?;
        if roots.iter().any(|r| canonical.starts_with(r)) {
            return Ok(canonical);
        }
        let list: Vec<String> = roots.iter().map(|r| r.display().to_string()).collect();
        Err(format!(
            "{} resolves to {}, outside the allowed roots ({}; the node's allowed_file_roots \
             parameter)",
            path.display(),
            canonical.display(),
            list.join(", ")
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch(name: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("kerf_roots_{name}_{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    #[test]
    fn files_under_a_root_pass_and_links_out_of_it_do_not() {
        let base = scratch("check");
        let inside = base.join("jobs");
        let outside = base.join("elsewhere");
        std::fs::create_dir_all(&inside).unwrap();
        std::fs::create_dir_all(&outside).unwrap();
        std::fs::write(inside.join("part.stl"), "x").unwrap();
        std::fs::write(outside.join("secret.stl"), "x").unwrap();
        std::os::unix::fs::symlink(outside.join("secret.stl"), inside.join("link.stl")).unwrap();
        let roots = AllowedRoots::only(std::slice::from_ref(&inside)).unwrap();
        assert!(!roots.is_any());
        assert!(roots.check(&inside.join("part.stl")).is_ok());
        for bad in [
            inside.join("link.stl"),
            inside.join("../elsewhere/secret.stl"),
            outside.join("secret.stl"),
        ] {
            let e = roots.check(&bad).unwrap_err();
            assert!(e.contains("outside the allowed roots"), "{e}");
        }
        assert!(roots
            .check(&inside.join("missing.stl"))
            .unwrap_err()
            .contains("cannot resolve"));
        // The shipped data is always allowed.
        let shipped = crate::data::path("urdf/laser_cutter.urdf").unwrap();
        assert!(roots.check(&shipped).is_ok());
        // Any: nothing is checked.
        assert!(AllowedRoots::any()
            .check(&outside.join("secret.stl"))
            .is_ok());
        assert!(AllowedRoots::only(&[base.join("nope")]).is_err());
        std::fs::remove_dir_all(&base).unwrap();
    }
}
