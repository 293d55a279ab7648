//! The size of answers (issue 11, items 2 and 6): what RustDDS delivers promptly.
//!
//! Measured over loopback (BENCHMARKS.md, "Large samples and memory"): reliable samples up to
//! 6 MiB arrive within 50 ms; 8 MiB took 0.7–1.3 s, 12 MiB sometimes never arrived, and a
//! sample that does not arrive blocks every later sample of its writer (a reliable reader
//! delivers in order). Every published sample of a planner node is therefore kept under
//! [`MAX_ANSWER_BYTES`], a factor of 2 below the cliff.

use kerf_msgs::trajectory_msgs::JointTrajectory;
use serde::Serialize;

/// Largest published sample of a planner node (bytes): the answer message (CDR), its YAML
/// text and the trajectory. Also the largest text request accepted.
pub const MAX_ANSWER_BYTES: usize = 4 << 20;

/// YAML bytes of one joint of one trajectory point in an answer's text (position, velocity
/// and acceleration as shortest-round-trip f64 in block style; 536 bytes were measured for a
/// six-joint point, rounded up).
pub const TEXT_BYTES_PER_JOINT_POINT: usize = 100;

/// The most trajectory points an answer of `joints` joints may have: its YAML text stays
/// under [`MAX_ANSWER_BYTES`] (6 joints: 6 990 points).
pub fn max_answer_points(joints: usize) -> usize {
    MAX_ANSWER_BYTES / (TEXT_BYTES_PER_JOINT_POINT * joints.max(1))
}

/// Checks a planned trajectory's size before its answer is rendered.
///
/// # Errors
/// The reason, naming the points, the joints and the limit.
pub fn check_points(points: usize, joints: usize) -> Result<(), String> {
    let max = max_answer_points(joints);
    if points > max {
        return Err(format!(
            "the plan has {points} trajectory points of {joints} joints, over the {max} an \
             answer may carry (answers are kept under {} MiB, what DDS delivers promptly): \
             lengthen sample_period, or split the path",
            MAX_ANSWER_BYTES >> 20
        ));
    }
    Ok(())
}

/// What an answer will carry, estimated from its request before planning
/// ([`super::PlanningService::answer_size`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct AnswerSize {
    /// Trajectory points.
    pub points: usize,
    /// Joints per point.
    pub joints: usize,
    /// Text bytes of everything else that grows with the request (e.g. the milling plan's
    /// per-segment table).
    pub extra_text_bytes: usize,
}

impl AnswerSize {
    /// The estimated size of the answer's YAML text, its largest sample (bytes).
    pub fn text_bytes(&self) -> usize {
        self.points
            .saturating_mul(self.joints.max(1))
            .saturating_mul(TEXT_BYTES_PER_JOINT_POINT)
            .saturating_add(self.extra_text_bytes)
    }

    /// Checks the estimate against [`MAX_ANSWER_BYTES`].
    ///
    /// # Errors
    /// The reason, naming the points, the estimated size and the limit.
    pub fn check(&self) -> Result<(), String> {
        let bytes = self.text_bytes();
        if bytes > MAX_ANSWER_BYTES {
            return Err(format!(
                "its answer would carry {} trajectory points of {} joints{}, about {bytes} bytes \
                 as text, over the limit of {MAX_ANSWER_BYTES} bytes (what DDS delivers \
                 promptly; {} points at most): lengthen sample_period, use fewer segments, or \
                 split the path",
                self.points,
                self.joints,
                if self.extra_text_bytes > 0 {
                    format!(" and {} bytes of per-segment data", self.extra_text_bytes)
                } else {
                    String::new()
                },
                max_answer_points(self.joints)
            ));
        }
        Ok(())
    }
}

/// The CDR size of a message (bytes), as published; `None` if it cannot be encoded.
pub fn cdr_bytes<T: Serialize>(message: &T) -> Option<usize> {
    cdr_encoding::to_vec::<T, byteorder::LittleEndian>(message)
        .ok()
        .map(|v| v.len())
}

/// Checks the sizes of the samples of one answer: the message, its text, the trajectory.
///
/// # Errors
/// The reason, naming the sample, its size and the limit.
pub fn check_answer<A: Serialize>(
    answer: &A,
    text: &str,
    trajectory: &JointTrajectory,
) -> Result<(), String> {
    let sizes = [
        ("answer message", cdr_bytes(answer)),
        ("answer text", Some(text.len())),
        ("trajectory", cdr_bytes(trajectory)),
    ];
    for (what, size) in sizes {
        match size {
            Some(n) if n <= MAX_ANSWER_BYTES => {}
            Some(n) => {
                return Err(format!(
                    "the {what} would be {n} bytes, over the limit of {MAX_ANSWER_BYTES} bytes \
                     (what DDS delivers promptly): lengthen sample_period, or split the path"
                ))
            }
            None => return Err(format!("the {what} cannot be encoded")),
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use kerf_msgs::trajectory_msgs::JointTrajectoryPoint;

    fn trajectory(points: usize) -> JointTrajectory {
        JointTrajectory {
            joint_names: (1..=6).map(|i| format!("q{i}")).collect(),
            points: (0..points)
                .map(|k| JointTrajectoryPoint {
                    positions: vec![0.1234567890123 * k as f64; 6],
                    velocities: vec![-1.234567890123e-3; 6],
                    accelerations: vec![2.345678901234e-2; 6],
                    ..JointTrajectoryPoint::default()
                })
                .collect(),
            ..JointTrajectory::default()
        }
    }

    #[test]
    fn the_point_estimate_keeps_the_text_under_the_limit() {
        let max = max_answer_points(6);
        assert_eq!(max, 6990);
        assert!(check_points(max, 6).is_ok());
        let e = check_points(max + 1, 6).unwrap_err();
        assert!(
            e.contains("6991 trajectory points") && e.contains("6990"),
            "{e}"
        );
        // The YAML of the largest accepted trajectory is within the limit.
        let t = trajectory(max);
        let text = serde_yaml_ng::to_string(&t).unwrap();
        assert!(text.len() <= MAX_ANSWER_BYTES, "{} bytes", text.len());
        check_answer(&t, &text, &t).unwrap();
    }

    #[test]
    fn estimates_count_the_points_and_the_extra_text() {
        let fits = AnswerSize {
            points: 6990,
            joints: 6,
            extra_text_bytes: 0,
        };
        assert!(fits.check().is_ok());
        let e = AnswerSize {
            extra_text_bytes: 100_000,
            ..fits
        }
        .check()
        .unwrap_err();
        assert!(
            e.contains("6990 trajectory points of 6 joints and 100000 bytes"),
            "{e}"
        );
    }

    #[test]
    fn an_oversized_sample_is_named() {
        let t = trajectory(30_000);
        let e = check_answer(&(), "", &t).unwrap_err();
        assert!(
            e.contains("the trajectory would be") && e.contains("4194304"),
            "{e}"
        );
        let big = "x".repeat(MAX_ANSWER_BYTES + 1);
        let e = check_answer(&(), &big, &trajectory(1)).unwrap_err();
        assert!(e.contains("answer text"), "{e}");
    }
}
