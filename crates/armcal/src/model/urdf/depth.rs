//! How deeply an XML text nests its elements, checked before the URDF parser sees it: the
//! parser (urdf-rs over serde-xml-rs) recurses once per level and overflows the stack at a
//! few thousand levels, taking time super-linear in the depth on the way (issue 15).

use crate::Error;

/// The deepest element nesting armcal reads; a URDF needs five levels (`robot`, `link`,
/// `visual`, `geometry`, `mesh`), so this leaves room for any extension's elements.
pub const MAX_DEPTH: usize = 256;

/// The deepest nesting of elements in `xml`, counting a start tag one level down, an end tag
/// one up and a self-closing tag neither; comments, processing instructions, `<!…>`
/// declarations and CDATA sections are skipped, and quoted attribute values may hold `>`.
/// A scan with no allocation, linear in the text.
pub fn nesting_depth(xml: &str) -> usize {
    let b = xml.as_bytes();
    let (mut i, mut depth, mut deepest) = (0usize, 0usize, 0usize);
    let skip_to = |from: usize, end: &str| {
        xml[from..]
            .find(end)
            .map_or(b.len(), |k| from + k + end.len())
    };
    while let Some(k) = xml[i..].find('<') {
        i += k;
        let rest = &xml[i..];
        if rest.starts_with("<!--") {
            i = skip_to(i, "-->");
        } else if rest.starts_with("<![CDATA[") {
            i = skip_to(i, "]]>");
        } else if rest.starts_with("<?") {
            i = skip_to(i, "?>");
        } else if rest.starts_with("<!") {
            i = skip_to(i, ">");
        } else if rest.starts_with("</") {
            depth = depth.saturating_sub(1);
            i = skip_to(i, ">");
        } else {
            // A start tag: to its `>` outside quotes; `/>` closes it at once.
            let mut j = i + 1;
            let mut quote = None;
            while j < b.len() {
                match (quote, b[j]) {
                    (None, q @ (b'"' | b'\'')) => quote = Some(q),
                    (Some(q), c) if c == q => quote = None,
                    (None, b'>') => break,
                    _ => {}
                }
                j += 1;
            }
            if j >= b.len() || b[j - 1] != b'/' {
                depth += 1;
                deepest = deepest.max(depth);
            }
            i = (j + 1).min(b.len());
        }
    }
    deepest
}

/// An error unless `xml` nests its elements at most [`MAX_DEPTH`] deep.
pub fn check_depth(xml: &str) -> Result<(), Error> {
    let depth = nesting_depth(xml);
    if depth > MAX_DEPTH {
        return Err(Error::Input(format!(
            "not a valid URDF document: its elements nest {depth} levels deep; armcal reads \
             at most {MAX_DEPTH}"
        )));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn depth_counts_elements_not_comments_or_self_closing_tags() {
        let xml = r#"<?xml version="1.0"?><!-- <a><b><c> --><robot name="r>x">
            <link name="a"/><joint><origin xyz="0 0 0"/><![CDATA[<x><y>]]></joint></robot>"#;
        assert_eq!(nesting_depth(xml), 2);
        assert_eq!(nesting_depth("<a><b><c></c></b></a>"), 3);
        assert_eq!(nesting_depth(""), 0);
        assert_eq!(nesting_depth("<a"), 1);
    }
}
