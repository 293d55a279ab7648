//! The indicator cache's file (module documentation of [`crate::cache`],
//! "File format"): [`IndicatorCache::save`], [`IndicatorCache::load`],
//! [`IndicatorCache::from_bytes`].

use std::path::Path;

use kerf_mill::MillCell;

use crate::cache::{CacheHeader, IndicatorCache, CACHE_MAGIC};
use crate::error::MillPlanError;
use crate::fingerprint::{cell_fingerprint, fnv1a};

impl IndicatorCache {
    /// Writes the cache file (module documentation).
    ///
    /// # Errors
    /// [`MillPlanError::Io`].
    pub fn save(&self, path: &Path) -> Result<(), MillPlanError> {
        let bytes: Vec<u8> = self.values.iter().flat_map(|v| v.to_le_bytes()).collect();
        let mut header = self.header.clone();
        header.data_checksum = format!("{:016x}", fnv1a(&bytes));
        let json = serde_json::to_string(&header).map_err(|e| MillPlanError::Io {
            path: path.display().to_string(),
            message: e.to_string(),
        })?;
        let mut out = Vec::with_capacity(bytes.len() + json.len() + 64);
        out.extend_from_slice(CACHE_MAGIC.as_bytes());
        out.push(b'\n');
        out.extend_from_slice(json.as_bytes());
        out.push(b'\n');
        out.extend_from_slice(&bytes);
        std::fs::write(path, out).map_err(|e| MillPlanError::Io {
            path: path.display().to_string(),
            message: e.to_string(),
        })
    }

    /// Reads a cache file and checks it against `cell`.
    ///
    /// # Errors
    /// [`MillPlanError::Io`] (unreadable file); [`MillPlanError::InvalidConfig`]
    /// for a wrong magic line, bad header, truncated/extra data, a checksum
    /// mismatch (corrupt file), or a fingerprint that differs from
    /// [`cell_fingerprint`]`(cell)` (stale cache: rebuild it with
    /// `cargo run --release -p kerf_millplan --example build_cache`).
    pub fn load(path: &Path, cell: &MillCell) -> Result<Self, MillPlanError> {
        let bytes = std::fs::read(path).map_err(|e| MillPlanError::Io {
            path: path.display().to_string(),
            message: e.to_string(),
        })?;
        let cache = Self::from_bytes(&bytes, &path.display().to_string())?;
        let expected = cell_fingerprint(cell);
        if cache.header.cell_fingerprint != expected {
            return Err(MillPlanError::InvalidConfig {
                name: format!("indicator cache {}", path.display()),
                reason: format!(
                    "stale: built for cell fingerprint {} but the cell's is {expected} (the cell \
                     file changed); rebuild with `cargo run --release -p kerf_millplan --example \
                     build_cache`",
                    cache.header.cell_fingerprint
                ),
            });
        }
        Ok(cache)
    }

    /// Parses the bytes of a cache file (no fingerprint check).
    ///
    /// # Errors
    /// As [`IndicatorCache::load`], except the fingerprint.
    pub fn from_bytes(bytes: &[u8], name: &str) -> Result<Self, MillPlanError> {
        let corrupt = |reason: String| MillPlanError::InvalidConfig {
            name: format!("indicator cache {name}"),
            reason,
        };
        let magic_end = bytes
            .iter()
            .position(|b| *b == b'\n')
            .ok_or_else(|| corrupt("no header line".to_string()))?;
        if bytes.get(..magic_end) != Some(CACHE_MAGIC.as_bytes()) {
            return Err(corrupt(format!(
                "not a cache file (first line must be `{CACHE_MAGIC}`)"
            )));
        }
        let rest = bytes.get(magic_end + 1..).unwrap_or(&[]);
        let json_end = rest
            .iter()
            .position(|b| *b == b'\n')
            .ok_or_else(|| corrupt("no JSON header line".to_string()))?;
        let json = std::str::from_utf8(rest.get(..json_end).unwrap_or(&[]))
            .map_err(|e| corrupt(format!("header is not UTF-8: {e}")))?;
        let header: CacheHeader =
            serde_json::from_str(json).map_err(|e| corrupt(format!("bad header: {e}")))?;
        header.grid.validate()?;
        let data = rest.get(json_end + 1..).unwrap_or(&[]);
        let expected = header.grid.node_count() * 8;
        if data.len() != expected {
            return Err(corrupt(format!(
                "{} data bytes, expected {expected} for the grid (truncated or extra data)",
                data.len()
            )));
        }
        let checksum = format!("{:016x}", fnv1a(data));
        if checksum != header.data_checksum {
            return Err(corrupt(format!(
                "data checksum {checksum} differs from the header's {} (corrupt file)",
                header.data_checksum
            )));
        }
        let values = data
            .chunks_exact(8)
            .map(|c| {
                let mut b = [0u8; 8];
                b.copy_from_slice(c);
                f64::from_le_bytes(b)
            })
            .collect();
        Ok(Self { header, values })
    }
}
