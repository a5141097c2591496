//! Fixed-length number arrays of the scene files read at their exact length: `[1, 2, 3, 4]`
//! where three numbers belong is an error naming the field ("expected 3 numbers, got 4"), in
//! TOML and JSON alike (serde's own arrays silently drop extra components in TOML and report
//! "trailing characters" without the field in JSON).
//!
//! Use on `Option<[f64; N]>` fields with `#[serde(default, deserialize_with = "exact::opt::<N, _>")]`
//! and on `Option<Vec<[f64; N]>>` with `exact::opt_list::<N, _>`.

use serde::de::{Deserialize, Deserializer, Error as _};

/// `N` numbers, exactly.
struct Exact<const N: usize>([f64; N]);

impl<'de, const N: usize> Deserialize<'de> for Exact<N> {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let v = Vec::<f64>::deserialize(d)?;
        let a: [f64; N] = v
            .as_slice()
            .try_into()
            .map_err(|_| D::Error::custom(format!("expected {N} numbers, got {}", v.len())))?;
        Ok(Exact(a))
    }
}

/// An optional array of exactly `N` numbers.
pub fn opt<'de, const N: usize, D: Deserializer<'de>>(d: D) -> Result<Option<[f64; N]>, D::Error> {
    Ok(Option::<Exact<N>>::deserialize(d)?.map(|e| e.0))
}

/// An optional list of arrays of exactly `N` numbers each.
pub fn opt_list<'de, const N: usize, D: Deserializer<'de>>(d: D) -> Result<Option<Vec<[f64; N]>>, D::Error> {
    Ok(Option::<Vec<Exact<N>>>::deserialize(d)?.map(|v| v.into_iter().map(|e| e.0).collect()))
}
