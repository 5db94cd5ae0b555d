//! The validated body (`Body::from_fxb`): its checks and what it computes.

mod validation;
