//! `placewords world import FILE.map -o WORLD.toml`: a MobileSim line map → a world file.

use clap::Args;
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Debug, Args)]
pub struct ImportArgs {
    /// MobileSim map (`.map`: header, `LINES` in millimetres, `Cairn: RobotHome`).
    pub map: PathBuf,
    /// World file to write (TOML). Written atomically, and only when `world check` accepts it:
    /// a segment drawn twice is imported once and a home heading brought into -180..180
    /// (each said as a warning); any other problem is an error and nothing is written.
    #[arg(short, long)]
    pub out: PathBuf,
}

pub fn run(args: ImportArgs) -> anyhow::Result<ExitCode> {
    use anyhow::Context;
    use placewords::authoring::import::{ImportError, import_map};
    use placewords::authoring::mobilesim::{self, MapError};
    let name = args.map.display().to_string();
    let out_name = args.out.display().to_string();
    let src = match placewords::spec::diag::read_text(&args.map) {
        Ok(src) => src,
        Err(e) => {
            super::print_problems(&e, Default::default())?;
            return Ok(ExitCode::from(placewords::eval::gate::EXIT_ERROR));
        }
    };
    let imported = match import_map(&src, &name, &out_name) {
        Ok(w) => w,
        Err(ImportError::Map(MapError::NoRoute {
            path,
            line,
            message,
            partial: Some(partial),
        })) => {
            // Walls and home are fine: write them, so only the route is left to add by hand.
            let text =
                mobilesim::world_to_toml(&partial, &name).context("cannot serialise the world")?;
            placewords::io::atomic::write_atomic(&args.out, text.as_bytes())
                .with_context(|| format!("{out_name}: cannot write"))?;
            errln!("{path}:{line}:1: {message}");
            errln!(
                "{out_name}: written with walls and home but no route; add the [[routes]] block there"
            );
            return Ok(ExitCode::from(placewords::eval::gate::EXIT_ERROR));
        }
        Err(e) => {
            errln!("{e}");
            return Ok(ExitCode::from(placewords::eval::gate::EXIT_ERROR));
        }
    };
    for d in &imported.repairs {
        errln!("{d}");
    }
    placewords::io::atomic::write_atomic(&args.out, imported.text.as_bytes())
        .with_context(|| format!("{out_name}: cannot write"))?;
    let spec = &imported.spec;
    let route = &spec.routes[0];
    let n = route.waypoints_m.len();
    let len: f64 = (0..n)
        .map(|i| {
            let (a, b) = (route.waypoints_m[i], route.waypoints_m[(i + 1) % n]);
            ((b[0] - a[0]).powi(2) + (b[1] - a[1]).powi(2)).sqrt()
        })
        .sum();
    outln!(
        "{out_name}: {} walls, home ({:.2}, {:.2}), route `{}` of {n} waypoints ({len:.1} m); no doors (add them by hand)",
        spec.walls.len(),
        spec.robot_home.x_m,
        spec.robot_home.y_m,
        route.id
    )?;
    Ok(ExitCode::SUCCESS)
}
