//! `kerf demo cut` and `kerf demo mill`: request → planner → executor → simulated cell, in
//! this process and without DDS (issue 15, item 3).
//!
//! The planner is the library the planner node runs (`kerf_mjto` for the cut, case 1 by
//! default; `kerf_millplan` for the mill, its default request); the executor is
//! `kerf_executor::Executor` with the node's defaults (250 Hz, no tolerances); the cell is
//! `kerf_cell` with the shipped cell file, stepped in lock-step with the control loop as the
//! executor node does in `hardware: sim`, and a contact during motion is the node's fault
//! ([`kerf_trajectory_executor::control::ContactWatch`]: controlled stop, goal aborted).
//! It prints the time, the tracking error, the contacts and the final state.

use clap::{Args, Subcommand, ValueEnum};
use kerf_cell::{Cell, CellSettings, Mode};
use kerf_executor::{
    Cycle, Executor, ExecutorConfig, GoalTolerances, Outcome, TrajectoryRequest,
    PATH_TOLERANCE_VIOLATED,
};
use kerf_robot::RobotModel;
use kerf_trajectory_executor::control::{contact_message, ContactWatch};

use crate::{
    bounds::Real,
    input::{self, InputFile},
};

/// `kerf demo`.
#[derive(Args, Debug)]
pub struct DemoArgs {
    #[command(subcommand)]
    what: DemoWhat,
}

#[derive(Subcommand, Debug)]
enum DemoWhat {
    /// Case 1 of seed 001 (or `--request`) on the laser cutter with the B-pillar.
    Cut(DemoOpts),
    /// The milling planner's default request (or `--request`) on the IRB 6660 with its plate.
    Mill(DemoOpts),
}

#[derive(Args, Debug)]
struct DemoOpts {
    /// How the cell follows the executor.
    #[arg(long, value_enum, default_value_t = ModeArg::Dynamic)]
    mode: ModeArg,
    /// The request (YAML): a cut request (`kerf plan cut` format) or a milling request (at
    /// most 4 MiB; `-` reads standard input).
    #[arg(long)]
    request: Option<InputFile>,
    /// Physics rate, an integer multiple of the 250 Hz control rate, at most what one control
    /// period runs in real time (kerf_cell::settings::MAX_PHYSICS_RATE_HZ); [250, 5000] Hz.
    #[arg(long, default_value_t = 1000.0, value_parser = PHYSICS_RATE)]
    physics_rate: f64,
}

#[derive(ValueEnum, Clone, Copy, Debug)]
enum ModeArg {
    Kinematic,
    Dynamic,
}

/// Control rate of the demo: the executor node's default.
const CONTROL_RATE: f64 = 250.0;

/// Wall-clock seconds between two progress lines of the simulation.
const PROGRESS_EVERY: f64 = 2.0;

/// `--physics-rate`: from the control rate up to the cell's bound.
const PHYSICS_RATE: Real =
    Real::closed(CONTROL_RATE, kerf_cell::settings::MAX_PHYSICS_RATE_HZ, "Hz");

/// What the cell saw while the executor ran a trajectory.
#[derive(Debug, Default)]
pub struct Summary {
    /// The trajectory's duration (s).
    pub planned: f64,
    /// Simulated time until the goal ended and the robot stood still (s).
    pub simulated: f64,
    /// How the goal ended.
    pub outcome: Option<Outcome>,
    /// Per joint: the largest |command − state| at the end of a period (the drives' error;
    /// 0 in kinematic mode).
    pub tracking: Vec<f64>,
    /// Per joint: the largest |reference − measured| the executor saw (its tolerance check:
    /// the drives' error plus one control period of motion).
    pub executor_error: Vec<f64>,
    /// Periods with a contact, and the deepest penetration (m).
    pub contact_periods: usize,
    /// The deepest penetration (m).
    pub deepest: f64,
    /// The first contact, described.
    pub first_contact: Option<String>,
    /// Periods in which some drive saturated.
    pub saturated_periods: usize,
    /// The final positions and velocities.
    pub final_positions: Vec<f64>,
    /// The final velocities.
    pub final_velocities: Vec<f64>,
}

/// Runs `request` from rest at its first point on the executor driving `cell`.
///
/// # Errors
/// An executor refusal (configuration or trajectory) or a cell error, as text.
pub fn simulate(
    robot: &RobotModel,
    mut cell: Cell,
    request: &TrajectoryRequest,
) -> Result<Summary, String> {
    let limits = robot.executor_limits().map_err(|e| e.to_string())?;
    let first = request
        .points
        .first()
        .ok_or("the trajectory has no points")?;
    let initial = first.positions.clone();
    let dt = 1.0 / CONTROL_RATE;
    let cfg = ExecutorConfig {
        control_period: dt,
        ..ExecutorConfig::default()
    };
    let mut exec = Executor::new(limits, cfg, initial.clone()).map_err(|e| e.to_string())?;
    cell.reset(&initial).map_err(|e| e.to_string())?;
    let t0 = cell.state().time;
    let id = exec
        .submit(request, &GoalTolerances::default(), t0)
        .map_err(|e| format!("the executor refused the plan: {e}"))?;
    let n = initial.len();
    let mut s = Summary {
        planned: request.points.last().map_or(0.0, |p| p.time_from_start),
        tracking: vec![0.0; n],
        executor_error: vec![0.0; n],
        ..Summary::default()
    };
    let mut watch = ContactWatch::default();
    let mut cycle = Cycle::default();
    let limit = t0 + s.planned + 10.0;
    let wall = std::time::Instant::now();
    let mut last_line = 0.0;
    let mut periods = 0u64;
    loop {
        periods += 1;
        if periods.is_multiple_of(64) {
            let elapsed = wall.elapsed().as_secs_f64();
            if elapsed - last_line >= PROGRESS_EVERY {
                last_line = elapsed;
                eprintln!(
                    "kerf demo: simulated {:.2} of {:.2} s in {elapsed:.0} s (Ctrl-C stops)",
                    cell.state().time - t0,
                    s.planned
                );
            }
        }
        let now = cell.state().time;
        let measured = cell.state().joint_sample();
        exec.update_into(now, &measured, &mut cycle)
            .map_err(|e| e.to_string())?;
        for ev in cycle.events.drain(..) {
            if ev.id == id {
                s.outcome = Some(ev.outcome);
            }
        }
        for (m, e) in s.executor_error.iter_mut().zip(&cycle.error.positions) {
            *m = m.max(e.abs());
        }
        if s.outcome.is_some() && !exec.is_moving(now) {
            break;
        }
        if now > limit {
            return Err(format!(
                "the goal did not end within {:.1} s of simulated time",
                limit - t0
            ));
        }
        let state = cell.step(&cycle.reference, dt).map_err(|e| e.to_string())?;
        for (m, e) in s.tracking.iter_mut().zip(&state.tracking_error) {
            *m = m.max(e.abs());
        }
        if state.saturated.iter().any(|&b| b) {
            s.saturated_periods += 1;
        }
        if !state.contacts.is_empty() {
            s.contact_periods += 1;
            for c in &state.contacts {
                s.deepest = s.deepest.max(c.depth);
            }
        }
        let moving = exec.is_moving(now) || exec.active_goal().is_some();
        let faults = watch.check(&state.contacts, moving);
        if !faults.is_empty() {
            let message = contact_message(&faults, state.time - t0);
            if s.first_contact.is_none() {
                s.first_contact = Some(message.clone());
            }
            exec.fault(now, PATH_TOLERANCE_VIOLATED, message)
                .map_err(|e| e.to_string())?;
        }
    }
    s.simulated = cell.state().time - t0;
    s.final_positions = cell.state().positions.clone();
    s.final_velocities = cell.state().velocities.clone();
    Ok(s)
}

fn outcome_text(o: &Option<Outcome>) -> String {
    match o {
        None => "none".into(),
        Some(Outcome::Succeeded) => "SUCCEEDED".into(),
        Some(Outcome::Aborted { message, .. }) => format!("ABORTED: {message}"),
        Some(Outcome::Preempted) => "PREEMPTED".into(),
        Some(Outcome::Canceled) => "CANCELED".into(),
    }
}

fn list(v: &[f64], scale: f64) -> String {
    let s: Vec<String> = v.iter().map(|x| format!("{:.3}", x * scale)).collect();
    format!("[{}]", s.join(", "))
}

/// Prints a [`Summary`].
fn print(what: &str, robot: &RobotModel, s: &Summary, wall: f64) {
    let names = robot.joint_names().join(", ");
    println!("{what}");
    println!(
        "  time: planned {:.3} s, simulated {:.3} s (until at rest), wall {wall:.2} s",
        s.planned, s.simulated
    );
    println!("  goal: {}", outcome_text(&s.outcome));
    println!(
        "  max tracking error (drives, command - state) [{names}]: {} (mm or mrad)",
        list(&s.tracking, 1e3)
    );
    println!(
        "  max executor error (reference - measured, one period of motion included): {} (mm or mrad)",
        list(&s.executor_error, 1e3)
    );
    println!(
        "  contacts: {} periods, deepest {:.3} mm{}",
        s.contact_periods,
        s.deepest * 1e3,
        s.first_contact
            .as_ref()
            .map_or(String::new(), |m| format!("; first fault: {m}"))
    );
    println!("  drive saturation: {} periods", s.saturated_periods);
    println!(
        "  final state: positions {} (m or rad), velocities {} (mm/s or mrad/s)",
        list(&s.final_positions, 1.0),
        list(&s.final_velocities, 1e3)
    );
}

/// Runs `kerf demo`.
pub fn run(a: DemoArgs) -> Result<(), String> {
    let (opts, robot_name, cell_name) = match &a.what {
        DemoWhat::Cut(o) => (o, "laser_cutter", "laser_bpillar"),
        DemoWhat::Mill(o) => (o, "irb6660", "irb6660_plate"),
    };
    // The request first (capped), before anything is loaded or planned.
    let request_text = match &opts.request {
        Some(f) => Some(input::read_text("--request", f, input::REQUEST_CAP)?),
        None => None,
    };
    let data = |rel: String| kerf_robot::data::default_path(rel);
    let urdf = data(format!("urdf/{robot_name}.urdf"));
    let limits = data(format!("urdf/{robot_name}_limits.yaml"));
    let cell_file = data(format!("urdf/cells/{cell_name}.yaml"));
    let robot = RobotModel::from_files(&urdf, Some(&limits)).map_err(|e| e.to_string())?;
    let settings = CellSettings {
        mode: match opts.mode {
            ModeArg::Kinematic => Mode::Kinematic,
            ModeArg::Dynamic => Mode::Dynamic,
        },
        control_rate_hz: CONTROL_RATE,
        physics_rate_hz: opts.physics_rate,
        ..CellSettings::default()
    };
    let cell = Cell::from_files(&urdf, &cell_file, settings)
        .map_err(|e| format!("cell {}: {e}", cell_file.display()))?;
    let started = std::time::Instant::now();
    let (title, request) = match &a.what {
        DemoWhat::Cut(_) => {
            let (name, text) = match (&opts.request, request_text) {
                (Some(f), Some(text)) => (f.to_string(), text),
                _ => {
                    let path = data("crates/mjto/cases/case1.yaml".into());
                    let f = InputFile::from(path.into_os_string());
                    (
                        f.to_string(),
                        input::read_text("case", &f, input::REQUEST_CAP)?,
                    )
                }
            };
            let request = kerf_mjto::CutRequest::from_yaml(&text)
                .map_err(|e| format!("--request {name}: {e}"))?;
            let machine = kerf_mjto::LaserMachine::default_machine().map_err(|e| e.to_string())?;
            let mut planner =
                kerf_mjto::planner::Planner::new(machine).map_err(|e| e.to_string())?;
            let plan = planner
                .plan(&request)
                .map_err(|e| format!("planner: {e}"))?;
            (
                format!("cut {name} ({})", request.request_id),
                plan.joint_trajectory(),
            )
        }
        DemoWhat::Mill(_) => {
            let request = match (&opts.request, &request_text) {
                (Some(f), Some(text)) => kerf_millplan::MillRequest::from_yaml_str(text)
                    .map_err(|e| format!("--request {f}: {e}"))?,
                _ => kerf_millplan::MillRequest::default(),
            };
            let planner = kerf_millplan::MillPlanner::with_default_cell()
                .map_err(|e| format!("milling cell: {e}"))?;
            let out = planner
                .plan(&request)
                .map_err(|e| format!("planner: {e}"))?;
            (
                format!(
                    "mill ({} planner, {:.3} s planned machining time)",
                    out.planner.name(),
                    out.plan.row().total_time
                ),
                out.executed.scaling.trajectory.request,
            )
        }
    };
    let planned_in = started.elapsed().as_secs_f64();
    println!(
        "planned in {planned_in:.2} s: {} points; cell {} ({:?}, physics {} Hz)",
        request.points.len(),
        cell_file.display(),
        settings.mode,
        settings.physics_rate_hz
    );
    let sim_start = std::time::Instant::now();
    let summary = simulate(&robot, cell, &request)?;
    print(&title, &robot, &summary, sim_start.elapsed().as_secs_f64());
    match summary.outcome {
        Some(Outcome::Succeeded) => Ok(()),
        other => Err(format!(
            "the goal did not succeed: {}",
            outcome_text(&other)
        )),
    }
}
