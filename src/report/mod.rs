//! Output for people and machines: JSON reports, text and Markdown tables, SVG pictures.
