//! The workspace's CI as code (library part): the run's bookkeeping ([`ci`]) and the source
//! rules ([`source`]). The binary (`src/main.rs`, `cargo xtask …`) holds the tasks.

pub mod ci;
pub mod source;
