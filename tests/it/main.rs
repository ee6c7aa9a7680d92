//! One integration-test binary (keeps link time down on 2 cores); one module per area.

mod architecture;
mod authoring;
mod bag;
#[path = "../support/big_world.rs"]
mod big_world;
mod budget;
mod cache;
mod ci;
mod cli;
mod common;
mod compare;
mod eval;
mod frontend_bound;
mod fuzz;
mod io;
mod longterm;
mod merge;
mod outputs;
mod plugin;
mod provenance;
mod recognizer;
mod routes;
mod scan_context;
mod schema;
mod settings;
mod sim;
mod spec;
#[path = "../support/synth.rs"]
mod synth;
mod tour;
mod world;
