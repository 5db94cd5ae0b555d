//! What can go wrong in a pack, each naming the file or value at fault, and the rules
//! for a model name: a file name and a C identifier at once. The errors carry data and
//! name no command-line option: the command that set a value names its option
//! (`fxbody pack`'s wording, in the CLI crate).

use std::path::PathBuf;

use crate::body::LoadError;
use crate::body::placement::PlacementError;
use crate::fmu::options::UnknownUnits;
use crate::fmu::zip::ZipError;
use crate::fxb::coords::CoordsError;
use crate::fxb::input::InputError;
use crate::scene::io::SceneError;

/// Why packing failed: each names the file or value at fault.
#[derive(Debug, thiserror::Error)]
pub enum PackError {
    /// The body file could not be read or is not a valid body.
    #[error(transparent)]
    Body(#[from] LoadError),
    /// The coordinate file could not be read or parsed.
    #[error(transparent)]
    Coords(#[from] CoordsError),
    /// A blocked body and no coordinate file.
    #[error("{0}: a blocked body needs node coordinates (a .fxb file holds none)")]
    BlockedNeedsCoords(String),
    /// The coordinate file contradicts the body's rigid modes.
    #[error(transparent)]
    Placement(#[from] Box<PlacementError>),
    /// The exposed nodes name a node the body does not have.
    #[error("node {id} is not a node of {body} (its nodes: {nodes})")]
    UnknownNode {
        /// The node ID.
        id: i64,
        /// The body file.
        body: String,
        /// A summary of the body's node IDs.
        nodes: String,
    },
    /// Exposed nodes without coordinates.
    #[error("{coords}: no coordinates for node(s) {ids} of {body}")]
    MissingCoordinates {
        /// The coordinate file, or "derived coordinates".
        coords: String,
        /// A summary of the node IDs.
        ids: String,
        /// The body file.
        body: String,
    },
    /// The unit system is not a known one.
    #[error(transparent)]
    Units(#[from] UnknownUnits),
    /// The model name is not a usable one.
    #[error("model name: {0}")]
    Name(#[from] NameError),
    /// No model name given and the file stem is too long to be one.
    #[error(
        "{body}: the model name would be the file name's {chars} characters, more than {MAX_NAME}"
    )]
    StemTooLong {
        /// The body file.
        body: String,
        /// The stem's length in characters.
        chars: usize,
    },
    /// No model name given and the file stem gives a reserved identifier ([`reserved`]).
    #[error("{body}: the model identifier would be the file name's '{id}', which is {why}")]
    StemReserved {
        /// The body file.
        body: String,
        /// The identifier the stem gives.
        id: String,
        /// What reserves it.
        why: &'static str,
    },
    /// The exposed nodes do not make a scene.
    #[error(transparent)]
    Scene(#[from] SceneError),
    /// An output names one of the inputs.
    #[error(
        "{}: is the same file as the {what} {}: refusing to overwrite an input; choose another output name",
        .out.display(), .input.display()
    )]
    Overwrite {
        /// The output path.
        out: PathBuf,
        /// What the input is ("body file", ...).
        what: String,
        /// The input path.
        input: PathBuf,
    },
    /// An input path (coordinates, library) that is not a regular file of a size its
    /// kind can have, refused before it is read.
    #[error(transparent)]
    Input(#[from] InputError),
    /// The running executable's path is unknown (needed to find the library).
    #[error("cannot locate the running executable: {0}")]
    Exe(std::io::Error),
    /// No library next to the executable.
    #[error(
        "cannot find the FMU library libfxbody.so (looked at {0}): build it with `cargo build --release` \
         or set FXBODY_LIB"
    )]
    LibNotFound(String),
    /// The DefaultExperiment step or stop time not a finite time > 0.
    #[error("{what} time: expected a time > 0 (s), found {}", crate::num::num(*.value))]
    Time {
        /// `step` or `stop`.
        what: &'static str,
        /// The value given.
        value: f64,
    },
    /// The step is longer than the stop time.
    #[error(
        "step {} s is longer than the DefaultExperiment stop time {} s{}",
        crate::num::num(*.step), crate::num::num(*.stop),
        if *.stop_given { "" } else { " (derived from the body)" }
    )]
    StepAfterStop {
        /// The step.
        step: f64,
        /// The stop time.
        stop: f64,
        /// Whether the stop time was given.
        stop_given: bool,
    },
    /// An added platform's library is for the platform of the library the pack embeds
    /// itself.
    #[error(
        "{platform} library {}: {platform} is the platform of the library this pack embeds itself",
        .path.display()
    )]
    NativeBinary {
        /// The platform name.
        platform: String,
        /// The library path.
        path: PathBuf,
    },
    /// An added platform's library (platform, path) refused.
    #[error("{platform} library {}: {why}", .path.display())]
    Binary {
        /// The platform name.
        platform: String,
        /// The library path.
        path: PathBuf,
        /// Why it was refused.
        why: String,
    },
    /// The OSP model description would describe another FMU, or is not ours.
    #[error(transparent)]
    Osp(#[from] crate::fmu::osp::OspClash),
    /// The OSP model description could not be written.
    #[error("{}: cannot write the OSP model description: {source}", .path.display())]
    WriteOsp {
        /// Its path.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
    /// The archive could not be built.
    #[error(transparent)]
    Zip(#[from] ZipError),
    /// The FMU could not be written.
    #[error("{}: cannot write the FMU: {source}", .path.display())]
    WriteFmu {
        /// The output path.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
}

/// A model name that cannot be a model identifier; `shown` is the name as quoted in the
/// message (cut after 40 characters).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum NameError {
    /// Empty or longer than [`MAX_NAME`].
    #[error("expected 1 to {MAX_NAME} characters, found {shown}")]
    Length {
        /// The name as shown.
        shown: String,
    },
    /// A character outside letters, digits and `_`.
    #[error(
        "expected letters, digits and '_' only (a file name and a C identifier), found {c:?} in {shown}"
    )]
    Character {
        /// The first such character.
        c: char,
        /// The name as shown.
        shown: String,
    },
    /// A digit first.
    #[error("expected a letter or '_' first (a C identifier), found {shown}")]
    DigitFirst {
        /// The name as shown.
        shown: String,
    },
    /// A name C or FMI reserves ([`reserved`]).
    #[error(
        "{shown} is {why}: the model identifier must be a C identifier of its own; choose another name"
    )]
    Reserved {
        /// The name as shown.
        shown: String,
        /// What reserves it.
        why: &'static str,
    },
}

/// The keywords of C (C89 to C23): not identifiers at all.
const C_KEYWORDS: [&str; 59] = [
    "auto",
    "break",
    "case",
    "char",
    "const",
    "continue",
    "default",
    "do",
    "double",
    "else",
    "enum",
    "extern",
    "float",
    "for",
    "goto",
    "if",
    "inline",
    "int",
    "long",
    "register",
    "restrict",
    "return",
    "short",
    "signed",
    "sizeof",
    "static",
    "struct",
    "switch",
    "typedef",
    "union",
    "unsigned",
    "void",
    "volatile",
    "while",
    "alignas",
    "alignof",
    "bool",
    "constexpr",
    "false",
    "nullptr",
    "static_assert",
    "thread_local",
    "true",
    "typeof",
    "typeof_unqual",
    "_Alignas",
    "_Alignof",
    "_Atomic",
    "_BitInt",
    "_Bool",
    "_Complex",
    "_Decimal128",
    "_Decimal32",
    "_Decimal64",
    "_Generic",
    "_Imaginary",
    "_Noreturn",
    "_Static_assert",
    "_Thread_local",
];

/// Why C or FMI 2.0 reserves `name` as an identifier, if it does: a C keyword; `main`,
/// the program's entry point; a name starting with `fmi2`, the prefix of every FMI 2.0
/// function, type and macro (`fmi2DoStep`, `fmi2Component`); or, as C reserves them
/// for any use, a name starting with `__` or with `_` and an upper-case letter.
pub fn reserved(name: &str) -> Option<&'static str> {
    let b = name.as_bytes();
    if C_KEYWORDS.contains(&name) {
        Some("a C keyword")
    } else if name == "main" {
        Some("the C program's entry point")
    } else if name.starts_with("fmi2") {
        Some("in FMI 2.0's namespace (fmi2..., its functions, types and macros)")
    } else if b.len() > 1 && b[0] == b'_' && (b[1] == b'_' || b[1].is_ascii_uppercase()) {
        Some(
            "reserved by C for the implementation (it starts with __ or _ and an upper-case letter)",
        )
    } else {
        None
    }
}

/// Longest model name: the model identifier names the library inside the archive and
/// the C symbols' prefix; 64 characters keep every path well under tool limits.
pub const MAX_NAME: usize = 64;

/// Check a model name given by the user: 1 to [`MAX_NAME`] characters, a letter or `_`
/// first, then letters, digits or `_`, and no name C or FMI reserves ([`reserved`]), so
/// it is usable unchanged as a file name and a C identifier (the FMI modelIdentifier).
pub fn check_name(name: &str) -> Result<(), NameError> {
    let shown = if name.chars().count() > 40 {
        format!(
            "'{}...' ({} characters)",
            name.chars().take(40).collect::<String>(),
            name.chars().count()
        )
    } else {
        format!("'{name}'")
    };
    if name.is_empty() || name.len() > MAX_NAME {
        return Err(NameError::Length { shown });
    }
    if let Some(c) = name
        .chars()
        .find(|c| !(c.is_ascii_alphanumeric() || *c == '_'))
    {
        return Err(NameError::Character { c, shown });
    }
    if name.starts_with(|c: char| c.is_ascii_digit()) {
        return Err(NameError::DigitFirst { shown });
    }
    if let Some(why) = reserved(name) {
        return Err(NameError::Reserved { shown, why });
    }
    Ok(())
}
