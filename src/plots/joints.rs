//! Joint trajectory plots of `kerf plan cut --plots DIR`: for each axis q1..q6 one SVG with
//! position, velocity, acceleration and jerk against time, MJTO against the
//! quaternion-interpolation (QI) baseline, as in seed 001 Figures 10 (rotary axes, QI red,
//! MJTO blue, limits dotted), 13 (q4, q5) and 15 (q1..q3). The series come from
//! [`kerf_mjto::series::JointSeries`].

use std::path::{Path, PathBuf};

use kerf_mjto::{
    machine::{AxisLimits, JOINT_NAMES},
    series::JointSeries,
};
use plotters::prelude::*;

use super::chart::{draw_err, figure, finite_bounds, widen, Axes, Frame};

/// Colour of the dotted limit lines.
const LIMIT_COLOR: RGBColor = RGBColor(0x80, 0x80, 0x80);

/// Selects one quantity (positions, velocities, …) of a [`JointSeries`].
type Rows = fn(&JointSeries) -> &Vec<[f64; 6]>;

/// Units of joint `j` (0-based): linear for q1..q3 and q6, angular for q4, q5.
fn units(j: usize) -> [&'static str; 4] {
    if j == 3 || j == 4 {
        ["rad", "rad/s", "rad/s²", "rad/s³"]
    } else {
        ["m", "m/s", "m/s²", "m/s³"]
    }
}

/// The y range covering every finite value of the given curves, padded by 5 % (a flat curve
/// gets ±1 % of its value, or ±1; no value: ±1).
fn y_range<'a>(curves: impl Iterator<Item = &'a [(f64, f64)]>) -> (f64, f64) {
    finite_bounds(curves.flat_map(|c| c.iter().map(|&(_, y)| y)))
        .map_or((-1.0, 1.0), |(lo, hi)| widen(lo, hi, 0.05, 1e-12))
}

/// A limit for a caption: rounded to 4 decimals, without trailing zeros (`-6.2832`, `10`).
fn short(v: f64) -> String {
    format!("{}", (v * 1e4).round() / 1e4)
}

/// `(t, value of joint j)` for every sample with a finite value.
fn curve(times: &[f64], rows: &[[f64; 6]], j: usize) -> Vec<(f64, f64)> {
    times
        .iter()
        .zip(rows)
        .map(|(t, r)| (*t, r[j]))
        .filter(|(t, y)| t.is_finite() && y.is_finite())
        .collect()
}

/// Writes `q1.svg` … `q6.svg` into `dir` (created if missing).
///
/// # Arguments
/// * `mjto` – the plan's series; `qi` – the baseline's, if it could be computed.
/// * `limits` – drawn as dotted lines where they fall inside a panel's range.
///
/// # Returns
/// The files written.
///
/// # Errors
/// A message naming the file that could not be created or drawn.
pub fn write_plots(
    dir: &Path,
    mjto: &JointSeries,
    qi: Option<&JointSeries>,
    limits: &[AxisLimits; 6],
) -> Result<Vec<PathBuf>, String> {
    std::fs::create_dir_all(dir).map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
    let t_end = mjto
        .times
        .iter()
        .chain(qi.map_or(&[][..], |s| &s.times[..]))
        .copied()
        .filter(|t| t.is_finite())
        .fold(0.0_f64, f64::max);
    let t_end = if t_end > 0.0 { t_end } else { 1.0 };
    let mut written = Vec::new();
    for (j, name) in JOINT_NAMES.iter().enumerate() {
        let path = dir.join(format!("{name}.svg"));
        let err = draw_err(&path);
        let root = figure(&path, (1000, 1100)).map_err(&err)?;
        let root = root
            .titled(
                &format!(
                    "{name}: MJTO (blue) vs quaternion interpolation (red){}",
                    if qi.is_some() {
                        ""
                    } else {
                        " - QI unavailable"
                    }
                ),
                ("sans-serif", 22),
            )
            .map_err(&err)?;
        let l = limits[j];
        let u = units(j);
        let panels: [(&str, &str, Rows, [f64; 2]); 4] = [
            ("position", u[0], |s| &s.positions, [l.min, l.max]),
            ("velocity", u[1], |s| &s.velocities, [-l.vel, l.vel]),
            ("acceleration", u[2], |s| &s.accelerations, [-l.acc, l.acc]),
            ("jerk", u[3], |s| &s.jerks, [-l.jerk, l.jerk]),
        ];
        for (area, (what, unit, rows, bounds)) in root.split_evenly((4, 1)).iter().zip(panels) {
            let m = curve(&mjto.times, rows(mjto), j);
            let q = qi.map(|s| curve(&s.times, rows(s), j)).unwrap_or_default();
            let (lo, hi) = y_range([&m[..], &q[..]].into_iter());
            let caption = format!(
                "{what} ({unit}), limits {} / {}",
                short(bounds[0]),
                short(bounds[1])
            );
            let mut chart = Frame {
                caption: &caption,
                caption_size: 16,
                margin: 8,
                x_label_area: 30,
                y_label_area: 70,
            }
            .build(area, 0.0..t_end, lo..hi)
            .map_err(&err)?;
            Axes {
                x_desc: "t (s)",
                y_desc: &format!("{what} ({unit})"),
                whole_x: false,
                grid: true,
            }
            .draw(&mut chart)
            .map_err(&err)?;
            if !q.is_empty() {
                chart
                    .draw_series(LineSeries::new(q, RED.stroke_width(1)))
                    .map_err(&err)?;
            }
            chart
                .draw_series(LineSeries::new(m, BLUE.stroke_width(2)))
                .map_err(&err)?;
            for b in bounds.into_iter().filter(|b| (lo..=hi).contains(b)) {
                // Dotted: short segments every 1 % of the time axis.
                let dots = (0..100).map(|k| {
                    let t0 = t_end * k as f64 / 100.0;
                    PathElement::new(vec![(t0, b), (t0 + t_end / 250.0, b)], LIMIT_COLOR)
                });
                chart.draw_series(dots).map_err(&err)?;
            }
        }
        root.present().map_err(&err)?;
        drop(root);
        written.push(path.clone());
    }
    Ok(written)
}

#[cfg(test)]
mod tests {
    use super::*;
    use kerf_mjto::LaserMachine;
    use kerf_testparts::straight::straight_cut;

    #[test]
    fn plots_are_written_per_axis() {
        let (request, plan) = straight_cut().unwrap();
        let machine = LaserMachine::default_machine().unwrap();
        let qi = JointSeries::qi_baseline(&request, &plan, machine.limits()).unwrap();
        let mjto = JointSeries {
            times: qi.times.clone(),
            positions: qi.positions.clone(),
            velocities: qi.velocities.clone(),
            accelerations: qi.accelerations.clone(),
            jerks: qi.jerks.clone(),
        };
        let dir = std::env::temp_dir().join(format!("kerf_plots_{}", std::process::id()));
        let files = write_plots(&dir, &mjto, Some(&qi), machine.limits()).unwrap();
        assert_eq!(files.len(), 6);
        for (f, name) in files.iter().zip(JOINT_NAMES) {
            assert_eq!(f.file_name().unwrap(), format!("{name}.svg").as_str());
            let svg = std::fs::read_to_string(f).unwrap();
            assert!(svg.starts_with("<svg"), "{}", &svg[..40.min(svg.len())]);
            // Four panels, each with an MJTO (blue) and a QI (red) polyline; no limit inside
            // any range (see below), so no grey dots.
            assert_eq!(svg.matches(r##"stroke="#0000FF""##).count(), 4, "{name}");
            assert_eq!(svg.matches(r##"stroke="#FF0000""##).count(), 4, "{name}");
            assert_eq!(svg.matches(r##"stroke="#808080""##).count(), 0, "{name}");
            for panel in ["position", "velocity", "acceleration", "jerk"] {
                assert!(svg.contains(panel), "{name}: {panel}");
            }
        }
        // q6 is constant: its limits (-0.1, 0.02) are outside the padded range, q1's velocity
        // limit 2 m/s is outside [0, 0.2]: no dotted limit line is drawn there.
        let q1 = std::fs::read_to_string(&files[0]).unwrap();
        assert!(q1.contains("limits -2 / 2"), "velocity caption");
        let q4 = std::fs::read_to_string(&files[3]).unwrap();
        assert!(
            q4.contains("position (rad), limits -6.2832 / 6.2832"),
            "position caption"
        );

        // A q1 velocity beyond its 2 m/s limit brings the +2 line (100 dots) into range, and
        // without QI only the MJTO curves are drawn.
        let mut fast = mjto.clone();
        for v in &mut fast.velocities {
            v[0] *= 15.0;
        }
        let files = write_plots(&dir, &fast, None, machine.limits()).unwrap();
        let q1 = std::fs::read_to_string(&files[0]).unwrap();
        assert_eq!(q1.matches(r##"stroke="#808080""##).count(), 100);
        assert_eq!(q1.matches(r##"stroke="#FF0000""##).count(), 0);
        assert!(q1.contains("QI unavailable"));
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn y_range_pads_and_survives_flat_and_empty_curves() {
        let (lo, hi) = y_range([&[(0.0, 1.0), (1.0, 3.0)][..]].into_iter());
        assert!((lo - 0.9).abs() < 1e-12 && (hi - 3.1).abs() < 1e-12);
        let (lo, hi) = y_range([&[(0.0, 2.0), (1.0, 2.0)][..]].into_iter());
        assert!((lo - 1.98).abs() < 1e-12 && (hi - 2.02).abs() < 1e-12);
        assert_eq!(y_range([&[(0.0, 0.0)][..]].into_iter()), (-1.0, 1.0));
        assert_eq!(y_range([&[][..]].into_iter()), (-1.0, 1.0));
        assert_eq!(y_range([&[(0.0, f64::NAN)][..]].into_iter()), (-1.0, 1.0));
    }
}
