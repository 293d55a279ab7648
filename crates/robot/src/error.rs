//! The single error type of `kerf_robot`.

use std::path::{Path, PathBuf};

/// Everything that can go wrong while loading a robot description or
/// evaluating its kinematics.
///
/// Every variant names the offending joint, link, field or value so that the
/// message alone says exactly what to fix.
#[derive(Debug, thiserror::Error)]
pub enum RobotError {
    /// A file could not be read.
    #[error("cannot read {}: {source}", path.display())]
    FileRead {
        /// The file that was being read.
        path: PathBuf,
        /// The underlying I/O error.
        source: std::io::Error,
    },

    /// The URDF text is not valid URDF XML.
    #[error("invalid URDF: {source}")]
    UrdfParse {
        /// The parser error from `urdf-rs`.
        source: urdf_rs::UrdfError,
    },

    /// The joint-limits text is not valid MoveIt `joint_limits.yaml`.
    #[error("invalid joint limits YAML: {source}")]
    LimitsParse {
        /// The parser error from `serde_yaml_ng`.
        source: serde_yaml_ng::Error,
    },

    /// A joint has no acceleration limit, which the executor's model needs.
    #[error(
        "joint '{joint}' has no acceleration limit (max_acceleration in the joint limits \
         YAML); the trajectory executor needs one to check trajectories"
    )]
    NoAccelerationLimit {
        /// The joint.
        joint: String,
    },

    /// Two links share a name.
    #[error("URDF defines link `{name}` more than once")]
    DuplicateLink {
        /// The repeated link name.
        name: String,
    },

    /// Two joints share a name.
    #[error("URDF defines joint `{name}` more than once")]
    DuplicateJoint {
        /// The repeated joint name.
        name: String,
    },

    /// A joint refers to a link that the URDF does not define.
    #[error("joint `{joint}` refers to link `{link}`, which the URDF does not define")]
    UnknownLink {
        /// The joint with the dangling reference.
        joint: String,
        /// The missing link name.
        link: String,
    },

    /// A link is the child of more than one joint.
    #[error("link `{link}` is the child of both joint `{first_joint}` and joint `{second_joint}`; a URDF must be a tree")]
    MultipleParents {
        /// The link with two parents.
        link: String,
        /// The first joint naming it as child.
        first_joint: String,
        /// The second joint naming it as child.
        second_joint: String,
    },

    /// The URDF does not have exactly one root link.
    #[error(
        "a URDF must have exactly one root link (a link that is no joint's child), found {roots:?}"
    )]
    RootNotUnique {
        /// All links without a parent joint (empty if every link has one).
        roots: Vec<String>,
    },

    /// A link cannot be reached from the root (it sits on a cycle of joints).
    #[error("link `{link}` is not reachable from root link `{root}` (the joints form a cycle)")]
    Unreachable {
        /// The unreachable link.
        link: String,
        /// The root link.
        root: String,
    },

    /// The requested tip link does not exist.
    #[error("tip link `{tip}` is not a link of the URDF")]
    UnknownTip {
        /// The requested tip link.
        tip: String,
    },

    /// No tip link was given, there is no `tool0` and the tree has several leaves.
    #[error("cannot choose a tip link: no `tool0` link and the tree has several leaf links {leaves:?}; name the tip explicitly")]
    AmbiguousTip {
        /// All leaf links of the tree.
        leaves: Vec<String>,
    },

    /// The joint type is not supported by the kinematic model.
    #[error("joint `{joint}` has type `{kind}`; only revolute, prismatic and fixed joints are supported")]
    UnsupportedJointType {
        /// The joint.
        joint: String,
        /// Its URDF type, e.g. `continuous`.
        kind: String,
    },

    /// The joint mimics another joint, which is not supported.
    #[error("joint `{joint}` mimics joint `{leader}`; mimic joints are not supported")]
    MimicJoint {
        /// The mimicking joint.
        joint: String,
        /// The joint it mimics.
        leader: String,
    },

    /// A movable joint does not lie on the root-to-tip chain.
    #[error("movable joint `{joint}` is not on the chain from root `{root}` to tip `{tip}`; only fixed joints may branch off the chain")]
    MovableJointOffChain {
        /// The off-chain joint.
        joint: String,
        /// The root link.
        root: String,
        /// The tip link.
        tip: String,
    },

    /// A joint axis is zero or not finite.
    #[error("joint `{joint}` has axis {axis:?}; it must be finite and non-zero")]
    InvalidAxis {
        /// The joint.
        joint: String,
        /// The axis as written in the URDF.
        axis: [f64; 3],
    },

    /// A joint origin contains a non-finite number.
    #[error("joint `{joint}` has origin xyz {xyz:?} rpy {rpy:?}; all values must be finite")]
    InvalidOrigin {
        /// The joint.
        joint: String,
        /// Origin translation (m).
        xyz: [f64; 3],
        /// Origin roll, pitch, yaw (rad).
        rpy: [f64; 3],
    },

    /// A limit value is not finite, or not strictly positive where it must be.
    #[error("{field} of joint `{joint}` is {value}; it must be {requirement}")]
    InvalidLimit {
        /// The joint.
        joint: String,
        /// The limit field, e.g. `max_velocity`.
        field: &'static str,
        /// The offending value.
        value: f64,
        /// What the value must satisfy, e.g. `finite and > 0`.
        requirement: &'static str,
    },

    /// The position range of a joint is empty.
    #[error("joint `{joint}` has lower position limit {min} >= upper position limit {max}")]
    EmptyRange {
        /// The joint.
        joint: String,
        /// Lower limit (m or rad).
        min: f64,
        /// Upper limit (m or rad).
        max: f64,
    },

    /// The YAML limit would widen the URDF limit.
    #[error("joint limits YAML sets {field} of joint `{joint}` to {yaml}, wider than the URDF limit {urdf}; the YAML may only tighten URDF limits")]
    LimitWidened {
        /// The joint.
        joint: String,
        /// The limit field, e.g. `max_position`.
        field: &'static str,
        /// The URDF value.
        urdf: f64,
        /// The YAML value.
        yaml: f64,
    },

    /// The YAML switches off a limit that the URDF defines.
    #[error("joint limits YAML sets {field}: false for joint `{joint}`, which would drop the URDF limit; the YAML may only tighten URDF limits")]
    LimitRemoved {
        /// The joint.
        joint: String,
        /// The `has_*_limits` flag, e.g. `has_velocity_limits`.
        field: &'static str,
    },

    /// The YAML enables a limit but gives no value for it.
    #[error("joint limits YAML sets {flag}: true for joint `{joint}` but gives no {field}")]
    MissingLimitValue {
        /// The joint.
        joint: String,
        /// The `has_*_limits` flag.
        flag: &'static str,
        /// The missing value field.
        field: &'static str,
    },

    /// The YAML names a joint that the URDF does not define.
    #[error("joint limits YAML names joint `{name}`, which the URDF does not define")]
    UnknownJoint {
        /// The unknown joint name.
        name: String,
    },

    /// The YAML gives limits for a fixed joint.
    #[error("joint limits YAML gives limits for joint `{joint}`, which is fixed")]
    LimitsForFixedJoint {
        /// The fixed joint.
        joint: String,
    },

    /// A joint vector has the wrong number of entries.
    #[error("expected {expected} joint values (one per movable joint), got {got}")]
    WrongLength {
        /// The number of movable joints.
        expected: usize,
        /// The number of values given.
        got: usize,
    },

    /// A joint value is NaN or infinite.
    #[error("value {value} for joint `{joint}` is not finite")]
    NonFinite {
        /// The joint.
        joint: String,
        /// The offending value.
        value: f64,
    },

    /// No kerf data directory was found (the search of `kerf_robot::data`).
    #[error("{}", describe_data_search(variable, marker, env.as_deref(), share.as_deref(), source_tree.as_deref()))]
    DataNotFound {
        /// The environment variable searched first, `KERF_DATA_DIR`.
        variable: &'static str,
        /// The file, relative to a directory, that makes it a kerf data directory.
        marker: &'static str,
        /// The variable's directory when it is set (then it is the only place searched).
        env: Option<PathBuf>,
        /// The share directory beside the binary, when searched.
        share: Option<PathBuf>,
        /// The source tree, when searched.
        source_tree: Option<PathBuf>,
    },

    /// A `package://` URI that does not name a path below the kerf data directory.
    #[error("{uri}: {reason}")]
    PackageUri {
        /// The URI as given.
        uri: String,
        /// What is wrong with it.
        reason: String,
    },

    /// A file reference of a request that names no local file: empty, holding a NUL byte,
    /// a URI of another scheme or host, or a malformed `file://` URI
    /// ([`crate::file::resolve_uri`]).
    #[error("file reference {uri:?}: {reason}")]
    FileUri {
        /// The reference as given.
        uri: String,
        /// What is wrong with it.
        reason: String,
    },

    /// A joint value is outside the joint's position limits.
    #[error("position {value} of joint `{joint}` is outside its limits [{min}, {max}]")]
    OutOfRange {
        /// The joint.
        joint: String,
        /// The offending position (m or rad).
        value: f64,
        /// Lower limit (m or rad).
        min: f64,
        /// Upper limit (m or rad).
        max: f64,
    },
}

/// The message of [`RobotError::DataNotFound`]: every place searched and how to fix it.
fn describe_data_search(
    variable: &str,
    marker: &str,
    env: Option<&Path>,
    share: Option<&Path>,
    source_tree: Option<&Path>,
) -> String {
    if let Some(env) = env {
        return format!(
            "{variable} is set to {}, which is not a kerf data directory (it has no {marker}); \
             only {variable} was searched: point it at a kerf data directory (PREFIX/share/kerf \
             as installed by launch_scripts/install.sh, or the source tree) or unset it to \
             search the share directory beside the binary and the source tree",
            env.display()
        );
    }
    let mut places = vec![format!("{variable} (unset)")];
    if let Some(share) = share {
        places.push(format!(
            "{} (share directory beside the binary)",
            share.display()
        ));
    }
    if let Some(tree) = source_tree {
        places.push(format!("{} (source tree)", tree.display()));
    }
    format!(
        "no kerf data directory (a directory holding {marker}) found; searched {}: set \
         {variable} to one, or install the data with launch_scripts/install.sh PREFIX \
         --data-only beside PREFIX/bin/kerf",
        places.join(", ")
    )
}
