//! Serde helpers for fixed-size arrays in TOML files: `[a, b, c]` must have exactly the
//! expected number of values (a fourth colour component or a third size value is an error,
//! not silently dropped). Use with `#[serde(deserialize_with = "...")]`.

use serde::de::Error as _;
use serde::{Deserialize, Deserializer};

/// Exactly `N` values.
pub fn exact<'de, D, T, const N: usize>(d: D) -> Result<[T; N], D::Error>
where
    D: Deserializer<'de>,
    T: Deserialize<'de>,
{
    let v: Vec<T> = Vec::deserialize(d)?;
    let found = v.len();
    v.try_into()
        .map_err(|_| D::Error::custom(format!("expected exactly {N} values, found {found}")))
}

/// An optional array of exactly `N` values (use with `#[serde(default)]`).
pub fn exact_option<'de, D, T, const N: usize>(d: D) -> Result<Option<[T; N]>, D::Error>
where
    D: Deserializer<'de>,
    T: Deserialize<'de>,
{
    exact(d).map(Some)
}
