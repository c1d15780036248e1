//! The subcommands.

pub mod areas;
pub mod check;
mod load;
