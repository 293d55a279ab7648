//! SVG plots of the G-code front end (issue 14), ROS-free and without a
//! plotting dependency: [`Chart`], a line chart with nice ticks, a legend,
//! limit lines and point markers, rendered to a standalone SVG string
//! ([`chart`], [`render`], [`legend`], [`ticks`], [`svg`]); [`pipeline_plots`], the figures of
//! seed 000 Fig. 5 and seed 003 Figs. 12–14 for one smoothed path and its
//! feed plan ([`pipeline`]).

pub mod chart;
pub mod legend;
pub mod pipeline;
pub mod render;
pub mod svg;
pub mod ticks;

pub use chart::{Chart, LimitLine, Series, Style};
pub use pipeline::{pipeline_charts, pipeline_plots};
pub use ticks::{nice_step, tick_label, Axis};
