//! The `qdem` binary: parses the command line, runs the command, renders errors once.
//! A run stopped by Ctrl-C or SIGTERM (checkpointed) exits with 130, as shells expect.

use qdem_cli::command::CliError;
use qdem_io::runner::RunError;
use std::process::ExitCode;

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    match qdem_cli::command::dispatch(&args) {
        Ok(()) => ExitCode::SUCCESS,
        Err(error @ CliError::Run(RunError::Interrupted { .. })) => {
            eprintln!("{error}");
            ExitCode::from(130)
        }
        Err(error) => {
            eprintln!("error: {error}");
            ExitCode::FAILURE
        }
    }
}
