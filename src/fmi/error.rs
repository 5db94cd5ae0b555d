//! Why an FMI call was refused: the boundary's own checks (NULL arguments, foreign state
//! handles, buffers) and the lower layers' errors wrapped unchanged. [`super::instance::enter`]
//! logs it as `"{function}: {error}"` and returns fmi2Error.

use std::path::PathBuf;

use super::fmu_state::HandleError;
use super::uri::UriError;
use crate::fmu::simulation::SimulationError;
use crate::fmu::snapshot::SnapshotError;
use crate::scene::io::ResourceError;

/// A refused FMI call.
#[derive(Debug, thiserror::Error)]
pub enum FmiError {
    /// A required pointer argument is NULL (the text names it).
    #[error("{0} is NULL")]
    Null(&'static str),
    /// An array argument is NULL with a nonzero length.
    #[error("{what} is NULL with {n} elements")]
    NullArray {
        /// The argument.
        what: &'static str,
        /// Its length.
        n: usize,
    },
    /// fmi2SetDebugLogging with a category this FMU does not declare.
    #[error("unknown log category '{name}' (declared: {declared})")]
    UnknownCategory {
        /// The category given.
        name: String,
        /// The declared categories, comma-separated.
        declared: String,
    },
    /// fmi2Instantiate without an instance name.
    #[error("instanceName is NULL or empty")]
    NoInstanceName,
    /// fmi2Instantiate without a resource location.
    #[error("fmuResourceLocation is NULL: the FMU needs its resources folder")]
    NoResourceLocation,
    /// fmi2Instantiate with an fmuType that is neither Model Exchange (0) nor
    /// co-simulation (1).
    #[error("fmuType {0}: expected fmi2ModelExchange (0) or fmi2CoSimulation (1)")]
    FmuType(i32),
    /// An interface the FMU was not packed for.
    #[error(
        "this FMU does not declare {asked} (it was packed with --interface {declared}; \
         pack it with --interface both to serve both)"
    )]
    InterfaceNotDeclared {
        /// The interface asked for.
        asked: &'static str,
        /// The interfaces declared (`cs`, `me`, `both`).
        declared: &'static str,
    },
    /// A function of the other interface.
    #[error("a {function_of} function, and this instance is a {instance} one")]
    WrongInterface {
        /// The interface the function belongs to.
        function_of: &'static str,
        /// The interface of the instance.
        instance: &'static str,
    },
    /// The caller's GUID is not the resources'.
    #[error(
        "GUID mismatch: the caller passed {given} but the FMU's resources ({}) give {found}; \
         the modelDescription.xml and the resources are from different packs",
        .dir.display()
    )]
    GuidMismatch {
        /// The GUID passed.
        given: String,
        /// The resources folder.
        dir: PathBuf,
        /// The GUID the resources give.
        found: String,
    },
    /// A value reference of a type this FMU has no variables of.
    #[error("value reference {vr}: this FMU has no {kind} variables")]
    NoVariables {
        /// The first value reference.
        vr: u32,
        /// "Boolean" or "String".
        kind: &'static str,
    },
    /// fmi2GetDirectionalDerivative.
    #[error("not provided by this FMU (providesDirectionalDerivative=\"false\")")]
    NoDirectionalDerivative,
    /// A state code no FMI state has.
    #[error("saved state has an unknown phase code {0}")]
    UnknownPhase(u8),
    /// A serialisation buffer too small.
    #[error("buffer is {size} bytes, the state needs {needs} (use fmi2SerializedFMUstateSize)")]
    BufferTooSmall {
        /// The buffer's size.
        size: usize,
        /// The bytes needed.
        needs: usize,
    },
    /// A serialised state for another number of inputs.
    #[error("serialized state has a different number of inputs than this FMU")]
    StateInputs,
    /// fmi3Instantiate* without a resource path.
    #[error("resourcePath is NULL: the FMU needs its resources folder")]
    NoResourcePath,
    /// An FMI 3.0 resource path that is not absolute.
    #[error(
        "resourcePath '{0}' is not an absolute path (FMI 3.0 passes the absolute path of \
         the FMU's resources folder, with a trailing separator)"
    )]
    RelativeResourcePath(String),
    /// A call this FMU does not provide (the text says what and which flag declares it).
    #[error("{0}")]
    NotProvided(&'static str),
    /// An FMI 3.0 getter or setter whose nValues is not its number of value references
    /// (every variable of this FMU is a scalar).
    #[error(
        "nValues is {n_values} but the {n_refs} value references name {n_refs} scalar \
         values (this FMU has no array variables)"
    )]
    NValues {
        /// nValues as passed.
        n_values: usize,
        /// nValueReferences.
        n_refs: usize,
    },
    /// FMI 3.0's independent variable where it cannot go.
    #[error("value reference {vr} is the independent variable time: {what}")]
    TimeVariable {
        /// Its value reference.
        vr: u32,
        /// Why it cannot go there.
        what: &'static str,
    },
    /// A state handle this instance cannot use.
    #[error(transparent)]
    Handle(#[from] HandleError),
    /// The resource location is not a local folder URI.
    #[error(transparent)]
    Uri(#[from] UriError),
    /// The resources could not be loaded.
    #[error(transparent)]
    Resources(#[from] ResourceError),
    /// The model refused the call.
    #[error(transparent)]
    Simulation(#[from] SimulationError),
    /// Serialised state bytes refused.
    #[error(transparent)]
    Snapshot(#[from] SnapshotError),
}
