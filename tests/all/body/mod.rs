//! The validated body (`Body::from_fxb`): its checks and what it computes.

mod invariance;
mod mass_props;
mod validation;
