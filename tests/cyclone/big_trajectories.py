#!/usr/bin/env python3
"""Sends 10^6-point trajectories to the kerf trajectory executor from Cyclone DDS, while the
robot moves (tests/cyclone_e2e.rs drives the motion and checks /joint_states).

Cyclone sends a 128 MB sample in seconds; RustDDS's own writer does not (issue 11, item 6), so
the large trajectories of the control-loop test come from here. The executor runs with
``ServiceMapping::Cyclone`` (rmw_cyclonedds_cpp's request/reply mapping, see
action_client.py, whose client this script reuses).

Scenario (every step bounded by a timeout):
  a. discovery: /joint_states arrives, the action server is available, the trajectory topic's
     reader is matched; then joint_1 moves (tests/cyclone_e2e.rs swings it);
  b. a FollowJointTrajectory goal of 10^6 points whose last point lies past joint_1's position
     limit: accepted, then ABORTED with an error_string naming point 999999;
  c. the same trajectory on the topic, then a valid 10^6-point trajectory (a 3 s start segment
     to joint_1 = 1 rad at rest, then a slow swing of joint_1, points every 1 ms, 1000 s); both
     acknowledged by the executor's reader. tests/cyclone_e2e.rs checks the statuses.

Exit code 0 on success, 1 on a failed check, 2 on bad arguments.

Usage::

    CYCLONEDDS_URI=file://$PWD/tests/cyclone/cyclonedds.xml \\
        tests/cyclone/.venv/bin/python tests/cyclone/big_trajectories.py --domain 51
"""

import argparse
import math
import os
import sys
import time
import uuid as uuidlib

from cyclonedds.core import Policy, Qos
from cyclonedds.pub import DataWriter
from cyclonedds.topic import Topic
from cyclonedds.util import duration

from action_client import ActionClient, SendGoalRequest, discover, result_str
from helpers import JOINTS, CheckFailed, dur, run_checked
from ros_types import (
    STATUS_ABORTED,
    UUID,
    FollowJointTrajectoryGoal,
    Header,
    JointTrajectory,
    JointTrajectoryPoint,
)

POINTS = 1_000_000
T0 = time.monotonic()


def log(msg: str) -> None:
    print(f"[big_trajectories {time.monotonic() - T0:7.3f}] {msg}", flush=True)


def big_points(bad_last_point: bool):
    """10^6 points every 1 ms after a 3 s start: joint_1 on 1 + 0.3 (1 - cos w s), w such that
    100 full swings fit, ending at rest (|v| <= 0.19 rad/s)."""
    t0 = 3.0
    n = POINTS
    w = 2.0 * math.pi / (0.001 * (n - 1)) * 100.0
    zeros5 = [0.0] * 5
    pts = []
    for k in range(n):
        s = 0.001 * k
        q = 1.0 + 0.3 * (1.0 - math.cos(w * s))
        v = 0.0 if k == n - 1 else 0.3 * w * math.sin(w * s)
        pts.append(
            JointTrajectoryPoint(
                positions=[q] + zeros5,
                velocities=[v] + zeros5,
                time_from_start=dur(t0 + s),
            )
        )
    if bad_last_point:
        last = pts[-1]
        pts[-1] = JointTrajectoryPoint(
            positions=[4.0] + zeros5,
            velocities=last.velocities,
            time_from_start=last.time_from_start,
        )
    return pts


def trajectory(points) -> JointTrajectory:
    return JointTrajectory(header=Header(), joint_names=list(JOINTS), points=points)


def scenario(args) -> None:
    c = ActionClient(args.domain)
    qos = Qos(
        Policy.Reliability.Reliable(duration(seconds=10)),
        Policy.History.KeepAll,
        Policy.Durability.Volatile,
    )
    topic = DataWriter(
        c.dp, Topic(c.dp, "rt/trajectory_executor/joint_trajectory", JointTrajectory), qos=qos
    )
    discover(c, args.discovery_timeout)
    c.wait_until(
        "the trajectory topic's reader",
        lambda: topic.get_publication_matched_status().current_count > 0,
        args.discovery_timeout,
    )

    t = time.monotonic()
    bad = big_points(bad_last_point=True)
    log(f"built {POINTS} points in {time.monotonic() - t:.1f} s")
    # The test process swings joint_1; send while the robot moves.
    c.wait_until(
        "joint_1 moving",
        lambda: abs(c.velocities.get("joint_1", 0.0)) > 0.2,
        args.discovery_timeout,
    )

    # b. by action
    t = time.monotonic()
    goal_ids = []

    def make(h):
        goal_ids.append(uuidlib.uuid4().bytes)
        c.record(goal_ids[-1])
        return SendGoalRequest(
            header=h,
            goal_id=UUID(uuid=goal_ids[-1]),
            goal=FollowJointTrajectoryGoal(trajectory=trajectory(bad)),
        )

    # The reply comes once the executor has received and read 128 MB.
    resp = c.call(c.send_goal_srv, make, timeout=args.timeout)
    goal_id = goal_ids[-1]
    log(f"goal of {POINTS} points answered after {time.monotonic() - t:.1f} s "
        f"(accepted {resp.accepted})")
    seq = c.request_result(goal_id)
    r = c.wait_result(seq, timeout=args.timeout)
    log(f"goal result after {time.monotonic() - t:.1f} s: {result_str(r)}")
    if r.status != STATUS_ABORTED or "999999" not in r.result.error_string:
        raise CheckFailed(f"expected ABORTED naming point 999999, got {result_str(r)}")

    # c. by topic: the invalid one, then a valid one
    t = time.monotonic()
    topic.write(trajectory(bad))
    log(f"invalid trajectory written in {time.monotonic() - t:.1f} s")
    del bad
    good = big_points(bad_last_point=False)
    t = time.monotonic()
    topic.write(trajectory(good))
    log(f"valid trajectory written in {time.monotonic() - t:.1f} s")
    t = time.monotonic()
    topic.wait_for_acks(duration(seconds=args.timeout))
    log(f"both acknowledged after {time.monotonic() - t:.1f} s")


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--domain", type=int, default=int(os.environ.get("ROS_DOMAIN_ID", "-1")))
    ap.add_argument("--urdf", help="the robot URDF the executor runs with (not used)")
    ap.add_argument("--discovery-timeout", type=float, default=15.0)
    ap.add_argument("--timeout", type=float, default=120.0)
    args = ap.parse_args()
    if sys.byteorder != "little":
        print("big_trajectories.py: the request headers assume a little-endian host",
              file=sys.stderr)
        return 2
    return run_checked("big_trajectories.py", args, scenario, log, T0)


if __name__ == "__main__":
    sys.exit(main())
