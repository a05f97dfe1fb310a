//! SSN-HB against the exact 3-D Moreau–Jean march on the frictional oscillator (two
//! tangential dofs, one normal dof): the relative difference of the first-harmonic
//! amplitudes and the dissipated energy as `H` grows, for stick-slip with a turning slip
//! direction and for liftoff, printed as the markdown table of `docs/frictional-contact.md`.
//!
//! ```sh
//! cargo run --release -p semismooth-contact --example frictional_march_table
//! ```

#[path = "../tests/common/disk_march.rs"]
mod disk_march;

use disk_march::{extrapolated, harmonic_balance, march, LIFTOFF, STICK_SLIP};

fn main() {
    let steps: [usize; 2] = std::env::args()
        .skip(1)
        .map(|a| a.parse().unwrap())
        .collect::<Vec<_>>()
        .try_into()
        .unwrap_or([4000, 8000]);
    println!("| case | H | x amplitude | y amplitude | energy per cycle | stick / slip / separated | difference to the march |");
    println!("|---|---|---|---|---|---|---|");
    for case in [STICK_SLIP, LIFTOFF] {
        let coarse = march(&case, steps[0]);
        let fine = march(&case, steps[1]);
        let reference = extrapolated(&coarse, &fine);
        let row = |label: String, m: &disk_march::Measures, difference: String| {
            let r = &m.report;
            println!(
                "| {} | {label} | {:.6} | {:.6} | {:.6} | {:.3} / {:.3} / {:.3} | {difference} |",
                case.name,
                m.amplitude[0],
                m.amplitude[1],
                r.dissipated_energy,
                r.stick_fraction,
                r.slip_fraction,
                r.separated_fraction
            );
        };
        for h in [5, 10, 20, 40, 80] {
            let hb = harmonic_balance(&case, h);
            row(
                h.to_string(),
                &hb,
                format!("{:.2e}", hb.difference(&reference)),
            );
        }
        row(
            format!("march {}", steps[0]),
            &coarse,
            format!("{:.2e}", coarse.difference(&reference)),
        );
        row(
            format!("march {}", steps[1]),
            &fine,
            format!("{:.2e}", fine.difference(&reference)),
        );
        row("march extrapolated".into(), &reference, "reference".into());
    }
}
