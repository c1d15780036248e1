//! The subcommands.

pub mod areas;
pub mod check;
mod load;
pub mod replay;
#[cfg(feature = "ros")]
pub mod run;
pub mod trajectory;
