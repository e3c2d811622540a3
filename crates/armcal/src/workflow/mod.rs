//! Whole workflows in one call, for the command line and for programs: each composes the
//! library's steps and the report of their records. The only module besides the CLI that
//! imports [`crate::report`]; nothing below it does.

pub mod demo;
