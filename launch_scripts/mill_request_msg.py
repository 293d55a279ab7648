#!/usr/bin/env python3
"""Print a kerf milling request file (the YAML/JSON schema of kerf_millplan::MillRequest, as
read by the milling planner's ~/mill_request_text and `kerf plan mill`) as the YAML of a
kerf_msgs/msg/MillRequest, for

    ros2 topic pub --once -w 1 /milling_planner/mill_request kerf_msgs/msg/MillRequest \
      "$(python3 launch_scripts/mill_request_msg.py request.yaml)"

Fields map one to one (SI units, rpm where named). The message takes each group (process,
limits, initial state) whole behind its has_* flag: a file's `process` must give all seven
fields (as the schema requires), its `limits` all three ranges and all three step bounds (the
message has no per-field default; the script refuses a partial `limits`), and missing fields
of `initial` take seed 004's initial value problem (2000 rpm, 0.04 m/s, 0 rad), as the
planner does; a missing field of `tolerances` takes the planner's (path_tolerance 5e-5 m,
min_condition_indicator 0 = no minimum). Needs PyYAML (Debian: python3-yaml).
"""
import json
import sys

import yaml

FIELDS = {
    "request_id", "points", "segments", "process", "limits", "initial", "planner", "policy_file",
    "time_budget", "tolerances", "start", "allow_chatter", "entry",
}
PROCESS = ["teeth", "tool_radius", "axial_depth", "kt", "kn", "entry_angle", "exit_angle"]
INITIAL = {"spindle_rpm": 2000.0, "feed": 0.04, "g": 0.0}
TOLERANCES = {"path_tolerance": 5e-5, "min_condition_indicator": 0.0}


def fail(path, why):
    sys.exit(f"{path}: {why}")


def num(path, name, v):
    """A number of the file; PyYAML (YAML 1.1) reads 6.44e8 as a string, YAML 1.2 as a float."""
    if isinstance(v, bool):
        fail(path, f"{name}: {v!r} is not a number")
    if isinstance(v, (int, float)):
        return v
    try:
        return float(v)
    except (TypeError, ValueError):
        fail(path, f"{name}: {v!r} is not a number")


def main(path):
    with open(path) as f:
        r = yaml.safe_load(f)
    if not isinstance(r, dict):
        fail(path, "not a YAML mapping")
    unknown = sorted(set(r) - FIELDS)
    if unknown:
        fail(path, f"unknown field(s) {', '.join(unknown)}; the fields are {', '.join(sorted(FIELDS))}")
    if "points" not in r:
        fail(path, "missing field points")
    msg = {
        "request_id": r.get("request_id", ""),
        "points": [
            {c: num(path, f"points[{i}]", v) for c, v in zip("xyz", p)} for i, p in enumerate(r["points"])
        ],
        "segments": r.get("segments", 0),
        "has_process": "process" in r,
        "has_limits": "limits" in r,
        "has_initial_state": "initial" in r,
        "planner": r.get("planner", "best"),
        "policy_file": r.get("policy_file", ""),
        "time_budget": num(path, "time_budget", r.get("time_budget", 0.0)),
        "has_tolerances": "tolerances" in r,
    }
    # Issue 28: answer a plan that chatters as executed; where the tool enters the material.
    allow = r.get("allow_chatter", False)
    if not isinstance(allow, bool):
        fail(path, f"allow_chatter: {allow!r} must be true or false")
    entry = r.get("entry", "")
    if entry not in ("", "run_in", "in_material"):
        fail(path, f"entry: {entry!r} must be run_in or in_material")
    msg["allow_chatter"], msg["entry"] = allow, entry
    # Issue 27: where the trajectory starts: left out, current, none, or joint positions.
    start = r.get("start")
    if start is None or start == "":
        msg["start"], msg["start_positions"] = "", []
    elif start in ("current", "none"):
        msg["start"], msg["start_positions"] = start, []
    elif isinstance(start, list) and start:
        msg["start"] = "given"
        msg["start_positions"] = [num(path, f"start[{i}]", v) for i, v in enumerate(start)]
    else:
        fail(path, f"start: {start!r} must be current, none or a list of joint positions")
    # Every field, so the message is complete also for readers without defaults; the fields
    # of a group whose flag is false are ignored by the node.
    zeros = PROCESS + [
        "spindle_min_rpm", "spindle_max_rpm", "feed_min", "feed_max", "g_min", "g_max",
        "max_spindle_step_rpm", "max_feed_step", "max_g_step",
        "initial_spindle_rpm", "initial_feed", "initial_g",
        "path_tolerance", "min_condition_indicator",
    ]
    msg.update({k: 0 if k == "teeth" else 0.0 for k in zeros})
    if "process" in r:
        p = r["process"] or {}
        missing = [k for k in PROCESS if k not in p]
        if missing:
            fail(path, f"process lacks {', '.join(missing)}")
        msg.update({k: num(path, f"process.{k}", p[k]) for k in PROCESS})
    if "limits" in r:
        lim = r["limits"] or {}
        steps = lim.get("step_bounds") or {}
        missing = [k for k in ("spindle_rpm", "feed", "redundancy_angle") if k not in lim]
        missing += [f"step_bounds.{k}" for k in ("spindle_rpm", "feed", "redundancy_angle") if k not in steps]
        if missing:
            fail(path, f"limits lacks {', '.join(missing)}: the message takes the limits group whole "
                       "(give every field, or leave limits out for the cell's)")
        for k in ("spindle_rpm", "feed", "redundancy_angle"):
            if not isinstance(lim[k], list) or len(lim[k]) != 2:
                fail(path, f"limits.{k}: {lim[k]!r} is not [min, max]")
        msg.update({
            "spindle_min_rpm": num(path, "limits.spindle_rpm[0]", lim["spindle_rpm"][0]),
            "spindle_max_rpm": num(path, "limits.spindle_rpm[1]", lim["spindle_rpm"][1]),
            "feed_min": num(path, "limits.feed[0]", lim["feed"][0]),
            "feed_max": num(path, "limits.feed[1]", lim["feed"][1]),
            "g_min": num(path, "limits.redundancy_angle[0]", lim["redundancy_angle"][0]),
            "g_max": num(path, "limits.redundancy_angle[1]", lim["redundancy_angle"][1]),
            "max_spindle_step_rpm": num(path, "limits.step_bounds.spindle_rpm", steps["spindle_rpm"]),
            "max_feed_step": num(path, "limits.step_bounds.feed", steps["feed"]),
            "max_g_step": num(path, "limits.step_bounds.redundancy_angle", steps["redundancy_angle"]),
        })
    if "initial" in r:
        i = r["initial"] or {}
        unknown = sorted(set(i) - set(INITIAL))
        if unknown:
            fail(path, f"initial: unknown field(s) {', '.join(unknown)}")
        msg.update({f"initial_{k}": num(path, f"initial.{k}", i.get(k, d))
                    for k, d in INITIAL.items()})
    if "tolerances" in r:
        t = r["tolerances"] or {}
        unknown = sorted(set(t) - set(TOLERANCES))
        if unknown:
            fail(path, f"tolerances: unknown field(s) {', '.join(unknown)}")
        msg.update({k: num(path, f"tolerances.{k}", t.get(k, d)) for k, d in TOLERANCES.items()})
    # JSON is valid YAML, and ros2 topic pub reads it on one line.
    print(json.dumps(msg))


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit("usage: mill_request_msg.py REQUEST.yaml")
    main(sys.argv[1])
