//! What a program does, in SI units: [`Motion`]s between points in metres,
//! at feeds in metres per second.

/// The plane of circular motion (G17, G18, G19) and its axes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Plane {
    /// G17: XY, the arc axis Z.
    Xy,
    /// G18: ZX (XZ), the arc axis Y.
    Zx,
    /// G19: YZ, the arc axis X.
    Yz,
}

impl Plane {
    /// The indices (first, second, normal) of the plane's axes in (x, y, z),
    /// ordered so that first × second = +normal (RS-274/NGC's G18 arcs turn
    /// about +Y with Z first: NISTIR 6556 section 3.5.3).
    pub fn axes(self) -> [usize; 3] {
        match self {
            Plane::Xy => [0, 1, 2],
            Plane::Zx => [2, 0, 1],
            Plane::Yz => [1, 2, 0],
        }
    }
}

/// A circular (or helical) arc.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ArcMove {
    /// Start \[m\].
    pub start: [f64; 3],
    /// End \[m\].
    pub end: [f64; 3],
    /// Centre \[m\] (its normal coordinate is the start's).
    pub center: [f64; 3],
    /// The plane.
    pub plane: Plane,
    /// G2 (clockwise seen from the normal's positive side) or G3.
    pub clockwise: bool,
    /// Full turns beyond the first partial one (the P word − 1; 0 without P).
    pub extra_turns: u32,
    /// Radius \[m\] (the start's distance from the centre).
    pub radius: f64,
    /// Signed angle swept \[rad\] (negative clockwise), full turns included.
    pub sweep: f64,
}

impl ArcMove {
    /// The point at the fraction `u` ∈ [0, 1] of the sweep (the normal
    /// coordinate moves linearly: a helix).
    pub fn point_at(&self, u: f64) -> [f64; 3] {
        let [a, b, n] = self.plane.axes();
        let a0 = (self.start[b] - self.center[b]).atan2(self.start[a] - self.center[a]);
        let angle = a0 + u * self.sweep;
        let mut p = [0.0; 3];
        p[a] = self.center[a] + self.radius * angle.cos();
        p[b] = self.center[b] + self.radius * angle.sin();
        p[n] = self.start[n] + u * (self.end[n] - self.start[n]);
        p
    }

    /// Length of the path \[m\]: √((r θ)² + h²) for the helix.
    pub fn length(&self) -> f64 {
        let n = self.plane.axes()[2];
        (self.radius * self.sweep).hypot(self.end[n] - self.start[n])
    }
}

/// One motion of a program, in the order the machine runs them.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Motion {
    /// G0: a travel move at the machine's rapid rate.
    Rapid {
        /// Start \[m\].
        start: [f64; 3],
        /// End \[m\].
        end: [f64; 3],
        /// Source line.
        line: usize,
    },
    /// G1: a straight move at the programmed feed.
    Line {
        /// Start \[m\].
        start: [f64; 3],
        /// End \[m\].
        end: [f64; 3],
        /// Feed \[m/s\].
        feed: f64,
        /// Beam or spindle on (M3/M4) or off (M5): a cut or a travel move.
        tool_on: bool,
        /// Source line.
        line: usize,
    },
    /// G2/G3: an arc (helical when the normal coordinate changes).
    Arc {
        /// The arc.
        arc: ArcMove,
        /// Feed \[m/s\] along the path.
        feed: f64,
        /// Beam or spindle on or off.
        tool_on: bool,
        /// Source line.
        line: usize,
    },
    /// G4: stand still.
    Dwell {
        /// Seconds.
        seconds: f64,
        /// Source line.
        line: usize,
    },
    /// M3/M4 (on) or M5 (off): the beam or spindle changes state here.
    Tool {
        /// On after this.
        on: bool,
        /// M4 (counter-clockwise spindle) rather than M3.
        reverse: bool,
        /// Spindle speed S in rev/min when programmed (0 when not).
        speed_rpm: f64,
        /// Source line.
        line: usize,
    },
    /// M2/M30: the program ends (nothing but blanks and comments may
    /// follow).
    End {
        /// Source line.
        line: usize,
    },
}

impl Motion {
    /// The source line.
    pub fn line(&self) -> usize {
        match self {
            Motion::Rapid { line, .. }
            | Motion::Line { line, .. }
            | Motion::Arc { line, .. }
            | Motion::Dwell { line, .. }
            | Motion::Tool { line, .. }
            | Motion::End { line } => *line,
        }
    }
}
