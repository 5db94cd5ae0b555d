//! The FMI 2.0 and FMI 3.0 boundary: the exports, the generated header and model description, C
//! masters, and every misuse a careless master can make.

mod bad_args;
mod c_master;
mod c_valgrind;
mod call_sequence;
mod fmi3_calls;
mod fmi3_runs;
mod header;
mod host_abi;
mod matrix;
mod me;
mod me_exports;
mod me_free;
mod method_param;
mod model_description;
mod nonfinite;
mod rotation_outputs;
mod states;
mod threads;
