//! One module per subcommand.

pub mod accuracy;
pub mod axes;
pub mod campaign;
pub mod check;
pub mod compensate;
pub mod demo;
pub mod digits;
pub mod export;
pub mod fk;
pub mod identify;
pub mod import;
pub mod model;
pub mod output;
pub mod pivot;
pub mod plan;
pub mod predict;
pub mod progress;
pub mod report;
pub mod robots;
pub mod simulate;
pub mod study;
pub mod tree;
