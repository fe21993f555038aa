//! The integration tests, one crate (one link) with a module per area:
//! the engine against closed forms, the ngspice interface, the CLI end to
//! end, and what bad or hostile input must never do.
//!
//! Tests that need ngspice skip with a note when it is missing and fail
//! when `REQUIRE_NGSPICE=1` (CI sets it); see [`common::ngspice`].

#[macro_use]
mod common;

mod analysis;
mod arcs;
mod capture;
mod circuit_params;
mod cli_bounce;
mod cli_check;
mod cli_raw;
mod cli_run;
mod cli_sweep;
mod coil;
mod coil_coupled;
mod coil_netlist;
mod coil_release;
mod coupling_accelerated;
mod drivers;
mod envelope;
mod extremes;
mod fit;
mod free_impact;
mod kicad;
mod kicad_project;
mod lockstep;
mod ltspice;
mod mechanics_closed_forms;
mod mechanics_sweep;
mod netlist;
mod packaging;
mod parts;
mod power_ratings;
mod rawfile;
mod rawfile_interp;
mod run;
mod safety;
mod scenario_base;
mod schema;
mod source_paths;
mod spice_runner;
mod sweep;
mod timing;
mod trajectory;
mod waveform;
