//! # ssn
//!
//! The application of `semismooth-contact`: scenes (TOML problem files), runs, studies,
//! figures, tables, outputs and the `ssn` program.

pub mod accuracy_cost;
pub mod accuracy_targets;
pub mod adaptive_sweeps;
pub mod cli;
pub mod describe;
pub mod exit;
pub mod figures;
pub mod friction_tables;
pub mod import;
pub mod input_file;
pub mod io;
pub mod json;
pub mod limits;
pub mod modes;
pub mod output;
pub mod paraview;
pub mod progress;
pub mod reduce;
pub mod scene;
pub mod solutions;
pub mod source;
pub mod state;
pub mod study;
pub mod sweep_table;
pub mod tables;
pub mod words;
pub mod work;
