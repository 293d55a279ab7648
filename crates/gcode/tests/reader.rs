//! The G-code reader on hand-written programs: SI results against hand computations, and every
//! kind of bad input refused with its line and column.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

use std::f64::consts::{FRAC_PI_2, PI, TAU};
use std::io::BufRead;

use kerf_gcode::{
    read_points, read_program, GcodeError, Motion, PathControl, Plane, PointUnit, Program,
    ReaderSettings,
};

fn read(text: &str) -> Vec<Motion> {
    read_program(text, ReaderSettings::default()).unwrap_or_else(|e| panic!("{e}"))
}

fn err(text: &str) -> GcodeError {
    read_program(text, ReaderSettings::default()).unwrap_err()
}

fn close(a: [f64; 3], b: [f64; 3]) -> bool {
    (0..3).all(|k| (a[k] - b[k]).abs() < 1e-12)
}

#[test]
fn lines_in_si_units_absolute_incremental_and_inches() {
    let m = read("G21 G90 F600\nG1 X10 Y20\nG91 X-5 Z1.5\nG20 G90 G1 X1 F60\nG0 Y0\n");
    assert_eq!(m.len(), 4);
    let Motion::Line {
        start,
        end,
        feed,
        tool_on,
        line,
    } = m[0]
    else {
        panic!("{m:?}")
    };
    assert!(close(start, [0.0; 3]) && close(end, [0.010, 0.020, 0.0]));
    assert!((feed - 0.01).abs() < 1e-15, "600 mm/min = 0.01 m/s");
    assert!(!tool_on);
    assert_eq!(line, 2);
    let Motion::Line { end, .. } = m[1] else {
        panic!()
    };
    assert!(close(end, [0.005, 0.020, 0.0015]), "{end:?}");
    let Motion::Line { end, feed, .. } = m[2] else {
        panic!()
    };
    assert!(close(end, [0.0254, 0.020, 0.0015]));
    assert!((feed - 60.0 * 0.0254 / 60.0).abs() < 1e-15, "F60 in/min");
    assert!(matches!(m[3], Motion::Rapid { end, .. } if close(end, [0.0254, 0.0, 0.0015])));
}

#[test]
fn full_f64_precision_is_kept() {
    let m = read("G1 X0.1234567890123456 F1\n");
    let Motion::Line { end, .. } = m[0] else {
        panic!()
    };
    assert_eq!(end[0], 0.1234567890123456 * 1e-3);
}

#[test]
fn comments_line_numbers_block_delete_and_delimiters() {
    let text =
        "%\n(header) ; more\nN10 G1 X1 F100 (move)\n/G1 X2\n n20 g1 x 3 ; lower case, blanks\n%\n";
    let mut p = Program::new(text.as_bytes(), ReaderSettings::default()).unwrap();
    let m: Vec<Motion> = p.by_ref().map(|r| r.unwrap()).collect();
    assert_eq!(m.len(), 2);
    assert_eq!(p.skipped_blocks(), 1);
    assert!(matches!(m[1], Motion::Line { end, .. } if close(end, [0.003, 0.0, 0.0])));
    // The switch off: the deleted block runs.
    let m = read_program(text, ReaderSettings::default().with_block_delete(false)).unwrap();
    assert_eq!(m.len(), 3);
}

#[test]
fn spindle_and_beam_mark_cuts_and_the_end_closes_the_program() {
    let m = read("F100 S12000 M3\nG1 X1\nM5\nG1 X2\nM30\n(trailing comment)\n\n");
    assert!(
        matches!(m[0], Motion::Tool { on: true, reverse: false, speed_rpm, .. } if speed_rpm == 12000.0)
    );
    assert!(matches!(m[1], Motion::Line { tool_on: true, .. }));
    assert!(matches!(m[2], Motion::Tool { on: false, .. }));
    assert!(matches!(m[3], Motion::Line { tool_on: false, .. }));
    assert!(matches!(m[4], Motion::End { line: 5 }));
}

#[test]
fn dwell() {
    let m = read("G4 P0.5\n");
    assert_eq!(
        m,
        vec![Motion::Dwell {
            seconds: 0.5,
            line: 1
        }]
    );
}

#[test]
fn arcs_centre_format_radius_format_full_circles_helices_planes() {
    // Quarter circle CW from (10, 0) about the origin to (0, -10): I-10 J0.
    let m = read("G0 X10\nG2 X0 Y-10 I-10 J0 F60\n");
    let Motion::Arc { arc, feed, .. } = m[1] else {
        panic!()
    };
    assert!(close(arc.center, [0.0; 3]));
    assert!((arc.radius - 0.010).abs() < 1e-15);
    assert!((arc.sweep + FRAC_PI_2).abs() < 1e-12, "{}", arc.sweep);
    assert!((feed - 0.001).abs() < 1e-15);
    assert!(close(arc.point_at(1.0), [0.0, -0.010, 0.0]));
    assert!(close(
        arc.point_at(0.5),
        [0.010 * (PI / 4.0).cos(), -0.010 * (PI / 4.0).sin(), 0.0]
    ));
    // The same end CCW: three quarters.
    let m = read("G0 X10\nG3 X0 Y-10 I-10 F60\n");
    let Motion::Arc { arc, .. } = m[1] else {
        panic!()
    };
    assert!((arc.sweep - 1.5 * PI).abs() < 1e-12);
    // Radius format: G3 (10,0) -> (0,10) with R10 is the quarter about the origin; R-10 the
    // three-quarter arc about (10, 10).
    let m = read("G0 X10\nG3 X0 Y10 R10 F60\n");
    let Motion::Arc { arc, .. } = m[1] else {
        panic!()
    };
    assert!(close(arc.center, [0.0; 3]), "{:?}", arc.center);
    assert!((arc.sweep - FRAC_PI_2).abs() < 1e-12);
    let m = read("G0 X10\nG3 X0 Y10 R-10 F60\n");
    let Motion::Arc { arc, .. } = m[1] else {
        panic!()
    };
    assert!(close(arc.center, [0.010, 0.010, 0.0]), "{:?}", arc.center);
    assert!((arc.sweep - 1.5 * PI).abs() < 1e-12);
    // G2 short arc with R: centre right of the chord.
    let m = read("G0 X10\nG2 X0 Y10 R10 F60\n");
    let Motion::Arc { arc, .. } = m[1] else {
        panic!()
    };
    assert!(close(arc.center, [0.010, 0.010, 0.0]), "{:?}", arc.center);
    assert!((arc.sweep + FRAC_PI_2).abs() < 1e-12);
    // Full circle, two turns (P2), helical: Z rises 2 mm.
    let m = read("G0 X10\nG3 X10 Y0 Z2 I-10 P2 F60\n");
    let Motion::Arc { arc, .. } = m[1] else {
        panic!()
    };
    assert!((arc.sweep - 2.0 * TAU).abs() < 1e-12);
    assert_eq!(arc.extra_turns, 1);
    assert!((arc.length() - (0.010 * 2.0 * TAU).hypot(0.002)).abs() < 1e-15);
    assert!(close(arc.point_at(0.5), [0.010, 0.0, 0.001]));
    // G18 (ZX plane, turning about +Y): from (10, 0, 0) CCW about the origin to (0, 0, 10)?
    // In ZX the first axis is Z: the start has angle atan2(x, z) = pi/2; the end (z = 10) angle
    // 0: CCW from pi/2 to 0 is 3/2 pi, CW is pi/2.
    let m = read("G18 G0 X10\nG2 X0 Z10 I-10 F60\n");
    let Motion::Arc { arc, .. } = m[1] else {
        panic!()
    };
    assert_eq!(arc.plane, Plane::Zx);
    assert!((arc.sweep + FRAC_PI_2).abs() < 1e-12, "{}", arc.sweep);
    // G19 with the absolute centre mode G90.1.
    let m = read("G19 G90.1 G0 Y10\nG3 Y0 Z10 J0 K0 F60\n");
    let Motion::Arc { arc, .. } = m[1] else {
        panic!()
    };
    assert!(close(arc.center, [0.0; 3]));
    assert!((arc.sweep - FRAC_PI_2).abs() < 1e-12);
}

#[test]
fn path_control_and_safe_state_codes() {
    let text = "G17 G21 G40 G49 G54 G80 G90 G94\nG64 P0.02 Q0.01\n";
    let mut p = Program::new(text.as_bytes(), ReaderSettings::default()).unwrap();
    // Before any code: blending without a tolerance (the planner's applies).
    assert_eq!(
        p.interpreter().path_control(),
        PathControl::Blend {
            tolerance: None,
            naive_tolerance: None
        }
    );
    assert_eq!(p.by_ref().count(), 0);
    assert_eq!(
        p.interpreter().path_control(),
        PathControl::Blend {
            tolerance: Some(2e-5),
            naive_tolerance: Some(1e-5)
        }
    );
}

/// (program, line, column, a word of the message).
const BAD: &[(&str, usize, usize, &str)] = &[
    ("G1 X1 F1\nG93 X2\n", 2, 1, "G93"),
    ("G1 X1 F1\nG0 G1 X2\n", 2, 4, "motion"),
    ("G1 X1 X2 F1\n", 1, 7, "twice"),
    ("G1 X10 F1\nG2 X0 Y-10 I-9\n", 2, 1, "not on the circle"),
    ("G1 X1\n", 1, 1, "without a feed"),
    ("X1\n", 1, 1, "motion mode"),
    ("G1 X(1\n", 1, 4, "needs a number"),
    ("G1 X1 (oops\n", 1, 7, "comment"),
    ("G1 X\n", 1, 4, "needs a number"),
    ("G1 X1 F1 A3\n", 1, 10, "A"),
    ("G1 X1 F1\nM30\nG1 X2\n", 3, 1, "after the program end"),
    ("G1 X1 N10 F1\n", 1, 7, "line number"),
    ("M6\n", 1, 1, "M6"),
    ("G1 X#1 F1\n", 1, 5, "parameters"),
    ("G4\n", 1, 1, "dwell"),
    ("G4 P-1\n", 1, 4, ">= 0"),
    ("G2 X1 Y1 F1\n", 1, 1, "centre"),
    ("G0 X10\nG2 X0 Y10 I-10 R10 F1\n", 2, 16, "R"),
    ("G0 X10\nG2 X-20 R10 F1\n", 2, 1, "half the chord"),
    ("G0 X1\nG2 X1 R1 F1\n", 2, 1, "full circle"),
    ("G0 X1 I1\n", 1, 7, "I"),
    ("G1 X1 F1 P2\n", 1, 10, "P"),
    ("G17 G2 X1 K1 F1\n", 1, 11, "normal"),
    ("G1 X1 F-1\n", 1, 7, ">= 0"),
    ("G1.5 X1\n", 1, 1, "G1.5"),
    ("G0 X1 ?\n", 1, 7, "unexpected"),
    ("G1 X1e5 F1\n", 1, 6, "E"),
];

#[test]
fn bad_programs_are_refused_with_line_and_column() {
    let mut wrong = Vec::new();
    for (text, line, column, needle) in BAD {
        let shown = err(text).to_string();
        if !(shown.contains(&format!("line {line}, column {column}:")) && shown.contains(needle)) {
            wrong.push(format!("{text:?}: {shown}"));
        }
    }
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
}

#[test]
fn an_error_stops_the_stream_after_the_motions_before_it() {
    let text = "G1 X1 F60\nG1 X2\nG7\nG1 X3\n";
    let items: Vec<_> = Program::new(text.as_bytes(), ReaderSettings::default())
        .unwrap()
        .collect();
    assert_eq!(items.len(), 3);
    assert!(items[0].is_ok() && items[1].is_ok());
    assert!(matches!(
        items[2],
        Err(GcodeError::Unsupported { line: 3, .. })
    ));
}

#[test]
fn bad_settings_are_refused() {
    for s in [
        ReaderSettings::default().with_arc_tolerance(0.0),
        ReaderSettings::default().with_arc_relative_tolerance(f64::NAN),
        ReaderSettings::default().with_start([f64::INFINITY, 0.0, 0.0]),
    ] {
        assert!(matches!(
            Program::new("".as_bytes(), s),
            Err(GcodeError::InvalidSetting { .. })
        ));
    }
}

/// A reader that makes a long program on the fly: `lines` moves of a zig-zag, never held in
/// memory whole.
struct Generated {
    lines: usize,
    next: usize,
    current: Vec<u8>,
    at: usize,
}

impl std::io::Read for Generated {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let n = self.fill_buf()?.len().min(buf.len());
        buf[..n].copy_from_slice(&self.current[self.at..self.at + n]);
        self.consume(n);
        Ok(n)
    }
}

impl BufRead for Generated {
    fn fill_buf(&mut self) -> std::io::Result<&[u8]> {
        if self.at == self.current.len() && self.next < self.lines {
            self.current = if self.next == 0 {
                b"G21 G90 F3000\n".to_vec()
            } else {
                format!(
                    "G1 X{:.3} Y{:.3}\n",
                    self.next as f64 * 0.01,
                    (self.next % 2) as f64
                )
                .into_bytes()
            };
            self.at = 0;
            self.next += 1;
        }
        Ok(&self.current[self.at..])
    }
    fn consume(&mut self, amt: usize) {
        self.at += amt;
    }
}

#[test]
fn long_programs_stream() {
    let lines = 200_000;
    let source = Generated {
        lines,
        next: 0,
        current: Vec::new(),
        at: 0,
    };
    let mut p = Program::new(source, ReaderSettings::default()).unwrap();
    let mut count = 0;
    let mut last = [0.0; 3];
    for m in p.by_ref() {
        if let Motion::Line { end, .. } = m.unwrap() {
            count += 1;
            last = end;
        }
    }
    assert_eq!(count, lines - 1);
    assert_eq!(p.lines_read(), lines);
    assert!((last[0] - (lines - 1) as f64 * 1e-5).abs() < 1e-12);
}

#[test]
fn point_lists() {
    let text = "# outline\n0 0\n10.5, 20 ; comma\n\n1 2 3\n";
    let p = read_points(text.as_bytes(), PointUnit::Millimetre).unwrap();
    assert_eq!(
        p,
        vec![[0.0, 0.0, 0.0], [0.0105, 0.020, 0.0], [0.001, 0.002, 0.003]]
    );
    let p = read_points("1 2\n".as_bytes(), PointUnit::Metre).unwrap();
    assert_eq!(p, vec![[1.0, 2.0, 0.0]]);
    let e = read_points("0 0\n1 x 2\n".as_bytes(), PointUnit::Metre).unwrap_err();
    assert!(e.to_string().starts_with("line 2, column 3:"), "{e}");
    let e = read_points("1 2 3 4\n".as_bytes(), PointUnit::Metre).unwrap_err();
    assert!(e.to_string().contains("4 numbers"), "{e}");
    let e = read_points("1 inf\n".as_bytes(), PointUnit::Metre).unwrap_err();
    assert!(
        matches!(
            e,
            GcodeError::BadValue {
                line: 1,
                column: 3,
                ..
            }
        ),
        "{e}"
    );
}

/// Random text from G-code's alphabet (a fixed-seed xorshift, 20 000 programs of 1–6 lines):
/// every program is read to a result or an error with a line inside it, never a panic.
#[test]
fn random_text_never_panics() {
    let alphabet: Vec<char> = "GMXYZIJKRFPQSNO0123456789.-+ ()%;/#[]\t\nAEgx"
        .chars()
        .collect();
    let mut state: u64 = 0x9E37_79B9_7F4A_7C15;
    let mut next = || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        state
    };
    let mut errors = 0;
    for _ in 0..20_000 {
        let len = (next() % 60) as usize;
        let text: String = (0..len)
            .map(|_| alphabet[(next() % alphabet.len() as u64) as usize])
            .collect();
        match read_program(&text, ReaderSettings::default()) {
            Ok(_) => {}
            Err(e) => {
                errors += 1;
                assert!(
                    e.line() >= 1 && e.line() <= text.lines().count().max(1),
                    "{text:?}: {e}"
                );
            }
        }
    }
    assert!(errors > 0);
}

#[test]
fn a_huge_radius_gives_a_finite_arc() {
    // R of 166 digits (inches): r² overflows; the centre must still be finite.
    let text = format!("G20 G91\nG1 X1 Y1 F10\nG2 X1 Y1 R1{}\n", "8".repeat(165));
    let motions = read_program(&text, ReaderSettings::default()).unwrap();
    let Motion::Arc { arc, .. } = motions[1] else {
        panic!("{:?}", motions[1])
    };
    assert!(arc.center.iter().all(|v| v.is_finite()), "{:?}", arc.center);
    assert!(arc.radius.is_finite() && arc.radius > 1e160);
    assert!(arc.sweep.is_finite() && arc.sweep < 0.0);
}

/// Issue 30, item 1: a program over the line limit is refused naming its first line beyond
/// the limit, whatever that line holds, as soon as it is reached.
#[test]
fn the_line_limit_names_the_first_line_beyond_it() {
    let limited = |text: &str, max: usize| -> Result<Vec<Motion>, GcodeError> {
        Program::new(text.as_bytes(), ReaderSettings::default())
            .unwrap()
            .with_max_lines(max)
            .collect()
    };
    // Motions beyond the limit, comments beyond it, a blank line beyond it.
    for text in [
        "G1 X1 F600\nG1 X2\nG1 X3\nG1 X4\nG1 X5\n",
        "G1 X1 F600\nG1 X2\nG1 X3\n(a comment)\n(another)\nG1 X4\n",
        "G1 X1 F600\n\n(three)\n\n",
    ] {
        let e = limited(text, 3).unwrap_err();
        assert_eq!(e, GcodeError::TooManyLines { line: 4, max: 3 }, "{text:?}");
        assert_eq!(e.line(), 4);
        let message = e.to_string();
        assert!(
            message.starts_with("line 4:") && message.contains("more than 3 lines"),
            "{message}"
        );
    }
    // Exactly the limit, with or without the last line ending, is read whole.
    for text in ["G1 X1 F600\nG1 X2\nG1 X3\n", "G1 X1 F600\nG1 X2\nG1 X3"] {
        assert_eq!(limited(text, 3).unwrap().len(), 3, "{text:?}");
    }
    // The motions before the limit come first; the refusal ends the program.
    let mut program = Program::new(
        "G1 X1 F600\nG1 X2\nG1 X3\n".as_bytes(),
        ReaderSettings::default(),
    )
    .unwrap()
    .with_max_lines(2);
    assert!(program.next().unwrap().is_ok());
    assert!(program.next().unwrap().is_ok());
    assert_eq!(
        program.next().unwrap().unwrap_err(),
        GcodeError::TooManyLines { line: 3, max: 2 }
    );
    assert!(program.next().is_none());
    assert_eq!(program.lines_read(), 2);
}
