//! Output for people and machines: JSON reports, text and Markdown tables, SVG pictures.

pub mod json;
pub mod junit;
pub mod lap_strip;
pub mod plot;
pub mod suite;
pub mod svg;
pub mod table;
pub mod world_render;
pub mod xml;

pub use world_render::{LegendEntry, PathOverlay, RenderOptions, SegmentOverlay, render_world_svg};
