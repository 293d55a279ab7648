//! Serde mirrors of the kerf_msgs ROS 2 interfaces and of the standard ROS 2 messages kerf uses
