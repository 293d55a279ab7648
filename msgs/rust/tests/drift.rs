//! Drift test: every Rust mirror must match its ROS 2 interface file in field
//! names, order and types (array-ness, fixed sizes, nested type names), in
//! constants (names, types, values) and in default values.
//!
//! The Rust side is traced with serde-reflection, so the test sees the serde
//! shape that ros2-client's CDR serializer puts on the wire, not the source.
//! The interface files are read with `kerf_msgs::idl`; when Debian's
//! `python3-rosidl` is installed, `rosidl_dump.py` parses them again with the
//! real ROS 2 parser and both views must agree.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

use std::collections::{BTreeMap, BTreeSet, HashMap};
use std::path::{Path, PathBuf};
use std::process::Command;

use kerf_msgs::idl::{self, Array, BaseType, FieldType, MessageSpec, Primitive, Value};
use kerf_msgs::{
    action, builtin_interfaces, control_msgs, geometry_msgs, msg, rosgraph_msgs, sensor_msgs, srv,
    std_msgs, trajectory_msgs, InterfaceKind, RosType,
};
use serde::{de::DeserializeOwned, Deserialize, Serialize};
use serde_json::json;
use serde_reflection::{ContainerFormat, Format, Registry, Samples, Tracer, TracerConfig};

// ---------------------------------------------------------------------------
// Interface files

/// The kerf_msgs colcon package directory (`msgs/`).
fn msgs_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// One interface file: path relative to `msgs/`, kind, package, parsed spec.
struct InterfaceFile {
    file: String,
    kind: InterfaceKind,
    package: String,
    spec: idl::InterfaceSpec,
}

const KINDS: [InterfaceKind; 3] = [
    InterfaceKind::Msg,
    InterfaceKind::Srv,
    InterfaceKind::Action,
];

fn sorted_files(dir: &Path, kind: InterfaceKind) -> Vec<PathBuf> {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return Vec::new();
    };
    let mut files: Vec<PathBuf> = entries
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == kind.as_str()))
        .collect();
    files.sort();
    files
}

/// Every interface file, in the order `rosidl_dump.py` lists them.
fn interface_files() -> Vec<InterfaceFile> {
    let root = msgs_dir();
    let mut found: Vec<(InterfaceKind, String, PathBuf)> = Vec::new();
    for kind in KINDS {
        for p in sorted_files(&root.join(kind.as_str()), kind) {
            found.push((kind, "kerf_msgs".to_owned(), p));
        }
    }
    let reference = root.join("rust").join("interfaces");
    let mut packages: Vec<String> = std::fs::read_dir(&reference)
        .expect("msgs/rust/interfaces exists")
        .filter_map(|e| e.ok().map(|e| e.file_name().to_string_lossy().into_owned()))
        .collect();
    packages.sort();
    for package in packages {
        for kind in KINDS {
            for p in sorted_files(&reference.join(&package).join(kind.as_str()), kind) {
                found.push((kind, package.clone(), p));
            }
        }
    }
    found
        .into_iter()
        .map(|(kind, package, path)| {
            let file = path
                .strip_prefix(&root)
                .expect("under msgs/")
                .to_string_lossy()
                .replace('\\', "/");
            let text = std::fs::read_to_string(&path).expect("readable interface file");
            let name = path
                .file_stem()
                .expect("file stem")
                .to_string_lossy()
                .into_owned();
            let spec = idl::parse_interface(kind, &package, &name, &text, &file)
                .unwrap_or_else(|e| panic!("{e}"));
            InterfaceFile {
                file,
                kind,
                package,
                spec,
            }
        })
        .collect()
}

/// Every message spec (parts of services and actions included) by ROS type
/// name `package/kind/Name`.
fn specs_by_ros_type(files: &[InterfaceFile]) -> BTreeMap<String, MessageSpec> {
    let mut map = BTreeMap::new();
    for f in files {
        for part in &f.spec.parts {
            let key = format!("{}/{}/{}", f.package, f.kind.as_str(), part.name);
            assert!(
                map.insert(key.clone(), part.clone()).is_none(),
                "{key} twice"
            );
        }
    }
    map
}

// ---------------------------------------------------------------------------
// Mirrors

/// A Rust mirror, type-erased: its ROS type, its serde trace and its default.
struct Mirror {
    ros_type: &'static str,
    trace: fn() -> Result<(String, Registry), String>,
    default_json: fn() -> serde_json::Value,
}

/// Traces `T` with serde-reflection, both ways (serialize a default value,
/// then deserialize), and returns its serde container name and the registry.
fn trace<T>() -> Result<(String, Registry), String>
where
    T: Serialize + DeserializeOwned + Default,
{
    let mut tracer = Tracer::new(TracerConfig::default());
    let mut samples = Samples::new();
    tracer
        .trace_value(&mut samples, &T::default())
        .map_err(|e| format!("serialize trace: {e}"))?;
    let (format, _) = tracer
        .trace_simple_type::<T>()
        .map_err(|e| format!("deserialize trace: {e}"))?;
    let Format::TypeName(name) = format else {
        return Err(format!("not a named struct: {format:?}"));
    };
    let registry = tracer.registry().map_err(|e| format!("registry: {e}"))?;
    Ok((name, registry))
}

fn default_json<T: Serialize + Default>() -> serde_json::Value {
    serde_json::to_value(T::default()).expect("mirrors serialize to JSON")
}

macro_rules! mirrors {
    ($($ty:ty),* $(,)?) => {
        vec![$(Mirror {
            ros_type: <$ty as RosType>::ROS_TYPE,
            trace: trace::<$ty>,
            default_json: default_json::<$ty>,
        }),*]
    };
}

/// Every mirror in the crate.
fn all_mirrors() -> Vec<Mirror> {
    mirrors![
        builtin_interfaces::Time,
        builtin_interfaces::Duration,
        std_msgs::Header,
        std_msgs::StringMsg,
        std_msgs::MultiArrayDimension,
        std_msgs::MultiArrayLayout,
        std_msgs::Float64MultiArray,
        geometry_msgs::Point,
        geometry_msgs::Vector3,
        geometry_msgs::Quaternion,
        geometry_msgs::Pose,
        geometry_msgs::Transform,
        geometry_msgs::Twist,
        trajectory_msgs::JointTrajectory,
        trajectory_msgs::JointTrajectoryPoint,
        trajectory_msgs::MultiDOFJointTrajectory,
        trajectory_msgs::MultiDOFJointTrajectoryPoint,
        sensor_msgs::JointState,
        control_msgs::JointTolerance,
        control_msgs::JointComponentTolerance,
        control_msgs::JointTrajectoryControllerState,
        control_msgs::FollowJointTrajectoryGoal,
        control_msgs::FollowJointTrajectoryResult,
        control_msgs::FollowJointTrajectoryFeedback,
        msg::TrajectoryStatus,
        msg::ReferencePoint,
        msg::StreamStatus,
        msg::CellContact,
        msg::CellContacts,
        msg::CutFeedLimit,
        rosgraph_msgs::Clock,
        msg::CutRequest,
        msg::PlanStretches,
        msg::CutPlan,
        msg::CutRto,
        msg::CutMetrics,
        msg::CutCollision,
        msg::MillRequest,
        msg::MillSegment,
        msg::MillCandidate,
        msg::MillPlan,
        msg::GcodeRequest,
        msg::GcodeToolEvent,
        msg::GcodePlan,
        srv::ValidateTrajectoryRequest,
        srv::ValidateTrajectoryResponse,
        action::PlanCutGoal,
        action::PlanCutResult,
        action::PlanCutFeedback,
        action::PlanMillGoal,
        action::PlanMillResult,
        action::PlanMillFeedback,
        action::PlanGcodeGoal,
        action::PlanGcodeResult,
        action::PlanGcodeFeedback,
    ]
}

/// Serde container name → ROS type, over all mirrors.
fn serde_names(mirrors: &[Mirror]) -> HashMap<String, String> {
    let mut names = HashMap::new();
    for m in mirrors {
        let (name, _) = (m.trace)().unwrap_or_else(|e| panic!("{}: {e}", m.ros_type));
        if let Some(previous) = names.insert(name.clone(), m.ros_type.to_owned()) {
            panic!("serde name {name} is used by {previous} and {}", m.ros_type);
        }
    }
    names
}

// ---------------------------------------------------------------------------
// Comparator

/// The serde format a field of `field_type` must have, described in terms of
/// the ROS type of nested messages; an error for types with no serde mirror.
fn expected_format(field_type: &FieldType) -> Result<Format, String> {
    let base = match &field_type.base {
        BaseType::Primitive(p) => match p {
            Primitive::Bool => Format::Bool,
            Primitive::Byte | Primitive::Char | Primitive::Uint8 => Format::U8,
            Primitive::Int8 => Format::I8,
            Primitive::Int16 => Format::I16,
            Primitive::Uint16 => Format::U16,
            Primitive::Int32 => Format::I32,
            Primitive::Uint32 => Format::U32,
            Primitive::Int64 => Format::I64,
            Primitive::Uint64 => Format::U64,
            Primitive::Float32 => Format::F32,
            Primitive::Float64 => Format::F64,
        },
        BaseType::String { wide: false, .. } => Format::Str,
        BaseType::String { wide: true, .. } => {
            return Err("wstring has no serde mirror (CDR encodes it as UTF-16)".into())
        }
        // Compared by ROS type: the serde name is mapped before comparison.
        BaseType::Message { package, name } => Format::TypeName(format!("{package}/msg/{name}")),
    };
    Ok(match field_type.array {
        Array::No => base,
        Array::Unbounded | Array::Bounded(_) => Format::Seq(Box::new(base)),
        Array::Fixed(size) => Format::TupleArray {
            content: Box::new(base),
            size,
        },
    })
}

/// Replaces serde container names by ROS type names (unknown names become
/// `<unmirrored serde type NAME>`) and writes tuples of equal elements as
/// fixed arrays.
fn to_ros_names(format: &Format, names: &HashMap<String, String>) -> Format {
    match format {
        Format::TypeName(n) => Format::TypeName(
            names
                .get(n)
                .cloned()
                .unwrap_or_else(|| format!("<unmirrored serde type {n}>")),
        ),
        Format::Seq(inner) => Format::Seq(Box::new(to_ros_names(inner, names))),
        Format::Option(inner) => Format::Option(Box::new(to_ros_names(inner, names))),
        Format::TupleArray { content, size } => Format::TupleArray {
            content: Box::new(to_ros_names(content, names)),
            size: *size,
        },
        // serde-reflection reports `[T; 1]` as a one-element tuple; a tuple of
        // equal elements is the same CDR as a fixed array.
        Format::Tuple(items) if !items.is_empty() && items.iter().all(|f| *f == items[0]) => {
            Format::TupleArray {
                content: Box::new(to_ros_names(&items[0], names)),
                size: items.len(),
            }
        }
        Format::Tuple(items) => {
            Format::Tuple(items.iter().map(|f| to_ros_names(f, names)).collect())
        }
        other => other.clone(),
    }
}

/// Compares the traced struct `root` with `spec`; returns one line per
/// difference, each naming the field.
fn compare_struct(
    ros_type: &str,
    spec: &MessageSpec,
    root: &str,
    registry: &Registry,
    names: &HashMap<String, String>,
) -> Vec<String> {
    let Some(ContainerFormat::Struct(fields)) = registry.get(root) else {
        return vec![format!(
            "{ros_type}: serde type {root} is not a struct with named fields"
        )];
    };
    let mut problems = Vec::new();
    for i in 0..spec.fields.len().max(fields.len()) {
        match (spec.fields.get(i), fields.get(i)) {
            (Some(want), Some(got)) => {
                if want.name != got.name {
                    problems.push(format!(
                        "{ros_type}: field #{i} is `{}` in the interface file but `{}` in Rust",
                        want.name, got.name
                    ));
                    continue;
                }
                let got_format = to_ros_names(&got.value, names);
                match expected_format(&want.field_type) {
                    Ok(want_format) if want_format == got_format => {}
                    Ok(want_format) => problems.push(format!(
                        "{ros_type}: field `{}` must be {want_format:?}, Rust has {got_format:?}",
                        want.name
                    )),
                    Err(why) => problems.push(format!("{ros_type}: field `{}`: {why}", want.name)),
                }
            }
            (Some(want), None) => problems.push(format!(
                "{ros_type}: field #{i} `{}` is missing in Rust",
                want.name
            )),
            (None, Some(got)) => problems.push(format!(
                "{ros_type}: Rust has extra field #{i} `{}` not in the interface file",
                got.name
            )),
            (None, None) => {}
        }
    }
    problems
}

/// The value `Default` must give a field: the file's default, else zero,
/// empty, or the nested message's own default.
fn expected_default(
    field_type: &FieldType,
    default: Option<&Value>,
    specs: &BTreeMap<String, MessageSpec>,
) -> serde_json::Value {
    fn scalar(v: &Value) -> serde_json::Value {
        match v {
            Value::Bool(b) => json!(b),
            Value::Int(i) => i64::try_from(*i)
                .map(|i| json!(i))
                .unwrap_or_else(|_| json!(u64::try_from(*i).unwrap_or(u64::MAX))),
            Value::Float(f) => json!(f),
            Value::String(s) => json!(s),
            Value::Array(items) => serde_json::Value::Array(items.iter().map(scalar).collect()),
        }
    }
    if let Some(v) = default {
        return scalar(v);
    }
    let zero = match &field_type.base {
        BaseType::Primitive(Primitive::Bool) => json!(false),
        BaseType::Primitive(Primitive::Float32 | Primitive::Float64) => json!(0.0),
        BaseType::Primitive(_) => json!(0),
        BaseType::String { .. } => json!(""),
        BaseType::Message { package, name } => {
            let key = format!("{package}/msg/{name}");
            let spec = specs
                .get(&key)
                .unwrap_or_else(|| panic!("no interface file for {key}"));
            message_default(spec, specs)
        }
    };
    match field_type.array {
        Array::No => zero,
        Array::Unbounded | Array::Bounded(_) => json!([]),
        Array::Fixed(n) => serde_json::Value::Array(vec![zero; n]),
    }
}

fn message_default(spec: &MessageSpec, specs: &BTreeMap<String, MessageSpec>) -> serde_json::Value {
    serde_json::Value::Object(
        spec.fields
            .iter()
            .map(|f| {
                (
                    f.name.clone(),
                    expected_default(&f.field_type, f.default.as_ref(), specs),
                )
            })
            .collect(),
    )
}

// ---------------------------------------------------------------------------
// Constants: every IDL constant as the Rust mirror defines it. The helper
// functions take the Rust constant by value, so a Rust constant of the wrong
// type does not compile.

fn c_u8(name: &'static str, v: u8) -> (&'static str, &'static str, Value) {
    (name, "uint8", Value::Int(v.into()))
}
fn c_u16(name: &'static str, v: u16) -> (&'static str, &'static str, Value) {
    (name, "uint16", Value::Int(v.into()))
}
fn c_i32(name: &'static str, v: i32) -> (&'static str, &'static str, Value) {
    (name, "int32", Value::Int(v.into()))
}
fn c_str(name: &'static str, v: &'static str) -> (&'static str, &'static str, Value) {
    (name, "string", Value::String(v.to_owned()))
}

type ConstantTable = Vec<(&'static str, Vec<(&'static str, &'static str, Value)>)>;

fn rust_constants() -> ConstantTable {
    type Jct = control_msgs::JointComponentTolerance;
    type Fjr = control_msgs::FollowJointTrajectoryResult;
    type Ts = msg::TrajectoryStatus;
    type Cp = msg::CutPlan;
    type Mr = msg::MillRequest;
    type Mp = msg::MillPlan;
    type Gr = msg::GcodeRequest;
    type Gp = msg::GcodePlan;
    type Pcf = action::PlanCutFeedback;
    type Pmf = action::PlanMillFeedback;
    type Pgf = action::PlanGcodeFeedback;
    vec![
        (
            Jct::ROS_TYPE,
            vec![
                c_u16("X_AXIS", Jct::X_AXIS),
                c_u16("Y_AXIS", Jct::Y_AXIS),
                c_u16("Z_AXIS", Jct::Z_AXIS),
                c_u16("TRANSLATION", Jct::TRANSLATION),
                c_u16("ROTATION", Jct::ROTATION),
            ],
        ),
        (
            Fjr::ROS_TYPE,
            vec![
                c_i32("SUCCESSFUL", Fjr::SUCCESSFUL),
                c_i32("INVALID_GOAL", Fjr::INVALID_GOAL),
                c_i32("INVALID_JOINTS", Fjr::INVALID_JOINTS),
                c_i32("OLD_HEADER_TIMESTAMP", Fjr::OLD_HEADER_TIMESTAMP),
                c_i32("PATH_TOLERANCE_VIOLATED", Fjr::PATH_TOLERANCE_VIOLATED),
                c_i32("GOAL_TOLERANCE_VIOLATED", Fjr::GOAL_TOLERANCE_VIOLATED),
            ],
        ),
        (
            Ts::ROS_TYPE,
            vec![
                c_u8("ACCEPTED", Ts::ACCEPTED),
                c_u8("REJECTED", Ts::REJECTED),
                c_u8("SUCCEEDED", Ts::SUCCEEDED),
                c_u8("ABORTED", Ts::ABORTED),
                c_u8("PREEMPTED", Ts::PREEMPTED),
                c_u8("CANCELED", Ts::CANCELED),
            ],
        ),
        (
            msg::StreamStatus::ROS_TYPE,
            vec![
                c_u8("START", msg::StreamStatus::START),
                c_u8("QUEUED", msg::StreamStatus::QUEUED),
                c_u8("REFUSED", msg::StreamStatus::REFUSED),
                c_u8("REACHED", msg::StreamStatus::REACHED),
                c_u8("NOT_REACHED", msg::StreamStatus::NOT_REACHED),
            ],
        ),
        (
            msg::CutRequest::ROS_TYPE,
            vec![
                c_str("START_CURRENT", msg::CutRequest::START_CURRENT),
                c_str("START_GIVEN", msg::CutRequest::START_GIVEN),
                c_str("START_NONE", msg::CutRequest::START_NONE),
            ],
        ),
        (
            Cp::ROS_TYPE,
            vec![
                c_u8("SUCCESS", Cp::SUCCESS),
                c_u8("INVALID_REQUEST", Cp::INVALID_REQUEST),
                c_u8("MESH_ERROR", Cp::MESH_ERROR),
                c_u8("UNREACHABLE", Cp::UNREACHABLE),
                c_u8("INFEASIBLE", Cp::INFEASIBLE),
                c_u8("COLLISION", Cp::COLLISION),
                c_u8("LIMIT_VIOLATION", Cp::LIMIT_VIOLATION),
                c_u8("INTERNAL_ERROR", Cp::INTERNAL_ERROR),
                c_u8("TIMEOUT", Cp::TIMEOUT),
                c_u8("QUEUE_FULL", Cp::QUEUE_FULL),
                c_u8("RESOURCE_LIMIT", Cp::RESOURCE_LIMIT),
                c_u8("NO_APPROACH", Cp::NO_APPROACH),
            ],
        ),
        (
            Mr::ROS_TYPE,
            vec![
                c_str("PLANNER_DDPG", Mr::PLANNER_DDPG),
                c_str("PLANNER_FIXED_G", Mr::PLANNER_FIXED_G),
                c_str("PLANNER_DP", Mr::PLANNER_DP),
                c_str("PLANNER_NAIVE", Mr::PLANNER_NAIVE),
                c_str("PLANNER_GREEDY", Mr::PLANNER_GREEDY),
                c_str("PLANNER_GREEDY_BEST_G", Mr::PLANNER_GREEDY_BEST_G),
                c_str("PLANNER_BEST", Mr::PLANNER_BEST),
                c_str("START_CURRENT", Mr::START_CURRENT),
                c_str("START_GIVEN", Mr::START_GIVEN),
                c_str("START_NONE", Mr::START_NONE),
                c_str("ENTRY_RUN_IN", Mr::ENTRY_RUN_IN),
                c_str("ENTRY_IN_MATERIAL", Mr::ENTRY_IN_MATERIAL),
            ],
        ),
        (
            Mp::ROS_TYPE,
            vec![
                c_u8("SUCCESS", Mp::SUCCESS),
                c_u8("INVALID_REQUEST", Mp::INVALID_REQUEST),
                c_u8("UNREACHABLE", Mp::UNREACHABLE),
                c_u8("POLICY_ERROR", Mp::POLICY_ERROR),
                c_u8("CHATTER_MODEL_ERROR", Mp::CHATTER_MODEL_ERROR),
                c_u8("QUEUE_FULL", Mp::QUEUE_FULL),
                c_u8("INTERNAL_ERROR", Mp::INTERNAL_ERROR),
                c_u8("TIMEOUT", Mp::TIMEOUT),
                c_u8("ILL_CONDITIONED", Mp::ILL_CONDITIONED),
                c_u8("RESOURCE_LIMIT", Mp::RESOURCE_LIMIT),
                c_u8("NO_APPROACH", Mp::NO_APPROACH),
                c_u8("CHATTER", Mp::CHATTER),
                c_u8("INFEASIBLE", Mp::INFEASIBLE),
            ],
        ),
        (
            Gr::ROS_TYPE,
            vec![
                c_str("MACHINE_LASER_CUTTER", Gr::MACHINE_LASER_CUTTER),
                c_str("MACHINE_IRB6660", Gr::MACHINE_IRB6660),
                c_str("METHOD_KERF", Gr::METHOD_KERF),
                c_str("METHOD_KERF_CURVATURE", Gr::METHOD_KERF_CURVATURE),
                c_str("METHOD_ICR", Gr::METHOD_ICR),
                c_str("METHOD_CCR", Gr::METHOD_CCR),
                c_str("METHOD_NURBS", Gr::METHOD_NURBS),
                c_str("METHOD_DRLS_NET", Gr::METHOD_DRLS_NET),
                c_str("FEED_NEAR_OPTIMAL", Gr::FEED_NEAR_OPTIMAL),
                c_str("FEED_CONSTANT_INTERVALS", Gr::FEED_CONSTANT_INTERVALS),
                c_str("START_CURRENT", Gr::START_CURRENT),
                c_str("START_GIVEN", Gr::START_GIVEN),
                c_str("START_NONE", Gr::START_NONE),
            ],
        ),
        (
            Gp::ROS_TYPE,
            vec![
                c_u8("SUCCESS", Gp::SUCCESS),
                c_u8("INVALID_REQUEST", Gp::INVALID_REQUEST),
                c_u8("PROGRAM_ERROR", Gp::PROGRAM_ERROR),
                c_u8("UNREACHABLE", Gp::UNREACHABLE),
                c_u8("QUEUE_FULL", Gp::QUEUE_FULL),
                c_u8("INTERNAL_ERROR", Gp::INTERNAL_ERROR),
                c_u8("TIMEOUT", Gp::TIMEOUT),
                c_u8("RESOURCE_LIMIT", Gp::RESOURCE_LIMIT),
                c_u8("NO_APPROACH", Gp::NO_APPROACH),
            ],
        ),
        (
            Pcf::ROS_TYPE,
            vec![
                c_str("STAGE_QUEUED", Pcf::STAGE_QUEUED),
                c_str("STAGE_PLANNING", Pcf::STAGE_PLANNING),
                c_str("STAGE_EXECUTING", Pcf::STAGE_EXECUTING),
            ],
        ),
        (
            Pmf::ROS_TYPE,
            vec![
                c_str("STAGE_QUEUED", Pmf::STAGE_QUEUED),
                c_str("STAGE_PLANNING", Pmf::STAGE_PLANNING),
                c_str("STAGE_EXECUTING", Pmf::STAGE_EXECUTING),
            ],
        ),
        (
            Pgf::ROS_TYPE,
            vec![
                c_str("STAGE_QUEUED", Pgf::STAGE_QUEUED),
                c_str("STAGE_PLANNING", Pgf::STAGE_PLANNING),
                c_str("STAGE_EXECUTING", Pgf::STAGE_EXECUTING),
            ],
        ),
    ]
}

/// Compares the constants of every spec with the table; one line per difference.
fn compare_constants(specs: &BTreeMap<String, MessageSpec>, table: &ConstantTable) -> Vec<String> {
    let mut problems = Vec::new();
    let rust: HashMap<&str, &Vec<(&str, &str, Value)>> =
        table.iter().map(|(t, c)| (*t, c)).collect();
    for (ros_type, spec) in specs {
        let got: &[(&str, &str, Value)] = rust.get(ros_type.as_str()).map_or(&[], |v| v);
        let file: Vec<(&str, &str, Value)> = spec
            .constants
            .iter()
            .map(|c| {
                let ty = match &c.constant_type {
                    BaseType::Primitive(p) => p.name(),
                    BaseType::String { wide: false, .. } => "string",
                    BaseType::String { wide: true, .. } => "wstring",
                    BaseType::Message { .. } => "message",
                };
                (c.name.as_str(), ty, c.value.clone())
            })
            .collect();
        for want in &file {
            match got.iter().find(|g| g.0 == want.0) {
                None => problems.push(format!(
                    "{ros_type}: constant {} {}={:?} has no Rust mirror",
                    want.1, want.0, want.2
                )),
                Some(g) if g != want => problems.push(format!(
                    "{ros_type}: constant {}: interface file has {} = {:?}, Rust has {} = {:?}",
                    want.0, want.1, want.2, g.1, g.2
                )),
                Some(_) => {}
            }
        }
        for g in got {
            if !file.iter().any(|w| w.0 == g.0) {
                problems.push(format!(
                    "{ros_type}: Rust constant {} is not in the interface file",
                    g.0
                ));
            }
        }
    }
    for (ros_type, _) in table {
        if !specs.contains_key(*ros_type) {
            problems.push(format!(
                "constant table names {ros_type}, which no file defines"
            ));
        }
    }
    problems
}

// ---------------------------------------------------------------------------
// Tests

#[test]
fn every_mirror_matches_its_interface_file() {
    let files = interface_files();
    let specs = specs_by_ros_type(&files);
    let mirrors = all_mirrors();
    let names = serde_names(&mirrors);
    let mut problems = Vec::new();
    let mut mirrored = BTreeSet::new();
    for m in &mirrors {
        mirrored.insert(m.ros_type.to_owned());
        let Some(spec) = specs.get(m.ros_type) else {
            problems.push(format!("{}: no interface file defines it", m.ros_type));
            continue;
        };
        let (root, registry) = (m.trace)().unwrap_or_else(|e| panic!("{}: {e}", m.ros_type));
        problems.extend(compare_struct(m.ros_type, spec, &root, &registry, &names));
        let want = message_default(spec, &specs);
        let got = (m.default_json)();
        if want != got {
            problems.push(format!(
                "{}: Default is {got}, the interface file's defaults are {want}",
                m.ros_type
            ));
        }
    }
    for ros_type in specs.keys() {
        if !mirrored.contains(ros_type) {
            problems.push(format!("{ros_type}: interface file has no Rust mirror"));
        }
    }
    assert!(
        problems.is_empty(),
        "mirror drift:\n{}",
        problems.join("\n")
    );
    assert_eq!(mirrors.len(), 55, "every mirror is checked");
}

#[test]
fn every_constant_matches_its_interface_file() {
    let specs = specs_by_ros_type(&interface_files());
    let problems = compare_constants(&specs, &rust_constants());
    assert!(
        problems.is_empty(),
        "constant drift:\n{}",
        problems.join("\n")
    );
}

#[test]
fn ros_types_name_their_files() {
    // PACKAGE/KIND/NAME agree with ROS_TYPE, and the file exists at the path
    // the name implies.
    fn check<T: RosType>() {
        assert_eq!(
            T::ROS_TYPE,
            format!("{}/{}/{}", T::PACKAGE, T::KIND.as_str(), T::NAME)
        );
        let stem = T::NAME.split('_').next().unwrap_or(T::NAME);
        let kind = T::KIND.as_str();
        let path = if T::PACKAGE == "kerf_msgs" {
            msgs_dir().join(kind).join(format!("{stem}.{kind}"))
        } else {
            msgs_dir()
                .join("rust/interfaces")
                .join(T::PACKAGE)
                .join(kind)
                .join(format!("{stem}.{kind}"))
        };
        assert!(
            path.is_file(),
            "{} has no file {}",
            T::ROS_TYPE,
            path.display()
        );
    }
    check::<builtin_interfaces::Time>();
    check::<std_msgs::StringMsg>();
    check::<std_msgs::Float64MultiArray>();
    check::<control_msgs::FollowJointTrajectoryGoal>();
    check::<control_msgs::JointTrajectoryControllerState>();
    check::<srv::ValidateTrajectoryResponse>();
    check::<msg::TrajectoryStatus>();
    check::<msg::CutRequest>();
    check::<msg::CutPlan>();
    check::<msg::CutRto>();
    check::<msg::CutMetrics>();
    check::<msg::CutCollision>();
    check::<msg::CellContact>();
    check::<msg::CellContacts>();
    check::<rosgraph_msgs::Clock>();
    check::<msg::MillRequest>();
    check::<msg::MillSegment>();
    check::<msg::MillCandidate>();
    check::<msg::MillPlan>();
    check::<msg::ReferencePoint>();
    check::<msg::StreamStatus>();
    check::<action::PlanCutGoal>();
    check::<action::PlanCutResult>();
    check::<action::PlanMillFeedback>();
    check::<action::PlanGcodeResult>();
}

// Negative tests: the comparator must catch drift.

/// `JointTrajectoryPoint` with `velocities` as `float32[]`, `effort` and
/// `accelerations` swapped, and `time_from_start` as `Time`.
#[derive(Debug, Default, Serialize, Deserialize)]
struct DriftedPoint {
    positions: Vec<f64>,
    velocities: Vec<f32>,
    effort: Vec<f64>,
    accelerations: Vec<f64>,
    time_from_start: builtin_interfaces::Time,
}

/// `Quaternion` as a fixed array, with an extra field.
#[derive(Debug, Default, Serialize, Deserialize)]
struct DriftedQuaternion {
    x: [f64; 1],
    y: f64,
    z: f64,
    w: f64,
    norm: f64,
}

#[test]
fn comparator_catches_field_drift() {
    let specs = specs_by_ros_type(&interface_files());
    let names = serde_names(&all_mirrors());

    let spec = &specs["trajectory_msgs/msg/JointTrajectoryPoint"];
    let (root, registry) = trace::<DriftedPoint>().unwrap();
    let problems = compare_struct("JointTrajectoryPoint", spec, &root, &registry, &names);
    let text = problems.join("\n");
    assert_eq!(problems.len(), 4, "{text}");
    assert!(
        text.contains("field `velocities` must be Seq(F64), Rust has Seq(F32)"),
        "{text}"
    );
    assert!(
        text.contains("field #2 is `accelerations` in the interface file but `effort`"),
        "{text}"
    );
    assert!(
        text.contains("field #3 is `effort` in the interface file but `accelerations`"),
        "{text}"
    );
    assert!(
        text.contains("field `time_from_start` must be TypeName(\"builtin_interfaces/msg/Duration\"), Rust has TypeName(\"builtin_interfaces/msg/Time\")"),
        "{text}"
    );

    let spec = &specs["geometry_msgs/msg/Quaternion"];
    let (root, registry) = trace::<DriftedQuaternion>().unwrap();
    let problems = compare_struct("Quaternion", spec, &root, &registry, &names);
    let text = problems.join("\n");
    assert_eq!(problems.len(), 2, "{text}");
    assert!(
        text.contains("field `x` must be F64, Rust has TupleArray"),
        "{text}"
    );
    assert!(text.contains("extra field #4 `norm`"), "{text}");
}

#[test]
fn comparator_catches_drift_against_parsed_text() {
    // Fixed sizes, bounded arrays, missing fields and unmirrored nested types.
    let spec = idl::parse_message(
        "pkg",
        "Drift",
        "float64[3] positions\nstring<=8[<=2] names\npkg/Unknown nested\nbool extra\n",
        "Drift.msg",
    )
    .unwrap();
    #[derive(Debug, Default, Serialize, Deserialize)]
    struct Drift {
        positions: [f64; 2],
        names: Vec<String>,
        nested: std_msgs::Header,
    }
    let names = serde_names(&all_mirrors());
    let (root, registry) = trace::<Drift>().unwrap();
    let problems = compare_struct("pkg/msg/Drift", &spec, &root, &registry, &names);
    let text = problems.join("\n");
    assert_eq!(problems.len(), 3, "{text}");
    assert!(
        text.contains("field `positions` must be TupleArray { content: F64, size: 3 }"),
        "{text}"
    );
    assert!(
        text.contains("field `nested` must be TypeName(\"pkg/msg/Unknown\")"),
        "{text}"
    );
    assert!(
        text.contains("field #3 `extra` is missing in Rust"),
        "{text}"
    );
}

#[test]
fn constant_comparison_catches_drift() {
    let specs = specs_by_ros_type(&interface_files());
    let mut table = rust_constants();
    // Wrong value, wrong type, a missing constant and an extra one.
    table[0].1[0] = c_u16("X_AXIS", 7);
    table[1].1[1] = c_u8("INVALID_GOAL", 1);
    table[2].1.pop();
    table[2].1.push(c_u8("PAUSED", 7));
    let text = compare_constants(&specs, &table).join("\n");
    assert!(
        text.contains(
            "constant X_AXIS: interface file has uint16 = Int(1), Rust has uint16 = Int(7)"
        ),
        "{text}"
    );
    assert!(
        text.contains(
            "constant INVALID_GOAL: interface file has int32 = Int(-1), Rust has uint8 = Int(1)"
        ),
        "{text}"
    );
    assert!(
        text.contains("constant uint8 CANCELED=Int(6) has no Rust mirror"),
        "{text}"
    );
    assert!(
        text.contains("Rust constant PAUSED is not in the interface file"),
        "{text}"
    );
}

#[test]
fn default_comparison_catches_drift() {
    let specs = specs_by_ros_type(&interface_files());
    // A Quaternion whose Default would be all zeros differs from the file's `w 1`.
    let want = message_default(&specs["geometry_msgs/msg/Quaternion"], &specs);
    assert_eq!(want, json!({"x": 0.0, "y": 0.0, "z": 0.0, "w": 1.0}));
    assert_ne!(want, json!({"x": 0.0, "y": 0.0, "z": 0.0, "w": 0.0}));
    // Nested defaults propagate: Pose.orientation.w is 1.
    let pose = message_default(&specs["geometry_msgs/msg/Pose"], &specs);
    assert_eq!(pose["orientation"]["w"], json!(1.0));
}

#[test]
fn cmake_lists_every_kerf_interface() {
    let cmake = std::fs::read_to_string(msgs_dir().join("CMakeLists.txt")).unwrap();
    for f in interface_files()
        .iter()
        .filter(|f| f.package == "kerf_msgs")
    {
        assert!(
            cmake.contains(&format!("\"{}\"", f.file)),
            "CMakeLists.txt does not list {}",
            f.file
        );
    }
}

// ---------------------------------------------------------------------------
// Second, independent parser: rosidl_adapter (Debian package python3-rosidl).

const PYTHON: &str = "/usr/bin/python3";

fn rosidl_available() -> bool {
    Command::new(PYTHON)
        .args(["-c", "import rosidl_adapter.parser"])
        .output()
        .is_ok_and(|o| o.status.success())
}

/// The Rust parser's view of a file, in the JSON shape of `rosidl_dump.py`.
fn file_json(f: &InterfaceFile) -> serde_json::Value {
    fn value(v: &Value) -> serde_json::Value {
        match v {
            Value::Bool(b) => json!(b),
            Value::Int(i) => i64::try_from(*i)
                .map(|i| json!(i))
                .unwrap_or_else(|_| json!(u64::try_from(*i).unwrap_or(u64::MAX))),
            Value::Float(x) if x.is_nan() => json!("nan"),
            Value::Float(x) if x.is_infinite() => json!(if *x > 0.0 { "inf" } else { "-inf" }),
            Value::Float(x) => json!(x),
            Value::String(s) => json!(s),
            Value::Array(items) => serde_json::Value::Array(items.iter().map(value).collect()),
        }
    }
    fn ty(t: &FieldType) -> serde_json::Value {
        let (package, name, bound) = match &t.base {
            BaseType::Primitive(p) => (None, p.name().to_owned(), None),
            BaseType::String { wide, upper_bound } => (
                None,
                if *wide { "wstring" } else { "string" }.to_owned(),
                *upper_bound,
            ),
            BaseType::Message { package, name } => (Some(package.clone()), name.clone(), None),
        };
        let (is_array, size, upper) = match t.array {
            Array::No => (false, None, false),
            Array::Unbounded => (true, None, false),
            Array::Bounded(n) => (true, Some(n), true),
            Array::Fixed(n) => (true, Some(n), false),
        };
        json!({
            "package": package, "type": name, "string_upper_bound": bound,
            "is_array": is_array, "array_size": size, "is_upper_bound": upper,
        })
    }
    let parts: Vec<serde_json::Value> = f
        .spec
        .parts
        .iter()
        .map(|p| {
            json!({
                "name": p.name,
                "fields": p.fields.iter().map(|fd| json!({
                    "name": fd.name,
                    "type": ty(&fd.field_type),
                    "default": fd.default.as_ref().map(value),
                })).collect::<Vec<_>>(),
                "constants": p.constants.iter().map(|c| json!({
                    "name": c.name,
                    "type": ty(&FieldType { base: c.constant_type.clone(), array: Array::No })["type"],
                    "value": value(&c.value),
                })).collect::<Vec<_>>(),
            })
        })
        .collect();
    json!({"file": f.file, "kind": f.kind.as_str(), "package": f.package, "parts": parts})
}

#[test]
fn rust_parser_agrees_with_rosidl() {
    if !rosidl_available() {
        eprintln!("skipped: python3-rosidl not installed (apt-get install -y python3-rosidl)");
        return;
    }
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/rosidl_dump.py");
    let out = Command::new(PYTHON)
        .arg(&script)
        .arg(msgs_dir())
        .output()
        .expect("run rosidl_dump.py");
    assert!(
        out.status.success(),
        "rosidl_dump.py failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let rosidl: Vec<serde_json::Value> =
        serde_json::from_slice(&out.stdout).expect("rosidl_dump.py prints JSON");
    let ours: Vec<serde_json::Value> = interface_files().iter().map(file_json).collect();
    let file_list = |v: &[serde_json::Value]| -> Vec<String> {
        v.iter()
            .map(|f| f["file"].as_str().unwrap_or("?").to_owned())
            .collect()
    };
    assert_eq!(
        file_list(&rosidl),
        file_list(&ours),
        "both parse the same files"
    );
    for (theirs, mine) in rosidl.iter().zip(&ours) {
        assert_eq!(
            theirs, mine,
            "rosidl and kerf_msgs::idl disagree on {}",
            mine["file"]
        );
    }
    assert_eq!(ours.len(), 46, "every interface file is compared");
}
