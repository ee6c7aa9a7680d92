//! The `placewords` command line: parses arguments and dispatches; no pipeline logic lives here.
//! Exit codes: 0 pass, 1 an expectation missed, 2 an error.

mod cli;

use clap::Parser;
use std::process::ExitCode;

fn main() -> ExitCode {
    let args = cli::Cli::parse();
    match cli::dispatch(args) {
        Ok(code) => code,
        Err(e) => {
            cli::out::write_err(format_args!("error: {e:#}\n"));
            ExitCode::from(placewords::eval::gate::EXIT_ERROR)
        }
    }
}
