//! Output for people and machines: JSON reports, text and Markdown tables, SVG pictures.

pub mod compare;
pub mod explain;
pub mod json;
pub mod junit;
pub(crate) mod lap_strip;
pub mod motion;
pub mod plot;
pub mod profile;
pub mod suite;
pub(crate) mod svg;
pub mod table;
pub(crate) mod world_render;
pub(crate) mod xml;

pub use world_render::{LegendEntry, PathOverlay, RenderOptions, SegmentOverlay, render_world_svg};
