//! The `chatterspice` binary: parse the command line, call the library,
//! print, map errors to exit codes (0 ok, 2 bad input or failure to run).

use std::io::{BufWriter, Write};
use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Context;
use chatterspice::rawfile::{RawFile, export};
use clap::{Parser, Subcommand, ValueEnum};

#[derive(Parser)]
#[command(
    name = "chatterspice",
    version,
    about = "Relay contact bounce from physics into ngspice"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Print a SPICE raw file: one plot as CSV, or a JSON summary of every plot.
    Raw {
        /// The raw file (ngspice binary or ASCII).
        file: PathBuf,
        /// Plot to print as CSV, numbered from 0 in file order [default: the last].
        #[arg(long)]
        plot: Option<usize>,
        #[arg(long, value_enum, default_value_t = Format::Csv)]
        format: Format,
    },
}

#[derive(Clone, Copy, ValueEnum)]
enum Format {
    Csv,
    Json,
}

fn main() -> ExitCode {
    match run(Cli::parse()) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            let broken_pipe = e
                .downcast_ref::<export::ExportError>()
                .is_some_and(export::ExportError::is_broken_pipe);
            if broken_pipe {
                return ExitCode::SUCCESS;
            }
            eprintln!("chatterspice: error: {}", message(&e));
            ExitCode::from(2)
        }
    }
}

/// The error and its causes, each said once: library errors already put
/// their cause's text in their own message.
fn message(e: &anyhow::Error) -> String {
    let mut msg = String::new();
    for cause in e.chain() {
        let text = cause.to_string();
        if !msg.contains(&text) {
            if !msg.is_empty() {
                msg.push_str(": ");
            }
            msg.push_str(&text);
        }
    }
    msg
}

fn run(cli: Cli) -> anyhow::Result<()> {
    match cli.command {
        Command::Raw { file, plot, format } => {
            let raw = RawFile::read(&file)?;
            for w in &raw.warnings {
                eprintln!("chatterspice: warning: {}: {w}", file.display());
            }
            // Checked for JSON too, so a wrong index is never silently ignored.
            let selected = export::select_plot(&raw, plot)
                .with_context(|| format!("in {}", file.display()))?;
            let mut out = BufWriter::new(std::io::stdout().lock());
            match format {
                Format::Csv => export::plot_csv(selected, &mut out)?,
                Format::Json => out
                    .write_all(export::summary_json(&raw).as_bytes())
                    .map_err(export::ExportError::Write)?,
            }
            out.flush().map_err(export::ExportError::Write)?;
            Ok(())
        }
    }
}
