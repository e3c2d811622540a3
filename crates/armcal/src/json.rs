//! Writing records as JSON text.
//!
//! The command-line files that armcal first built by hand (`serde_json::json!`) have their
//! object keys in alphabetical order (serde_json's map without `preserve_order`), at every
//! level. The typed records that replaced them keep that text: [`sorted_pretty`] goes
//! through a [`serde_json::Value`], whose maps sort their keys. Records that were always
//! typed (estimate, design, demo summary) keep their field order with
//! `serde_json::to_string_pretty`.

use crate::Error;
use serde::Serialize;

/// `value` as pretty-printed JSON with the keys of every object in alphabetical order.
pub fn sorted_pretty<T: Serialize + ?Sized>(value: &T) -> Result<String, Error> {
    let fail = |e: serde_json::Error| Error::Input(e.to_string());
    serde_json::to_string_pretty(&serde_json::to_value(value).map_err(fail)?).map_err(fail)
}

/// Reads a number that armcal writes as `null` when it is undefined (serde_json writes NaN
/// as `null`): `null` becomes NaN, so a record with, e.g., no degrees of freedom for a
/// variance factor reads back as it was written. Use as
/// `#[serde(deserialize_with = "crate::json::nan_from_null")]`.
pub fn nan_from_null<'de, D: serde::Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
    let v: Option<f64> = serde::Deserialize::deserialize(d)?;
    Ok(v.unwrap_or(f64::NAN))
}
