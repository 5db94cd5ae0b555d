//! The free-body methods (`solver::free`): the explicit reference scheme, the implicit
//! method, and where we differ from Radioss.

mod drag_warning;
mod explicit;
mod fe_reference;
mod frame_rates;
mod held_loads;
mod implicit;
mod me;
mod radioss_differences;
mod rotations;
mod spin;
mod split;
mod stable_step;
mod validity;
