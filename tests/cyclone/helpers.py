"""Robot-side helpers shared by the Cyclone DDS interop scenarios (``peer.py``,
``action_client.py``): the IRB 6660's joints and limits from its URDF, and smooth test
trajectories."""

import xml.etree.ElementTree as ET
from dataclasses import dataclass
from typing import Dict, List

from ros_types import Duration, Header, JointTrajectory, JointTrajectoryPoint, Time

JOINTS = [f"joint_{i}" for i in range(1, 7)]
POSITION_TOLERANCE = 1e-3


class CheckFailed(Exception):
    """A check of the scenario failed; the message says which and why."""


def dur(seconds: float) -> Duration:
    ns = int(round(seconds * 1e9))
    return Duration(sec=ns // 1_000_000_000, nanosec=ns % 1_000_000_000)


def stamp_ns(t: Time) -> int:
    return t.sec * 1_000_000_000 + t.nanosec


@dataclass
class Limit:
    lower: float
    upper: float
    velocity: float


def read_limits(urdf: str) -> Dict[str, Limit]:
    root = ET.parse(urdf).getroot()
    out = {}
    for j in root.findall("joint"):
        lim = j.find("limit")
        if j.get("name") in JOINTS and lim is not None:
            out[j.get("name")] = Limit(
                float(lim.get("lower")), float(lim.get("upper")), float(lim.get("velocity"))
            )
    missing = [n for n in JOINTS if n not in out]
    if missing:
        raise CheckFailed(f"{urdf} has no <limit> for {missing}")
    return out


def smooth_trajectory(
    start: Dict[str, float], goal: Dict[str, float], order: List[str], total: float
) -> JointTrajectory:
    """Cubic smoothstep start → goal over `total` s, sampled at 1/4, 1/2 and 1 (ends at rest).

    The smoothstep is itself a cubic, so the executor's Hermite segments reproduce it: peak
    velocity 1.5 d / total, peak acceleration 6 d / total².
    """
    points = []
    for u in (0.25, 0.5, 1.0):
        s = 3 * u * u - 2 * u ** 3
        ds = 6 * u * (1 - u) / total
        points.append(
            JointTrajectoryPoint(
                positions=[start[j] + s * (goal[j] - start[j]) for j in order],
                velocities=[ds * (goal[j] - start[j]) for j in order],
                time_from_start=dur(u * total),
            )
        )
    return JointTrajectory(header=Header(), joint_names=list(order), points=points)


def choose_target(
    start: Dict[str, float], limits: Dict[str, Limit], scale: float = 1.0
) -> Dict[str, float]:
    """A distinct offset per joint (a joint mix-up would show), towards the middle of the range.

    The offsets are 0.22 … 0.50 rad, times `scale`.
    """
    offsets = dict(zip(JOINTS, (0.30, 0.22, 0.26, 0.40, 0.34, 0.50)))
    target = {}
    for j in JOINTS:
        lim = limits[j]
        d = scale * offsets[j]
        d = d if start[j] <= (lim.lower + lim.upper) / 2 else -d
        target[j] = start[j] + d
        if not lim.lower < target[j] < lim.upper:
            raise CheckFailed(f"cannot choose a target for {j} from {start[j]} within {lim}")
    return target


def run_checked(name, args, scenario, log, t0: float) -> int:
    """Common entry of the peer scripts.

    Refuses to run without a domain in 0..232 or without the loopback-only Cyclone config
    (CYCLONEDDS_URI), runs `scenario(args)`, and maps a CheckFailed to exit status 1.
    """
    import os
    import sys
    import time

    if not 0 <= args.domain <= 232:
        print(f"{name}: give --domain (or ROS_DOMAIN_ID) in 0..232", file=sys.stderr)
        return 2
    if not os.environ.get("CYCLONEDDS_URI"):
        print(
            f"{name}: CYCLONEDDS_URI is not set; refusing to run with Cyclone's default "
            "(multicast on every interface). Use tests/cyclone/cyclonedds.xml.",
            file=sys.stderr,
        )
        return 2
    log(f"domain {args.domain}, CYCLONEDDS_URI={os.environ['CYCLONEDDS_URI']}")
    try:
        scenario(args)
    except CheckFailed as e:
        log(f"FAILED: {e}")
        return 1
    log(f"PASSED in {time.monotonic() - t0:.3f} s")
    return 0


def wait_until(pump, what: str, cond, timeout: float) -> None:
    """Calls `pump()` every 2 ms until `cond()` holds; CheckFailed after `timeout` s."""
    import time

    deadline = time.monotonic() + timeout
    while True:
        pump()
        if cond():
            return
        if time.monotonic() > deadline:
            raise CheckFailed(f"timed out after {timeout:.1f} s waiting for {what}")
        time.sleep(0.002)
