//! `kerf train curve`: the training curve (seed 004 Fig. 5) of a saved history.

use kerf_millplan::history::parse_history;

use super::CurveArgs;
use crate::{input, output_paths::check_dir_writable, plots::training};

/// Runs `kerf train curve`.
///
/// # Errors
/// The message to print: an unreadable or invalid history, an unwritable directory, a
/// drawing failure.
pub fn curve(a: CurveArgs) -> Result<(), String> {
    if a.window == 0 {
        return Err("--window 0: must be at least 1".to_string());
    }
    let text = input::read_text("--history", &a.history, input::HISTORY_CAP)?;
    let csv = a
        .history
        .path()
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("csv"));
    let history = parse_history(&a.history.to_string(), &text, csv).map_err(|e| e.to_string())?;
    check_dir_writable("--plots", &a.plots)?;
    let file = a.plots.join("training_curve.svg");
    let name = a
        .history
        .path()
        .file_name()
        .map_or_else(String::new, |n| n.to_string_lossy().into_owned());
    training::training_curve(
        &file,
        &history,
        a.window,
        &format!("DDPG training, {name} ({} episodes)", history.len()),
    )?;
    println!(
        "training curve of {} episodes written to {}",
        history.len(),
        file.display()
    );
    Ok(())
}
