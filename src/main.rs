//! The `chatterspice` binary: parse the command line, run the command,
//! print errors, map them to exit codes. The work is in the library.

mod cli;

use std::io::Write;
use std::process::ExitCode;

use clap::Parser;

/// Exit code for a `check` whose limits did not all hold.
const EXIT_CHECK_FAILED: u8 = 1;

/// Exit code for bad input or a failure to run (docs/output.md).
const EXIT_FAILURE: u8 = 2;

fn main() -> ExitCode {
    let cli = match cli::Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => {
            let _ = e.print();
            // --help and --version are not errors.
            return if e.use_stderr() {
                ExitCode::from(EXIT_FAILURE)
            } else {
                ExitCode::SUCCESS
            };
        }
    };
    if let Err(e) = chatterspice::interrupt::install() {
        eprintln!(
            "warning: cannot watch for Ctrl-C ({e}): an interrupted run may leave ngspice running"
        );
    }
    match cli.command.run() {
        Ok(cli::Status::Success) => ExitCode::SUCCESS,
        Ok(cli::Status::CheckFailed) => ExitCode::from(EXIT_CHECK_FAILED),
        Err(err) => {
            report_error(&err);
            ExitCode::from(EXIT_FAILURE)
        }
    }
}

/// The error, then each cause on its own indented lines (a TOML cause
/// carries a multi-line excerpt of the file).
fn report_error(err: &anyhow::Error) {
    let mut stderr = std::io::stderr().lock();
    let _ = writeln!(stderr, "error: {err}");
    for cause in err.chain().skip(1) {
        let text = cause.to_string();
        let mut lines = text.trim_end().lines();
        if let Some(first) = lines.next() {
            let _ = writeln!(stderr, "  caused by: {first}");
        }
        for line in lines {
            let _ = writeln!(stderr, "    {line}");
        }
    }
}
