//! The subcommands.

pub mod areas;
pub mod check;
pub mod replay;
#[cfg(feature = "ros")]
pub mod run;
mod load;
