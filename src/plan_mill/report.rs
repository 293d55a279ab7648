//! What `kerf plan mill` prints: per plan a header, the per-segment table, the totals as
//! planned and as executed, warnings; and the status of a failure.

use std::fmt::Write as _;

use kerf_millplan::{plan::Plan, planner::status_name, status_of, MillPlanError, MillPlanOutput};

/// Paths with at most this many segments print every row of the table.
const ALL_ROWS_UP_TO: usize = 20;

/// Row stride of the table of longer paths.
const ROW_STRIDE: usize = 10;

/// "STATUS (code): message" of a planner error.
pub fn describe(e: &MillPlanError) -> String {
    let code = status_of(e);
    let name = status_name(code).unwrap_or("?");
    format!("{name} ({code}): {e}")
}

/// `request 'ID', ` for a request with an id, nothing otherwise.
pub fn request_label(id: &str) -> String {
    if id.is_empty() {
        String::new()
    } else {
        format!("request '{id}', ")
    }
}

/// Short totals for a plot title.
pub fn totals_title(p: &Plan) -> String {
    format!(
        "time {:.2} s, max |mu|max {:.3}, min 1/K {:.3}, reward {:.2}",
        p.total_time, p.max_spectral_radius, p.min_condition_indicator, p.total_reward
    )
}

/// The segments a table shows: all when `all` or the path is short, else every
/// [`ROW_STRIDE`]th and the last.
pub fn table_rows(n: usize, all: bool) -> Vec<usize> {
    if all || n <= ALL_ROWS_UP_TO {
        return (0..n).collect();
    }
    let mut rows: Vec<usize> = (0..n).step_by(ROW_STRIDE).collect();
    if rows.last() != Some(&(n - 1)) {
        rows.push(n - 1);
    }
    rows
}

/// The totals line of a plan (parsed by `tests/mill_cli.rs`: keep the wording).
pub fn totals_line(p: &Plan) -> String {
    format!(
        "totals: machining time {:.6} s, chatter-free {}, max |μ|max {:.6}, min 1/K {:.6}, \
         total reward {:.6}",
        p.total_time,
        if p.chatter_free { "yes" } else { "no" },
        p.max_spectral_radius,
        p.min_condition_indicator,
        p.total_reward
    )
}

/// The totals line of a plan as executed (`o.executed`; parsed by `tests/mill_cli.rs`: keep
/// the wording): the totals of [`totals_line`] and how much the joint limits slowed it.
pub fn executed_line(o: &MillPlanOutput) -> String {
    let (p, sc) = (&o.executed.plan, &o.executed.scaling);
    let lowest_feed = p
        .segments
        .iter()
        .map(|g| g.feed)
        .fold(f64::INFINITY, f64::min);
    let cached = match o.executed.cached_segments.len() {
        0 => String::new(),
        k => format!(", |μ|max of {k} segments from the indicator cache"),
    };
    format!(
        "as executed (time-scaled to the joint limits, from rest to rest): machining time \
         {:.6} s, chatter-free {}, max |μ|max {:.6}, min 1/K {:.6}, total reward {:.6}, {} of \
         {} segments slowed, lowest feed {:.5} m/s, {} trajectory points, tool tip within \
         {:.4} mm of the path{cached}",
        p.total_time,
        if p.chatter_free { "yes" } else { "no" },
        p.max_spectral_radius,
        p.min_condition_indicator,
        p.total_reward,
        sc.slowed_segments(),
        sc.segment_slowdown.len(),
        lowest_feed,
        sc.trajectory.points().len(),
        sc.deviation.max_off_path.max(sc.deviation.max_off_plane) * 1e3
    )
}

/// The printed report of one plan: header, table, totals as planned and as executed, branch
/// jumps.
pub fn plan_report(o: &MillPlanOutput, all_rows: bool) -> String {
    let mut s = String::new();
    let p = &o.plan;
    let _ = writeln!(
        s,
        "{}planner {}: SUCCESS (0): {} segments, planned in {:.3} s{}",
        request_label(&o.request_id),
        o.planner.name(),
        p.segments.len(),
        o.planning_seconds,
        o.policy_file
            .as_ref()
            .map_or(String::new(), |f| format!(", policy {}", f.display()))
    );
    let _ = writeln!(
        s,
        "  indicator: {}; default cell's cache {}",
        o.indicator.note,
        if o.cache_used {
            "applied"
        } else {
            "not applied"
        }
    );
    let _ = writeln!(
        s,
        "  {:>7} {:>9} {:>9} {:>8} {:>8} {:>7} {:>8} {:>8}",
        "segment", "Ω [rpm]", "f [m/s]", "g [rad]", "|μ|max", "1/K", "time [s]", "reward"
    );
    let rows = table_rows(p.segments.len(), all_rows);
    for &i in &rows {
        let g = &p.segments[i];
        let _ = writeln!(
            s,
            "  {:>7} {:>9.2} {:>9.5} {:>8.4} {:>8.4} {:>7.4} {:>8.4} {:>8.4}",
            g.segment,
            g.rpm,
            g.feed,
            g.g,
            g.spectral_radius,
            g.condition_indicator,
            g.time,
            g.reward.total
        );
    }
    if rows.len() < p.segments.len() {
        let _ = writeln!(
            s,
            "  ({} of {} segments shown; --all-rows shows every one)",
            rows.len(),
            p.segments.len()
        );
    }
    let _ = writeln!(s, "  {}", totals_line(p));
    let _ = writeln!(s, "  {}", executed_line(o));
    let _ = writeln!(s, "  {}", o.judge_text());
    if !o.candidates.is_empty() {
        let _ = writeln!(s, "  {}", o.candidates_text());
    }
    if o.plan.chatter_free && !o.executed.plan.chatter_free {
        let _ = writeln!(
            s,
            "  warning: chatter-free as planned but NOT as executed: the joint limits slow it \
             to feeds where |μ|max >= 1"
        );
    }
    for j in &o.branch_jumps {
        let _ = writeln!(
            s,
            "  warning: {} jumps {:.4} rad at trajectory point {} (IK branch change?)",
            j.joint, j.step, j.index
        );
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn long_tables_show_every_tenth_segment_and_the_last() {
        assert_eq!(table_rows(5, false), vec![0, 1, 2, 3, 4]);
        assert_eq!(table_rows(20, false).len(), 20);
        assert_eq!(
            table_rows(100, false),
            vec![0, 10, 20, 30, 40, 50, 60, 70, 80, 90, 99]
        );
        assert_eq!(table_rows(91, false).last(), Some(&90));
        assert_eq!(table_rows(91, false).len(), 10);
        assert_eq!(table_rows(100, true).len(), 100);
    }

    #[test]
    fn errors_name_status_and_code() {
        let e = MillPlanError::Policy {
            path: "p.safetensors".into(),
            reason: "weights file not found".into(),
        };
        assert_eq!(
            describe(&e),
            "POLICY_ERROR (3): policy p.safetensors: weights file not found"
        );
    }
}
