//! # semismooth-contact
//!
//! Periodic vibrations of structures with unilateral contact, as a library built only on
//! the public API of the `semismooth` core: the structural model
//! `M u'' + D u' + K u = f(t) + G^T lambda(t)` with contact
//! `G u - g <= 0, lambda <= 0, (G u - g) . lambda = 0`, its builders (the finite-element
//! rod of Shi & Legrand, a beam, a bladed disk, Matrix Market files), the formulations that
//! solve it (harmonic balance with exact or penalty contact, the periodic LCP, time
//! marching), stability, frequency responses and the solutions at one frequency.

pub mod builder;
pub mod contacts;
pub mod cyclic;
pub mod describing_function;
mod dynamic;
mod error;
pub mod exact;
pub mod from_zero;
pub mod hb;
pub mod import;
pub mod jenkins;
pub mod law;
pub mod lcp;
pub mod march;
pub mod matrix_market;
pub mod model;
pub mod modes;
pub mod operator;
pub mod reduction;
pub mod rod;
pub mod settings;
pub mod solutions;
pub mod solve;
pub mod stability;
pub mod structures;
pub mod sweep;

pub use error::{Error, ErrorKind};
pub use solve::accuracy;
pub use solve::solve;
