//! The fuzz targets ([`crate::TARGETS`]). Each one panics only on a bug: a panic of the code
//! under test, or a broken property of an accepted input (`assert!` with the property).

use std::sync::OnceLock;

use arbitrary::Unstructured;
use byteorder::{BigEndian, ByteOrder, LittleEndian};
use kerf_executor::{JointLimits, TrajectoryRequest};
use kerf_millplan::MillRequest;
use kerf_mjto::{mesh::MeshData, CutRequest};
use kerf_msgs::{
    control_msgs::FollowJointTrajectoryGoal, msg, srv::ValidateTrajectoryRequest,
    std_msgs::StringMsg, trajectory_msgs::JointTrajectory,
};
use kerf_robot::document;
use serde::{de::DeserializeOwned, Serialize};

use crate::gen;

/// The bytes as text, as a kerf parser would get them (invalid UTF-8 → U+FFFD).
fn text(data: &[u8]) -> std::borrow::Cow<'_, str> {
    String::from_utf8_lossy(data)
}

// ---------------------------------------------------------------------------------------------
// Properties of accepted inputs
// ---------------------------------------------------------------------------------------------

/// A cut request: validation returns a value, and a validated path is finite, with a strictly
/// increasing arc length from 0 and unit axes.
fn check_cut_request(req: &CutRequest) {
    let Ok(v) = req.validate() else { return };
    let n = req.points.len();
    assert!(
        v.points.len() == n && v.axes.len() == n && v.arc_length.len() == n && v.u.len() == n,
        "validated request: lengths differ from the {n} points"
    );
    for (i, (p, a)) in v.points.iter().zip(&v.axes).enumerate() {
        assert!(
            p.iter().all(|c| c.is_finite()),
            "validated request: machine-frame point {i} is not finite"
        );
        assert!(
            (a.norm() - 1.0).abs() < 1e-5,
            "validated request: machine-frame axis {i} is not a unit vector"
        );
    }
    assert!(
        v.arc_length[0] == 0.0 && v.arc_length.windows(2).all(|w| w[1] > w[0]),
        "validated request: arc length not strictly increasing from 0"
    );
    assert!(
        v.sigma.is_finite() && v.sigma > 0.0 && v.sigma == v.arc_length[n - 1],
        "validated request: path length {} not finite and positive",
        v.sigma
    );
    assert!(
        v.u.iter().all(|u| (0.0..=1.0).contains(u)) && v.u[n - 1] == 1.0,
        "validated request: normalized arc length outside [0, 1]"
    );
}

/// A mill request: validation returns a value (it builds the spline of the path).
fn check_mill_request(req: &MillRequest) {
    if req.validate().is_ok() {
        assert!(
            req.points.iter().flatten().all(|c| c.is_finite()),
            "validated mill request with a non-finite point"
        );
        let [rpm, feed, g] = req.initial_state();
        assert!(
            rpm.is_finite() && feed.is_finite() && feed > 0.0 && g.is_finite(),
            "validated mill request with a bad initial state"
        );
    }
}

/// `value` written as YAML and read back by `parse` writes the same YAML (a canonical round
/// trip; compared as text so that NaN fields compare equal).
fn yaml_round_trip<T: Serialize + std::fmt::Debug, E: std::fmt::Display>(
    value: &T,
    parse: impl Fn(&str) -> Result<T, E>,
) {
    let Ok(first) = serde_yaml_ng::to_string(value) else {
        return;
    };
    match parse(&first) {
        Ok(back) => {
            let second = serde_yaml_ng::to_string(&back).ok();
            assert!(
                second.as_deref() == Some(first.as_str()),
                "YAML round trip changed the request"
            );
        }
        Err(e) => panic!("an accepted request written as YAML is refused when read back: {e}"),
    }
}

/// The depth of a YAML value as `kerf_robot::document::nesting_depth` counts it (a collection
/// is one level more than its deepest key or value; tags add none).
fn value_depth(v: &serde_yaml_ng::Value) -> usize {
    use serde_yaml_ng::Value;
    match v {
        Value::Sequence(s) => 1 + s.iter().map(value_depth).max().unwrap_or(0),
        Value::Mapping(m) => {
            1 + m
                .iter()
                .map(|(k, v)| value_depth(k).max(value_depth(v)))
                .max()
                .unwrap_or(0)
        }
        Value::Tagged(t) => value_depth(&t.value),
        _ => 0,
    }
}

// ---------------------------------------------------------------------------------------------
// Text targets
// ---------------------------------------------------------------------------------------------

/// `~/cut_request_text`: `kerf_mjto_planner::text::parse_request` (YAML/JSON or the line
/// format), then validation of an accepted request.
pub fn cut_text(data: &[u8]) {
    let text = text(data);
    match kerf_mjto_planner::text::parse_request(&text) {
        Ok(req) => check_cut_request(&req),
        Err(e) => drop(e.to_string()),
    }
}

/// The line format alone (`parse_lines`, then the message conversion and validation), whatever
/// the text looks like.
pub fn cut_lines(data: &[u8]) {
    let text = text(data);
    if let Ok(m) = kerf_mjto_planner::text::parse_lines(&text) {
        if let Ok(req) = kerf_mjto_planner::convert::request_from_msg(&m) {
            check_cut_request(&req);
        }
    }
}

/// `kerf_mjto::CutRequest::from_yaml` (the request file of `kerf plan cut`); an accepted
/// request validates, and survives a YAML round trip.
pub fn cut_yaml(data: &[u8]) {
    let text = text(data);
    if let Ok(req) = CutRequest::from_yaml(&text) {
        check_cut_request(&req);
        yaml_round_trip(&req, CutRequest::from_yaml);
    }
}

/// JSON cut requests: whatever JSON itself accepts as a `CutRequest`, `from_yaml` (which reads
/// YAML, or JSON where YAML refuses it) accepts too, as the same request.
pub fn cut_json(data: &[u8]) {
    let text = text(data);
    let yaml = CutRequest::from_yaml(&text);
    if let Ok(json) = serde_json::from_str::<CutRequest>(&text) {
        if document::check_depth(&text).is_ok() {
            match &yaml {
                Ok(req) => assert!(
                    serde_json::to_string(req).ok() == serde_json::to_string(&json).ok(),
                    "a JSON request reads differently through from_yaml"
                ),
                Err(e) => panic!("a JSON request accepted by JSON is refused by from_yaml: {e}"),
            }
        }
    }
    if let Ok(req) = yaml {
        check_cut_request(&req);
    }
}

/// `~/mill_request_text`: `kerf_milling_planner::text::parse_request`, then validation.
pub fn mill_text(data: &[u8]) {
    let text = text(data);
    match kerf_milling_planner::text::parse_request(&text) {
        Ok(req) => check_mill_request(&req),
        Err(e) => drop(e.to_string()),
    }
}

/// `kerf_millplan::MillRequest::from_yaml_str` (the request file of `kerf plan mill`); an
/// accepted request validates, and survives a YAML round trip through `to_yaml_string`.
pub fn mill_yaml(data: &[u8]) {
    let text = text(data);
    if let Ok(req) = MillRequest::from_yaml_str(&text) {
        check_mill_request(&req);
        if let Ok(first) = req.to_yaml_string() {
            match MillRequest::from_yaml_str(&first) {
                Ok(back) => assert!(
                    back.to_yaml_string().ok().as_deref() == Some(first.as_str()),
                    "YAML round trip changed the mill request"
                ),
                Err(e) => panic!("a mill request written by to_yaml_string is refused: {e}"),
            }
        }
    }
}

/// `kerf_millplan::MillRequest::from_json_str` (a `.json` request file); what it accepts,
/// `from_yaml_str` accepts as the same request.
pub fn mill_json(data: &[u8]) {
    let text = text(data);
    if let Ok(req) = MillRequest::from_json_str(&text) {
        check_mill_request(&req);
        match MillRequest::from_yaml_str(&text) {
            Ok(y) => assert!(
                serde_json::to_string(&y).ok() == serde_json::to_string(&req).ok(),
                "a JSON mill request reads differently through from_yaml_str"
            ),
            Err(e) => panic!("a JSON mill request is refused by from_yaml_str: {e}"),
        }
    }
}

/// `kerf_robot::document::from_yaml_or_json` (every request document goes through it) into a
/// generic value, and `kerf_ros::planner::yaml_field`. An accepted document nests at most
/// `MAX_DEPTH` levels: deeper ones must be refused before the YAML parser, whose time grows
/// quadratically with the depth, sees them. (Aliases are left out: they repeat nodes that were
/// counted where they were defined.)
pub fn document(data: &[u8]) {
    let text = text(data);
    if let Ok(v) = document::from_yaml_or_json::<serde_yaml_ng::Value>(&text) {
        if !text.contains('*') {
            let depth = value_depth(&v);
            assert!(
                depth <= document::MAX_DEPTH,
                "an accepted document nests {depth} levels, over MAX_DEPTH"
            );
        }
    }
    drop(kerf_ros::planner::yaml_field(&text, "request_id"));
}

// ---------------------------------------------------------------------------------------------
// Meshes
// ---------------------------------------------------------------------------------------------

/// An accepted mesh is usable: triangles, indices in range, finite, within the extent limit.
fn check_mesh(mesh: &MeshData) {
    let n = mesh.vertices.len();
    assert!(
        !mesh.triangles.is_empty(),
        "accepted mesh without triangles"
    );
    assert!(
        mesh.triangles
            .iter()
            .all(|t| t.iter().all(|&k| (k as usize) < n) && t[0] != t[1] && t[1] != t[2]),
        "accepted mesh with an index out of range or a repeated index"
    );
    assert!(
        mesh.vertices.iter().flatten().all(|c| c.is_finite()),
        "accepted mesh with a non-finite vertex"
    );
    if let Some((lo, hi)) = mesh.bounds() {
        assert!(
            (0..3).all(|i| hi[i] - lo[i] <= kerf_mjto::mesh::MAX_EXTENT),
            "accepted mesh larger than MAX_EXTENT"
        );
    }
}

/// The STL reader (binary or ASCII), as `kerf_mjto::mesh::load` reads a `.stl` file.
pub fn mesh_stl(data: &[u8]) {
    if let Ok(mesh) = kerf_mjto::mesh::parse(data, "stl", "fuzz.stl") {
        check_mesh(&mesh);
    }
}

/// The OBJ reader, as `kerf_mjto::mesh::load` reads a `.obj` file.
pub fn mesh_obj(data: &[u8]) {
    if let Ok(mesh) = kerf_mjto::mesh::parse(data, "obj", "fuzz.obj") {
        check_mesh(&mesh);
    }
}

// ---------------------------------------------------------------------------------------------
// Messages
// ---------------------------------------------------------------------------------------------

/// `kerf_mjto_planner::convert::request_from_msg` of a `CutRequest` message, then validation.
pub(crate) fn cut_msg_of(m: &msg::CutRequest) {
    if let Ok(req) = kerf_mjto_planner::convert::request_from_msg(m) {
        check_cut_request(&req);
    }
}

/// `kerf_milling_planner::convert::request_from_msg` of a `MillRequest` message, then
/// validation; an accepted message keeps its points.
pub(crate) fn mill_msg_of(m: &msg::MillRequest) {
    if let Ok(req) = kerf_milling_planner::convert::request_from_msg(m) {
        assert!(
            req.points.len() == m.points.len(),
            "mill request conversion lost points"
        );
        check_mill_request(&req);
    }
}

/// The executor's joint limits of the laser cutter (0) and of the IRB 6660 (1), loaded once.
fn robot_limits(robot: usize) -> &'static [JointLimits] {
    static LIMITS: OnceLock<[Vec<JointLimits>; 2]> = OnceLock::new();
    let all = LIMITS.get_or_init(|| {
        let load = |urdf: &str, limits: &str| -> Vec<JointLimits> {
            let (Ok(urdf), Ok(limits)) =
                (kerf_robot::data::path(urdf), kerf_robot::data::path(limits))
            else {
                return Vec::new();
            };
            kerf_robot::RobotModel::from_files(&urdf, Some(&limits))
                .ok()
                .and_then(|r| r.executor_limits().ok())
                .unwrap_or_default()
        };
        [
            load("urdf/laser_cutter.urdf", "urdf/laser_cutter_limits.yaml"),
            load("urdf/irb6660.urdf", "urdf/irb6660_limits.yaml"),
        ]
    });
    &all[robot.min(1)]
}

/// An accepted conversion keeps every point, and its times are finite.
fn check_request(msg: &JointTrajectory, req: &TrajectoryRequest) {
    assert!(
        req.points.len() == msg.points.len() && req.joint_names == msg.joint_names,
        "trajectory conversion lost points or names"
    );
    assert!(
        req.points.iter().all(|p| p.time_from_start.is_finite())
            && req.start_time.is_none_or(f64::is_finite),
        "trajectory conversion produced a non-finite time"
    );
}

/// `kerf_ros::planner::{trajectory_request, check_trajectory_msg}` of a `JointTrajectory` for
/// robot `robot`.
fn trajectory_of(msg: &JointTrajectory, robot: usize) {
    let clock = kerf_trajectory_executor::convert::Clock::start();
    if let Ok(req) = kerf_ros::planner::trajectory_request(msg, |s| clock.from_stamp(s)) {
        check_request(msg, &req);
    }
    let limits = robot_limits(robot);
    if let Err(e) = kerf_ros::planner::check_trajectory_msg(limits, msg) {
        drop(e);
    }
}

/// A `CutRequest` message built from the bytes ([`gen::cut_request`]) through the planner
/// node's conversion and validation.
pub fn cut_msg(data: &[u8]) {
    let mut u = Unstructured::new(data);
    if let Ok(m) = gen::cut_request(&mut u) {
        cut_msg_of(&m);
    }
}

/// A `MillRequest` message built from the bytes ([`gen::mill_request`]) through the milling
/// node's conversion and validation.
pub fn mill_msg(data: &[u8]) {
    let mut u = Unstructured::new(data);
    if let Ok(m) = gen::mill_request(&mut u) {
        mill_msg_of(&m);
    }
}

/// A `JointTrajectory` built from the bytes ([`gen::joint_trajectory`]; the first byte picks
/// the robot) through the one conversion to the executor's type and the executability check.
pub fn trajectory_msg(data: &[u8]) {
    let robot = usize::from(data.first().copied().unwrap_or(0) & 1);
    let mut u = Unstructured::new(data.get(1..).unwrap_or_default());
    if let Ok(m) = gen::joint_trajectory(&mut u, robot) {
        trajectory_of(&m, robot);
    }
}

/// Decodes `body` as a `T` in byte order `BO` as a subscription does, and checks the decoded
/// message re-encodes to bytes that decode to the same message (compared as bytes, so NaN
/// payloads compare equal).
fn cdr_decode<T, BO>(body: &[u8]) -> Option<T>
where
    T: DeserializeOwned + Serialize,
    BO: ByteOrder,
{
    let (m, used) = cdr_encoding::from_bytes::<T, BO>(body).ok()?;
    assert!(
        used <= body.len(),
        "CDR decoder consumed more than the input"
    );
    let first = cdr_encoding::to_vec::<T, BO>(&m).ok()?;
    let (back, _) = match cdr_encoding::from_bytes::<T, BO>(&first) {
        Ok(b) => b,
        Err(e) => panic!("a decoded message re-encoded does not decode: {e}"),
    };
    let second = cdr_encoding::to_vec::<T, BO>(&back).ok();
    assert!(
        second.as_deref() == Some(first.as_slice()),
        "CDR round trip changed the message"
    );
    Some(m)
}

fn cdr_in<BO: ByteOrder>(kind: u8, body: &[u8]) {
    match kind % 6 {
        0 => {
            if let Some(m) = cdr_decode::<msg::CutRequest, BO>(body) {
                cut_msg_of(&m);
            }
        }
        1 => {
            if let Some(m) = cdr_decode::<msg::MillRequest, BO>(body) {
                mill_msg_of(&m);
            }
        }
        2 => {
            if let Some(m) = cdr_decode::<JointTrajectory, BO>(body) {
                trajectory_of(&m, usize::from(kind & 0x40 != 0));
            }
        }
        3 => {
            if let Some(g) = cdr_decode::<FollowJointTrajectoryGoal, BO>(body) {
                let clock = kerf_trajectory_executor::convert::Clock::start();
                if let Ok((req, tol)) = kerf_trajectory_executor::convert::goal_request(&g, &clock)
                {
                    check_request(&g.trajectory, &req);
                    assert!(tol.goal_time.is_finite(), "goal time tolerance not finite");
                }
            }
        }
        4 => {
            if let Some(r) = cdr_decode::<ValidateTrajectoryRequest, BO>(body) {
                trajectory_of(&r.trajectory, usize::from(kind & 0x40 != 0));
            }
        }
        _ => {
            // A text request topic: the string goes to both text parsers.
            if let Some(s) = cdr_decode::<StringMsg, BO>(body) {
                cut_text(s.data.as_bytes());
                mill_text(s.data.as_bytes());
            }
        }
    }
}

/// CDR bytes of a message as a kerf node's subscription receives them: the first byte picks
/// the type (its value mod 6: `CutRequest`, `MillRequest`, `JointTrajectory`,
/// `FollowJointTrajectory` goal, `ValidateTrajectory` request, `std_msgs/String`; bit 6 the
/// robot; bit 7 big-endian), the rest is the CDR body. A decoded message goes through the
/// conversion its node applies.
pub fn cdr(data: &[u8]) {
    let Some((&kind, body)) = data.split_first() else {
        return;
    };
    if kind & 0x80 == 0 {
        cdr_in::<LittleEndian>(kind, body);
    } else {
        cdr_in::<BigEndian>(kind, body);
    }
}

// ---------------------------------------------------------------------------------------------
// G-code (issue 14)
// ---------------------------------------------------------------------------------------------

/// `kerf_gcode::Program` over the text (what `kerf plan gcode` and the node stream): every
/// motion read is finite, an arc's radius is positive and its end lies on its circle within
/// the reader's tolerance, and reading stops at the first error.
pub fn gcode_program(data: &[u8]) {
    use kerf_gcode::{Motion, Program, ReaderSettings};
    let text = text(data);
    let settings = ReaderSettings::default();
    let Ok(program) = Program::new(text.as_bytes(), settings) else {
        panic!("the default reader settings are refused");
    };
    let finite = |p: &[f64; 3]| p.iter().all(|v| v.is_finite());
    for m in program {
        match m {
            Ok(Motion::Rapid { start, end, .. }) => {
                assert!(finite(&start) && finite(&end), "a rapid is not finite");
            }
            Ok(Motion::Line {
                start, end, feed, ..
            }) => {
                assert!(finite(&start) && finite(&end), "a line is not finite");
                assert!(feed.is_finite() && feed > 0.0, "a line's feed is {feed}");
            }
            Ok(Motion::Arc { arc, feed, .. }) => {
                assert!(
                    finite(&arc.start) && finite(&arc.end) && finite(&arc.center),
                    "an arc is not finite"
                );
                assert!(
                    arc.radius.is_finite() && arc.radius > 0.0,
                    "arc radius {}",
                    arc.radius
                );
                assert!(arc.sweep.is_finite(), "arc sweep {}", arc.sweep);
                assert!(feed.is_finite() && feed > 0.0, "an arc's feed is {feed}");
            }
            Ok(Motion::Dwell { seconds, .. }) => {
                assert!(seconds.is_finite() && seconds >= 0.0, "dwell {seconds}");
            }
            Ok(_) => {}
            Err(e) => {
                drop(e.to_string());
                break;
            }
        }
    }
}

/// The G-code planner node's text request (`kerf_gcode_planner::text::parse_request`) and,
/// when it is accepted, its settings and the whole plan on the laser cutter under small limits
/// (200 lines, 2 000 points): a value or an error, never a panic; a plan's trajectory is
/// executable and its executed deviation within the interpolation tolerance.
pub fn gcode_text(data: &[u8]) {
    let text = text(data);
    let Ok(req) = kerf_gcode_planner::text::parse_request(&text) else {
        return;
    };
    let Ok(settings) = req.settings() else { return };
    if req.machine_kind() != Ok(kerf_gcodeplan::MachineKind::LaserCutter) {
        return;
    }
    let Ok(kerf_gcodeplan::ProgramSource::Text(program)) = req.source() else {
        return;
    };
    let settings = settings.with_max_lines(200).with_max_points(2_000);
    let Some(machine) = laser_sheet() else { return };
    if let Ok(plan) = kerf_gcodeplan::plan_program(
        program.as_bytes(),
        machine,
        &settings,
        &kerf_budget::Budget::unlimited(),
    ) {
        assert!(
            plan.max_interpolation_deviation <= settings.interpolation_tolerance(),
            "executed deviation {} over {}",
            plan.max_interpolation_deviation,
            settings.interpolation_tolerance()
        );
        assert!(
            plan.trajectory.points.len() <= 2_000,
            "{} points",
            plan.trajectory.points.len()
        );
    }
}

/// The shipped laser cutter over its default sheet, loaded once.
fn laser_sheet() -> Option<&'static kerf_gcodeplan::LaserSheet> {
    static SHEET: OnceLock<Option<kerf_gcodeplan::LaserSheet>> = OnceLock::new();
    SHEET
        .get_or_init(|| kerf_gcodeplan::LaserSheet::default_sheet().ok())
        .as_ref()
}
