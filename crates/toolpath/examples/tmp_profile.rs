#![allow(missing_docs)]
use kerf_toolpath::corner::{corner_transition_with, ShapeObjective};
use kerf_toolpath::corner_jerk::curvature_and_rate;
use kerf_toolpath::CornerCurve;
fn main() {
    for deg in [30.0f64, 90.0, 150.0] {
        let t = deg.to_radians();
        for obj in [ShapeObjective::Jerk, ShapeObjective::Curvature] {
            let c = corner_transition_with(
                [-1.0, 0.0, 0.0],
                [0.0; 3],
                [t.cos(), t.sin(), 0.0],
                1e-4,
                1.0,
                obj,
            )
            .unwrap()
            .unwrap();
            let CornerCurve::Quintic(q) = c.curve else {
                panic!()
            };
            let mut line = format!("{deg} {obj:?} κmax {:.0}:", c.max_curvature);
            for k in 0..=10 {
                let u = 0.05 * k as f64;
                let (kk, r) = curvature_and_rate(&q, [0.0, 0.0, 1.0], u);
                line += &format!(
                    " u{u:.2} g {:.2e} κ² {:.1e};",
                    (r * r + kk.powi(4)).sqrt(),
                    kk * kk
                );
            }
            println!("{line}");
        }
    }
}
