//! The table `kerf lobes` prints: a `#` header (cell state, settings) and one row per
//! speed.

use std::fmt::Write as _;

use kerf_chatter::{feed_lower_bound, natural_frequencies, symmetric_eigenvalues, DelayModel};

use super::LobesReport;

/// A critical depth in mm for the table: `>MAX` when stable up to the max depth.
fn depth_mm(d: Option<f64>, max_depth: f64) -> String {
    match d {
        Some(v) => format!("{:.4}", v * 1e3),
        None => format!(">{:.4}", max_depth * 1e3),
    }
}

/// Indices of the lowest, middle and highest feed of the grid.
pub fn feed_columns(n: usize) -> [usize; 3] {
    let last = n.saturating_sub(1);
    [0, last / 2, last]
}

/// The printed report: a `#` header (cell state, settings) and one row per speed.
///
/// Columns: `rpm`, `a_lim_const_mm`, `a_lim_sd_mm` (`-` for the constant model; `>MAX` =
/// stable up to the max depth), `mu@f=…` for the lowest, middle and highest grid feed at the
/// cell's depth, `feed_lb_m/s` ([`feed_lower_bound`]).
pub fn table(r: &LobesReport) -> String {
    let mut s = String::new();
    let (st, c) = (&r.state, &r.chart);
    let k = &st.modal.stiffness;
    let eig = symmetric_eigenvalues(k[(0, 0)], k[(0, 1)], k[(1, 1)]);
    let _ = writeln!(s, "# kerf lobes: segment {}, g = {} rad", r.segment, r.g);
    let _ = writeln!(
        s,
        "# joints [rad]: [{}]",
        st.joints
            .iter()
            .map(|q| format!("{q:.6}"))
            .collect::<Vec<_>>()
            .join(", ")
    );
    let _ = writeln!(
        s,
        "# condition number K = {:.4}, condition indicator 1/K = {:.4}",
        st.condition_number, st.condition_indicator
    );
    let _ = writeln!(
        s,
        "# tool-tip stiffness [N/m] (cutting frame): [[{:.6e}, {:.6e}], [{:.6e}, {:.6e}]], eigenvalues {:.6e}, {:.6e}",
        k[(0, 0)],
        k[(0, 1)],
        k[(1, 0)],
        k[(1, 1)],
        eig[0],
        eig[1]
    );
    if let Some([f1, f2]) = natural_frequencies(&st.modal) {
        let _ = writeln!(s, "# undamped tool-tip modes: {f1:.3} Hz, {f2:.3} Hz");
    }
    let p = &c.process;
    let model = match c.settings.model {
        DelayModel::Constant => "constant delay".to_string(),
        DelayModel::StateDependent => format!(
            "state-dependent (force exponent {}, reference chip {} m, wall term {})",
            c.settings.equilibrium.force_law.exponent,
            c.settings.equilibrium.force_law.reference_chip,
            if c.settings.wall_term { "on" } else { "off" }
        ),
    };
    let _ = writeln!(
        s,
        "# process: {} teeth, R = {} m, cell depth a_p = {} mm, engagement [{:.4}, {:.4}] rad; model {model}, m = {}",
        p.teeth,
        p.radius,
        p.axial_depth * 1e3,
        p.entry_angle,
        p.exit_angle,
        c.settings.steps
    );
    let _ = writeln!(
        s,
        "# depth search 0..{} mm, {} scan intervals, tolerance {} um; state-dependent lobe at the nominal feed {} m/s",
        c.options.max_depth * 1e3,
        c.options.scan_points,
        c.options.tolerance * 1e6,
        c.nominal_feed
    );
    let cols = feed_columns(c.feeds.len());
    let feed_at = |i: usize| c.feeds.get(i).copied().unwrap_or(f64::NAN);
    let _ = writeln!(
        s,
        "# {:>9} {:>15} {:>12} {:>14} {:>14} {:>14} {:>12}",
        "rpm",
        "a_lim_const_mm",
        "a_lim_sd_mm",
        format!("mu@f={:.4}", feed_at(cols[0])),
        format!("mu@f={:.4}", feed_at(cols[1])),
        format!("mu@f={:.4}", feed_at(cols[2])),
        "feed_lb_m/s"
    );
    for (i, rpm) in c.rpms.iter().enumerate() {
        let constant = c.constant.get(i).map_or("error".to_string(), |p| {
            depth_mm(p.critical_depth, c.options.max_depth)
        });
        let sd = match &c.state_dependent {
            None => "-".to_string(),
            Some(v) => v
                .get(i)
                .map_or("error".to_string(), |d| depth_mm(*d, c.options.max_depth)),
        };
        let row = c.map.get(i).map_or(&[][..], |v| &v[..]);
        let mu = |j: usize| match row.get(j) {
            Some(Some(m)) => format!("{m:.6}"),
            Some(None) => "undef".to_string(),
            None => "-".to_string(),
        };
        let _ = writeln!(
            s,
            "{:>11.3} {:>15} {:>12} {:>14} {:>14} {:>14} {:>12}",
            rpm,
            constant,
            sd,
            mu(cols[0]),
            mu(cols[1]),
            mu(cols[2]),
            feed_lower_bound(&c.feeds, row).to_string()
        );
    }
    s
}
