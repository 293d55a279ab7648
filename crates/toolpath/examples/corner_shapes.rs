//! Prints a corner shape table of [`kerf_toolpath::corner`]: per turning angle of
//! `kerf_toolpath::corner::table_angles` (5°, 10°, …, 175°, then closer up to 179.95°),
//! the shape of least objective with the tolerance binding and with the length binding, by
//! `kerf_toolpath::corner::ShapeObjective::search_shape` with 40 steps. Without an argument the
//! curvature table (`corner_shapes.in`, κ_max · δ and κ_max · L), with `jerk` the jerk table
//! (`corner_jerk_shapes.in`, g_max · δ² and g_max · L², g = √(κ′² + κ⁴)).
//!
//! ```sh
//! cargo run --release -p kerf_toolpath --example corner_shapes > crates/toolpath/src/corner_shapes.in
//! cargo run --release -p kerf_toolpath --example corner_shapes -- jerk > crates/toolpath/src/corner_jerk_shapes.in
//! ```

use kerf_toolpath::corner::{table_angles, Binding, ShapeObjective};

fn main() {
    let objective = match std::env::args().nth(1).as_deref() {
        None | Some("curvature") => ShapeObjective::Curvature,
        Some("jerk") => ShapeObjective::Jerk,
        Some(other) => {
            eprintln!("unknown objective {other:?}: curvature or jerk");
            std::process::exit(2);
        }
    };
    println!("[");
    for deg in table_angles() {
        let turn = f64::to_radians(deg);
        let t = objective.search_shape(turn, Binding::Tolerance, 40);
        let l = objective.search_shape(turn, Binding::Length, 40);
        println!(
            "    [{deg:.2}, {:.9e}, {:.9e}, {:.9e}, {:.9e}],",
            t.b, t.c, l.b, l.c
        );
    }
    println!("]");
}
