//! The error of an option outside its allowed range, shared by every options type.

/// An option outside its allowed range: its name (dotted for a nested field), the value
/// given and what is allowed, in words. Each crate's error holds it in its `InvalidOption`
/// variant, which says whose option it is.
#[derive(Clone, Copy, Debug, PartialEq, thiserror::Error)]
#[error("{name} = {value}: allowed {allowed}")]
pub struct InvalidOption {
    /// The option's name.
    pub name: &'static str,
    /// The value given.
    pub value: f64,
    /// What is allowed.
    pub allowed: &'static str,
}

impl InvalidOption {
    /// The error for option `name` given `value`, where `allowed` is allowed.
    pub fn new(name: &'static str, value: f64, allowed: &'static str) -> Self {
        Self {
            name,
            value,
            allowed,
        }
    }

    /// `Ok` when `valid`, the error for `name = value` otherwise.
    pub fn check(
        valid: bool,
        name: &'static str,
        value: f64,
        allowed: &'static str,
    ) -> Result<(), Self> {
        if valid {
            Ok(())
        } else {
            Err(Self::new(name, value, allowed))
        }
    }
}
