//! The `qdem` binary: parses the command line, runs the command, renders errors once.
//! `--help` and `--version` print on stdout and succeed; a bad command line exits with 1 like
//! any other error; a run stopped by Ctrl-C or SIGTERM (checkpointed) exits with 130, as shells
//! expect. Built with `--features mpi` and started by `mpirun -np N` (N > 1), `qdem run`
//! decomposes its run over the N processes; rank 0 prints and writes the outputs.

use clap::Parser;
use qdem_cli::command::{dispatch, Cli, CliError};
use qdem_core::parallel::Communicator;
use qdem_io::runner::RunError;
use std::process::ExitCode;
use std::sync::Arc;

/// Transparent huge pages for the large arrays ([`qdem_cli::huge_pages`]).
#[global_allocator]
static ALLOCATOR: qdem_cli::huge_pages::HugePages = qdem_cli::huge_pages::HugePages;

fn main() -> ExitCode {
    #[cfg(feature = "mpi")]
    let mpi = qdem_cli::mpi_ranks::start().map(|(universe, ranks)| (universe, Arc::new(ranks)));
    #[cfg(feature = "mpi")]
    let ranks = mpi
        .as_ref()
        .map(|(_, r)| r.clone() as Arc<dyn Communicator>);
    #[cfg(not(feature = "mpi"))]
    let ranks: Option<Arc<dyn Communicator>> = None;
    let leader = ranks.as_ref().is_none_or(|r| r.rank() == 0);
    let result = match Cli::try_parse() {
        Ok(cli) => dispatch(cli, ranks),
        Err(help) if !help.use_stderr() => {
            // --help, help and --version: clap's text, not an error.
            if leader {
                let _ = help.print();
            }
            Ok(())
        }
        Err(usage) => Err(CliError::Usage(usage)),
    };
    let code = match result {
        Ok(()) => return ExitCode::SUCCESS,
        Err(error @ CliError::Run(RunError::Interrupted { .. })) => {
            print_error(&error.to_string());
            return ExitCode::from(130);
        }
        Err(error) => {
            if leader {
                print_error(&format!("error: {error}"));
            }
            1
        }
    };
    // A rank that fails may be alone in failing (an output rank 0 cannot write): the others
    // would wait for it at their next exchange, so the whole run ends now. Rank 0 has
    // printed the error; the others, which fail with the same error, give it a second to
    // do so before they end the run.
    #[cfg(feature = "mpi")]
    if let Some((_, ranks)) = &mpi {
        if !leader {
            std::thread::sleep(std::time::Duration::from_secs(1));
        }
        ranks.abort(code);
    }
    ExitCode::from(code as u8)
}

/// Writes the error as one line in a single write: under mpirun, a message written in pieces
/// can be split by the launcher's own abort notice, which it prints while it forwards ours.
fn print_error(message: &str) {
    use std::io::Write;
    let _ = std::io::stderr().write_all(format!("{message}\n").as_bytes());
}
