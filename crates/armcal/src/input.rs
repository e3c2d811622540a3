//! Reading a user's file with a size cap: every reader of a cell, URDF, JSON record or data
//! file goes through [`read_capped`], so no input (`/dev/zero`, a mistaken multi-GB file) can
//! exhaust memory (issue 15).

use std::io::Read;
use std::path::Path;

/// The cap for text armcal reads whole (cell TOML, URDF, estimate / design / report JSON):
/// 64 MiB.
pub const TEXT_CAP: u64 = 64 << 20;
/// The cap for data files (measurement and joint CSVs, programs): 1 GiB.
pub const DATA_CAP: u64 = 1 << 30;
/// The environment variable that sets every cap, in MiB (e.g. `ARMCAL_MAX_INPUT_MIB=4096`
/// for a larger data file).
pub const CAP_VARIABLE: &str = "ARMCAL_MAX_INPUT_MIB";

/// The cap in force for a file whose default is `default` bytes: [`CAP_VARIABLE`] if it
/// holds a whole number of MiB, else `default`.
pub fn cap(default: u64) -> u64 {
    std::env::var(CAP_VARIABLE)
        .ok()
        .and_then(|v| v.trim().parse::<u64>().ok())
        .map_or(default, |mib| mib.saturating_mul(1 << 20))
}

/// The text of `path`, read up to [`cap`]`(default)` bytes; a longer file is an
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
                "the file is larger than {} MiB, the most armcal reads (set {CAP_VARIABLE} \
                 to a larger number of MiB to raise the cap)",
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
