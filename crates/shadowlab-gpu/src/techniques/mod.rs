//! One folder per technique: its Rust (`mod.rs`, its passes) and WGSL side by side, and the
//! picture helpers several share. The trait is [`crate::technique`], the list of all of them
//! [`crate::registry`].

pub mod csm;
pub mod cube;
pub mod dpsm;
pub mod filtered;
pub mod iasm;
pub mod lt;
pub mod mdsm;
pub mod min_sm;
pub mod pictures;
pub mod sdsm;
pub mod sm;
pub mod sv;
pub mod virtual_sm;
pub mod warp;
