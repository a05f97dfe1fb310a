//! # semismooth-problems
//!
//! Concrete periodic contact problems built only on the public API of the `semismooth`
//! core: the structural model `M u'' + D u' + K u = f(t) + G^T lambda(t)` with unilateral
//! contact `G u - g <= 0, lambda <= 0, (G u - g) . lambda = 0`, the finite-element rod of
//! Shi & Legrand, and the formulations that solve it.

pub mod branch;
pub mod cli;
pub mod contacts;
mod dynamic;
pub mod figures;
pub mod from_zero;
pub mod hb;
pub mod import;
pub mod io;
pub mod lcp;
pub mod limits;
pub mod march;
pub mod model;
pub mod output;
pub mod rod;
pub mod runner;
pub mod scene;
pub mod solutions;
pub mod stability;
pub mod state;
pub mod structures;
pub mod study;
pub mod sweep;
pub mod tables;
