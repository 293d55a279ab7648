//! A cache of loaded meshes, reloaded when their file changes.

use std::collections::HashMap;
use std::path::PathBuf;
use std::sync::Arc;
use std::time::SystemTime;

use super::{load_path, resolve, MeshData};
use crate::PlanError;

/// Identity of a file version: length and modification time.
type FileStamp = (u64, Option<SystemTime>);

/// A cache of loaded meshes, so a planner node loads each mesh once.
///
/// Keyed by the resolved (canonical when possible) path; an entry is
/// reused while the file's length and modification time are unchanged,
/// and reloaded otherwise.
#[derive(Debug, Default)]
pub struct MeshCache {
    entries: HashMap<PathBuf, (FileStamp, Arc<MeshData>)>,
    loads: usize,
}

impl MeshCache {
    /// An empty cache.
    pub fn new() -> Self {
        Self::default()
    }

    /// The mesh of `reference`, loaded on first use or when the file
    /// changed.
    ///
    /// # Errors
    /// As [`load`](super::load); a file whose metadata cannot be read is a
    /// [`PlanError::Mesh`] ("cannot read").
    ///
    /// # Performance
    /// A cache hit costs one `stat` of the file and an `Arc` clone.
    pub fn get(&mut self, reference: &str) -> Result<Arc<MeshData>, PlanError> {
        let path = resolve(reference)?;
        let key = std::fs::canonicalize(&path).unwrap_or_else(|_| path.clone());
        let meta = std::fs::metadata(&key).map_err(|e| PlanError::Mesh {
            source_name: reference.to_owned(),
            reason: format!("cannot read {}: {e}", path.display()),
        })?;
        let stamp = (meta.len(), meta.modified().ok());
        if let Some((s, mesh)) = self.entries.get(&key) {
            if *s == stamp {
                return Ok(Arc::clone(mesh));
            }
        }
        let mesh = Arc::new(load_path(&key, reference)?);
        self.loads += 1;
        self.entries.insert(key, (stamp, Arc::clone(&mesh)));
        Ok(mesh)
    }

    /// Number of meshes held.
    pub fn len(&self) -> usize {
        self.entries.len()
    }

    /// True when no mesh is held.
    pub fn is_empty(&self) -> bool {
        self.entries.is_empty()
    }

    /// Number of file loads so far (misses, including reloads of changed
    /// files).
    pub fn loads(&self) -> usize {
        self.loads
    }
}
