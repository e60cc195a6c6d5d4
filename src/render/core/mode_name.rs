//! How mode flags and scene keys are spelled: `name`, or `name:count` (`oit:8`, `soft:4`).

/// `name` or `name:count` (a whole number) of a mode flag such as `oit:8`; `what` names the
/// flag in errors.
pub fn name_and_count<'a>(what: &str, s: &'a str) -> Result<(&'a str, Option<u32>), String> {
    match s.split_once(':') {
        Some((n, c)) => c
            .parse::<u32>()
            .map(|c| (n, Some(c)))
            .map_err(|_| format!("{what} '{s}': '{c}' is not a whole number")),
        None => Ok((s, None)),
    }
}
