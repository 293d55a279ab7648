//! Wire bytes: mirrors encoded with the CDR serializer ros2-client uses
//! (cdr-encoding, little endian, without the 4-byte encapsulation header).
//!
//! Expected bytes follow OMG CDR (DDS-XTypes 1.3, XCDR1 as used by ROS 2):
//! primitives aligned to their size from the start of the payload, `string`
//! as uint32 length including the terminating NUL then the bytes and NUL,
//! sequences as uint32 element count then the elements.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

use byteorder::LittleEndian;
use kerf_msgs::builtin_interfaces::{Duration, Time};
use kerf_msgs::msg::TrajectoryStatus;
use kerf_msgs::std_msgs::{Header, StringMsg};
use kerf_msgs::trajectory_msgs::JointTrajectoryPoint;
use serde::{de::DeserializeOwned, Serialize};

fn encode<T: Serialize>(value: &T) -> Vec<u8> {
    cdr_encoding::to_vec::<T, LittleEndian>(value).expect("CDR encoding")
}

fn decode<T: DeserializeOwned>(bytes: &[u8]) -> T {
    let (value, used) = cdr_encoding::from_bytes::<T, LittleEndian>(bytes).expect("CDR decoding");
    assert_eq!(used, bytes.len(), "whole payload consumed");
    value
}

#[test]
fn string_and_header() {
    let s = StringMsg { data: "hi".into() };
    let bytes = encode(&s);
    assert_eq!(bytes, [3, 0, 0, 0, b'h', b'i', 0]);
    assert_eq!(decode::<StringMsg>(&bytes), s);

    let h = Header {
        stamp: Time { sec: 1, nanosec: 2 },
        frame_id: "a".into(),
    };
    let bytes = encode(&h);
    assert_eq!(bytes, [1, 0, 0, 0, 2, 0, 0, 0, 2, 0, 0, 0, b'a', 0]);
    assert_eq!(decode::<Header>(&bytes), h);
}

#[test]
fn trajectory_point_alignment() {
    let p = JointTrajectoryPoint {
        positions: vec![1.0],
        time_from_start: Duration {
            sec: -1,
            nanosec: 5,
        },
        ..Default::default()
    };
    let bytes = encode(&p);
    let mut want = vec![1, 0, 0, 0, 0, 0, 0, 0]; // count 1, then padding to 8
    want.extend_from_slice(&1.0_f64.to_le_bytes()); // positions[0] at offset 8
    want.extend_from_slice(&[0; 12]); // velocities, accelerations, effort: count 0
    want.extend_from_slice(&(-1_i32).to_le_bytes()); // time_from_start.sec
    want.extend_from_slice(&5_u32.to_le_bytes()); // time_from_start.nanosec
    assert_eq!(bytes, want);
    assert_eq!(decode::<JointTrajectoryPoint>(&bytes), p);
}

#[test]
fn trajectory_status_layout() {
    let s = TrajectoryStatus {
        status: TrajectoryStatus::REJECTED,
        error_code: -2,
        ..Default::default()
    };
    let bytes = encode(&s);
    let mut want = vec![0; 8]; // header.stamp
    want.extend_from_slice(&[1, 0, 0, 0, 0]); // header.frame_id "" (length 1, NUL)
    want.extend_from_slice(&[0; 3]); // padding to 16
    want.extend_from_slice(&[0; 8]); // trajectory_stamp
    want.extend_from_slice(&[1, 0, 0, 0, 0]); // source ""
    want.extend_from_slice(&[0; 3]); // padding to 32
    want.extend_from_slice(&[1, 0, 0, 0, 0]); // goal_id ""
    want.push(2); // status (uint8) at 37
    want.extend_from_slice(&[0; 2]); // padding to 40
    want.extend_from_slice(&(-2_i32).to_le_bytes()); // error_code
    want.extend_from_slice(&[1, 0, 0, 0, 0]); // message ""
    assert_eq!(bytes, want);
    assert_eq!(decode::<TrajectoryStatus>(&bytes), s);
}
