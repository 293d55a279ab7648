//! ROS-free trajectory executor core: validation, interpolation, tolerances, motion state machine
