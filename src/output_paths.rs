//! Output paths of `kerf plan mill` and `kerf train`, checked before any long computation.

use std::path::Path;

/// Checks that `path` can be written as a file: creates its parent directories, refuses a
/// directory, and opens it for appending (a file created by the check is removed again, an
/// existing one is left untouched).
///
/// # Errors
/// A message naming the option and the path.
pub fn check_writable(option: &str, path: &Path) -> Result<(), String> {
    let fail =
        |e: &dyn std::fmt::Display| format!("{option} {}: cannot write: {e}", path.display());
    if path.as_os_str().is_empty() {
        return Err(format!("{option}: empty path"));
    }
    if path.is_dir() {
        return Err(fail(&"is a directory"));
    }
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).map_err(|e| fail(&e))?;
    }
    let existed = path.exists();
    std::fs::OpenOptions::new()
        .append(true)
        .create(true)
        .open(path)
        .map_err(|e| fail(&e))?;
    if !existed {
        let _ = std::fs::remove_file(path);
    }
    Ok(())
}

/// Creates the directory `dir` (and parents) and checks that a file can be written in it.
///
/// # Errors
/// A message naming the option and the directory.
pub fn check_dir_writable(option: &str, dir: &Path) -> Result<(), String> {
    std::fs::create_dir_all(dir).map_err(|e| {
        format!(
            "{option} {}: cannot create the directory: {e}",
            dir.display()
        )
    })?;
    let probe = dir.join(format!(".kerf_write_check_{}", std::process::id()));
    std::fs::write(&probe, b"")
        .map_err(|e| format!("{option} {}: cannot write in it: {e}", dir.display()))?;
    let _ = std::fs::remove_file(&probe);
    Ok(())
}
