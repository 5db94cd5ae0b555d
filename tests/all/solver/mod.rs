//! The blocked-body methods (exact, implicit, explicit) built by `solver::build`.

mod all_or_nothing;
mod damping_ratio;
mod exact;
mod fe_reference;
mod held_loads;
mod integrators;
mod outputs;
mod rotations;
