//! One module per subcommand.

pub mod fk;
pub mod model;
pub mod robots;
