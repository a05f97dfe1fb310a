//! The optional positional arguments of the examples.

/// The `i`-th command-line argument (1-based) parsed as `T`, or `default` when there is
/// none; stops the example with a message naming `what` when it does not parse.
pub fn positional<T: std::str::FromStr>(i: usize, default: T, what: &str) -> T {
    match std::env::args().nth(i) {
        None => default,
        Some(text) => text
            .parse()
            .unwrap_or_else(|_| panic!("argument {i}: {what}, not {text:?}")),
    }
}
