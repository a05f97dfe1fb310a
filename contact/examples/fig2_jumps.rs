//! The jumps of a slow experiment on the paper's Fig. 2 rod (consistent mass, gap 0.5)
//! against the folds of its harmonic-balance branch: Moreau–Jean time marching
//! (restitution 0) with the frequency stepped up, then down, each step started from the
//! last state of the previous one; the amplitude drops where the upper branch ends and
//! rises where the lower one meets the stop. Prints both sweeps' amplitudes and the table
//! of jump frequencies against the folds at `H = 5` (the figure's) and `H = 20`.
//!
//! ```text
//! cargo run --release -p semismooth-contact --example fig2_jumps [STEP STEPS_PER_PERIOD]
//! ```
//!
//! `STEP` is the frequency step in `omega_1` (default 0.002), `STEPS_PER_PERIOD` the
//! march's (default 500).
mod args;
#[path = "../tests/common/stepped_march.rs"]
mod stepped_march;

use std::time::Instant;

use args::positional;
use semismooth_contact::march::{MarchOptions, MarchScheme};
use semismooth_contact::rod::{build_rod, RodSpec};
use stepped_march::{branch_folds, jump, stepped_amplitudes};

fn main() {
    let step = positional(1, 0.002, "STEP: a number");
    let steps_per_period = positional(2, 500, "STEPS_PER_PERIOD: an integer");
    let rod = build_rod(&RodSpec::canonical().with_tip_gap(Some(0.5))).expect("the rod");
    let w1 = rod.omega_1;
    let (folds_5, folds_20) = (branch_folds(&rod, 5), branch_folds(&rod, 20));
    // Up from omega_1 (on the contact branch) past the upper fold, and back down.
    let top = folds_5[0] + 0.01;
    let count = ((top - 1.0) / step).ceil() as usize;
    let up: Vec<f64> = (0..=count).map(|k| (1.0 + k as f64 * step) * w1).collect();
    let down: Vec<f64> = up.iter().rev().copied().collect();
    let options = MarchOptions {
        steps_per_period,
        tolerance: 1e-6,
        max_periods: 1500,
        scheme: MarchScheme::MOREAU_JEAN_DEFAULT,
    };
    let start = Instant::now();
    let a_up = stepped_amplitudes(&rod.model, &up, &options, rod.tip_dof());
    let a_down = stepped_amplitudes(&rod.model, &down, &options, rod.tip_dof());
    let seconds = start.elapsed().as_secs_f64();
    println!("omega/omega_1  amplitude up  amplitude down");
    for k in 0..up.len() {
        println!(
            "{:>13.4}  {:>12.4}  {:>14.4}",
            up[k] / w1,
            a_up[k],
            a_down[up.len() - 1 - k]
        );
    }
    let (jump_up, drop) = jump(&up, &a_up);
    let (jump_down, rise) = jump(&down, &a_down);
    println!("\nsweep  jump (omega_1)  amplitude change  fold H = 5  fold H = 20");
    println!(
        "up     {:>14.4}  {drop:>16.3}  {:>10.4}  {:>11.4}",
        jump_up / w1,
        folds_5[0],
        folds_20[0]
    );
    println!(
        "down   {:>14.4}  {rise:>16.3}  {:>10.4}  {:>11.4}",
        jump_down / w1,
        folds_5[1],
        folds_20[1]
    );
    println!(
        "\n{} frequencies each way, step {step} omega_1, {steps_per_period} steps per period: {seconds:.1} s",
        up.len()
    );
}
