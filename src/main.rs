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
            // The causes after the message, each once: `{e:#}` repeats one that the message
            // already quotes ("cannot read: No such file or directory: No such file …").
            let mut text = e.to_string();
            for cause in e.chain().skip(1).map(|c| c.to_string()) {
                if !text.contains(&cause) {
                    text = format!("{text}: {cause}");
                }
            }
            cli::out::write_err(format_args!("error: {text}\n"));
            ExitCode::from(placewords::eval::gate::EXIT_ERROR)
        }
    }
}
