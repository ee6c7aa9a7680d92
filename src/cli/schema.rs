//! `placewords schema world|scenario [-o FILE]`: the JSON Schema (draft-07) of a world or
//! scenario file, for editors (docs/editors.md).

use clap::Args;
use placewords::schema::FileKind;
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Debug, Args)]
pub struct SchemaArgs {
    /// Which file the schema describes.
    #[arg(value_name = "world|scenario", value_parser = ["world", "scenario"])]
    pub kind: String,
    /// Write the schema to this file (atomically) instead of printing it.
    #[arg(long, short, alias = "output", value_name = "OUT.json")]
    pub out: Option<PathBuf>,
}

pub fn run(args: SchemaArgs) -> anyhow::Result<ExitCode> {
    let Some(kind) = FileKind::from_name(&args.kind) else {
        anyhow::bail!("unknown schema `{}`; use world or scenario", args.kind);
    };
    let text = kind.schema_text();
    match &args.out {
        Some(path) => {
            super::common::check_extension(path, "json")?;
            super::common::write_file(path, text.as_bytes())?;
        }
        None => out!("{text}")?,
    }
    Ok(ExitCode::SUCCESS)
}
