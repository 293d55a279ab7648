#!/usr/bin/env python3
"""Print a kerf cut request file (crates/mjto/cases/*.yaml, the schema of
kerf_mjto::CutRequest) as the YAML of a kerf_msgs/msg/CutRequest, for

    ros2 topic pub --once -w 1 /mjto_planner/cut_request kerf_msgs/msg/CutRequest \
      "$(python3 launch_scripts/cut_request_msg.py crates/mjto/cases/case1.yaml)"

Fields map one to one (SI units); the GFD grid is flattened into gfd_*; the
planner weights have no message field and must be the defaults (the script
refuses a file that changes them); `start` (current, none or a list of joint
positions) becomes start and start_positions. Needs PyYAML (Debian: python3-yaml).
"""
import json
import sys

import yaml

DEFAULT_WEIGHTS = {"k1": 1.0, "k2": 0.5, "k4": 1.0, "k5": 1.0, "k6": 100.0}


def start_fields(path, start):
    """The message's start and start_positions of a file's `start` (issue 27): left out,
    current, none, or a list of joint positions (given)."""
    if start is None or start == "":
        return "", []
    if start in ("current", "none"):
        return start, []
    if isinstance(start, list) and start and all(
        isinstance(v, (int, float)) and not isinstance(v, bool) for v in start
    ):
        return "given", [float(v) for v in start]
    sys.exit(f"{path}: start: {start!r} must be current, none or a list of joint positions")


def main(path):
    with open(path) as f:
        r = yaml.safe_load(f)
    o = r.get("options", {}) or {}
    weights = o.get("weights", DEFAULT_WEIGHTS)
    if any(abs(weights.get(k, v) - v) > 1e-12 for k, v in DEFAULT_WEIGHTS.items()):
        sys.exit(f"{path}: options.weights differ from the defaults; CutRequest has no field for them")
    g = o.get("gfd", {}) or {}
    pose = r.get("workpiece_pose", {"position": [0, 0, 0], "orientation": [0, 0, 0, 1]})
    msg = {
        "request_id": r.get("request_id", ""),
        "points": [dict(zip("xyz", p)) for p in r["points"]],
        "axes": [dict(zip("xyz", a)) for a in r["axes"]],
        "feedrate": r["feedrate"],
        "feed_acceleration": r.get("feed_acceleration", 0.0),
        "feed_jerk": r.get("feed_jerk", 0.0),
        "sample_period": r["sample_period"],
        "max_lead_angle": r["max_lead_angle"],
        "max_tilt_angle": r["max_tilt_angle"],
        "mesh": r["mesh"],
        "workpiece_pose": {
            "position": dict(zip("xyz", pose["position"])),
            "orientation": dict(zip("xyzw", pose["orientation"])),
        },
        "control_points": o.get("control_points", 0),
        "max_iterations": o.get("max_iterations", 0),
        "gfd_q4_steps": g.get("q4_steps", 0),
        "gfd_q5_steps": g.get("q5_steps", 0),
        "gfd_q6_steps": g.get("q6_steps", 0),
        "gfd_q4_half_range": g.get("q4_half_range", 0.0),
        "gfd_q5_half_range": g.get("q5_half_range", 0.0),
        "rto_indices": o.get("rto_indices", []),
        "rto_spacing": o.get("rto_spacing", 0.0),
        "rto_angle": o.get("rto_angle", 0.0),
        "has_reference_standoff": "reference_standoff" in o,
        "reference_standoff": o.get("reference_standoff", 0.0),
        "clearance": o.get("clearance", 0.0),
        "cl_tolerance": o.get("cl_tolerance", 0.0),
        "feed_law": o.get("feed_law", ""),
        "rto_constraint": o.get("rto_constraint", ""),
        "orientation_corridor": o.get("orientation_corridor", ""),
        "time_budget": r.get("time_budget", 0.0),
    }
    msg["start"], msg["start_positions"] = start_fields(path, r.get("start"))
    # JSON is valid YAML, and ros2 topic pub reads it on one line.
    print(json.dumps(msg))


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit("usage: cut_request_msg.py REQUEST.yaml")
    main(sys.argv[1])
