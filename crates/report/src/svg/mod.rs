//! Minimal hand-written SVG charts: line charts (torque curves) and grouped bar charts
//! (the paper's Fig. 7).
//!
//! Why not `plotters`: its chart layout measures text through a font backend (`ttf` →
//! font-kit → system fonts), which would tie report generation to fonts installed on the
//! machine; without it, labelled axes are not available. Two chart kinds with axes, ticks and a
//! legend are a few hundred lines, produce small, well-formed XML (the report is
//! XHTML-compatible), let the browser render text with its own fonts, and give full control over
//! escaping. Text widths are estimated (0.6 em per character) only to lay out the legend and
//! the bar groups, with generous spacing.

mod bar;
mod line;
mod placement;
mod primitives;
mod scatter;
#[cfg(test)]
mod tests;

pub use bar::*;
pub use line::*;
pub use primitives::{Marker, PALETTE, nice_ticks};
pub use scatter::*;
