//! ROS 2 plumbing shared by every kerf node
