//! Where kerf's shipped data lives: the one search every default path of kerf goes through.
//!
//! kerf ships data files next to its code: the robot descriptions and meshes (`urdf/`), the
//! milling cell (`urdf/irb6660_milling.yaml`), the milling policies
//! (`crates/millplan/policies/`), the indicator cache (`crates/millplan/data/`) and the cut
//! cases (`crates/mjto/cases/`). They sit below one directory, the *data root*, with the same
//! relative paths as in the source tree. The data root is found by, in order:
//!
//! 1. [`DATA_DIR_VAR`] (`KERF_DATA_DIR`): when set, it must name a kerf data directory, else
//!    the search fails with an error naming the variable (it never falls back to the places
//!    below);
//! 2. the share directory beside the running binary, `<exe dir>/../share/kerf` (what
//!    `launch_scripts/install.sh PREFIX` fills for `PREFIX/bin/kerf`);
//! 3. the source tree kerf was built from (the workspace root).
//!
//! A directory is a kerf data directory when it holds [`MARKER`] (`urdf/laser_cutter.urdf`).
//! `package://kerf/<path>` URIs name `<path>` below the data root
//! ([`resolve_package_uri`]).
//!
//! # Example
//!
//! ```
//! use kerf_robot::data::{self, DataSource};
//!
//! // From the source tree, with KERF_DATA_DIR unset, the workspace root is the data root.
//! let root = data::DataRoot::search(None, None, &data::source_tree())?;
//! assert_eq!(root.source, DataSource::SourceTree);
//! assert!(root.join("urdf/irb6660.urdf").is_file());
//! assert_eq!(
//!     data::resolve_package_uri_in(&root, "package://kerf/urdf/irb6660.urdf")?,
//!     root.join("urdf/irb6660.urdf"),
//! );
//! # Ok::<(), kerf_robot::RobotError>(())
//! ```

use std::{
    ffi::OsStr,
    fmt,
    path::{Component, Path, PathBuf},
};

use crate::RobotError;

/// The environment variable that names the kerf data root (first place searched).
pub const DATA_DIR_VAR: &str = "KERF_DATA_DIR";

/// The file, relative to a directory, whose presence makes it a kerf data directory.
pub const MARKER: &str = "urdf/laser_cutter.urdf";

/// The share directory below an install prefix: `PREFIX/share/kerf`.
pub const SHARE_SUBDIR: &str = "share/kerf";

/// Which place of the search found the data root.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DataSource {
    /// The directory named by [`DATA_DIR_VAR`].
    Env,
    /// The share directory beside the binary, `<exe dir>/../share/kerf`.
    Share,
    /// The source tree kerf was built from.
    SourceTree,
}

impl fmt::Display for DataSource {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            DataSource::Env => DATA_DIR_VAR,
            DataSource::Share => "share directory beside the binary",
            DataSource::SourceTree => "source tree",
        })
    }
}

/// The kerf data root found by the search, and which place of the search it is.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct DataRoot {
    /// The directory; shipped files are below it at their source-tree relative paths.
    pub path: PathBuf,
    /// Where the search found it.
    pub source: DataSource,
}

impl fmt::Display for DataRoot {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} ({})", self.path.display(), self.source)
    }
}

impl DataRoot {
    /// Runs the search on explicit inputs (what [`root`] does with the process's own).
    ///
    /// # Arguments
    /// * `env` - the value of [`DATA_DIR_VAR`], `None` when unset.
    /// * `exe` - the running binary, `None` when unknown (no share directory is searched).
    /// * `source_tree` - the source tree's root (normally [`source_tree`]).
    ///
    /// # Returns
    /// The first of `env`, [`share_dir`]`(exe)` and `source_tree` that holds [`MARKER`];
    /// when `env` is set it is the only place searched.
    ///
    /// # Errors
    /// [`RobotError::DataNotFound`], naming every place searched: `env` when set and not a
    /// kerf data directory, else the share directory and the source tree when neither is.
    pub fn search(
        env: Option<&OsStr>,
        exe: Option<&Path>,
        source_tree: &Path,
    ) -> Result<DataRoot, RobotError> {
        let not_found = |env: Option<PathBuf>, share: Option<PathBuf>, tree: Option<PathBuf>| {
            RobotError::DataNotFound {
                variable: DATA_DIR_VAR,
                marker: MARKER,
                env,
                share,
                source_tree: tree,
            }
        };
        if let Some(env) = env {
            let path = PathBuf::from(env);
            return if holds_data(&path) {
                Ok(DataRoot {
                    path,
                    source: DataSource::Env,
                })
            } else {
                Err(not_found(Some(path), None, None))
            };
        }
        let share = exe.and_then(share_dir);
        if let Some(path) = share.as_ref().filter(|p| holds_data(p)) {
            return Ok(DataRoot {
                path: path.clone(),
                source: DataSource::Share,
            });
        }
        if holds_data(source_tree) {
            return Ok(DataRoot {
                path: source_tree.to_path_buf(),
                source: DataSource::SourceTree,
            });
        }
        Err(not_found(None, share, Some(source_tree.to_path_buf())))
    }

    /// A path below the data root.
    ///
    /// # Arguments
    /// * `rel` - the path relative to the data root, as in the source tree (`urdf/irb6660.urdf`).
    ///
    /// # Returns
    /// `self.path.join(rel)`; whether the file exists is not checked.
    pub fn join(&self, rel: impl AsRef<Path>) -> PathBuf {
        self.path.join(rel)
    }
}

/// The source tree kerf was built from: the workspace root, fixed at compile time.
///
/// # Returns
/// The directory two levels above `kerf_robot`'s manifest directory (`crates/robot`).
pub fn source_tree() -> PathBuf {
    let manifest = Path::new(env!("CARGO_MANIFEST_DIR"));
    manifest
        .parent()
        .and_then(Path::parent)
        .map_or_else(|| manifest.join("../.."), Path::to_path_buf)
}

/// The share directory beside a binary: `<exe dir>/../share/kerf`.
///
/// # Arguments
/// * `exe` - the binary, e.g. `PREFIX/bin/kerf`.
///
/// # Returns
/// `PREFIX/share/kerf`; `None` when `exe` has no grandparent directory.
pub fn share_dir(exe: &Path) -> Option<PathBuf> {
    exe.parent()
        .and_then(Path::parent)
        .map(|prefix| prefix.join(SHARE_SUBDIR))
}

/// Whether a directory is a kerf data directory.
///
/// # Arguments
/// * `dir` - the candidate data root.
///
/// # Returns
/// `true` when `dir/`[`MARKER`] is a file.
pub fn holds_data(dir: &Path) -> bool {
    dir.join(MARKER).is_file()
}

/// Finds the kerf data root of this process (module documentation).
///
/// # Returns
/// [`DataRoot::search`] with [`DATA_DIR_VAR`] from the environment,
/// [`std::env::current_exe`] (not searched when unknown) and [`source_tree`].
///
/// # Errors
/// [`RobotError::DataNotFound`], naming every place searched.
pub fn root() -> Result<DataRoot, RobotError> {
    let env = std::env::var_os(DATA_DIR_VAR);
    let exe = std::env::current_exe().ok();
    DataRoot::search(env.as_deref(), exe.as_deref(), &source_tree())
}

/// A shipped file or directory, found through [`root`].
///
/// # Arguments
/// * `rel` - the path relative to the data root, as in the source tree
///   (`crates/millplan/policies/ddpg.safetensors`).
///
/// # Returns
/// The path below the data root (whether it exists is not checked).
///
/// # Errors
/// As [`root`].
pub fn path(rel: impl AsRef<Path>) -> Result<PathBuf, RobotError> {
    Ok(root()?.join(rel))
}

/// The data root for a default that cannot report an error: [`root`] when the search
/// succeeds, else the place the search failed at ([`DATA_DIR_VAR`]'s directory when set,
/// else the source tree), so that reading below it fails naming that path. Loaders report the
/// search's own error ([`root`], [`path`]) before reading such a default.
///
/// # Returns
/// The data root's path, or the place the search failed at.
pub fn default_root() -> PathBuf {
    match root() {
        Ok(root) => root.path,
        Err(_) => std::env::var_os(DATA_DIR_VAR).map_or_else(source_tree, PathBuf::from),
    }
}

/// A shipped file for a default that cannot report an error: `rel` below [`default_root`].
///
/// # Arguments
/// * `rel` - the path relative to the data root, as in the source tree.
///
/// # Returns
/// The path below the data root, or below the place the search failed at.
pub fn default_path(rel: impl AsRef<Path>) -> PathBuf {
    default_root().join(rel)
}

/// Resolves a `package://kerf/<path>` URI to `<path>` below the data root of this process.
///
/// # Arguments
/// * `uri` - the URI, e.g. `package://kerf/urdf/meshes/bpillar.obj`.
///
/// # Returns
/// The file path (whether it exists is not checked).
///
/// # Errors
/// [`RobotError::PackageUri`] as [`resolve_package_uri_in`]; [`RobotError::DataNotFound`]
/// when the URI is well formed but no data root is found.
pub fn resolve_package_uri(uri: &str) -> Result<PathBuf, RobotError> {
    let rel = package_relative_path(uri)?;
    path(rel)
}

/// Resolves a `package://kerf/<path>` URI below a given data root.
///
/// # Arguments
/// * `root` - the data root.
/// * `uri` - the URI.
///
/// # Returns
/// `root.join(<path>)`.
///
/// # Errors
/// [`RobotError::PackageUri`] when `uri` is not a `package://` URI, names another package
/// than `kerf`, has no path, or a path that is absolute or leaves the data root (`..`).
pub fn resolve_package_uri_in(root: &DataRoot, uri: &str) -> Result<PathBuf, RobotError> {
    Ok(root.join(package_relative_path(uri)?))
}

/// The path of a `package://kerf/` URI relative to the data root (see
/// [`resolve_package_uri_in`] for the errors).
fn package_relative_path(uri: &str) -> Result<&Path, RobotError> {
    let err = |reason: &str| RobotError::PackageUri {
        uri: uri.to_owned(),
        reason: reason.to_owned(),
    };
    let Some(rest) = uri.strip_prefix("package://") else {
        return Err(err("not a package:// URI"));
    };
    let (package, rel) = rest.split_once('/').unwrap_or((rest, ""));
    if package != "kerf" {
        return Err(RobotError::PackageUri {
            uri: uri.to_owned(),
            reason: format!(
                "package '{package}' is not supported: only package://kerf/<path> (the kerf \
                 repository root) is resolved"
            ),
        });
    }
    let rel = Path::new(rel);
    if rel.as_os_str().is_empty() {
        return Err(err("package://kerf/ needs a file path"));
    }
    if rel
        .components()
        .any(|c| !matches!(c, Component::Normal(_) | Component::CurDir))
    {
        return Err(err(
            "a package://kerf/ path must be relative and stay inside the repository",
        ));
    }
    Ok(rel)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A fresh directory under the system temp dir.
    fn scratch(name: &str) -> PathBuf {
        let dir =
            std::env::temp_dir().join(format!("kerf_robot_data_{name}_{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    /// Makes `dir` a kerf data directory (the marker only).
    fn mark(dir: &Path) {
        let marker = dir.join(MARKER);
        std::fs::create_dir_all(marker.parent().unwrap()).unwrap();
        std::fs::write(marker, "<robot name=\"marker\"/>").unwrap();
    }

    #[test]
    fn the_source_tree_is_the_workspace_root_and_holds_the_data() {
        let tree = source_tree();
        assert!(holds_data(&tree), "{}", tree.display());
        assert!(tree.join("crates/robot/Cargo.toml").is_file());
        assert!(Path::new(env!("CARGO_MANIFEST_DIR")).starts_with(&tree));
        let root = DataRoot::search(None, None, &tree).unwrap();
        assert_eq!(
            root,
            DataRoot {
                path: tree.clone(),
                source: DataSource::SourceTree
            }
        );
        assert_eq!(
            root.to_string(),
            format!("{} (source tree)", tree.display())
        );
    }

    #[test]
    fn the_env_var_wins_over_share_and_source_tree() {
        let base = scratch("env_wins");
        let env = base.join("env");
        mark(&env);
        let prefix = base.join("prefix");
        mark(&prefix.join(SHARE_SUBDIR));
        let exe = prefix.join("bin/kerf");
        let root = DataRoot::search(Some(env.as_os_str()), Some(&exe), &source_tree()).unwrap();
        assert_eq!(root.path, env);
        assert_eq!(root.source, DataSource::Env);
        std::fs::remove_dir_all(&base).unwrap();
    }

    #[test]
    fn a_bad_env_var_is_an_error_naming_it_never_a_fallback() {
        let base = scratch("env_bad");
        let prefix = base.join("prefix");
        mark(&prefix.join(SHARE_SUBDIR));
        let exe = prefix.join("bin/kerf");
        for bad in [base.join("absent"), base.join("prefix")] {
            let err =
                DataRoot::search(Some(bad.as_os_str()), Some(&exe), &source_tree()).unwrap_err();
            let RobotError::DataNotFound {
                env,
                share,
                source_tree,
                ..
            } = &err
            else {
                panic!("{err:?}");
            };
            assert_eq!(env.as_deref(), Some(bad.as_path()));
            assert_eq!(
                (share, source_tree),
                (&None, &None),
                "only the variable searched"
            );
            let msg = err.to_string();
            assert!(msg.contains("KERF_DATA_DIR"), "{msg}");
            assert!(msg.contains(&bad.display().to_string()), "{msg}");
            assert!(msg.contains(MARKER), "{msg}");
        }
        std::fs::remove_dir_all(&base).unwrap();
    }

    #[test]
    fn the_share_dir_beside_the_binary_comes_before_the_source_tree() {
        let base = scratch("share");
        let prefix = base.join("prefix");
        let exe = prefix.join("bin/kerf");
        assert_eq!(share_dir(&exe), Some(prefix.join("share/kerf")));
        // Not yet a data directory: the source tree is found.
        let root = DataRoot::search(None, Some(&exe), &source_tree()).unwrap();
        assert_eq!(root.source, DataSource::SourceTree);
        mark(&prefix.join(SHARE_SUBDIR));
        let root = DataRoot::search(None, Some(&exe), &source_tree()).unwrap();
        assert_eq!(root.path, prefix.join("share/kerf"));
        assert_eq!(root.source, DataSource::Share);
        std::fs::remove_dir_all(&base).unwrap();
    }

    #[test]
    fn nothing_found_names_every_place_searched() {
        let base = scratch("none");
        let exe = base.join("prefix/bin/kerf");
        let tree = base.join("tree");
        let err = DataRoot::search(None, Some(&exe), &tree).unwrap_err();
        let msg = err.to_string();
        for place in [
            "KERF_DATA_DIR (unset)".to_string(),
            base.join("prefix/share/kerf").display().to_string(),
            tree.display().to_string(),
        ] {
            assert!(msg.contains(&place), "{place} missing in: {msg}");
        }
        // Without a known binary, the share directory is not searched.
        let err = DataRoot::search(None, None, &tree).unwrap_err();
        assert!(
            matches!(err, RobotError::DataNotFound { share: None, .. }),
            "{err:?}"
        );
        std::fs::remove_dir_all(&base).unwrap();
    }

    #[test]
    fn package_uris_resolve_below_the_root() {
        let root = DataRoot {
            path: PathBuf::from("/opt/kerf/share/kerf"),
            source: DataSource::Share,
        };
        assert_eq!(
            resolve_package_uri_in(&root, "package://kerf/urdf/meshes/bpillar.obj").unwrap(),
            Path::new("/opt/kerf/share/kerf/urdf/meshes/bpillar.obj")
        );
        for bad in [
            "package://kerf_msgs/x.stl",
            "package://kerf/",
            "package://kerf",
            "package://kerf/../etc/passwd",
            "package://kerf//etc/passwd",
            "file:///tmp/x.stl",
        ] {
            assert!(
                matches!(
                    resolve_package_uri_in(&root, bad),
                    Err(RobotError::PackageUri { .. })
                ),
                "{bad}"
            );
        }
    }
}
