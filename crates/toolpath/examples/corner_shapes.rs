//! Prints the table `crates/toolpath/src/corner_shapes.in` ([`kerf_toolpath::corner::SHAPES`]):
//! per turning angle 5°, 10°, …, 175°, the corner shape of least κ_max · δ and of least
//! κ_max · L, by `kerf_toolpath::corner::search_shape` with 40 steps.
//!
//! ```sh
//! cargo run --release -p kerf_toolpath --example corner_shapes > crates/toolpath/src/corner_shapes.in
//! ```

use kerf_toolpath::corner::{search_shape, Binding};

fn main() {
    println!("[");
    for k in 0..35 {
        let deg = 5.0 + 5.0 * k as f64;
        let turn = f64::to_radians(deg);
        let t = search_shape(turn, Binding::Tolerance, 40);
        let l = search_shape(turn, Binding::Length, 40);
        println!(
            "    [{deg:.1}, {:.4}, {:.4}, {:.4}, {:.4}],",
            t.b, t.c, l.b, l.c
        );
    }
    println!("]");
}
