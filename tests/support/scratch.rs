//! Scratch directories of a test.

use std::path::PathBuf;

/// An empty directory `kerf_<test>_<pid>_<name>` under the system's temporary directory
/// (emptied if it is left over); the test removes it when it passes.
pub fn scratch(test: &str, name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("kerf_{test}_{}_{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("scratch directory");
    dir
}
