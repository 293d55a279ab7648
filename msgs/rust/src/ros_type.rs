//! The [`RosType`] trait: the ROS 2 type name of each mirror.

/// The three kinds of ROS 2 interface files.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum InterfaceKind {
    /// A message, `<package>/msg/<Name>.msg`.
    Msg,
    /// A service, `<package>/srv/<Name>.srv` (request `---` response).
    Srv,
    /// An action, `<package>/action/<Name>.action` (goal `---` result `---` feedback).
    Action,
}

impl InterfaceKind {
    /// The directory and type-name infix of this kind: `"msg"`, `"srv"` or `"action"`.
    pub const fn as_str(self) -> &'static str {
        match self {
            InterfaceKind::Msg => "msg",
            InterfaceKind::Srv => "srv",
            InterfaceKind::Action => "action",
        }
    }
}

/// A Rust mirror of a ROS 2 interface type.
///
/// The names follow the ROS 2 conventions of `rosidl`: service parts are
/// `<Service>_Request` / `<Service>_Response`, action parts are
/// `<Action>_Goal`, `<Action>_Result` and `<Action>_Feedback`.
pub trait RosType {
    /// The ROS 2 package, e.g. `"trajectory_msgs"`.
    const PACKAGE: &'static str;
    /// The interface kind the type comes from.
    const KIND: InterfaceKind;
    /// The type name within the package, e.g. `"JointTrajectory"` or
    /// `"FollowJointTrajectory_Goal"`.
    const NAME: &'static str;
    /// The full ROS 2 type name `<package>/<kind>/<name>`, e.g.
    /// `"trajectory_msgs/msg/JointTrajectory"`.
    const ROS_TYPE: &'static str;

    /// The type name used on DDS: `<package>::<kind>::dds_::<name>_`, e.g.
    /// `"trajectory_msgs::msg::dds_::JointTrajectory_"`. Source: the ROS 2
    /// design article "Topic and Service name mapping to DDS" and
    /// `rosidl_typesupport_fastrtps`, as ros2-client 0.12 `MessageTypeName::dds_msg_type` builds it.
    fn dds_type_name() -> String {
        format!(
            "{}::{}::dds_::{}_",
            Self::PACKAGE,
            Self::KIND.as_str(),
            Self::NAME
        )
    }
}

/// Implements [`RosType`] (and, with the `ros2` feature, `ros2_client::Message`)
/// for a mirror: `impl_ros_type!(Type, "package", msg, "Name")`.
macro_rules! impl_ros_type {
    ($ty:ty, $package:literal, msg, $name:literal) => {
        $crate::ros_type::impl_ros_type!(@impl $ty, $package, msg, Msg, $name);
    };
    ($ty:ty, $package:literal, srv, $name:literal) => {
        $crate::ros_type::impl_ros_type!(@impl $ty, $package, srv, Srv, $name);
    };
    ($ty:ty, $package:literal, action, $name:literal) => {
        $crate::ros_type::impl_ros_type!(@impl $ty, $package, action, Action, $name);
    };
    (@impl $ty:ty, $package:literal, $kind:ident, $variant:ident, $name:literal) => {
        impl $crate::RosType for $ty {
            const PACKAGE: &'static str = $package;
            const KIND: $crate::InterfaceKind = $crate::InterfaceKind::$variant;
            const NAME: &'static str = $name;
            const ROS_TYPE: &'static str = concat!($package, "/", stringify!($kind), "/", $name);
        }

        #[cfg(feature = "ros2")]
        impl ros2_client::Message for $ty {}
    };
}
pub(crate) use impl_ros_type;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{control_msgs, srv, trajectory_msgs};

    #[test]
    fn names_of_a_message() {
        type T = trajectory_msgs::JointTrajectory;
        assert_eq!(T::ROS_TYPE, "trajectory_msgs/msg/JointTrajectory");
        assert_eq!(
            T::dds_type_name(),
            "trajectory_msgs::msg::dds_::JointTrajectory_"
        );
    }

    #[test]
    fn names_of_service_and_action_parts() {
        assert_eq!(
            srv::ValidateTrajectoryRequest::ROS_TYPE,
            "kerf_msgs/srv/ValidateTrajectory_Request"
        );
        assert_eq!(
            srv::ValidateTrajectoryResponse::dds_type_name(),
            "kerf_msgs::srv::dds_::ValidateTrajectory_Response_"
        );
        assert_eq!(
            control_msgs::FollowJointTrajectoryGoal::ROS_TYPE,
            "control_msgs/action/FollowJointTrajectory_Goal"
        );
        assert_eq!(
            control_msgs::FollowJointTrajectoryFeedback::dds_type_name(),
            "control_msgs::action::dds_::FollowJointTrajectory_Feedback_"
        );
        assert_eq!(
            crate::action::PlanCutGoal::ROS_TYPE,
            "kerf_msgs/action/PlanCut_Goal"
        );
    }

    /// With the `ros2` feature the mirrors are `ros2_client::Message`s (a
    /// compile-time check: this does not build if one is not).
    #[cfg(feature = "ros2")]
    #[test]
    fn mirrors_are_ros2_client_messages() {
        fn message_type_name<T: ros2_client::Message + RosType>() -> ros2_client::MessageTypeName {
            ros2_client::MessageTypeName::new(T::PACKAGE, T::NAME)
        }
        let name = message_type_name::<crate::msg::TrajectoryStatus>();
        assert_eq!(
            name.dds_msg_type(),
            crate::msg::TrajectoryStatus::dds_type_name()
        );
        message_type_name::<control_msgs::FollowJointTrajectoryGoal>();
        message_type_name::<control_msgs::FollowJointTrajectoryResult>();
        message_type_name::<control_msgs::FollowJointTrajectoryFeedback>();
        message_type_name::<srv::ValidateTrajectoryRequest>();
        message_type_name::<srv::ValidateTrajectoryResponse>();
        message_type_name::<crate::action::PlanCutGoal>();
        message_type_name::<crate::action::PlanMillResult>();
        message_type_name::<crate::action::PlanGcodeFeedback>();
    }
}
