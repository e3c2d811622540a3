//! Writing CSV tables: the one writer behind every CSV file armcal writes.
//!
//! A field is quoted when it holds a comma, a quote, a line break or a `#` (RFC 4180, with
//! `#` because armcal's readers skip `#` comment lines), so a name or status with any of
//! them reads back as the one field it was; every other field is written as it is, so a
//! table without such characters has the bytes a hand-joined line would have.

/// A CSV table being written: a header, then rows of the header's width.
pub struct Table {
    writer: csv::Writer<Vec<u8>>,
}

impl Table {
    /// A table with these column names.
    pub fn new<I, S>(header: I) -> Table
    where
        I: IntoIterator<Item = S>,
        S: AsRef<[u8]>,
    {
        let writer = csv::WriterBuilder::new()
            .comment(Some(b'#'))
            .from_writer(Vec::new());
        let mut table = Table { writer };
        table.row(header);
        table
    }

    /// Appends one row. It has as many fields as the header: a row of another width is a
    /// bug in its writer, and panics.
    pub fn row<I, S>(&mut self, fields: I)
    where
        I: IntoIterator<Item = S>,
        S: AsRef<[u8]>,
    {
        self.writer
            .write_record(fields)
            .expect("a CSV row as wide as its header, written to memory");
    }

    /// The table's text.
    pub fn into_string(self) -> String {
        let bytes = self
            .writer
            .into_inner()
            .expect("flushing a CSV writer into memory");
        // armcal's fields are text, and quoting adds only ASCII.
        String::from_utf8(bytes).expect("CSV of UTF-8 fields is UTF-8")
    }
}

#[cfg(test)]
mod tests {
    use super::Table;

    #[test]
    fn quotes_only_fields_that_need_it() {
        let mut t = Table::new(["id", "status"]);
        t.row(["1", "converged"]);
        t.row(["#2", "singular: j5, \"wrist\""]);
        assert_eq!(
            t.into_string(),
            "id,status\n1,converged\n\"#2\",\"singular: j5, \"\"wrist\"\"\"\n"
        );
    }
}
