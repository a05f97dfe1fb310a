//! # ssn
//!
//! The application of `semismooth-contact`: scenes (TOML problem files), runs, studies,
//! figures, tables, outputs and the `ssn` program.
//!
//! Without the `cli` feature (on by default) it is the scene layer alone: scenes, loading
//! ([`load`]), studies and the JSON documents, with none of the program's commands,
//! arguments, progress bars, figures or ParaView files (the Python package builds it so).

pub mod accuracy_cost;
#[cfg(feature = "cli")]
pub mod accuracy_targets;
#[cfg(feature = "cli")]
pub mod adaptive_sweeps;
#[cfg(feature = "cli")]
pub mod cli;
#[cfg(feature = "cli")]
pub mod describe;
pub mod exit;
#[cfg(feature = "cli")]
pub mod figures;
#[cfg(feature = "cli")]
pub mod friction_tables;
pub mod import;
pub mod input_file;
pub mod io;
pub mod json;
pub mod limits;
pub mod load;
pub mod modes;
pub mod output;
#[cfg(feature = "cli")]
pub mod paraview;
#[cfg(feature = "cli")]
pub mod progress;
pub mod reduce;
pub mod scene;
pub mod solutions;
pub mod source;
pub mod state;
pub mod study;
#[cfg(feature = "cli")]
pub mod sweep_table;
#[cfg(feature = "cli")]
pub mod tables;
pub mod words;
pub mod work;
