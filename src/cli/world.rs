//! `placewords world ...`: check, render, info.

use anyhow::{Context, bail};
use clap::{Args, Subcommand};
use placewords::report::{RenderOptions, render_world_svg};
use placewords::spec::suggest;
use placewords::world::{DoorStates, World};
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Debug, Subcommand)]
pub enum WorldCommand {
    /// Validate world files; every problem is printed as file:line:col on stderr (exit 2).
    Check(CheckArgs),
    /// Draw a world as SVG: walls, doors, routes, home pose, scale bar, legend.
    Render(RenderArgs),
    /// Print a world's size, wall length, doors and routes (lengths, corners).
    Info(InfoArgs),
    /// Import a MobileSim line map (.map) as a world file, with a generated lap route.
    Import(super::import::ImportArgs),
}

#[derive(Debug, Args)]
pub struct CheckArgs {
    /// World files (TOML).
    #[arg(required = true)]
    pub files: Vec<PathBuf>,
}

#[derive(Debug, Args)]
pub struct RenderArgs {
    /// World file (TOML).
    pub file: PathBuf,
    /// Output SVG file.
    #[arg(short = 'o', long = "output", value_name = "OUT.svg")]
    pub output: PathBuf,
    /// Doors to draw open, by id (comma-separated or repeated).
    #[arg(long, value_name = "ID,...", value_delimiter = ',')]
    pub open: Vec<String>,
    /// Draw every door open.
    #[arg(long, conflicts_with = "open")]
    pub all_open: bool,
    /// Title above the picture (default: the world's name).
    #[arg(long)]
    pub title: Option<String>,
}

#[derive(Debug, Args)]
pub struct InfoArgs {
    /// World file (TOML).
    pub file: PathBuf,
    /// Print JSON instead of text.
    #[arg(long)]
    pub json: bool,
}

pub fn run(cmd: WorldCommand) -> anyhow::Result<ExitCode> {
    match cmd {
        WorldCommand::Check(a) => check(a),
        WorldCommand::Render(a) => render(a),
        WorldCommand::Info(a) => info(a),
        WorldCommand::Import(a) => super::import::run(a),
    }
}

fn check(args: CheckArgs) -> anyhow::Result<ExitCode> {
    let mut failed = false;
    for f in &args.files {
        match placewords::spec::world::load_world(f) {
            Ok(w) => outln!(
                "{}: ok ({} walls, {} doors, {} routes)",
                f.display(),
                w.walls.len(),
                w.doors.len(),
                w.routes.len()
            )?,
            Err(e) => {
                eprintln!("{e}");
                failed = true;
            }
        }
    }
    Ok(if failed {
        ExitCode::from(2)
    } else {
        ExitCode::SUCCESS
    })
}

/// Loads a world; on invalid input prints every located problem and returns `None`.
fn load(path: &std::path::Path) -> Option<World> {
    match placewords::spec::world::load_world(path) {
        Ok(w) => Some(w),
        Err(e) => {
            eprintln!("{e}");
            None
        }
    }
}

/// Door states from `--open` / `--all-open`; unknown ids are an error naming the closest id.
fn door_states(world: &World, open: &[String], all_open: bool) -> anyhow::Result<DoorStates> {
    if all_open {
        return Ok(DoorStates::all_open(world));
    }
    let mut states = DoorStates::all_closed(world);
    for id in open.iter().map(|s| s.trim()).filter(|s| !s.is_empty()) {
        match world.door_index(id) {
            Some(i) => states.open[i] = true,
            None => {
                let hint = suggest::hint(id, world.doors.iter().map(|d| d.id.as_str()), "door ids");
                bail!("--open: world '{}' has no door '{id}'; {hint}", world.name);
            }
        }
    }
    Ok(states)
}

fn render(args: RenderArgs) -> anyhow::Result<ExitCode> {
    let Some(world) = load(&args.file) else {
        return Ok(ExitCode::from(2));
    };
    let doors = door_states(&world, &args.open, args.all_open)?;
    let opts = RenderOptions {
        doors,
        title: args.title.clone(),
        ..RenderOptions::default()
    };
    let svg = render_world_svg(&world, &opts);
    placewords::io::atomic::write_atomic(&args.output, svg.as_bytes())
        .with_context(|| format!("cannot write {}", args.output.display()))?;
    eprintln!("wrote {}", args.output.display());
    Ok(ExitCode::SUCCESS)
}

fn info(args: InfoArgs) -> anyhow::Result<ExitCode> {
    let Some(world) = load(&args.file) else {
        return Ok(ExitCode::from(2));
    };
    let info = placewords::world::info::world_info(&world);
    if args.json {
        outln!("{}", serde_json::to_string_pretty(&info)?)?;
    } else {
        out!("{info}")?;
    }
    Ok(ExitCode::SUCCESS)
}
