//! What a finished `ssn` process said: its standard error, its exit code, the words a
//! refusal must name.

#![allow(dead_code)]

use std::process::Output;

/// The process's standard error as text.
pub fn err(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// The process ended with `code` and did not panic.
pub fn assert_exit(o: &Output, code: i32, what: &str) {
    assert_eq!(o.status.code(), Some(code), "{what}: stderr {}", err(o));
    assert!(!err(o).contains("panicked"), "{what}: {}", err(o));
}

/// Standard error names every one of `words`.
pub fn assert_mentions(o: &Output, words: &[&str]) {
    for w in words {
        assert!(err(o).contains(w), "`{w}` not in: {}", err(o));
    }
}
