"""ROS 2 (Jazzy) message types for the Cyclone DDS interop tests, field for field as rosidl
generates them, with their DDS type names (``<pkg>::msg::dds_::<Type>_``).

Shared by ``peer.py`` (topics) and ``action_client.py`` (the FollowJointTrajectory action).
Field lists follow ``msgs/rust/interfaces/`` (verbatim Jazzy definitions) and ``msgs/msg/``.
Service request/reply types are not here: their DDS form depends on the RMW's request/reply
mapping (see ``action_client.py``).
"""

from dataclasses import dataclass, field

from cyclonedds.idl import IdlStruct
from cyclonedds.idl.types import array, float64, int8, int32, sequence, uint8, uint16, uint32

# ----- builtin_interfaces, std_msgs ----------------------------------------------------------


@dataclass
class Time(IdlStruct, typename="builtin_interfaces::msg::dds_::Time_"):
    sec: int32 = 0
    nanosec: uint32 = 0


@dataclass
class Duration(IdlStruct, typename="builtin_interfaces::msg::dds_::Duration_"):
    sec: int32 = 0
    nanosec: uint32 = 0


@dataclass
class Header(IdlStruct, typename="std_msgs::msg::dds_::Header_"):
    stamp: Time = field(default_factory=Time)
    frame_id: str = ""


# ----- geometry_msgs -------------------------------------------------------------------------


@dataclass
class Vector3(IdlStruct, typename="geometry_msgs::msg::dds_::Vector3_"):
    x: float64 = 0.0
    y: float64 = 0.0
    z: float64 = 0.0


@dataclass
class Quaternion(IdlStruct, typename="geometry_msgs::msg::dds_::Quaternion_"):
    x: float64 = 0.0
    y: float64 = 0.0
    z: float64 = 0.0
    w: float64 = 1.0


@dataclass
class Transform(IdlStruct, typename="geometry_msgs::msg::dds_::Transform_"):
    translation: Vector3 = field(default_factory=Vector3)
    rotation: Quaternion = field(default_factory=Quaternion)


@dataclass
class Twist(IdlStruct, typename="geometry_msgs::msg::dds_::Twist_"):
    linear: Vector3 = field(default_factory=Vector3)
    angular: Vector3 = field(default_factory=Vector3)


# ----- trajectory_msgs, sensor_msgs ----------------------------------------------------------


@dataclass
class JointTrajectoryPoint(IdlStruct, typename="trajectory_msgs::msg::dds_::JointTrajectoryPoint_"):
    positions: sequence[float64] = field(default_factory=list)
    velocities: sequence[float64] = field(default_factory=list)
    accelerations: sequence[float64] = field(default_factory=list)
    effort: sequence[float64] = field(default_factory=list)
    time_from_start: Duration = field(default_factory=Duration)


@dataclass
class JointTrajectory(IdlStruct, typename="trajectory_msgs::msg::dds_::JointTrajectory_"):
    header: Header = field(default_factory=Header)
    joint_names: sequence[str] = field(default_factory=list)
    points: sequence[JointTrajectoryPoint] = field(default_factory=list)


@dataclass
class MultiDOFJointTrajectoryPoint(
    IdlStruct, typename="trajectory_msgs::msg::dds_::MultiDOFJointTrajectoryPoint_"
):
    transforms: sequence[Transform] = field(default_factory=list)
    velocities: sequence[Twist] = field(default_factory=list)
    accelerations: sequence[Twist] = field(default_factory=list)
    time_from_start: Duration = field(default_factory=Duration)


@dataclass
class MultiDOFJointTrajectory(
    IdlStruct, typename="trajectory_msgs::msg::dds_::MultiDOFJointTrajectory_"
):
    header: Header = field(default_factory=Header)
    joint_names: sequence[str] = field(default_factory=list)
    points: sequence[MultiDOFJointTrajectoryPoint] = field(default_factory=list)


@dataclass
class JointState(IdlStruct, typename="sensor_msgs::msg::dds_::JointState_"):
    header: Header = field(default_factory=Header)
    name: sequence[str] = field(default_factory=list)
    position: sequence[float64] = field(default_factory=list)
    velocity: sequence[float64] = field(default_factory=list)
    effort: sequence[float64] = field(default_factory=list)


# ----- kerf_msgs -----------------------------------------------------------------------------


@dataclass
class TrajectoryStatus(IdlStruct, typename="kerf_msgs::msg::dds_::TrajectoryStatus_"):
    header: Header = field(default_factory=Header)
    trajectory_stamp: Time = field(default_factory=Time)
    source: str = ""
    goal_id: str = ""
    status: uint8 = 0
    error_code: int32 = 0
    message: str = ""


# ----- unique_identifier_msgs, action_msgs ---------------------------------------------------


@dataclass
class UUID(IdlStruct, typename="unique_identifier_msgs::msg::dds_::UUID_"):
    uuid: array[uint8, 16] = field(default_factory=lambda: bytes(16))


@dataclass
class GoalInfo(IdlStruct, typename="action_msgs::msg::dds_::GoalInfo_"):
    goal_id: UUID = field(default_factory=UUID)
    stamp: Time = field(default_factory=Time)


@dataclass
class GoalStatus(IdlStruct, typename="action_msgs::msg::dds_::GoalStatus_"):
    goal_info: GoalInfo = field(default_factory=GoalInfo)
    status: int8 = 0


@dataclass
class GoalStatusArray(IdlStruct, typename="action_msgs::msg::dds_::GoalStatusArray_"):
    status_list: sequence[GoalStatus] = field(default_factory=list)


# action_msgs/msg/GoalStatus constants.
STATUS_UNKNOWN, STATUS_ACCEPTED, STATUS_EXECUTING, STATUS_CANCELING = 0, 1, 2, 3
STATUS_SUCCEEDED, STATUS_CANCELED, STATUS_ABORTED = 4, 5, 6
GOAL_STATUS_NAMES = {
    STATUS_UNKNOWN: "UNKNOWN",
    STATUS_ACCEPTED: "ACCEPTED",
    STATUS_EXECUTING: "EXECUTING",
    STATUS_CANCELING: "CANCELING",
    STATUS_SUCCEEDED: "SUCCEEDED",
    STATUS_CANCELED: "CANCELED",
    STATUS_ABORTED: "ABORTED",
}

# action_msgs/srv/CancelGoal response codes.
CANCEL_ERROR_NONE, CANCEL_ERROR_REJECTED, CANCEL_ERROR_UNKNOWN_GOAL_ID = 0, 1, 2
CANCEL_ERROR_GOAL_TERMINATED = 3


# ----- control_msgs --------------------------------------------------------------------------


@dataclass
class JointTolerance(IdlStruct, typename="control_msgs::msg::dds_::JointTolerance_"):
    name: str = ""
    position: float64 = 0.0
    velocity: float64 = 0.0
    acceleration: float64 = 0.0


@dataclass
class JointComponentTolerance(
    IdlStruct, typename="control_msgs::msg::dds_::JointComponentTolerance_"
):
    joint_name: str = ""
    component: uint16 = 0
    position: float64 = 0.0
    velocity: float64 = 0.0
    acceleration: float64 = 0.0


@dataclass
class FollowJointTrajectoryGoal(
    IdlStruct, typename="control_msgs::action::dds_::FollowJointTrajectory_Goal_"
):
    trajectory: JointTrajectory = field(default_factory=JointTrajectory)
    multi_dof_trajectory: MultiDOFJointTrajectory = field(default_factory=MultiDOFJointTrajectory)
    path_tolerance: sequence[JointTolerance] = field(default_factory=list)
    component_path_tolerance: sequence[JointComponentTolerance] = field(default_factory=list)
    goal_tolerance: sequence[JointTolerance] = field(default_factory=list)
    component_goal_tolerance: sequence[JointComponentTolerance] = field(default_factory=list)
    goal_time_tolerance: Duration = field(default_factory=Duration)


@dataclass
class FollowJointTrajectoryResult(
    IdlStruct, typename="control_msgs::action::dds_::FollowJointTrajectory_Result_"
):
    error_code: int32 = 0
    error_string: str = ""


# control_msgs/action/FollowJointTrajectory result codes.
SUCCESSFUL, INVALID_GOAL, INVALID_JOINTS, OLD_HEADER_TIMESTAMP = 0, -1, -2, -3
PATH_TOLERANCE_VIOLATED, GOAL_TOLERANCE_VIOLATED = -4, -5


@dataclass
class FollowJointTrajectoryFeedback(
    IdlStruct, typename="control_msgs::action::dds_::FollowJointTrajectory_Feedback_"
):
    header: Header = field(default_factory=Header)
    joint_names: sequence[str] = field(default_factory=list)
    desired: JointTrajectoryPoint = field(default_factory=JointTrajectoryPoint)
    actual: JointTrajectoryPoint = field(default_factory=JointTrajectoryPoint)
    error: JointTrajectoryPoint = field(default_factory=JointTrajectoryPoint)
    multi_dof_joint_names: sequence[str] = field(default_factory=list)
    multi_dof_desired: MultiDOFJointTrajectoryPoint = field(
        default_factory=MultiDOFJointTrajectoryPoint
    )
    multi_dof_actual: MultiDOFJointTrajectoryPoint = field(
        default_factory=MultiDOFJointTrajectoryPoint
    )
    multi_dof_error: MultiDOFJointTrajectoryPoint = field(
        default_factory=MultiDOFJointTrajectoryPoint
    )


@dataclass
class FollowJointTrajectoryFeedbackMessage(
    IdlStruct, typename="control_msgs::action::dds_::FollowJointTrajectory_FeedbackMessage_"
):
    goal_id: UUID = field(default_factory=UUID)
    feedback: FollowJointTrajectoryFeedback = field(default_factory=FollowJointTrajectoryFeedback)
