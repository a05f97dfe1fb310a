//! The rows of `ssn sweep --csv`: one per point of the `T`-periodic branch and, when the
//! sweep followed period-2 branches (`[sweep] period_two = true`), one per point of each,
//! told apart by two more columns, `branch` (0: the sweep; `k`: its `k`-th period-2 branch)
//! and `period_multiple` (the orbit's period in periods of the forcing: 1 or 2). A sweep
//! without period-2 branches has neither column. `contact_force_mean` and
//! `max_penetration` (sums over the unilateral contacts) are written where the branch has
//! unilateral contacts; the friction points' columns where it has friction points.

use semismooth_contact::sweep::doubling::PeriodTwoOutcome;
use semismooth_contact::sweep::FrequencyResponse;

use crate::output::stability_numbers;

/// The named columns of the points of one branch.
fn branch_columns(response: &FrequencyResponse) -> Vec<(String, Vec<f64>)> {
    let points = &response.points;
    let field = |f: &dyn Fn(&semismooth_contact::sweep::ResponsePoint) -> f64| -> Vec<f64> {
        points.iter().map(f).collect()
    };
    let (stable, floquet) = stability_numbers(response);
    let mut columns = vec![
        ("omega".to_string(), field(&|p| p.omega)),
        ("omega_ratio".to_string(), response.omega_ratio()),
        ("tip_max".to_string(), field(&|p| p.observed_max)),
        ("tip_min".to_string(), field(&|p| p.observed_min)),
        ("amplitude".to_string(), response.amplitudes()),
        ("stable".to_string(), stable),
        ("floquet_max_abs".to_string(), floquet),
    ];
    // The unilateral contacts' sums belong to a branch with such contacts: a damper-only
    // (friction) or linear branch has no normal force and no penetration to report.
    if points.iter().any(|p| !p.contacts.is_empty()) {
        columns.push((
            "contact_force_mean".to_string(),
            response.contact_force_mean(),
        ));
        columns.push((
            "max_penetration".to_string(),
            field(&|p| p.stability.max_penetration),
        ));
    }
    columns.extend(response.contact_columns());
    columns
}

/// The sweep's CSV columns (module documentation).
pub fn sweep_columns(response: &FrequencyResponse) -> Vec<(String, Vec<f64>)> {
    let mut columns = branch_columns(response);
    let branches: Vec<&FrequencyResponse> = (response.period_two.iter())
        .filter_map(|outcome| match outcome {
            PeriodTwoOutcome::Followed(b) => Some(&b.response),
            _ => None,
        })
        .collect();
    if branches.is_empty() {
        return columns;
    }
    let rows = response.points.len();
    columns.push(("branch".into(), vec![0.0; rows]));
    columns.push(("period_multiple".into(), vec![1.0; rows]));
    for (k, branch) in branches.iter().enumerate() {
        let mut more = branch_columns(branch);
        let len = branch.points.len();
        more.push(("branch".into(), vec![(k + 1) as f64; len]));
        more.push(("period_multiple".into(), vec![2.0; len]));
        // By name (a column the branch lacks is not a number there).
        for (name, values) in &mut columns {
            match more.iter_mut().find(|(other, _)| other == name) {
                Some((_, extra)) => values.append(extra),
                None => values.extend(std::iter::repeat_n(f64::NAN, len)),
            }
        }
    }
    columns
}
