//! The subcommands.

pub mod areas;
pub mod check;
pub mod replay;
mod load;
