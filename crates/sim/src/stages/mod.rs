//! The stages, one file per concept. Each is a plain function over the simulation; see
//! [`crate::pipeline`] for their order.

pub(crate) mod bounds;
pub(crate) mod detect;
pub(crate) mod lifetimes;
pub(crate) mod motion;
pub(crate) mod remove;
pub(crate) mod rest;
pub(crate) mod script;
pub(crate) mod separate;
