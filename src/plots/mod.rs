//! Every figure `kerf` draws (SVG, plotters), over one helper layer ([`chart`]: figure,
//! frame, axes, ranges, line runs, legend):
//!
//! * [`joints`] — `kerf plan cut --plots`: q1..q6 against time, MJTO vs the QI baseline
//!   (seed 001 Figures 10, 13, 15);
//! * [`lobes`] and [`feed_map`] — `kerf lobes`: the stability-lobe diagram and the
//!   feed × speed |μ|max map (seed 004 Fig. 4, Fig. 7);
//! * [`training`] — `kerf train mill --plots`, `kerf train curve`: the training curve (seed
//!   004 Fig. 5);
//! * [`mill_plan`] — `kerf plan mill --plots`: the per-segment panels (seed 004 Fig. 6,
//!   Fig. 8).
//!
//! Figures draw what the libraries computed; they compute nothing but ranges and pixels.
//! Text in the SVG is ASCII (`|mu|max`, `Omega`). A non-finite value breaks a curve instead
//! of being drawn.

pub mod chart;
pub mod feed_map;
pub mod joints;
pub mod lobes;
pub mod mill_plan;
pub mod training;

use plotters::style::RGBColor;

/// Colours of the curves of several planners, in order.
pub const PALETTE: [RGBColor; 6] = [
    RGBColor(0x1f, 0x4e, 0xc8),
    RGBColor(0xd0, 0x30, 0x20),
    RGBColor(0x20, 0x90, 0x40),
    RGBColor(0x90, 0x40, 0xb0),
    RGBColor(0xe0, 0x90, 0x10),
    RGBColor(0x40, 0x40, 0x40),
];
