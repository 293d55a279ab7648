//! `kerf cli-model` (hidden): every argument of every command, walked from clap's own model,
//! one JSON object a line, so that the bounds test (`tests/cli_bounds.rs`) covers a new command
//! or argument from its first commit.
//!
//! Each line: `path` (the subcommand names), `id`, `long` (or null), `positional`, `takes_value`,
//! `kind` — `real` (`f64`), `count` (a whole number), `grid` (`MIN:MAX:COUNT`), `point`
//! (`x,y,z`, or three named reals such as `V,A,J`), `input` (an
//! [`InputFile`]: a file the command reads), `enum` (a fixed set of values), `other` — and
//! `help`.

use clap::{Arg, ArgAction, Command};
use serde_json::json;

use crate::{bounds::Point3, input::InputFile, lobes::Grid};

/// The kind of an argument's value, from its value parser's type.
fn kind(arg: &Arg) -> &'static str {
    let id = arg.get_value_parser().type_id();
    if id == std::any::TypeId::of::<f64>() || id == std::any::TypeId::of::<f32>() {
        "real"
    } else if [
        std::any::TypeId::of::<usize>(),
        std::any::TypeId::of::<u64>(),
        std::any::TypeId::of::<u32>(),
        std::any::TypeId::of::<u16>(),
        std::any::TypeId::of::<u8>(),
        std::any::TypeId::of::<i64>(),
        std::any::TypeId::of::<i32>(),
        std::any::TypeId::of::<isize>(),
    ]
    .iter()
    .any(|t| id == *t)
    {
        "count"
    } else if id == std::any::TypeId::of::<Grid>() {
        "grid"
    } else if id == std::any::TypeId::of::<Point3>() || id == std::any::TypeId::of::<[f64; 3]>() {
        "point"
    } else if id == std::any::TypeId::of::<InputFile>() {
        "input"
    } else if !arg.get_possible_values().is_empty() {
        "enum"
    } else {
        "other"
    }
}

/// Appends the lines of `cmd` and its subcommands (hidden ones and `help` left out).
fn walk(cmd: &Command, path: &mut Vec<String>, out: &mut String) {
    for arg in cmd.get_arguments() {
        let id = arg.get_id().as_str();
        if id == "help" || id == "version" || arg.is_hide_set() {
            continue;
        }
        let takes_value = matches!(arg.get_action(), ArgAction::Set | ArgAction::Append);
        let line = json!({
            "path": path,
            "id": id,
            "long": arg.get_long(),
            "positional": arg.is_positional(),
            "takes_value": takes_value,
            "kind": kind(arg),
            "help": arg.get_help().map(|h| h.to_string()).unwrap_or_default(),
        });
        out.push_str(&line.to_string());
        out.push('\n');
    }
    for sub in cmd.get_subcommands() {
        if sub.is_hide_set() || sub.get_name() == "help" {
            continue;
        }
        path.push(sub.get_name().to_string());
        walk(sub, path, out);
        path.pop();
    }
}

/// The model of `cli` as JSON lines.
pub fn model(cli: &Command) -> String {
    let mut out = String::new();
    let mut cli = cli.clone();
    cli.build();
    walk(&cli, &mut Vec::new(), &mut out);
    out
}
