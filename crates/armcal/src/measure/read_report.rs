//! What a data file's reader found besides the data ([`ReadReport`]).

/// What the reader found besides the data.
#[derive(Clone, Debug, Default)]
pub struct ReadReport {
    /// Header names of the columns the reader did not use.
    pub ignored: Vec<String>,
    /// Rows read with a remark, each a sentence naming file, line and field: joint values a
    /// little past the model's limits ([`crate::model::MEASURED_LIMIT_TOLERANCE`]).
    pub warnings: Vec<String>,
}
