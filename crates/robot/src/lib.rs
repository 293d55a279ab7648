//! Robot descriptions: URDF plus joint-limits YAML into a kinematic model
