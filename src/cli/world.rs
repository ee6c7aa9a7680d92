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
    /// Validate world files and test-drive their routes (with all doors closed and all open); every problem is printed as file:line:col on stderr (exit 2).
    #[command(after_help = "Example:\n  placewords world check worlds/*.toml")]
    Check(CheckArgs),
    /// Draw a world as SVG: walls, doors, routes, home pose, scale bar, legend (an invalid world as far as it read, its problems marked from 0).
    #[command(
        after_help = "Example:\n  placewords world render worlds/institute-floor.toml -o floor.svg --open s-04,n-01 --waypoints"
    )]
    Render(RenderArgs),
    /// Print a world's size, wall length, doors and routes (lengths, corners).
    #[command(after_help = "Example:\n  placewords world info worlds/institute-floor.toml --json")]
    Info(InfoArgs),
    /// Import a MobileSim line map (.map) as a world file, with a generated lap route.
    #[command(
        after_help = "Example:\n  placewords world import ../shared/data/mobilesim/office.map -o office.toml"
    )]
    Import(super::import::ImportArgs),
    /// Colour every free cell by the density class the recognizer gives it (paper Fig. 2a).
    #[command(
        after_help = "Example:\n  placewords world density worlds/institute-floor.toml -o d.svg"
    )]
    Density(DensityArgs),
    /// Drive a route once without noise and mark the stretches the recognizer will confuse.
    #[command(
        after_help = "Example:\n  placewords world ambiguity worlds/institute-floor.toml --route lap -o a.svg --json"
    )]
    Ambiguity(AmbiguityArgs),
    /// Write a random valid floor (corridor loop, offices with doors, niches, walking areas, a lap route).
    #[command(
        after_help = "Example:\n  placewords world generate --seed 1 -o floor.toml\n  placewords world generate --seed 2 --size-m 60,40 --doors 20 -o big.toml\n  placewords world generate --seed 3 --size-m 60,30 --double-loaded --rooms 30 -o ward.toml"
    )]
    Generate(GenerateArgs),
}

/// `--size-m W,H`: two numbers, separated by a comma or spaces.
fn size_m(text: &str) -> Result<(f64, f64), String> {
    let parts: Vec<&str> = text
        .split(|c: char| c == ',' || c.is_whitespace())
        .filter(|p| !p.is_empty())
        .collect();
    let numbers: Vec<f64> = parts.iter().filter_map(|p| p.parse().ok()).collect();
    match numbers[..] {
        [w, h] if parts.len() == 2 => Ok((w, h)),
        _ => Err("two numbers, width and height in metres: 50,40 or \"50 40\"".to_string()),
    }
}

#[derive(Debug, Args)]
pub struct GenerateArgs {
    /// Seed: the same seed and options give the same file.
    #[arg(long)]
    pub seed: u64,
    /// Floor size in metres, x and y (each 24-2000): `50,40` or `"50 40"`.
    #[arg(long = "size-m", value_name = "W,H", default_value = "40,30", value_parser = size_m)]
    pub size_m: (f64, f64),
    /// Number of offices, each with one door (more than fit is refused with the number that fits).
    #[arg(long, visible_alias = "rooms", default_value_t = 12)]
    pub doors: usize,
    /// Corridors of the loop: 4, 6, 8, 10 or 12.
    #[arg(long, default_value_t = 4)]
    pub corridors: usize,
    /// Offices on both sides of every corridor (inside the loop too), as in a hospital ward.
    #[arg(long)]
    pub double_loaded: bool,
    /// Make the corridors look alike on purpose: offices of one width, doors at one place, no
    /// niches (the recognizer's hardest case).
    #[arg(long)]
    pub look_alike: bool,
    /// Output world file (TOML).
    #[arg(short = 'o', long = "out", alias = "output", value_name = "WORLD.toml")]
    pub output: PathBuf,
}

#[derive(Debug, Args)]
pub struct DensityArgs {
    /// World file (TOML).
    pub file: PathBuf,
    /// Output SVG file.
    #[arg(short = 'o', long = "out", alias = "output", value_name = "OUT.svg")]
    pub output: PathBuf,
    /// Doors open, by id (comma-separated or repeated); the others are closed.
    #[arg(long, value_name = "ID,...", value_delimiter = ',')]
    pub open: Vec<String>,
}

#[derive(Debug, Args)]
pub struct AmbiguityArgs {
    /// World file (TOML); not needed with --scenario, which names its world.
    #[arg(required_unless_present = "scenario", conflicts_with = "scenario")]
    pub file: Option<PathBuf>,
    /// Map a scenario instead: its world and route, every door set its runs use (a random-door
    /// run: four draws), its robot and its recognizer settings; door changes between runs are
    /// flagged too.
    #[arg(long, value_name = "FILE", conflicts_with_all = ["open", "levels"])]
    pub scenario: Option<PathBuf>,
    /// With --scenario: also run the scenario at these seeds and say how many of the
    /// recognizer's false pairs (deepest level configuration) fall in flagged stretches.
    #[arg(long, value_name = "A..B", requires = "scenario")]
    pub measure: Option<placewords::spec::seeds::SeedRange>,
    /// Route to drive, by id.
    #[arg(long, default_value = "lap")]
    pub route: String,
    /// Output SVG file.
    #[arg(short = 'o', long = "out", alias = "output", value_name = "OUT.svg")]
    pub output: PathBuf,
    /// Doors open during the drive, by id (comma-separated or repeated).
    #[arg(long, value_name = "ID,...", value_delimiter = ',')]
    pub open: Vec<String>,
    /// Print the ambiguous stretches as JSON on stdout.
    #[arg(long)]
    pub json: bool,
    /// Search this many level configurations (1 = level-0 words only; default 3, as `run`).
    #[arg(long, value_parser = clap::value_parser!(u8).range(1..=4))]
    pub levels: Option<u8>,
}

#[derive(Debug, Args)]
pub struct CheckArgs {
    /// World files (TOML).
    #[arg(required = true)]
    pub files: Vec<PathBuf>,
    #[command(flatten)]
    pub format: super::MessageFormatArg,
}

#[derive(Debug, Args)]
pub struct RenderArgs {
    /// World file (TOML).
    pub file: PathBuf,
    /// Output SVG file.
    #[arg(short = 'o', long = "out", alias = "output", value_name = "OUT.svg")]
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
    /// Draw a coordinate grid with labelled metres.
    #[arg(long)]
    pub grid: bool,
    /// Number the route waypoints (from 0, as messages count them).
    #[arg(long)]
    pub waypoints: bool,
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
        WorldCommand::Density(a) => density(a),
        WorldCommand::Ambiguity(a) => ambiguity(a),
        WorldCommand::Generate(a) => generate(a),
    }
}

fn check(args: CheckArgs) -> anyhow::Result<ExitCode> {
    let mut failed = false;
    for f in &args.files {
        let format = placewords::spec::diag::MessageFormat::from_name(&args.format.message_format)
            .unwrap_or_default();
        match placewords::sim::test_drive::check_world(f) {
            Ok((w, warnings)) => print_world_ok(f, &w, warnings, format)?,
            Err(e) => {
                super::print_problems(&e, format)?;
                failed = true;
            }
        }
    }
    Ok(if failed {
        ExitCode::from(placewords::eval::gate::EXIT_ERROR)
    } else {
        ExitCode::SUCCESS
    })
}

/// The warnings of a world file that checked, then its one-line summary.
fn print_world_ok(
    f: &std::path::Path,
    w: &World,
    warnings: Vec<placewords::spec::diag::Diagnostic>,
    format: placewords::spec::diag::MessageFormat,
) -> anyhow::Result<()> {
    let n = warnings.len();
    for line in placewords::spec::diag::SpecError::Invalid(warnings).render(format) {
        errln!("{line}");
    }
    outln!(
        "{}: ok ({} walls, {} doors, {} routes{})",
        f.display(),
        w.walls.len(),
        w.doors.len(),
        w.routes.len(),
        match n {
            0 => String::new(),
            n => format!(", {n} warning(s)"),
        }
    )?;
    Ok(())
}

/// Loads a world; on invalid input prints every located problem and returns `None`.
fn load(path: &std::path::Path) -> Option<World> {
    match placewords::world::load_world(path) {
        Ok(w) => Some(w),
        Err(e) => {
            errln!("{e}");
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

/// Renders a world; an invalid one is drawn as far as it could be read with its problems
/// marked (numbered from 0 in the order they are printed), and exits 2.
fn render(args: RenderArgs) -> anyhow::Result<ExitCode> {
    super::common::check_extension(&args.output, "svg")?;
    let src = std::fs::read_to_string(&args.file)
        .with_context(|| format!("{}: cannot read", args.file.display()))?;
    let path = args.file.display().to_string();
    let base = RenderOptions {
        title: args.title.clone(),
        show_grid: args.grid,
        show_waypoints: args.waypoints,
        ..RenderOptions::default()
    };
    let world = match placewords::world::parse_world(&src, &path) {
        Ok(w) => w,
        Err(_) => return render_problems(&src, &path, &base, &args.output),
    };
    let doors = door_states(&world, &args.open, args.all_open)?;
    let opts = RenderOptions { doors, ..base };
    let svg = render_world_svg(&world, &opts);
    super::common::write_file(&args.output, svg.as_bytes())?;
    errln!("wrote {}", args.output.display());
    Ok(ExitCode::SUCCESS)
}

/// For a world file that does not load: its problems on stderr and, when it can be drawn,
/// a picture of them at `output`; exit code 2.
fn render_problems(
    src: &str,
    path: &str,
    base: &RenderOptions,
    output: &std::path::Path,
) -> anyhow::Result<ExitCode> {
    let (svg, diags) = placewords::authoring::problems::problems_svg(src, path, base);
    diags.iter().for_each(|d| errln!("{d}"));
    if let Some(svg) = svg {
        super::common::write_file(output, svg.as_bytes())?;
        errln!(
            "wrote {} with the problems above marked 0.. in their order",
            output.display()
        );
    }
    Ok(ExitCode::from(placewords::eval::gate::EXIT_ERROR))
}

fn info(args: InfoArgs) -> anyhow::Result<ExitCode> {
    let Some(world) = load(&args.file) else {
        return Ok(ExitCode::from(placewords::eval::gate::EXIT_ERROR));
    };
    let info = placewords::world::info::world_info(&world);
    if args.json {
        outln!("{}", serde_json::to_string_pretty(&info)?)?;
    } else {
        out!("{info}")?;
    }
    Ok(ExitCode::SUCCESS)
}

fn density(args: DensityArgs) -> anyhow::Result<ExitCode> {
    super::common::check_extension(&args.output, "svg")?;
    let Some(world) = load(&args.file) else {
        return Ok(ExitCode::from(placewords::eval::gate::EXIT_ERROR));
    };
    let doors = door_states(&world, &args.open, false)?;
    let svg = placewords::authoring::density::density_picture(&world, &doors);
    super::common::write_file(&args.output, svg.as_bytes())?;
    errln!("wrote {}", args.output.display());
    Ok(ExitCode::SUCCESS)
}

fn ambiguity(args: AmbiguityArgs) -> anyhow::Result<ExitCode> {
    super::common::check_extension(&args.output, "svg")?;
    if let Some(path) = &args.scenario {
        return scenario_ambiguity(path, &args);
    }
    let Some(file) = &args.file else {
        anyhow::bail!("give a world file or --scenario FILE");
    };
    let Some(world) = load(file) else {
        return Ok(ExitCode::from(placewords::eval::gate::EXIT_ERROR));
    };
    let doors = door_states(&world, &args.open, false)?;
    let levels = args.levels.map(usize::from);
    let (report, svg) =
        placewords::authoring::ambiguity::ambiguity_picture(&world, &args.route, &doors, levels)
            .with_context(|| format!("{}", file.display()))?;
    super::common::write_file(&args.output, svg.as_bytes())?;
    let text = if args.json {
        format!("{}\n", report.to_json())
    } else {
        report.summary()
    };
    print_quietly(&text)?;
    errln!("wrote {}", args.output.display());
    Ok(ExitCode::SUCCESS)
}

/// `world ambiguity --scenario FILE [--measure SEEDS]`.
fn scenario_ambiguity(path: &std::path::Path, args: &AmbiguityArgs) -> anyhow::Result<ExitCode> {
    use placewords::authoring::{ambiguity, prediction};
    let scn = match placewords::experiment::load_scenario(path) {
        Ok(s) => s,
        Err(e) => {
            errln!("{e}");
            return Ok(ExitCode::from(placewords::eval::gate::EXIT_ERROR));
        }
    };
    let (report, _) =
        prediction::scenario_ambiguity(&scn).with_context(|| format!("{}", path.display()))?;
    let closed = placewords::world::DoorStates::all_closed(&scn.sim.world);
    let svg = ambiguity::ambiguity_svg(&scn.sim.world, &closed, &report);
    super::common::write_file(&args.output, svg.as_bytes())?;
    errln!("wrote {}", args.output.display());
    let measured = match &args.measure {
        Some(range) => {
            let seeds: Vec<u64> = range.seeds().collect();
            let tell = |seed: u64| errln!("running {} seed {seed}", scn.sim.name);
            Some(
                prediction::predict(&scn, &report, &seeds, &tell)
                    .with_context(|| format!("{}", path.display()))?,
            )
        }
        None => None,
    };
    let text = if args.json {
        let mut v = serde_json::to_value(&report)?;
        if let Some(m) = &measured {
            v["prediction"] = serde_json::to_value(m)?;
        }
        format!("{}\n", serde_json::to_string_pretty(&v)?)
    } else {
        let mut t = report.summary();
        if let Some(m) = &measured {
            t.push_str(&m.summary());
        }
        t
    };
    print_quietly(&text)?;
    Ok(ExitCode::SUCCESS)
}

/// Writes to stdout; a closed pipe (`| head`) ends quietly.
fn print_quietly(text: &str) -> anyhow::Result<()> {
    Ok(out!("{text}")?)
}

fn generate(args: GenerateArgs) -> anyhow::Result<ExitCode> {
    use placewords::authoring::generate::{GenerateOptions, generate_toml};
    super::common::check_extension(&args.output, "toml")?;
    let opts = GenerateOptions {
        seed: args.seed,
        size_m: args.size_m,
        doors: args.doors,
        corridors: args.corridors,
        double_loaded: args.double_loaded,
        look_alike: args.look_alike,
    };
    let text = generate_toml(&opts)?;
    super::common::write_file(&args.output, text.as_bytes())?;
    errln!("wrote {}", args.output.display());
    Ok(ExitCode::SUCCESS)
}
