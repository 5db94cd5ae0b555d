//! The FMI 2.0 co-simulation C ABI: the only module with `unsafe` and raw pointers.
