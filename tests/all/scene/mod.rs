//! Scenes: mode truncation with the residual-flexibility correction, `fxbody reduce`,
//! participation figures, and the `pack` options that change the scene.

mod pack_doc;
mod pack_fmax;
mod pack_options;
mod participation;
mod placement;
mod reduce;
mod residual;
mod truncation;
