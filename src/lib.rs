//! placewords: long-term place recognition for a mobile robot with a 2D laser, by multi-level
//! words of spatial densities, and the harness that proves it (worlds, a simulated Pioneer 3-DX,
//! scenarios with doors that open and close, ground truth, precision/recall).
//!
//! Data flow: world file → [`spec`] → [`world::World`]; scenario → [`sim`] → [`log`] records
//! (laps of odometry, scans and truth); odometry and scans → a [`place::PlaceRecognizer`]
//! ([`recognizer`] or [`baseline`]) → matches; matches and truth → [`eval`] (scores) →
//! [`report`] (formatting). Real logs enter through [`io`] as the same [`log`] records.
//! Modules depend one way; ARCHITECTURE.md gives the layers.

pub mod authoring;
pub mod baseline;
pub mod clock;
pub mod eval;
pub mod experiment;
pub mod external;
pub mod geom;
pub mod io;
pub mod log;
pub mod place;
pub mod recognizer;
pub mod report;
pub mod scan;
pub mod schema;
pub mod sim;
pub mod spec;
pub mod world;
