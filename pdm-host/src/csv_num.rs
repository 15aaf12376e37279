//! How the host's CSV files write floating-point numbers: Rust's `{:e}` (the shortest digits
//! that read back to the same f64, in scientific notation: `1.6666666666666666e-1`), and NaN as
//! an empty field. Use with `#[serde(with = "crate::csv_num")]` on an `f64` field.

use serde::{de::Error as _, Deserialize, Deserializer, Serializer};

/// Writes `x` as `{:e}`, or an empty field for NaN.
///
/// # Errors
/// Those of the serializer.
pub fn serialize<S: Serializer>(x: &f64, s: S) -> Result<S::Ok, S::Error> {
    if x.is_nan() {
        s.serialize_str("")
    } else {
        s.collect_str(&format_args!("{x:e}"))
    }
}

/// Reads a number in any notation `f64::from_str` accepts; an empty field is NaN.
///
/// # Errors
/// A field that is not a number.
pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
    let text = String::deserialize(d)?;
    let text = text.trim();
    if text.is_empty() {
        Ok(f64::NAN)
    } else {
        text.parse().map_err(|_| D::Error::custom(format!("not a number: {text:?}")))
    }
}
