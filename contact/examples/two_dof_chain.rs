//! Scratch: two-dof chain with a stop on a mass-carrying dof, swept at H = 10, 20, 40.
#[path = "../tests/common/chain.rs"]
mod chain;

use semismooth_contact::settings::{SolverSettings, SweepSettings};
use semismooth_contact::sweep::frequency_response;

fn main() {
    let arg = |i: usize, d: f64| {
        std::env::args()
            .nth(i)
            .map(|s| s.parse().unwrap())
            .unwrap_or(d)
    };
    // Arguments: gap, damping ratio, force on mass 0, force on mass 1.
    let structure = chain::chain(arg(1, 0.5), arg(2, 0.02), [arg(3, 0.0), arg(4, 0.1)]);
    let omega_1 = structure.omega_1;
    let hs: Vec<usize> = std::env::var("HS")
        .map(|v| v.split(',').map(|x| x.parse().unwrap()).collect())
        .unwrap_or(vec![10, 20, 40]);
    for h in hs {
        let settings = SolverSettings::with_harmonics(h);
        let t = std::time::Instant::now();
        let r =
            frequency_response(&structure, &settings, &SweepSettings::new(0.5, 3.0), None).unwrap();
        println!("H = {h}: points {} converged {} {:?} folds {:?} corners {} restarts {} last {:.4} stable {} unstable {} undecided {} {:.2}s stab {:.2}s",
            r.points(), r.converged(), r.termination, r.folds.iter().map(|w| w / omega_1).collect::<Vec<_>>(), r.corner_folds.len(), r.restarts,
            r.omega.last().unwrap() / omega_1,
            r.stability.stable.iter().filter(|s| **s == Some(true)).count(),
            r.stability.stable.iter().filter(|s| **s == Some(false)).count(),
            r.stability.stable.iter().filter(|s| s.is_none()).count(),
            t.elapsed().as_secs_f64(), r.stability_seconds);
        if std::env::var("DUMP").is_ok() {
            for i in 0..r.points() {
                println!(
                    "{i} {:.6} {:.6} {:.6} it {} stable {:?} mu {:?} placed {}",
                    r.omega[i] / omega_1,
                    r.tip_max[i],
                    r.tip_min[i],
                    r.iterations[i],
                    r.stability.stable[i],
                    r.stability.floquet_max_abs[i],
                    r.stability.placed_by_fold[i]
                );
            }
        }
    }
}
