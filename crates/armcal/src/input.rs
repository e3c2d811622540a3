//! Reading a user's file with a size cap: every reader of a cell, URDF, JSON record or data
//! file goes through [`read_capped`], so no input (`/dev/zero`, a mistaken multi-GB file) can
//! exhaust memory (issue 15).

use serde::{Deserialize, Serialize};
use std::io::Read;
use std::path::Path;
use std::sync::atomic::{AtomicU64, Ordering};

/// The cap for text armcal reads whole (cell TOML, URDF, estimate / design / report JSON):
/// 64 MiB.
pub const TEXT_CAP: u64 = 64 << 20;
/// The cap for data files (measurement and joint CSVs, programs): 1 GiB.
pub const DATA_CAP: u64 = 1 << 30;
/// The largest files armcal reads, a setting of the library ([`set_input_limits`]): the
/// command line sets it from its environment variable `ARMCAL_MAX_INPUT_MIB`, a program
/// from its own configuration.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct InputLimits {
    /// The cap of text read whole (cell TOML, URDF, JSON records), bytes.
    pub text_bytes: u64,
    /// The cap of data files (measurement and joint CSVs, programs), bytes.
    pub data_bytes: u64,
}

impl Default for InputLimits {
    /// [`TEXT_CAP`] and [`DATA_CAP`].
    fn default() -> Self {
        InputLimits {
            text_bytes: TEXT_CAP,
            data_bytes: DATA_CAP,
        }
    }
}

impl InputLimits {
    /// Both caps `mib` MiB.
    pub fn all_mib(mib: u64) -> InputLimits {
        let bytes = mib.saturating_mul(1 << 20);
        InputLimits {
            text_bytes: bytes,
            data_bytes: bytes,
        }
    }
}

// The setting is process-wide (as rayon's thread pool): every reader of a cell, record or
// data file consults it, and passing it through each of their signatures would change the
// whole reading API for one number.
static TEXT_LIMIT: AtomicU64 = AtomicU64::new(TEXT_CAP);
static DATA_LIMIT: AtomicU64 = AtomicU64::new(DATA_CAP);

/// Sets the caps every later read of this process uses ([`InputLimits::default`] until
/// set).
///
/// ```
/// use armcal::{input_limits, set_input_limits, InputLimits};
/// set_input_limits(InputLimits::all_mib(4096));
/// assert_eq!(input_limits().data_bytes, 4096 << 20);
/// set_input_limits(InputLimits::default());
/// ```
pub fn set_input_limits(limits: InputLimits) {
    TEXT_LIMIT.store(limits.text_bytes, Ordering::Relaxed);
    DATA_LIMIT.store(limits.data_bytes, Ordering::Relaxed);
}

/// The caps in force ([`set_input_limits`]).
pub fn input_limits() -> InputLimits {
    InputLimits {
        text_bytes: TEXT_LIMIT.load(Ordering::Relaxed),
        data_bytes: DATA_LIMIT.load(Ordering::Relaxed),
    }
}

/// The cap in force for a file whose built-in cap is `default`: the setting's data cap for
/// [`DATA_CAP`], its text cap for [`TEXT_CAP`], `default` itself for any other number.
pub fn cap(default: u64) -> u64 {
    let limits = input_limits();
    match default {
        DATA_CAP => limits.data_bytes,
        TEXT_CAP => limits.text_bytes,
        other => other,
    }
}

/// The text of `path`, read up to `cap``(default)` bytes; a longer file is an
/// [`std::io::ErrorKind::InvalidData`] error that says the cap and how to raise it, and
/// stops the read there.
pub fn read_capped(path: &Path, default: u64) -> std::io::Result<String> {
    let cap = cap(default);
    let mut text = String::new();
    std::fs::File::open(path)?
        .take(cap.saturating_add(1))
        .read_to_string(&mut text)?;
    if text.len() as u64 > cap {
        return Err(std::io::Error::new(
            std::io::ErrorKind::InvalidData,
            format!(
                "the file is larger than {} MiB, the most armcal reads (set \
                 ARMCAL_MAX_INPUT_MIB to a larger number of MiB to raise the cap; in a \
                 program, armcal::set_input_limits)",
                cap >> 20
            ),
        ));
    }
    Ok(text)
}

/// The 1-based line of `field:` in the block that starts at the first line `key:` of a YAML
/// text (the line of `key:` itself for an empty `field`; 0 without `key:`): where an error
/// found after parsing (a value that is not finite) points the user.
pub fn field_line(text: &str, key: &str, field: &str) -> usize {
    let lines: Vec<&str> = text.lines().collect();
    let Some(start) = lines
        .iter()
        .position(|l| l.trim_start().starts_with(&format!("{key}:")))
    else {
        return 0;
    };
    if field.is_empty() {
        return start + 1;
    }
    lines
        .iter()
        .enumerate()
        .skip(start)
        .find(|(_, l)| l.contains(&format!("{field}:")))
        .map_or(start + 1, |(i, _)| i + 1)
}
