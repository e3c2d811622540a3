//! The library's error type. Every message names what is wrong and where.

/// Errors returned by armcal.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// An inconsistent model (field counts, names, limits, conventions).
    #[error("model: {0}")]
    Model(String),
    /// Bad user input: joint values, data rows, options, or an estimate or design that does
    /// not fit the model it is used with.
    #[error("{0}")]
    Input(String),
    /// A solver or linear-algebra failure: a singular matrix, a non-finite residual, a
    /// failed step or projection.
    #[error("{0}")]
    Numerical(String),
    /// A document could not be written: serialisation, a CSV writer, a figure, the
    /// embedded font.
    #[error("{0}")]
    Output(String),
    /// A file could not be read or parsed; the message gives file, line and field.
    #[error("{file}: {message}")]
    File {
        /// Path of the file.
        file: String,
        /// What is wrong, with line and field where known.
        message: String,
    },
    /// A conversion between conventions that cannot be done exactly.
    #[error("conversion: {0}")]
    Conversion(String),
    /// Reading or writing failed at the operating system.
    #[error("{0}")]
    Io(#[from] std::io::Error),
}

/// `std::result::Result` with armcal's [`Error`] as default error type.
pub type Result<T, E = Error> = std::result::Result<T, E>;
