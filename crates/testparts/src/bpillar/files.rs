//! The committed files: the default part and both requests, generated and
//! written under a repository root.

use std::path::{Path, PathBuf};

use kerf_mjto::mesh;
use kerf_mjto::CutRequest;

use super::corner_case::{corner_case, CornerCaseParams};
use super::params::BPillarParams;
use super::part::BPillar;
use super::request::request_yaml;
use super::trim_case::{trim_case, TrimCaseParams};
use super::{CASE1_FILE, CASE2_FILE, MESH_FILE};
use crate::TestPartError;

/// Everything [`generate`] builds.
#[derive(Debug, Clone)]
pub struct Generated {
    /// The workpiece (default parameters).
    pub pillar: BPillar,
    /// Case 1 (default [`TrimCaseParams`]).
    pub case1: CutRequest,
    /// Case 2 (default [`CornerCaseParams`]).
    pub case2: CutRequest,
}

/// Builds the default workpiece and both requests.
///
/// # Errors
/// Only if the defaults were inconsistent ([`TestPartError::Invalid`]).
pub fn generate() -> Result<Generated, TestPartError> {
    let pillar = BPillar::new(BPillarParams::default())?;
    let case1 = trim_case(&pillar, &TrimCaseParams::default())?;
    let case2 = corner_case(&pillar, &CornerCaseParams::default())?;
    Ok(Generated {
        pillar,
        case1,
        case2,
    })
}

/// Title lines of the two request files.
const CASE1_TITLE: &str = "kerf MJTO cut request, case 1 of seed 001 (section 3.1, Table 1): \
                           0.8 m side trim along the left flange, tool axis near vertical, six RTOs.";
const CASE2_TITLE: &str = "kerf MJTO cut request, case 2 of seed 001 (section 3.2, Table 1): \
                           cut across the foot (flange, fillet, wall, fillet, top), two 77 deg \
                           turns, ten RTOs.";

/// Generates and writes `urdf/meshes/bpillar.obj` and
/// `crates/mjto/cases/case{1,2}.yaml` under `root` (creating the
/// directories).
///
/// # Returns
/// What was written, and the three file paths (mesh, case 1, case 2).
///
/// # Errors
/// Any I/O error; a generation error as `ErrorKind::InvalidData`.
pub fn write_files(root: &Path) -> std::io::Result<(Generated, [PathBuf; 3])> {
    let invalid =
        |e: TestPartError| std::io::Error::new(std::io::ErrorKind::InvalidData, e.to_string());
    let g = generate().map_err(invalid)?;
    let paths = [
        root.join(MESH_FILE),
        root.join(CASE1_FILE),
        root.join(CASE2_FILE),
    ];
    for p in &paths {
        if let Some(dir) = p.parent() {
            std::fs::create_dir_all(dir)?;
        }
    }
    let [mesh_path, case1_path, case2_path] = &paths;
    mesh::write_obj(mesh_path, g.pillar.mesh())?;
    std::fs::write(
        case1_path,
        request_yaml(&g.case1, CASE1_TITLE).map_err(invalid)?,
    )?;
    std::fs::write(
        case2_path,
        request_yaml(&g.case2, CASE2_TITLE).map_err(invalid)?,
    )?;
    Ok((g, paths))
}
