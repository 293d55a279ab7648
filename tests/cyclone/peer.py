#!/usr/bin/env python3
"""End-to-end test of the kerf trajectory executor from an independent DDS implementation.

Cyclone DDS (Python binding, ``cyclonedds``) talks to the executor (RustDDS via ros2-client)
with the ROS 2 wire conventions only: topic names ``rt/...``, type names
``<pkg>::msg::dds_::<Type>_``, plain CDR structs exactly as ``rosidl`` defines them.

Scenario (every step bounded by a timeout):
  a. wait for ``/joint_states`` (discovery done) and record the start positions;
  b. send a valid trajectory (joints shuffled) and wait until the robot is at its target and a
     SUCCEEDED status arrives;
  c. send malformed trajectories (unknown joint, NaN, non-increasing times, over the velocity
     limit): each must be REJECTED with a message naming the problem, and the robot must not
     move;
  d. send a valid trajectory back to the start: the executor still serves.

Exit code 0 on success, 1 on a failed check (the reason is printed), 2 on bad arguments.

Usage (see tests/cyclone_e2e.rs)::

    CYCLONEDDS_URI=file://$PWD/tests/cyclone/cyclonedds.xml \\
        tests/cyclone/.venv/bin/python tests/cyclone/peer.py --domain 77 --urdf urdf/irb6660.urdf
"""

import argparse
import math
import os
import random
import sys
import time
from typing import Callable, Dict, List, Optional

from cyclonedds.core import Policy, Qos
from cyclonedds.domain import DomainParticipant
from cyclonedds.pub import DataWriter
from cyclonedds.sub import DataReader
from cyclonedds.topic import Topic
from cyclonedds.util import duration

from helpers import (
    run_checked,
    wait_until,
    JOINTS,
    POSITION_TOLERANCE,
    CheckFailed,
    choose_target,
    dur,
    read_limits,
    smooth_trajectory,
    stamp_ns,
)
from ros_types import (
    Header,
    JointState,
    JointTrajectory,
    JointTrajectoryPoint,
    TrajectoryStatus,
)

ACCEPTED, REJECTED, SUCCEEDED, ABORTED, PREEMPTED, CANCELED = 1, 2, 3, 4, 5, 6
STATUS_NAMES = {
    ACCEPTED: "ACCEPTED",
    REJECTED: "REJECTED",
    SUCCEEDED: "SUCCEEDED",
    ABORTED: "ABORTED",
    PREEMPTED: "PREEMPTED",
    CANCELED: "CANCELED",
}
INVALID_GOAL, INVALID_JOINTS = -1, -2


def log(msg: str) -> None:
    print(f"[peer {time.monotonic() - T0:7.3f}s] {msg}", flush=True)


def status_str(s: TrajectoryStatus) -> str:
    return (
        f"{STATUS_NAMES.get(s.status, s.status)} (code {s.error_code}, source '{s.source}'): "
        f"'{s.message}'"
    )


# ----- the DDS side --------------------------------------------------------------------------


class Peer:
    """One Cyclone participant with the three endpoints of the test."""

    def __init__(self, domain: int) -> None:
        self.dp = DomainParticipant(domain)
        reliable = Policy.Reliability.Reliable(duration(seconds=1))
        keep10 = Policy.History.KeepLast(10)
        t_traj = Topic(self.dp, "rt/trajectory_executor/joint_trajectory", JointTrajectory)
        t_js = Topic(self.dp, "rt/joint_states", JointState)
        t_status = Topic(self.dp, "rt/trajectory_executor/trajectory_status", TrajectoryStatus)
        self.traj_writer = DataWriter(
            self.dp, t_traj, qos=Qos(reliable, keep10, Policy.Durability.Volatile)
        )
        self.js_reader = DataReader(
            self.dp, t_js, qos=Qos(reliable, keep10, Policy.Durability.Volatile)
        )
        self.status_reader = DataReader(
            self.dp, t_status, qos=Qos(reliable, keep10, Policy.Durability.TransientLocal)
        )
        self.latest: Optional[Dict[str, float]] = None
        self.latest_stamp_ns = 0  # header.stamp of self.latest (executor clock)
        self.js_count = 0
        self.statuses: List[TrajectoryStatus] = []  # received, not yet consumed

    def pump(self) -> bool:
        """Takes everything available; True if anything arrived."""
        got = False
        for s in self.js_reader.take(N=256):
            if isinstance(s, JointState):
                got = True
                self.js_count += 1
                if len(s.name) != len(s.position):
                    raise CheckFailed(
                        f"/joint_states: {len(s.name)} names but {len(s.position)} positions"
                    )
                self.latest = dict(zip(s.name, s.position))
                self.latest_stamp_ns = stamp_ns(s.header.stamp)
        for s in self.status_reader.take(N=64):
            if isinstance(s, TrajectoryStatus):
                got = True
                log(f"status: {status_str(s)}")
                self.statuses.append(s)
        return got

    def wait_until(self, what: str, cond: Callable[[], bool], timeout: float) -> None:
        wait_until(self.pump, what, cond, timeout)

    def next_status(self, timeout: float) -> TrajectoryStatus:
        self.wait_until("a trajectory status", lambda: bool(self.statuses), timeout)
        return self.statuses.pop(0)

    def positions(self) -> Dict[str, float]:
        assert self.latest is not None
        return dict(self.latest)

    def send(self, traj: JointTrajectory) -> None:
        self.traj_writer.write(traj)
        # Reliable: returns once every matched reader (the executor) has acknowledged it.
        if not self.traj_writer.wait_for_acks(duration(seconds=5)):
            raise CheckFailed("the executor did not acknowledge the trajectory within 5 s")


# ----- scenario ------------------------------------------------------------------------------


def shuffled_joints(rng: random.Random) -> List[str]:
    order = list(JOINTS)
    for _ in range(100):
        rng.shuffle(order)
        if order != JOINTS and order != JOINTS[::-1]:
            break
    return order


def hold_trajectory(
    start: Dict[str, float], order: List[str], times: List[float]
) -> JointTrajectory:
    """Points that all stay at `start`, at the given times (to be broken by the caller)."""
    return JointTrajectory(
        header=Header(),
        joint_names=list(order),
        points=[
            JointTrajectoryPoint(
                positions=[start[j] for j in order],
                velocities=[0.0] * len(order),
                time_from_start=dur(t),
            )
            for t in times
        ],
    )


def move_and_check(peer: Peer, name: str, traj: JointTrajectory, goal: Dict[str, float]) -> None:
    log(f"{name}: sending {len(traj.points)} points, joints {traj.joint_names}")
    t0 = time.monotonic()
    peer.send(traj)
    st = peer.next_status(timeout=5)
    if st.status != ACCEPTED:
        raise CheckFailed(f"{name}: expected ACCEPTED, got {status_str(st)}")

    def arrived() -> bool:
        p = peer.latest or {}
        return all(abs(p.get(j, math.inf) - goal[j]) <= POSITION_TOLERANCE for j in JOINTS)

    try:
        peer.wait_until(f"{name}: the robot at {goal}", arrived, timeout=20)
    except CheckFailed as e:
        raise CheckFailed(f"{e}; last /joint_states positions {peer.latest}") from None
    log(f"{name}: at the target after {time.monotonic() - t0:.3f} s: {peer.positions()}")
    st = peer.next_status(timeout=10)
    if st.status != SUCCEEDED:
        raise CheckFailed(f"{name}: expected SUCCEEDED, got {status_str(st)}")
    # /joint_states and the status are separate streams: settle on a state sample produced a few
    # control cycles after the SUCCEEDED status, when the robot is at rest at the goal.
    settled = stamp_ns(st.header.stamp) + 20_000_000
    peer.wait_until(
        f"{name}: a /joint_states sample 20 ms after SUCCEEDED",
        lambda: peer.latest_stamp_ns >= settled,
        timeout=5,
    )
    p = peer.positions()
    off = {j: p[j] - goal[j] for j in JOINTS if abs(p[j] - goal[j]) > POSITION_TOLERANCE}
    if off:
        raise CheckFailed(f"{name}: after SUCCEEDED, joints off the goal by {off}")


def reject_and_check(
    peer: Peer,
    name: str,
    traj: JointTrajectory,
    code: int,
    must_contain: List[str],
) -> str:
    before = peer.positions()
    log(f"{name}: sending a malformed trajectory")
    peer.send(traj)
    st = peer.next_status(timeout=5)
    if st.status != REJECTED:
        raise CheckFailed(f"{name}: expected REJECTED, got {status_str(st)}")
    if st.error_code != code:
        raise CheckFailed(f"{name}: expected error code {code}, got {status_str(st)}")
    missing = [s for s in must_contain if s not in st.message]
    if missing:
        raise CheckFailed(f"{name}: the message lacks {missing}: '{st.message}'")
    # The robot must not move: watch /joint_states for a while.
    count0 = peer.js_count
    deadline = time.monotonic() + 0.4
    worst = 0.0
    while time.monotonic() < deadline:
        peer.pump()
        p = peer.positions()
        worst = max(worst, max(abs(p[j] - before[j]) for j in JOINTS))
        if peer.statuses:
            raise CheckFailed(f"{name}: unexpected status {status_str(peer.statuses[0])}")
        time.sleep(0.005)
    if peer.js_count - count0 < 20:
        raise CheckFailed(
            f"{name}: only {peer.js_count - count0} /joint_states samples in 0.4 s after the "
            f"rejection (expected ~100 at 250 Hz): did the executor stop?"
        )
    if worst > 1e-9:
        raise CheckFailed(f"{name}: the robot moved by {worst} rad after a rejected trajectory")
    return st.message


def scenario(args: argparse.Namespace) -> None:
    limits = read_limits(args.urdf)
    rng = random.Random(args.seed)
    peer = Peer(args.domain)

    # a. discovery: /joint_states samples arrive.
    peer.wait_until(
        "the first /joint_states sample (discovery)",
        lambda: peer.latest is not None,
        timeout=args.discovery_timeout,
    )
    log(f"discovered: /joint_states arriving; start positions {peer.latest}")
    if sorted(peer.latest) != JOINTS:
        raise CheckFailed(f"/joint_states names {sorted(peer.latest)}, expected {JOINTS}")
    # The trajectory writer must be matched with the executor's subscription, else the
    # (volatile) sample would be lost.
    peer.wait_until(
        "the executor's joint_trajectory subscription to match",
        lambda: peer.traj_writer.get_publication_matched_status().current_count > 0,
        timeout=args.discovery_timeout,
    )
    log("discovered: joint_trajectory writer matched")
    n_js = len(peer.js_reader.get_matched_publications())
    n_traj = peer.traj_writer.get_publication_matched_status().current_count
    if n_js != 1 or n_traj != 1:
        raise CheckFailed(
            f"domain {args.domain} has {n_js} /joint_states publisher(s) and {n_traj} "
            f"joint_trajectory subscriber(s), expected 1 each: is another test using this "
            f"domain? (choose another one)"
        )
    # Statuses already latched (there should be none for a fresh executor) are not ours.
    time.sleep(0.2)
    peer.pump()
    if peer.statuses:
        log(f"ignoring {len(peer.statuses)} latched status(es) from before this run")
        peer.statuses.clear()
    start = peer.positions()

    # b. a valid trajectory, joints shuffled.
    order = shuffled_joints(rng)
    target = choose_target(start, limits)
    move_and_check(peer, "valid #1", smooth_trajectory(start, target, order, 2.0), target)
    here = peer.positions()

    # c. malformed trajectories.
    seen = {}
    t = hold_trajectory(here, order, [0.5, 1.0])
    t.joint_names[order.index("joint_3")] = "elbow_joint"
    seen["unknown joint"] = reject_and_check(
        peer, "unknown joint", t, INVALID_JOINTS, ["unknown joint", "'elbow_joint'"]
    )

    t = hold_trajectory(here, order, [0.5, 1.0])
    t.points[1].positions[order.index("joint_4")] = math.nan
    seen["NaN position"] = reject_and_check(
        peer, "NaN position", t, INVALID_GOAL, ["points[1].positions", "joint joint_4", "NaN", "finite"]
    )

    t = hold_trajectory(here, order, [0.5, 1.0, 1.0])
    seen["non-increasing times"] = reject_and_check(
        peer, "non-increasing times", t, INVALID_GOAL, ["point 2", "strictly increase"]
    )

    # joint_1 jumps 1.5 rad in 0.5 s between waypoints 0 and 1 (cubic, at rest at both ends):
    # peak 4.5 rad/s, over the limit of ~1.92 rad/s.
    lim = limits["joint_1"]
    jump = 1.5 if here["joint_1"] <= (lim.lower + lim.upper) / 2 else -1.5
    t = hold_trajectory(here, order, [1.0, 1.5])
    t.points[1].positions[order.index("joint_1")] = here["joint_1"] + jump
    seen["over the velocity limit"] = reject_and_check(
        peer,
        "over the velocity limit",
        t,
        INVALID_GOAL,
        ["joint 'joint_1'", "velocity", "between point 0 and point 1", "exceeds the limit"],
    )

    # d. still serving: back to the start, in another joint order.
    order2 = shuffled_joints(rng)
    move_and_check(peer, "valid #2", smooth_trajectory(here, start, order2, 2.0), start)

    log("rejection messages seen:")
    for k, v in seen.items():
        log(f"  {k}: {v}")


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--domain", type=int, default=int(os.environ.get("ROS_DOMAIN_ID", "-1")))
    ap.add_argument("--urdf", required=True, help="the robot URDF the executor runs with")
    ap.add_argument("--seed", type=int, default=6660, help="seed of the joint-order shuffles")
    ap.add_argument("--discovery-timeout", type=float, default=20.0)
    args = ap.parse_args()
    return run_checked("peer.py", args, scenario, log, T0)


T0 = time.monotonic()

if __name__ == "__main__":
    sys.exit(main())
