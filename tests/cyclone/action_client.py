#!/usr/bin/env python3
"""A FollowJointTrajectory action client on Cyclone DDS that speaks rmw_cyclonedds_cpp's
request/reply mapping, against the kerf trajectory executor started with
``RMW_IMPLEMENTATION=rmw_cyclonedds_cpp`` (ros2-client's ``ServiceMapping::Cyclone``).

The rmw_cyclonedds mapping (Jazzy, ros2/rmw_cyclonedds branch ``jazzy``):
  * a service ``/s`` is the topic pair ``rq/sRequest`` / ``rr/sReply``, with the DDS type names
    ``<pkg>::srv::dds_::<Srv>_Request_`` / ``..._Response_`` (for an action's services
    ``<pkg>::action::dds_::<Action>_SendGoal_Request_`` etc.);
  * every request and every reply is the plain CDR of the rosidl struct, prefixed inside the
    serialized payload by ``cdds_request_header_t { uint64_t guid; int64_t seq; }``
    (``rmw_cyclonedds_cpp/src/serdata.hpp``), written as 16 raw bytes in the host's byte order
    right after the 4-byte encapsulation header, which says the same byte order
    (``Serialization.cpp``, ``serialize_top_level(cursor, const cdds_request_wrapper_t &)``);
  * a client sets ``guid`` to the DDS instance handle of its request writer and ``seq`` to a
    process-wide counter starting at 1 (``rmw_node.cpp``, ``rmw_send_request``: ``header.guid =
    info->client.pub->pubiid; header.seq = ++next_request_id``);
  * a server copies both fields back into its reply (``rmw_send_response``), and a client takes
    only replies whose ``guid`` is its own (``rmw_take_response_request``, ``srcfilter``);
  * a client deems the server available when its request writer has matched a reader and its
    reply reader has matched a writer (``check_for_service_reader_writer``: the fallback when
    the server's endpoints carry no ``serviceid`` user data, as RustDDS's do not).

This client does exactly that (one request writer + reply reader per service, header structs
that serialize to those 16 bytes: checked at start-up), and checks every reply's header against
its request byte for byte.

Scenario (every step bounded by a timeout):
  a. discovery: ``/joint_states`` arrives, the three services are available, the feedback and
     status topics are matched; probe get_result and cancel_goal with an unknown goal id
     (STATUS_UNKNOWN, ERROR_UNKNOWN_GOAL_ID), retrying until a reply arrives;
  b. a valid goal (joint_1..joint_6, 3 points with positions and velocities, at rest at the
     end, 1.5 s): accepted, SUCCEEDED with error_code 0, the robot at the target on
     ``/joint_states``, feedback for the goal with 6 joint names and 6 desired positions, and
     the status topic reporting SUCCEEDED;
  c. a goal with an unknown joint: accepted, then ABORTED with INVALID_JOINTS (-2) and an
     error_string naming the joint; the robot does not move;
  d. a 4 s goal canceled after ~1 s: the cancel reply lists the goal (ERROR_NONE), the result is
     CANCELED, and ``/joint_states`` comes to a standstill well before the target.

Exit code 0 on success, 1 on a failed check (the reason is printed), 2 on bad arguments.

Usage (see tests/cyclone_e2e.rs)::

    CYCLONEDDS_URI=file://$PWD/tests/cyclone/cyclonedds.xml \\
        tests/cyclone/.venv/bin/python tests/cyclone/action_client.py --domain 88 \\
        --urdf urdf/irb6660.urdf
"""

import argparse
import itertools
import os
import struct
import sys
import time
import uuid as uuidlib
from dataclasses import dataclass, field
from typing import Callable, Dict, List, Optional, Tuple

from cyclonedds.core import Policy, Qos
from cyclonedds.domain import DomainParticipant
from cyclonedds.idl import IdlStruct
from cyclonedds.idl.types import int8, int64, sequence, uint64
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
    Limit,
    choose_target,
    dur,
    read_limits,
    smooth_trajectory,
    stamp_ns,
)
from ros_types import (
    CANCEL_ERROR_NONE,
    CANCEL_ERROR_UNKNOWN_GOAL_ID,
    GOAL_STATUS_NAMES,
    INVALID_JOINTS,
    STATUS_ABORTED,
    STATUS_CANCELED,
    STATUS_SUCCEEDED,
    STATUS_UNKNOWN,
    SUCCESSFUL,
    UUID,
    FollowJointTrajectoryFeedbackMessage,
    FollowJointTrajectoryGoal,
    FollowJointTrajectoryResult,
    GoalInfo,
    GoalStatusArray,
    Header,
    JointState,
    JointTrajectory,
    JointTrajectoryPoint,
    Time,
)

ACTION = "/trajectory_executor/follow_joint_trajectory"


def log(msg: str) -> None:
    print(f"[action_client {time.monotonic() - T0:7.3f}s] {msg}", flush=True)


# ----- the rmw_cyclonedds request/reply mapping ----------------------------------------------


@dataclass
class CddsRequestHeader(IdlStruct, typename="rmw_cyclonedds::cdds_request_header_t"):
    """``cdds_request_header_t``: 8 + 8 bytes, 8-aligned at offset 0, so it serializes to the
    16 raw bytes rmw_cyclonedds puts in front of the request/reply struct."""

    guid: uint64 = 0
    seq: int64 = 0


@dataclass
class SendGoalRequest(
    IdlStruct, typename="control_msgs::action::dds_::FollowJointTrajectory_SendGoal_Request_"
):
    header: CddsRequestHeader = field(default_factory=CddsRequestHeader)
    goal_id: UUID = field(default_factory=UUID)
    goal: FollowJointTrajectoryGoal = field(default_factory=FollowJointTrajectoryGoal)


@dataclass
class SendGoalResponse(
    IdlStruct, typename="control_msgs::action::dds_::FollowJointTrajectory_SendGoal_Response_"
):
    header: CddsRequestHeader = field(default_factory=CddsRequestHeader)
    accepted: bool = False
    stamp: Time = field(default_factory=Time)


@dataclass
class GetResultRequest(
    IdlStruct, typename="control_msgs::action::dds_::FollowJointTrajectory_GetResult_Request_"
):
    header: CddsRequestHeader = field(default_factory=CddsRequestHeader)
    goal_id: UUID = field(default_factory=UUID)


@dataclass
class GetResultResponse(
    IdlStruct, typename="control_msgs::action::dds_::FollowJointTrajectory_GetResult_Response_"
):
    header: CddsRequestHeader = field(default_factory=CddsRequestHeader)
    status: int8 = 0
    result: FollowJointTrajectoryResult = field(default_factory=FollowJointTrajectoryResult)


@dataclass
class CancelGoalRequest(IdlStruct, typename="action_msgs::srv::dds_::CancelGoal_Request_"):
    header: CddsRequestHeader = field(default_factory=CddsRequestHeader)
    goal_info: GoalInfo = field(default_factory=GoalInfo)


@dataclass
class CancelGoalResponse(IdlStruct, typename="action_msgs::srv::dds_::CancelGoal_Response_"):
    header: CddsRequestHeader = field(default_factory=CddsRequestHeader)
    return_code: int8 = 0
    goals_canceling: sequence[GoalInfo] = field(default_factory=list)


def header_bytes(h: CddsRequestHeader) -> bytes:
    """The 16 bytes rmw_cyclonedds writes for a header on a little-endian host."""
    return struct.pack("<Qq", h.guid, h.seq)


def check_wire_layout() -> None:
    """The wrapper structs serialize exactly as rmw_cyclonedds lays a request out: CDR_LE
    encapsulation, the 16 header bytes, then the request struct, 8-aligned as if it started
    the payload."""
    h = CddsRequestHeader(guid=0x0123456789ABCDEF, seq=0x1122334455667788)
    goal_id = UUID(uuid=bytes(range(16)))
    wire = GetResultRequest(header=h, goal_id=goal_id).serialize()
    expected = b"\x00\x01\x00\x00" + header_bytes(h) + bytes(range(16))
    if wire != expected:
        raise CheckFailed(f"GetResult request layout {wire.hex()} != expected {expected.hex()}")
    # A struct whose first member needs 8-byte alignment must not be padded after the header.
    msg = SendGoalRequest(header=h, goal_id=goal_id)
    body = msg.serialize()
    if body[4:20] != header_bytes(h) or body[20:36] != bytes(range(16)):
        raise CheckFailed(f"SendGoal request layout unexpected: {body[:40].hex()}")


def csid_to_string(data: bytes) -> str:
    """``csid_to_string`` of rmw_node.cpp: hex bytes joined by '.', the first one `setw(2)`."""
    return f"{data[0]:2x}" + "".join(f".{b:x}" for b in data[1:])


def user_data_key(lookup, handle: int, key: str) -> Optional[str]:
    """`get_user_data_key` of rmw_node.cpp: the value of `key=value;` in a matched endpoint's
    user data, or None."""
    try:
        ep = lookup(handle)
    except Exception:  # the endpoint went away meanwhile
        return None
    if ep is None or Policy.Userdata not in ep.qos:
        return None
    for item in ep.qos[Policy.Userdata].data.decode(errors="replace").split(";"):
        k, sep, v = item.partition("=")
        if sep and k == key:
            return v
    return None


class RmwCycloneClient:
    """One service client with rmw_cyclonedds's endpoints and header handling."""

    # rmw_send_request: `static std::atomic_uint next_request_id; header.seq = ++next_request_id`
    # (one counter for every client of the process).
    _next_request_id = itertools.count(1)
    # get_unique_csid: participant GUID prefix + a per-context counter (big-endian).
    _next_csid = itertools.count(1)

    def __init__(self, dp: DomainParticipant, service: str, req_type, rep_type) -> None:
        self.service = service
        self.req_type = req_type
        self.rep_type = rep_type
        csid = dp.guid.bytes[:12] + struct.pack(">I", next(self._next_csid))
        # rmw_qos_profile_services_default; user data as rmw_cyclonedds sets it for a client.
        qos = Qos(
            Policy.Reliability.Reliable(duration(seconds=1)),
            Policy.History.KeepLast(10),
            Policy.Durability.Volatile,
            Policy.Userdata(f"clientid={csid_to_string(csid)};".encode()),
        )
        self.writer = DataWriter(dp, Topic(dp, f"rq{service}Request", req_type), qos=qos)
        self.reader = DataReader(dp, Topic(dp, f"rr{service}Reply", rep_type), qos=qos)
        # rmw_cyclonedds: pub->pubiid = dds_get_instance_handle(writer); header.guid = pubiid
        # (a uint64; the Python binding hands the handle out as a signed 64-bit int).
        self.guid = self.writer.get_instance_handle() & 0xFFFF_FFFF_FFFF_FFFF
        self.sent: Dict[int, Tuple[float, bytes]] = {}  # seq -> (time sent, header bytes)
        self.replies: Dict[int, Tuple[object, float]] = {}  # seq -> (reply, time received)
        self.foreign = 0  # replies for another client (guid differs): rmw drops them
        self.rtts: List[float] = []

    def available(self) -> Tuple[bool, str]:
        """rmw_service_server_is_available for this client (check_for_service_reader_writer):
        a matched request reader and a matched reply writer; if the readers advertise a
        `serviceid` in their user data (rmw_cyclonedds servers do, RustDDS's do not), a reply
        writer with one of those ids."""
        rds = self.writer.get_matched_subscriptions()
        wrs = self.reader.get_matched_publications()
        needles = set()
        for ih in rds:
            sid = user_data_key(self.writer.get_matched_subscription_data, ih, "serviceid")
            if sid is not None:
                needles.add(sid)
        counts = f"{len(rds)} request reader(s), {len(wrs)} reply writer(s)"
        if not needles:
            return bool(rds) and bool(wrs), f"{counts} (no serviceid: fallback rule)"
        ok = any(
            user_data_key(self.reader.get_matched_publication_data, ih, "serviceid") in needles
            for ih in wrs
        )
        return ok, f"{counts} (serviceid {sorted(needles)})"

    def send(self, make: Callable[[CddsRequestHeader], object]) -> int:
        seq = next(self._next_request_id)
        header = CddsRequestHeader(guid=self.guid, seq=seq)
        request = make(header)
        wire = request.serialize()
        if wire[4:20] != header_bytes(header):
            raise CheckFailed(f"{self.service}: request header bytes {wire[4:20].hex()}")
        self.sent[seq] = (time.monotonic(), wire[4:20])
        self.writer.write(request)
        return seq

    def pump(self) -> bool:
        got = False
        for s in self.reader.take(N=32):
            if not isinstance(s, self.rep_type):
                continue
            got = True
            now = time.monotonic()
            # rmw_take_response_request: srcfilter == wrap.header.guid, else dropped.
            if s.header.guid != self.guid:
                self.foreign += 1
                log(
                    f"{self.service}: reply for another client (guid {s.header.guid:#018x}, "
                    f"ours {self.guid:#018x}) dropped"
                )
                continue
            seq = s.header.seq
            if seq not in self.sent:
                raise CheckFailed(
                    f"{self.service}: reply with our guid but unknown seq {seq} "
                    f"(sent {sorted(self.sent)}): header {header_bytes(s.header).hex()}"
                )
            t_sent, sent_header = self.sent[seq]
            echoed = s.serialize()[4:20]
            if echoed != sent_header:
                raise CheckFailed(
                    f"{self.service}: reply header {echoed.hex()} != request header "
                    f"{sent_header.hex()}"
                )
            if seq in self.replies:
                raise CheckFailed(f"{self.service}: a second reply to seq {seq}")
            self.replies[seq] = (s, now)
            self.rtts.append(now - t_sent)
        return got


# ----- the client participant ----------------------------------------------------------------


@dataclass
class GoalRecord:
    feedback: List[FollowJointTrajectoryFeedbackMessage] = field(default_factory=list)
    statuses: List[int] = field(default_factory=list)  # distinct statuses seen on ~/status


def uuid_hex(u: bytes) -> str:
    return bytes(u).hex()


class ActionClient:
    def __init__(self, domain: int) -> None:
        self.dp = DomainParticipant(domain)
        base = f"{ACTION}/_action"
        self.send_goal_srv = RmwCycloneClient(
            self.dp, f"{base}/send_goal", SendGoalRequest, SendGoalResponse
        )
        self.get_result_srv = RmwCycloneClient(
            self.dp, f"{base}/get_result", GetResultRequest, GetResultResponse
        )
        self.cancel_srv = RmwCycloneClient(
            self.dp, f"{base}/cancel_goal", CancelGoalRequest, CancelGoalResponse
        )
        self.services = [self.send_goal_srv, self.get_result_srv, self.cancel_srv]
        reliable = Policy.Reliability.Reliable(duration(seconds=1))
        # rcl_action: feedback with the default profile, status reliable/transient-local/depth 1.
        self.feedback_reader = DataReader(
            self.dp,
            Topic(self.dp, f"rt{base}/feedback", FollowJointTrajectoryFeedbackMessage),
            qos=Qos(reliable, Policy.History.KeepLast(100), Policy.Durability.Volatile),
        )
        self.status_reader = DataReader(
            self.dp,
            Topic(self.dp, f"rt{base}/status", GoalStatusArray),
            qos=Qos(reliable, Policy.History.KeepLast(1), Policy.Durability.TransientLocal),
        )
        self.js_reader = DataReader(
            self.dp,
            Topic(self.dp, "rt/joint_states", JointState),
            qos=Qos(reliable, Policy.History.KeepLast(10), Policy.Durability.Volatile),
        )
        self.positions: Optional[Dict[str, float]] = None
        self.velocities: Dict[str, float] = {}
        self.js_stamp_ns = 0
        self.js_count = 0
        self.goals: Dict[str, GoalRecord] = {}
        self.feedback_other = 0
        # (stamp ns, positions, velocities) of every /joint_states sample while tracing.
        self.trace: Optional[List[Tuple[int, Dict[str, float], Dict[str, float]]]] = None

    def record(self, goal_id: bytes) -> GoalRecord:
        return self.goals.setdefault(uuid_hex(goal_id), GoalRecord())

    def pump(self) -> None:
        for s in self.js_reader.take(N=256):
            if isinstance(s, JointState):
                if len(s.name) != len(s.position) or len(s.name) != len(s.velocity):
                    raise CheckFailed(f"/joint_states: lengths {s}")
                self.positions = dict(zip(s.name, s.position))
                self.velocities = dict(zip(s.name, s.velocity))
                self.js_stamp_ns = stamp_ns(s.header.stamp)
                self.js_count += 1
                if self.trace is not None:
                    self.trace.append((self.js_stamp_ns, self.positions, self.velocities))
        for s in self.feedback_reader.take(N=256):
            if isinstance(s, FollowJointTrajectoryFeedbackMessage):
                key = uuid_hex(s.goal_id.uuid)
                if key in self.goals:
                    self.goals[key].feedback.append(s)
                else:
                    self.feedback_other += 1
        for s in self.status_reader.take(N=16):
            if isinstance(s, GoalStatusArray):
                for st in s.status_list:
                    rec = self.goals.get(uuid_hex(st.goal_info.goal_id.uuid))
                    if rec is not None and (not rec.statuses or rec.statuses[-1] != st.status):
                        rec.statuses.append(st.status)
        for c in self.services:
            c.pump()

    def wait_until(self, what: str, cond: Callable[[], bool], timeout: float) -> None:
        wait_until(self.pump, what, cond, timeout)

    def wait_reply(self, client: RmwCycloneClient, seq: int, timeout: float):
        """The reply to request `seq`, or None after `timeout` s."""
        deadline = time.monotonic() + timeout
        while seq not in client.replies:
            self.pump()
            if time.monotonic() > deadline:
                return None
            time.sleep(0.002)
        return client.replies[seq][0]

    def call(
        self,
        client: RmwCycloneClient,
        make: Callable[[CddsRequestHeader], object],
        timeout: float,
        attempts: int = 1,
    ):
        """Sends a request and waits for its reply; with `attempts` > 1, a request that got no
        reply within `timeout` s is sent again (a new seq: `make` is called again)."""
        for attempt in range(1, attempts + 1):
            seq = client.send(make)
            reply = self.wait_reply(client, seq, timeout)
            if reply is not None:
                rtt = client.replies[seq][1] - client.sent[seq][0]
                log(
                    f"{client.service}: reply to seq {seq} (guid {client.guid:#018x}) after "
                    f"{rtt * 1e3:.1f} ms, header bytes {header_bytes(reply.header).hex()}"
                )
                return reply
            log(f"{client.service}: no reply to seq {seq} within {timeout:.1f} s "
                f"(attempt {attempt}/{attempts})")
        raise CheckFailed(f"{client.service}: no reply after {attempts} attempt(s)")

    # ----- the action, step by step -----

    def send_goal(
        self, make_goal: Callable[[], FollowJointTrajectoryGoal], attempts: int = 1
    ) -> Tuple[bytes, SendGoalResponse]:
        """Sends the goal `make_goal()` makes; an attempt without a reply is repeated with a
        fresh goal id (a repeated id would be a duplicate goal) and a goal made anew (from the
        current state: the unanswered goal may have been accepted and moved the robot)."""
        ids: List[bytes] = []

        def make(h: CddsRequestHeader) -> SendGoalRequest:
            ids.append(uuidlib.uuid4().bytes)
            self.record(ids[-1])
            return SendGoalRequest(header=h, goal_id=UUID(uuid=ids[-1]), goal=make_goal())

        resp = self.call(self.send_goal_srv, make, timeout=2.0, attempts=attempts)
        return ids[-1], resp

    def request_result(self, goal_id: bytes) -> int:
        return self.get_result_srv.send(
            lambda h: GetResultRequest(header=h, goal_id=UUID(uuid=goal_id))
        )

    def wait_result(self, seq: int, timeout: float) -> GetResultResponse:
        r = self.wait_reply(self.get_result_srv, seq, timeout)
        if r is None:
            raise CheckFailed(f"no GetResult reply to seq {seq} within {timeout:.1f} s")
        return r

    def wait_status(self, goal_id: bytes, status: int, timeout: float) -> None:
        rec = self.record(goal_id)
        self.wait_until(
            f"{GOAL_STATUS_NAMES[status]} on the status topic for goal {uuid_hex(goal_id)} "
            f"(seen {[GOAL_STATUS_NAMES.get(s, s) for s in rec.statuses]})",
            lambda: status in rec.statuses,
            timeout,
        )


def result_str(r: GetResultResponse) -> str:
    return (
        f"{GOAL_STATUS_NAMES.get(r.status, r.status)} (error_code {r.result.error_code}, "
        f"'{r.result.error_string}')"
    )


def positions_str(p: Dict[str, float]) -> str:
    return "{" + ", ".join(f"{j}: {p[j]:+.4f}" for j in JOINTS) + "}"


def hold_goal(here: Dict[str, float], names: List[str]) -> FollowJointTrajectoryGoal:
    """Two points that stay at `here` (the caller breaks them)."""
    return FollowJointTrajectoryGoal(
        trajectory=JointTrajectory(
            header=Header(),
            joint_names=list(names),
            points=[
                JointTrajectoryPoint(
                    positions=[here[j] for j in JOINTS],
                    velocities=[0.0] * len(JOINTS),
                    time_from_start=dur(t),
                )
                for t in (0.5, 1.0)
            ],
        )
    )


# ----- scenario ------------------------------------------------------------------------------


def discover(c: ActionClient, timeout: float) -> None:
    c.wait_until("the first /joint_states sample", lambda: c.positions is not None, timeout)
    log(f"discovered: /joint_states arriving; positions {positions_str(c.positions)}")
    if sorted(c.positions) != JOINTS:
        raise CheckFailed(f"/joint_states names {sorted(c.positions)}, expected {JOINTS}")

    def ready() -> bool:
        return (
            all(s.available()[0] for s in c.services)
            and c.feedback_reader.get_subscription_matched_status().current_count > 0
            and c.status_reader.get_subscription_matched_status().current_count > 0
        )

    c.wait_until("the action server (3 services, feedback, status)", ready, timeout)
    for s in c.services:
        ok, how = s.available()
        log(f"available: {s.service}: {how}")
        n_rd = s.writer.get_publication_matched_status().current_count
        n_wr = s.reader.get_subscription_matched_status().current_count
        if n_rd != 1 or n_wr != 1:
            raise CheckFailed(
                f"{s.service}: {n_rd} request reader(s) and {n_wr} reply writer(s), expected "
                f"1 each: is another test using domain {c.dp.domain_id}? (choose another one)"
            )
    log(f"discovered: action server ready; client guids (request writer instance handles) "
        f"{[f'{s.guid:#018x}' for s in c.services]}")


def probe(c: ActionClient) -> None:
    """get_result and cancel_goal with an unknown goal id: harmless requests that show the
    request/reply mapping works before anything moves. Retried, because the server's reply
    writer may not have matched our reply reader yet when we see it matched (discovery is
    asymmetric, and a volatile reply written before that match is lost)."""
    unknown = uuidlib.uuid4().bytes
    r = c.call(
        c.get_result_srv,
        lambda h: GetResultRequest(header=h, goal_id=UUID(uuid=unknown)),
        timeout=1.0,
        attempts=5,
    )
    if r.status != STATUS_UNKNOWN:
        raise CheckFailed(f"get_result of an unknown goal: expected UNKNOWN, got {result_str(r)}")
    r = c.call(
        c.cancel_srv,
        lambda h: CancelGoalRequest(header=h, goal_info=GoalInfo(goal_id=UUID(uuid=unknown))),
        timeout=1.0,
        attempts=5,
    )
    if r.return_code != CANCEL_ERROR_UNKNOWN_GOAL_ID or r.goals_canceling:
        raise CheckFailed(
            f"cancel of an unknown goal: expected ERROR_UNKNOWN_GOAL_ID and no goals, got "
            f"return_code {r.return_code}, {len(r.goals_canceling)} goal(s)"
        )
    log("probes answered: get_result → UNKNOWN, cancel_goal → ERROR_UNKNOWN_GOAL_ID")


def valid_goal(c: ActionClient, limits: Dict[str, Limit], timings: Dict[str, float]) -> None:
    start = dict(c.positions)
    target = choose_target(start, limits)

    def make_goal() -> FollowJointTrajectoryGoal:
        here = dict(c.positions)
        return FollowJointTrajectoryGoal(trajectory=smooth_trajectory(here, target, JOINTS, 1.5))

    log(f"goal 1: 3 points over 1.5 s to {positions_str(target)}")
    t0 = time.monotonic()
    goal_id, resp = c.send_goal(make_goal, attempts=3)
    if not resp.accepted:
        raise CheckFailed(f"goal 1: not accepted ({resp})")
    if stamp_ns(resp.stamp) == 0:
        raise CheckFailed("goal 1: accepted with a zero stamp")
    log(f"goal 1 {uuid_hex(goal_id)}: accepted, stamp {resp.stamp.sec}.{resp.stamp.nanosec:09d}")
    seq = c.request_result(goal_id)
    r = c.wait_result(seq, timeout=10)
    timings["goal 1: send → result"] = time.monotonic() - t0
    log(f"goal 1: result {result_str(r)} after {time.monotonic() - t0:.3f} s")
    if r.status != STATUS_SUCCEEDED or r.result.error_code != SUCCESSFUL:
        raise CheckFailed(f"goal 1: expected SUCCEEDED with error_code 0, got {result_str(r)}")

    def arrived() -> bool:
        return all(abs(c.positions[j] - target[j]) <= POSITION_TOLERANCE for j in JOINTS)

    try:
        c.wait_until("goal 1: the robot at the target on /joint_states", arrived, timeout=3)
    except CheckFailed as e:
        raise CheckFailed(f"{e}; last positions {positions_str(c.positions)}") from None
    # Settle: a few more state samples, still at the target and at rest.
    n = c.js_count
    c.wait_until("goal 1: 10 more /joint_states samples", lambda: c.js_count >= n + 10, 3)
    off = {
        j: c.positions[j] - target[j]
        for j in JOINTS
        if abs(c.positions[j] - target[j]) > POSITION_TOLERANCE
    }
    moving = {j: v for j, v in c.velocities.items() if abs(v) > 1e-3}
    if off or moving:
        raise CheckFailed(f"goal 1: after SUCCEEDED off the target by {off}, moving {moving}")
    log(f"goal 1: robot at the target and at rest: {positions_str(c.positions)}")

    c.wait_status(goal_id, STATUS_SUCCEEDED, timeout=3)
    rec = c.record(goal_id)
    log(f"goal 1: status topic {[GOAL_STATUS_NAMES.get(s, s) for s in rec.statuses]}")
    fb = rec.feedback
    if len(fb) < 5:
        raise CheckFailed(f"goal 1: only {len(fb)} feedback messages in 1.5 s (20 Hz expected)")
    for m in fb:
        f = m.feedback
        if list(f.joint_names) != JOINTS or len(f.desired.positions) != 6:
            raise CheckFailed(
                f"goal 1: feedback with joint_names {list(f.joint_names)} and "
                f"{len(f.desired.positions)} desired positions"
            )
    # The desired positions go from the start to the target.
    first, last = fb[0].feedback.desired.positions, fb[-1].feedback.desired.positions
    log(
        f"goal 1: {len(fb)} feedback messages, joint_names {list(fb[-1].feedback.joint_names)}, "
        f"desired joint_6 {first[5]:+.3f} → {last[5]:+.3f} (start {start['joint_6']:+.3f}, "
        f"target {target['joint_6']:+.3f})"
    )


def unknown_joint_goal(c: ActionClient) -> None:
    here = dict(c.positions)
    names = list(JOINTS)
    names[2] = "elbow_joint"
    log("goal 2: joint_3 named 'elbow_joint'")
    goal_id, resp = c.send_goal(lambda: hold_goal(here, names))
    if not resp.accepted:
        raise CheckFailed("goal 2: not accepted (kerf accepts invalid goals, then aborts them)")
    r = c.wait_result(c.request_result(goal_id), timeout=5)
    log(f"goal 2: result {result_str(r)}")
    if r.status != STATUS_ABORTED or r.result.error_code != INVALID_JOINTS:
        raise CheckFailed(f"goal 2: expected ABORTED with INVALID_JOINTS (-2), got {result_str(r)}")
    if "elbow_joint" not in r.result.error_string:
        raise CheckFailed(f"goal 2: error_string does not name the joint: {result_str(r)}")
    c.wait_status(goal_id, STATUS_ABORTED, timeout=3)
    n = c.js_count
    c.wait_until("goal 2: 25 more /joint_states samples", lambda: c.js_count >= n + 25, 3)
    moved = max(abs(c.positions[j] - here[j]) for j in JOINTS)
    if moved > 1e-9:
        raise CheckFailed(f"goal 2: the robot moved by {moved} rad after an aborted goal")


def describe_stop(trace: List[Tuple[int, Dict[str, float], Dict[str, float]]]) -> None:
    """Logs how the executor stopped: speed when the cancel was sent, time (executor stamps)
    until every velocity is 0, and the peak deceleration per joint."""
    t0, _, v0 = trace[0]
    t_rest = next((t for t, _, v in trace[1:] if all(x == 0.0 for x in v.values())), None)
    peak = {j: 0.0 for j in JOINTS}
    for (ta, _, va), (tb, _, vb) in zip(trace, trace[1:]):
        if tb > ta:
            for j in JOINTS:
                peak[j] = max(peak[j], abs(vb[j] - va[j]) / ((tb - ta) * 1e-9))
    log(
        "goal 3: velocity at the cancel {"
        + ", ".join(f"{j}: {v0[j]:+.3f}" for j in JOINTS)
        + "} rad/s; all velocities 0 after "
        + (f"{(t_rest - t0) * 1e-9 * 1e3:.0f} ms" if t_rest is not None else "never")
        + " (executor stamps); peak |dv/dt| {"
        + ", ".join(f"{j}: {peak[j]:.2f}" for j in JOINTS)
        + "} rad/s²"
    )


def canceled_goal(c: ActionClient, target: Dict[str, float], timings: Dict[str, float]) -> None:
    start = dict(c.positions)
    goal = FollowJointTrajectoryGoal(trajectory=smooth_trajectory(start, target, JOINTS, 4.0))
    log(f"goal 3: 3 points over 4 s to {positions_str(target)}; cancel after ~1 s")
    goal_id, resp = c.send_goal(lambda: goal)
    if not resp.accepted:
        raise CheckFailed("goal 3: not accepted")
    t_accept = time.monotonic()
    result_seq = c.request_result(goal_id)
    c.wait_until("goal 3: 1 s of motion", lambda: time.monotonic() - t_accept >= 1.0, 2)
    if c.record(goal_id).feedback == []:
        raise CheckFailed("goal 3: no feedback after 1 s of motion")
    at_cancel = dict(c.positions)
    c.trace = [(c.js_stamp_ns, dict(c.positions), dict(c.velocities))]
    t_cancel = time.monotonic()
    r = c.call(
        c.cancel_srv,
        lambda h: CancelGoalRequest(header=h, goal_info=GoalInfo(goal_id=UUID(uuid=goal_id))),
        timeout=3.0,
    )
    canceling = [bytes(g.goal_id.uuid) for g in r.goals_canceling]
    log(f"goal 3: cancel reply return_code {r.return_code}, goals_canceling "
        f"{[g.hex() for g in canceling]}")
    if r.return_code != CANCEL_ERROR_NONE or canceling != [goal_id]:
        raise CheckFailed(
            f"goal 3: expected ERROR_NONE with [{uuid_hex(goal_id)}], got return_code "
            f"{r.return_code} with {[g.hex() for g in canceling]}"
        )
    res = c.wait_result(result_seq, timeout=5)
    timings["goal 3: cancel → result"] = time.monotonic() - t_cancel
    log(f"goal 3: result {result_str(res)} {time.monotonic() - t_cancel:.3f} s after the cancel")
    if res.status != STATUS_CANCELED:
        raise CheckFailed(f"goal 3: expected CANCELED, got {result_str(res)}")

    # Standstill: 25 consecutive samples (0.1 s at 250 Hz) at rest and not moving.
    still = {"n": 0, "p": None}

    def at_rest() -> bool:
        p = c.positions
        if max(abs(v) for v in c.velocities.values()) < 1e-4 and still["p"] is not None and max(
            abs(p[j] - still["p"][j]) for j in JOINTS
        ) < 1e-9:
            still["n"] += 1
        else:
            still["n"] = 0
        still["p"] = dict(p)
        return still["n"] >= 25

    c.wait_until("goal 3: standstill on /joint_states", at_rest, timeout=3)
    timings["goal 3: cancel → standstill seen"] = time.monotonic() - t_cancel
    stop = dict(c.positions)
    describe_stop(c.trace)
    c.trace = None
    log(f"goal 3: standstill at {positions_str(stop)}")
    for j in JOINTS:
        total = target[j] - start[j]
        done = (stop[j] - start[j]) / total
        if not 0.05 < done < 0.6:
            raise CheckFailed(
                f"goal 3: {j} stopped {done:.0%} of the way to the target (start "
                f"{start[j]:+.4f}, at cancel {at_cancel[j]:+.4f}, stop {stop[j]:+.4f}, target "
                f"{target[j]:+.4f}): expected a standstill well before the target"
            )
    log(
        "goal 3: stopped at "
        + ", ".join(f"{j} {(stop[j] - start[j]) / (target[j] - start[j]):.0%}" for j in JOINTS)
        + " of the way"
    )
    c.wait_status(goal_id, STATUS_CANCELED, timeout=3)
    log(f"goal 3: status topic {[GOAL_STATUS_NAMES.get(s, s) for s in c.record(goal_id).statuses]}")


def scenario(args: argparse.Namespace) -> None:
    check_wire_layout()
    limits = read_limits(args.urdf)
    c = ActionClient(args.domain)
    timings: Dict[str, float] = {}
    t = time.monotonic()
    discover(c, args.discovery_timeout)
    probe(c)
    timings["discovery + probes"] = time.monotonic() - t
    start = dict(c.positions)
    valid_goal(c, limits, timings)
    unknown_joint_goal(c)
    canceled_goal(c, start, timings)
    for s in c.services:
        rtts = sorted(s.rtts)
        log(
            f"{s.service}: {len(s.sent)} request(s), {len(s.replies)} reply(ies), "
            f"{s.foreign} foreign; round trip min {rtts[0] * 1e3:.1f} ms, "
            f"max {rtts[-1] * 1e3:.1f} ms"
            if rtts
            else f"{s.service}: no replies"
        )
        if len(s.replies) != len(s.sent):
            unanswered = sorted(set(s.sent) - set(s.replies))
            log(f"{s.service}: requests without a reply: seq {unanswered}")
    for k, v in timings.items():
        log(f"timing: {k}: {v:.3f} s")


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--domain", type=int, default=int(os.environ.get("ROS_DOMAIN_ID", "-1")))
    ap.add_argument("--urdf", required=True, help="the robot URDF the executor runs with")
    ap.add_argument("--discovery-timeout", type=float, default=15.0)
    args = ap.parse_args()
    if sys.byteorder != "little":
        print("action_client.py: the header checks assume a little-endian host", file=sys.stderr)
        return 2
    return run_checked("action_client.py", args, scenario, log, T0)


T0 = time.monotonic()

if __name__ == "__main__":
    sys.exit(main())
