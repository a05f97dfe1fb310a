//! Progress on standard error: bars and spinners, shown only on a terminal and when the
//! run is not quiet ([`crate::io::quiet`]).

use std::io::IsTerminal;
use std::sync::OnceLock;

/// The process's bars, drawn together so that bars of work running side by side do not
/// overwrite each other's line.
fn bars() -> &'static indicatif::MultiProgress {
    static BARS: OnceLock<indicatif::MultiProgress> = OnceLock::new();
    BARS.get_or_init(indicatif::MultiProgress::new)
}

/// A spinner on stderr when it is a terminal and the run is not quiet.
pub fn progress_spinner(message: &str) -> indicatif::ProgressBar {
    if crate::io::quiet() || !std::io::stderr().is_terminal() {
        return indicatif::ProgressBar::hidden();
    }
    let bar = bars().add(indicatif::ProgressBar::new_spinner());
    bar.set_message(message.to_string());
    bar.enable_steady_tick(std::time::Duration::from_millis(120));
    bar
}

/// A progress bar on stderr when it is a terminal and the run is not quiet.
pub fn progress_bar(len: u64, message: &str) -> indicatif::ProgressBar {
    if crate::io::quiet() || !std::io::stderr().is_terminal() {
        return indicatif::ProgressBar::hidden();
    }
    let bar = bars().add(indicatif::ProgressBar::new(len));
    bar.set_style(
        indicatif::ProgressStyle::with_template("{msg:32} [{bar:30}] {pos}/{len} {elapsed}")
            .expect("valid template")
            .progress_chars("=> "),
    );
    bar.set_message(message.to_string());
    bar
}

/// A progress bar on stderr with the count done, the elapsed time and an estimate of the
/// time left, when stderr is a terminal and the run is not quiet.
pub fn progress_bar_with_estimate(len: u64, message: &str) -> indicatif::ProgressBar {
    let bar = progress_bar(len, message);
    bar.set_style(
        indicatif::ProgressStyle::with_template(
            "{msg} [{bar:30}] {pos}/{len} cases, {elapsed} elapsed, about {eta} left",
        )
        .expect("valid template")
        .progress_chars("=> "),
    );
    bar
}
