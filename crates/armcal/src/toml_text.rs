//! Writing TOML text by hand (the cell exports lay out their sections and comments as a
//! user would, which a serializer does not): every string a user gave — a name, a column, a
//! frame — goes through [`string`], so quotes, backslashes and control characters come out
//! as TOML escapes and the file reads back to the same string. (Rust's `{:?}` is not TOML:
//! it writes `\u{1b}` where TOML needs `\u001B`.)

/// `s` as a TOML basic string, quotes included (the `toml` crate's own escaping).
pub fn string(s: &str) -> String {
    toml::Value::String(s.to_owned()).to_string()
}

/// `items` as a TOML array of strings: `["a", "b"]`.
pub fn strings<S: AsRef<str>>(items: &[S]) -> String {
    let items: Vec<String> = items.iter().map(|s| string(s.as_ref())).collect();
    format!("[{}]", items.join(", "))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_string_reads_back_as_itself() {
        for s in [
            "plain",
            "a \"quoted\" name",
            "back\\slash\\\\L",
            "tab\tnew\nline",
            "\u{1b}[0m\u{7f}",
            "ü → 😀",
            "",
        ] {
            let text = format!("name = {}\nlist = {}\n", string(s), strings(&[s, "x"]));
            let v: toml::Table = toml::from_str(&text).unwrap_or_else(|e| panic!("{text}: {e}"));
            assert_eq!(v["name"].as_str(), Some(s), "{text}");
            assert_eq!(v["list"][0].as_str(), Some(s), "{text}");
        }
    }
}
