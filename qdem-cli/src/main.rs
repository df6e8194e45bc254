//! The `qdem` binary: parses the command line, runs the command, renders errors once.
//! `--help` and `--version` print on stdout and succeed; a bad command line exits with 1 like
//! any other error; a run stopped by Ctrl-C or SIGTERM (checkpointed) exits with 130, as shells
//! expect.

use clap::Parser;
use qdem_cli::command::{dispatch, Cli, CliError};
use qdem_io::runner::RunError;
use std::process::ExitCode;

fn main() -> ExitCode {
    let result = match Cli::try_parse() {
        Ok(cli) => dispatch(cli),
        Err(help) if !help.use_stderr() => {
            // --help, help and --version: clap's text, not an error.
            let _ = help.print();
            Ok(())
        }
        Err(usage) => Err(CliError::Usage(usage)),
    };
    match result {
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
