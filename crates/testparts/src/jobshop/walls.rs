//! Trims near walls and flanges, closed cut-outs beside a wall, a cut whose nominal tool axis
//! collides while its allowance does not, and the two refusals of issue 16's "Bad input".

use nalgebra::{Vector2, Vector3};

use super::case::{Expectation, JobShopCase, Process};
use super::channel::ChannelParams;
use super::contour::Outline;
use super::part::Part;
use crate::TestPartError;

/// One case on a flat face: outline in the face's (x, y) at height z, normal +z.
struct FlatCase {
    name: &'static str,
    title: &'static str,
    outline: Outline,
    z: f64,
    process: Process,
    expect: Expectation,
}

fn build(part: &Part, c: FlatCase) -> Result<JobShopCase, TestPartError> {
    let curve = |t: f64| {
        let p = c.outline.at(t);
        (Vector3::new(p.x, p.y, c.z), Vector3::z())
    };
    JobShopCase::cut(
        c.name,
        c.title.to_owned(),
        part,
        &curve,
        c.outline.closed,
        c.process,
        c.expect,
    )
}

/// The channel cases (walls 120 mm high, inner faces at y = ±0.15): a floor trim 60 mm from
/// a wall (the fork arms, 115 mm from the tool axis, reach the wall unless they point along
/// the cut), a trim across the floor ending 60 mm from both walls (the arms must point across
/// the cut), a flange trim and a 100 × 50 mm cut-out whose long side runs 60 mm from a wall.
///
/// # Errors
/// Only for inconsistent defaults.
pub(super) fn channel_cases(
    channel: &ChannelParams,
    part: &Part,
) -> Result<Vec<JobShopCase>, TestPartError> {
    let wall = channel.width / 2.0;
    let cases = [
        FlatCase {
            name: "channel_floor_trim",
            title: "300 mm floor trim 60 mm from a 120 mm wall of a 3 mm U channel; 15 m/min, 10°/10°",
            outline: Outline::line(Vector2::new(0.1, -wall + 0.06), Vector2::new(0.4, -wall + 0.06)),
            z: 0.0,
            process: Process::shop(15.0, 10.0, 10.0, 10.0),
            expect: Expectation::Plan,
        },
        FlatCase {
            name: "channel_cross_trim",
            title: "trim across the channel floor, ending 60 mm from both walls; 12 m/min, 10°/10°",
            outline: Outline::line(Vector2::new(0.25, -wall + 0.06), Vector2::new(0.25, wall - 0.06)),
            z: 0.0,
            process: Process::shop(12.0, 4.0, 10.0, 10.0),
            expect: Expectation::Plan,
        },
        FlatCase {
            name: "channel_flange_trim",
            title: "300 mm trim along the top flange, 35 mm outside the wall's inner face; 20 m/min, 10°/10°",
            outline: Outline::line(Vector2::new(0.1, wall + 0.035), Vector2::new(0.4, wall + 0.035)),
            z: channel.height,
            process: Process::shop(20.0, 10.0, 10.0, 10.0),
            expect: Expectation::Plan,
        },
        FlatCase {
            name: "channel_cutout",
            title: "closed 100 × 50 mm cut-out (R10 corners) in the channel floor, long side 60 mm from a wall; 10 m/min, 10°/10°",
            outline: Outline::rounded_rectangle(
                Vector2::new(0.25, -wall + 0.085),
                Vector2::new(0.1, 0.05),
                0.01,
            ),
            z: 0.0,
            process: Process::shop(10.0, 4.0, 10.0, 10.0),
            expect: Expectation::Plan,
        },
    ];
    cases.into_iter().map(|c| build(part, c)).collect()
}

/// The angle cases (wall 300 mm high, inner face y = 0): a trim 85 mm from the wall, where
/// the C-axis motor housing (radius 90 mm, from 190 mm above the CL point) hits the wall with
/// the nominal vertical axis and clears it when the axis tilts 5° to 10° away from the wall; a
/// Ø50 hole whose near side is 85 mm from the wall; and the refusals: a 1 m trim requested at
/// 3 m/s along the machine x axis (q1 moves at most 2 m/s: INFEASIBLE, about 2 m/s, q1) and a
/// trim 30 mm from the wall (every head orientation inside 10° touches it: COLLISION).
///
/// # Errors
/// Only for inconsistent defaults.
pub(super) fn angle_cases(part: &Part) -> Result<Vec<JobShopCase>, TestPartError> {
    let cases = [
        FlatCase {
            name: "angle_wall_trim",
            title: "300 mm trim 85 mm from a 300 mm wall: the nominal vertical axis collides, a 5-10° tilt away clears; 10 m/min, 10°/10°",
            outline: Outline::line(Vector2::new(0.45, -0.085), Vector2::new(0.75, -0.085)),
            z: 0.0,
            process: Process::shop(10.0, 10.0, 10.0, 10.0),
            expect: Expectation::Plan,
        },
        FlatCase {
            name: "angle_wall_hole",
            title: "Ø50 hole whose near side is 85 mm from a 300 mm wall (nominal axis collides there); 6 m/min, 10°/10°",
            outline: Outline::circle(Vector2::new(0.6, -0.11), 0.025),
            z: 0.0,
            process: Process::shop(6.0, 4.0, 10.0, 10.0),
            expect: Expectation::Plan,
        },
        FlatCase {
            name: "angle_overspeed",
            title: "bad input: 1 m trim along machine x requested at 180 m/min (q1 reaches 2 m/s): INFEASIBLE, about 2 m/s, q1",
            outline: Outline::line(Vector2::new(0.1, -0.15), Vector2::new(1.1, -0.15)),
            z: 0.0,
            process: Process::shop(180.0, 10.0, 10.0, 10.0),
            expect: Expectation::Infeasible {
                max_feedrate: 2.0,
                tolerance: 0.02,
                joint: "q1",
            },
        },
        FlatCase {
            name: "angle_too_close",
            title: "bad input: trim 30 mm from a 300 mm wall, no head orientation within 10° clears it: COLLISION",
            outline: Outline::line(Vector2::new(0.5, -0.03), Vector2::new(0.7, -0.03)),
            z: 0.0,
            process: Process::shop(10.0, 10.0, 10.0, 10.0),
            expect: Expectation::Collision,
        },
    ];
    cases.into_iter().map(|c| build(part, c)).collect()
}
