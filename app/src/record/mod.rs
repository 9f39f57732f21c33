//! Rerun recordings: what a simulation looks like in one ([`recorder`], body by body: [`body_parts`]), writing one safely
//! ([`session`], its file by [`file_writer`]), the viewer's layout ([`layout`]), and reading one back with Rerun's own decoder
//! ([`summary`], which `tetlab inspect` prints and `record` uses to check its own file). The
//! subcommands `record` and `lesson --record` are set-up around these.

pub mod body_parts;
pub mod file_writer;
pub mod layout;
pub mod recorder;
pub mod session;
pub mod summary;

pub use layout::send_layout;
pub use recorder::{ArrowsMode, Recorder};
pub use session::{Destination, Ending, INTERRUPTED, Session};
