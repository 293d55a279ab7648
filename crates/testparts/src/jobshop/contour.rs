//! Cut outlines in a flat or developed coordinate plane: lines, round holes, obround slots
//! and rounded rectangles, as chains of straight pieces and circular arcs.

use nalgebra::Vector2;

/// One piece of an outline.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Piece {
    /// From `a` to `b`.
    Line { a: Vector2<f64>, b: Vector2<f64> },
    /// Centre, radius, start angle, signed sweep (rad; positive counter-clockwise).
    Arc {
        c: Vector2<f64>,
        r: f64,
        start: f64,
        sweep: f64,
    },
}

impl Piece {
    fn length(&self) -> f64 {
        match *self {
            Piece::Line { a, b } => (b - a).norm(),
            Piece::Arc { r, sweep, .. } => r * sweep.abs(),
        }
    }

    fn at(&self, f: f64) -> Vector2<f64> {
        match *self {
            Piece::Line { a, b } => a + (b - a) * f,
            Piece::Arc { c, r, start, sweep } => {
                let phi = start + sweep * f;
                c + Vector2::new(phi.cos(), phi.sin()) * r
            }
        }
    }
}

/// An outline: pieces joined end to end, parametrised by arc length over t in [0, 1].
#[derive(Debug, Clone, PartialEq)]
pub struct Outline {
    pieces: Vec<Piece>,
    /// True when the last piece ends where the first begins.
    pub closed: bool,
}

impl Outline {
    /// A straight cut from `a` to `b`.
    pub fn line(a: Vector2<f64>, b: Vector2<f64>) -> Self {
        Self {
            pieces: vec![Piece::Line { a, b }],
            closed: false,
        }
    }

    /// A round hole: the circle of `radius` about `centre`, counter-clockwise from angle 0.
    pub fn circle(centre: Vector2<f64>, radius: f64) -> Self {
        Self {
            pieces: vec![Piece::Arc {
                c: centre,
                r: radius,
                start: 0.0,
                sweep: std::f64::consts::TAU,
            }],
            closed: true,
        }
    }

    /// An obround slot of overall `length` and `width` (end radius width/2) about `centre`,
    /// its long axis at `angle` (rad) to the first coordinate, counter-clockwise, starting at
    /// the beginning of one straight side.
    pub fn obround(centre: Vector2<f64>, length: f64, width: f64, angle: f64) -> Self {
        let r = width / 2.0;
        let half = (length - width) / 2.0;
        let u = Vector2::new(angle.cos(), angle.sin());
        let n = Vector2::new(-u.y, u.x);
        let (c1, c2) = (centre + u * half, centre - u * half);
        Self {
            pieces: vec![
                Piece::Line {
                    a: c2 - n * r,
                    b: c1 - n * r,
                },
                Piece::Arc {
                    c: c1,
                    r,
                    start: angle - std::f64::consts::FRAC_PI_2,
                    sweep: std::f64::consts::PI,
                },
                Piece::Line {
                    a: c1 + n * r,
                    b: c2 + n * r,
                },
                Piece::Arc {
                    c: c2,
                    r,
                    start: angle + std::f64::consts::FRAC_PI_2,
                    sweep: std::f64::consts::PI,
                },
            ],
            closed: true,
        }
    }

    /// An axis-aligned rectangle `size` about `centre` with corner radius `r`,
    /// counter-clockwise from the start of its lower side.
    pub fn rounded_rectangle(centre: Vector2<f64>, size: Vector2<f64>, r: f64) -> Self {
        let (hx, hy) = (size.x / 2.0 - r, size.y / 2.0 - r);
        let q = std::f64::consts::FRAC_PI_2;
        // Arc centres counter-clockwise from the lower right; corner k's arc starts at angle
        // −π/2 + kπ/2 where the straight side from corner k − 1 ends.
        let signs = [(1.0, -1.0), (1.0, 1.0), (-1.0, 1.0), (-1.0, -1.0)];
        let centres: Vec<Vector2<f64>> = signs
            .iter()
            .map(|&(sx, sy)| centre + Vector2::new(sx * hx, sy * hy))
            .collect();
        let mut pieces = Vec::with_capacity(8);
        for k in 0..4 {
            let start = -q + q * k as f64;
            let dir = Vector2::new(start.cos(), start.sin()) * r;
            pieces.push(Piece::Line {
                a: centres[(k + 3) % 4] + dir,
                b: centres[k] + dir,
            });
            pieces.push(Piece::Arc {
                c: centres[k],
                r,
                start,
                sweep: q,
            });
        }
        Self {
            pieces,
            closed: true,
        }
    }

    /// Total length.
    pub fn length(&self) -> f64 {
        self.pieces.iter().map(Piece::length).sum()
    }

    /// The point at arc-length fraction `t` in [0, 1].
    pub fn at(&self, t: f64) -> Vector2<f64> {
        let mut s = t.clamp(0.0, 1.0) * self.length();
        for p in &self.pieces {
            let l = p.length();
            if s <= l {
                return p.at(if l > 0.0 { s / l } else { 0.0 });
            }
            s -= l;
        }
        self.pieces
            .last()
            .map_or_else(Vector2::zeros, |p| p.at(1.0))
    }
}
