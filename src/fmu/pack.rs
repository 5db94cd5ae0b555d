//! `fxbody pack`: a body file, its coordinates and the options into an `.fmu` archive
//! with modelDescription.xml, the library, resources/ (the scene file, sized to the
//! scene, and the options) and documentation/.

use std::path::{Path, PathBuf};

use super::doc::index_html;
use super::options::{SceneOptions, UnitSystem, UnknownUnits};
use super::scene_io::{
    OPTIONS_FILE, SCENE_FILE, SOURCE_FILE, SceneError, coords_from_rigid_modes, guid, make_scene,
    summary,
};
use super::scenefile;
use super::vars::VarTable;
use super::xml::model_description;
use super::zip::{Entry, ZipError, write};
use crate::body::placement::PlacementError;
use crate::body::{self, LoadError};
use crate::fxb::coords::{self, CoordsError};
use crate::scene::Scene;

/// Why packing failed: each names the file or option at fault.
#[derive(Debug, thiserror::Error)]
pub enum PackError {
    /// The body file could not be read or is not a valid body.
    #[error(transparent)]
    Body(#[from] LoadError),
    /// The coordinate file could not be read or parsed.
    #[error(transparent)]
    Coords(#[from] CoordsError),
    /// A blocked body and no coordinate file.
    #[error(
        "{0}: a blocked body needs node coordinates (a .fxb file holds none): \
         give --coords with a Radioss /NODE deck or a CSV file id,x,y,z"
    )]
    BlockedNeedsCoords(String),
    /// The coordinate file contradicts the body's rigid modes.
    #[error(transparent)]
    Placement(#[from] Box<PlacementError>),
    /// `--nodes` names a node the body does not have.
    #[error("--nodes: node {id} is not a node of {body} (its nodes: {nodes})")]
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
    /// `--units` names no known system.
    #[error(transparent)]
    Units(#[from] UnknownUnits),
    /// `--name` is not a usable model name.
    #[error(transparent)]
    Name(#[from] NameError),
    /// No `--name` and the file stem is too long to be one.
    #[error(
        "{body}: the model name would be the file name's {chars} characters, more than {MAX_NAME}: give --name"
    )]
    StemTooLong {
        /// The body file.
        body: String,
        /// The stem's length in characters.
        chars: usize,
    },
    /// The exposed nodes do not make a scene.
    #[error(transparent)]
    Scene(#[from] SceneError),
    /// `-o` names one of the inputs.
    #[error(
        "-o {}: is the same file as the {what} {}: refusing to overwrite an input; choose another output name",
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
    /// `--lib` names no file.
    #[error("--lib {}: no such file", .0.display())]
    NoLib(PathBuf),
    /// `FXBODY_LIB` names no file.
    #[error("FXBODY_LIB={}: no such file", .0.display())]
    NoEnvLib(PathBuf),
    /// The running executable's path is unknown (needed to find the library).
    #[error("cannot locate the running executable: {0}")]
    Exe(std::io::Error),
    /// No library next to the executable.
    #[error(
        "cannot find the FMU library libfxbody.so (looked at {0}): build it with `cargo build --release`, \
         or give --lib PATH or FXBODY_LIB"
    )]
    LibNotFound(String),
    /// The library could not be read.
    #[error("{}: cannot read the library: {source}", .path.display())]
    ReadLib {
        /// The library path.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
    /// `--step` or `--stop` not a finite time > 0.
    #[error("--{what}: expected a time > 0 (s), found {}", crate::num::num(*.value))]
    Time {
        /// `step` or `stop`.
        what: &'static str,
        /// The value given.
        value: f64,
    },
    /// The step is longer than the stop time.
    #[error(
        "--step {} s is longer than the DefaultExperiment stop time {} s{}",
        crate::num::num(*.step), crate::num::num(*.stop),
        if *.stop_given { "" } else { " (derived from the body): give --stop too" }
    )]
    StepAfterStop {
        /// The step.
        step: f64,
        /// The stop time.
        stop: f64,
        /// Whether the stop time was given.
        stop_given: bool,
    },
    /// `--binary` with a bad platform or file.
    #[error("--binary {platform}={}: {why}", .path.display())]
    Binary {
        /// The platform name.
        platform: String,
        /// The library path.
        path: PathBuf,
        /// Why it was refused.
        why: String,
    },
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

/// A `--name` that cannot be a model identifier; `shown` is the name as quoted in the
/// message (cut after 40 characters).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum NameError {
    /// Empty or longer than [`MAX_NAME`].
    #[error("--name: expected 1 to {MAX_NAME} characters, found {shown}")]
    Length {
        /// The name as shown.
        shown: String,
    },
    /// A character outside letters, digits and `_`.
    #[error(
        "--name: expected letters, digits and '_' only (a file name and a C identifier), found {c:?} in {shown}"
    )]
    Character {
        /// The first such character.
        c: char,
        /// The name as shown.
        shown: String,
    },
    /// A digit first.
    #[error("--name: expected a letter or '_' first (a C identifier), found {shown}")]
    DigitFirst {
        /// The name as shown.
        shown: String,
    },
}

/// What to pack.
#[derive(Debug, Clone, Default)]
pub struct PackRequest {
    /// The `.fxb` file.
    pub body: PathBuf,
    /// A `/NODE` deck or CSV with node coordinates (required for blocked bodies).
    pub coords: Option<PathBuf>,
    /// Exposed node IDs (default: all nodes).
    pub nodes: Option<Vec<i64>>,
    /// Model name (default: the file stem).
    pub name: Option<String>,
    /// Unit system name (default: no units).
    pub units: Option<String>,
    /// Also store the body file itself in resources/ (`--embed-source`), for
    /// traceability only: the FMU reads the scene file.
    pub embed_source: bool,
}

/// What `pack` is asked beyond the files: mode truncation, the DefaultExperiment, the
/// method's start value and libraries for other platforms.
#[derive(Debug, Clone, Default)]
pub struct PackOptions {
    /// `--fmax HZ|auto`.
    pub fmax: Option<Fmax>,
    /// `--step H` (s): the DefaultExperiment step size (and `--fmax auto`'s H).
    pub step: Option<f64>,
    /// `--stop T` (s): the DefaultExperiment stop time.
    pub stop: Option<f64>,
    /// `--method`: the `method` parameter's start value.
    pub method: Option<crate::solver::Method>,
    /// `--binary PLATFORM=PATH`: libraries built on other platforms.
    pub binaries: Vec<(String, PathBuf)>,
}

/// A scene ready to be described or packed.
pub struct Prepared {
    /// The scene.
    pub scene: Scene,
    /// Its variables.
    pub table: VarTable,
    /// The options.
    pub options: SceneOptions,
    /// Content GUID.
    pub guid: String,
    /// The body file's bytes with `embed_source` (stored in resources/), else empty.
    pub body_bytes: Vec<u8>,
    /// Whether the archive carries the body file too (`--embed-source`).
    pub embed_source: bool,
    /// resources/scene.fxs: the scene's solver data ([`scenefile`]).
    pub scene_file: Vec<u8>,
    /// resources/scene.txt.
    pub options_text: String,
    /// modelDescription.xml.
    pub xml: String,
    /// Notes for the user (derived coordinates, body warnings).
    pub notes: Vec<String>,
    /// Libraries for other platforms (`--binary`), by FMI platform name.
    pub other_binaries: Vec<(String, Vec<u8>)>,
}

/// Read and check everything, and generate the description (no library needed).
pub fn prepare(req: &PackRequest) -> Result<Prepared, PackError> {
    prepare_with(req, None)
}

/// Mode truncation asked of `pack` (`--fmax HZ|auto`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Fmax {
    /// Keep the modes up to this frequency, Hz.
    Hz(f64),
    /// Twice the Nyquist frequency 1/(2H) of the DefaultExperiment step H, i.e. 1/H.
    Auto,
}

/// [`prepare`] with mode truncation: the options carry the resolved fmax, and the scene
/// (here and in the FMU, from the full file) keeps the modes up to it plus the residual
/// flexibility of the rest ([`crate::reduce`]).
pub fn prepare_with(req: &PackRequest, fmax: Option<Fmax>) -> Result<Prepared, PackError> {
    prepare_opts(
        req,
        &PackOptions {
            fmax,
            ..PackOptions::default()
        },
    )
}

/// [`prepare`] with every pack option ([`PackOptions`]); the libraries of `--binary`
/// are checked here, before anything is written.
pub fn prepare_opts(req: &PackRequest, popts: &PackOptions) -> Result<Prepared, PackError> {
    prepare_reporting(req, popts, &mut |_, _| {})
}

/// [`prepare_opts`], telling `progress` (bytes parsed, total) while the body file is
/// read ([`body::load_reporting`]).
pub fn prepare_reporting(
    req: &PackRequest,
    popts: &PackOptions,
    progress: &mut dyn FnMut(u64, u64),
) -> Result<Prepared, PackError> {
    for (what, v) in [("step", popts.step), ("stop", popts.stop)] {
        if let Some(value) = v
            && !(value.is_finite() && value > 0.0)
        {
            return Err(PackError::Time { what, value });
        }
    }
    let mut platforms = Vec::new();
    let mut other_binaries = Vec::new();
    for (platform, path) in &popts.binaries {
        let refuse = |why: String| PackError::Binary {
            platform: platform.clone(),
            path: path.clone(),
            why,
        };
        if platform == super::platforms::NATIVE {
            return Err(refuse(format!(
                "{platform} is the library this pack embeds itself (give it with --lib)"
            )));
        }
        if platforms.contains(platform) {
            return Err(refuse(format!("{platform} is given twice")));
        }
        let bytes = std::fs::read(path).map_err(|e| refuse(format!("cannot read: {e}")))?;
        super::platforms::check_library(platform, &bytes).map_err(refuse)?;
        platforms.push(platform.clone());
        other_binaries.push((platform.clone(), bytes));
    }
    let fmax = popts.fmax;
    let body_name = req.body.display().to_string();
    // The body file's bytes are kept only to be stored (--embed-source); otherwise it is
    // parsed as it is read, never whole in memory.
    let (body, body_bytes) = if req.embed_source {
        body::load_with_bytes_reporting(&req.body, progress)?
    } else {
        (body::load_reporting(&req.body, progress)?, Vec::new())
    };
    let mut notes: Vec<String> = body
        .warnings
        .iter()
        .map(|w| format!("warning: {w}"))
        .collect();
    let xyz = match &req.coords {
        Some(p) => coords::read_coords(p)?,
        None => match coords_from_rigid_modes(&body) {
            Some(c) => {
                notes.push("no --coords: node coordinates derived from the rigid modes, frame origin L0 at (0, 0, 0)".into());
                c
            }
            None => {
                return Err(PackError::BlockedNeedsCoords(body_name));
            }
        },
    };
    let map = coords::to_map(&xyz);
    if let Some(c) = &req.coords
        && let Some(o) =
            crate::body::placement::check_coords(&body, &map, &c.display().to_string(), &body_name)?
    {
        notes.push(format!(
            "{}: node positions match the rigid modes; frame origin L0 placed at ({}, {}, {})",
            c.display(),
            crate::num::num(o[0]),
            crate::num::num(o[1]),
            crate::num::num(o[2])
        ));
    }
    let nodes = req.nodes.clone().unwrap_or_else(|| body.node_ids.clone());
    for id in &nodes {
        if body.node_index(*id).is_none() {
            return Err(PackError::UnknownNode {
                id: *id,
                body: body_name,
                nodes: summary(&body.node_ids),
            });
        }
    }
    let missing: Vec<i64> = nodes
        .iter()
        .copied()
        .filter(|id| !map.contains_key(id))
        .collect();
    if !missing.is_empty() {
        return Err(PackError::MissingCoordinates {
            coords: req
                .coords
                .as_ref()
                .map_or("derived coordinates".to_string(), |p| {
                    p.display().to_string()
                }),
            ids: summary(&missing),
            body: body_name,
        });
    }
    let stem = req
        .body
        .file_stem()
        .map_or("fxbody".to_string(), |s| s.to_string_lossy().into_owned());
    let units = req.units.as_deref().map(UnitSystem::parse).transpose()?;
    let fmax = match fmax {
        None => None,
        Some(Fmax::Hz(f)) => Some(f),
        Some(Fmax::Auto) => {
            let h = match popts.step {
                Some(h) => h,
                None => {
                    // The step follows the frequencies only: a probe body without node
                    // rows, not a copy of every node's modes.
                    let bare = crate::reduce::select_nodes(&body, &[]);
                    let probe = Scene::new(std::sync::Arc::new(bare), Vec::new(), Vec::new());
                    super::xml::default_experiment(&probe).1
                }
            };
            notes.push(format!(
                "--fmax auto: {} Hz, twice the Nyquist frequency 1/(2H) of the DefaultExperiment step H = {h} s",
                1.0 / h
            ));
            Some(1.0 / h)
        }
    };
    if let Some(f) = fmax {
        let basis = crate::reduce::ModalBasis::of(&body);
        let kept = basis.count_below(f);
        let first = basis.frequencies_hz().first().copied().unwrap_or(0.0);
        if kept == 0 {
            notes.push(format!(
                "warning: --fmax {f} Hz is below the first mode ({} Hz): no mode kept, the body follows its loads only quasi-statically (residual flexibility); raise --fmax to keep modes",
                crate::num::num(first)
            ));
        }
        if kept == body.nl() {
            notes.push(format!(
                "--fmax {f} Hz: all {kept} modes kept (every mode is below it), no residual correction"
            ));
        } else {
            notes.push(format!(
            "--fmax {f} Hz: {kept} of {} modes kept, the other {} by their static (residual-flexibility) contribution; positions, rotations and strain energy now depend on the same-instant loads",
            body.nl(),
            body.nl() - kept
        ));
        }
    }
    match &req.name {
        Some(n) => check_name(n)?,
        None if stem.chars().count() > MAX_NAME => {
            return Err(PackError::StemTooLong {
                body: body_name,
                chars: stem.chars().count(),
            });
        }
        None => {}
    }
    let all_exposed = req.nodes.is_none();
    for &id in &nodes {
        let n = body.node_index(id).unwrap_or(0);
        let moved = [&body.phi_r, &body.phi_l]
            .iter()
            .any(|m| (6 * n..6 * n + 6).any(|r| m.row(r).iter().any(|&v| v != 0.0)));
        if !moved {
            notes.push(format!(
                "warning: node {id} is fully blocked: no mode of {body_name} moves it, so its outputs stay at their initial values and loads on it do nothing"
            ));
        }
    }
    let options = SceneOptions {
        name: req.name.clone().unwrap_or(stem),
        nodes,
        units,
        fmax,
        step: popts.step,
        stop: popts.stop,
        method: popts.method,
        platforms,
    };
    let options_text = options.to_text();
    let scene = make_scene(body, &map, &options, &body_name)?;
    let scene_file = scenefile::to_bytes(&scene);
    let guid = guid(scenefile::checksum_of(&scene_file), &options_text);
    let table = VarTable::new(&scene).with_default_method(options.method);
    let (stop, step) = options.experiment(&scene);
    if step > stop {
        return Err(PackError::StepAfterStop {
            step,
            stop,
            stop_given: options.stop.is_some(),
        });
    }
    if all_exposed && table.vars.len() > 1000 {
        notes.push(format!(
            "warning: all {} nodes are exposed, which makes {} variables; expose only the nodes the scene couples to (--nodes or --nodes-file)",
            scene.nodes.len(),
            table.vars.len()
        ));
    }
    let xml = model_description(&scene, &table, &options, &guid);
    Ok(Prepared {
        scene,
        table,
        options,
        guid,
        body_bytes,
        embed_source: req.embed_source,
        scene_file,
        options_text,
        xml,
        notes,
        other_binaries,
    })
}

/// Longest `--name`: the model identifier names the library inside the archive and
/// the C symbols' prefix; 64 characters keep every path well under tool limits.
pub const MAX_NAME: usize = 64;

/// Check a model name given by the user: 1 to [`MAX_NAME`] characters, a letter or `_`
/// first, then letters, digits or `_`, so it is usable unchanged as a file name and a
/// C identifier (the FMI modelIdentifier).
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
    Ok(())
}

/// Refuse to write `out` over one of the `inputs` (`(what, path)`): the same file by
/// device and inode, so a link or a `./` spelling is caught too. An `out` that does not
/// exist yet is no input.
pub fn refuse_overwrite(out: &Path, inputs: &[(&str, &Path)]) -> Result<(), PackError> {
    use std::os::unix::fs::MetadataExt;
    let Ok(o) = std::fs::metadata(out) else {
        return Ok(());
    };
    for (what, p) in inputs {
        if let Ok(m) = std::fs::metadata(p)
            && m.dev() == o.dev()
            && m.ino() == o.ino()
        {
            return Err(PackError::Overwrite {
                out: out.to_path_buf(),
                what: what.to_string(),
                input: p.to_path_buf(),
            });
        }
    }
    Ok(())
}

/// Find the FMU library: `explicit`, else `$FXBODY_LIB`, else `libfxbody.so` next to the
/// running executable (or one folder up, for test executables in `deps/`).
pub fn find_library(explicit: Option<&Path>) -> Result<PathBuf, PackError> {
    if let Some(p) = explicit {
        return if p.is_file() {
            Ok(p.to_path_buf())
        } else {
            Err(PackError::NoLib(p.to_path_buf()))
        };
    }
    if let Some(p) = std::env::var_os("FXBODY_LIB") {
        let p = PathBuf::from(p);
        return if p.is_file() {
            Ok(p)
        } else {
            Err(PackError::NoEnvLib(p))
        };
    }
    let exe = std::env::current_exe().map_err(PackError::Exe)?;
    let mut tried = Vec::new();
    let mut dir = exe.parent();
    for _ in 0..2 {
        let Some(d) = dir else { break };
        let p = d.join("libfxbody.so");
        if p.is_file() {
            return Ok(p);
        }
        tried.push(p.display().to_string());
        dir = d.parent();
    }
    Err(PackError::LibNotFound(tried.join(", ")))
}

/// The archive bytes for a prepared scene and the library bytes.
pub fn archive(p: &Prepared, lib: &[u8]) -> Result<Vec<u8>, PackError> {
    let id = p.options.model_identifier();
    let mut entries = vec![
        Entry {
            name: "modelDescription.xml".into(),
            data: p.xml.clone().into_bytes(),
            mode: 0o644,
        },
        Entry {
            name: format!("binaries/linux64/{id}.so"),
            data: lib.to_vec(),
            mode: 0o755,
        },
    ];
    for (platform, data) in &p.other_binaries {
        entries.push(Entry {
            name: format!(
                "binaries/{platform}/{}",
                super::platforms::library_name(platform, &id)
            ),
            data: data.clone(),
            mode: 0o755,
        });
    }
    entries.extend(resource_entries(p));
    entries.push(Entry {
        name: "documentation/index.html".into(),
        data: index_html(&p.scene, &p.table, &p.options, &p.guid).into_bytes(),
        mode: 0o644,
    });
    Ok(write(&entries)?)
}

/// The files of `resources/`, named as in the archive: the scene file and the options
/// (all the FMU reads), and the body file when `embed_source` asks for it.
pub fn resource_entries(p: &Prepared) -> Vec<Entry> {
    let mut files = vec![
        (SCENE_FILE, p.scene_file.clone()),
        (OPTIONS_FILE, p.options_text.clone().into_bytes()),
    ];
    if p.embed_source {
        files.push((SOURCE_FILE, p.body_bytes.clone()));
    }
    files
        .into_iter()
        .map(|(name, data)| Entry {
            name: format!("resources/{name}"),
            data,
            mode: 0o644,
        })
        .collect()
}

/// Pack `req` with the library at `lib` into `out`. Returns the prepared scene.
///
/// A program next to `libfxbody.so` finds it with [`find_library`]`(None)`; this
/// example, run by the tests from elsewhere, takes the one cargo built, and reads the
/// archive back with the workspace's FMU importer (`fxbody_host`, a dev-dependency).
///
/// ```
/// use std::path::Path;
///
/// use fxbody::fmu::pack::{PackRequest, pack};
///
/// let root = Path::new(env!("CARGO_MANIFEST_DIR"));
/// # let lib = ["release", "debug"].iter().map(|p| root.join("target").join(p).join("libfxbody.so"))
/// #     .find(|p| p.is_file()).expect("libfxbody.so: run cargo build first");
/// let req = PackRequest {
///     body: root.join("fixtures/cantilever.fxb"),
///     coords: Some(root.join("fixtures/cantilever.nodes.rad")),
///     nodes: Some(vec![121]),
///     ..PackRequest::default()
/// };
/// let dir = std::env::temp_dir().join(format!("fxbody_doc_pack_{}", std::process::id()));
/// std::fs::create_dir_all(&dir)?;
/// let prepared = pack(&req, &lib, &dir.join("tip.fmu"))?;
/// assert!(prepared.table.vars.iter().any(|v| v.name == "node_121.fy"));
/// let files = fxbody_host::zip::read(&std::fs::read(dir.join("tip.fmu"))?)?;
/// let names: Vec<&str> = files.iter().map(|(name, _)| name.as_str()).collect();
/// assert!(names.contains(&"modelDescription.xml"));
/// assert!(names.contains(&"binaries/linux64/cantilever.so"));
/// std::fs::remove_dir_all(&dir)?;
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn pack(req: &PackRequest, lib: &Path, out: &Path) -> Result<Prepared, PackError> {
    pack_with(req, None, lib, out)
}

/// [`pack`] with mode truncation ([`prepare_with`]).
pub fn pack_with(
    req: &PackRequest,
    fmax: Option<Fmax>,
    lib: &Path,
    out: &Path,
) -> Result<Prepared, PackError> {
    pack_opts(
        req,
        &PackOptions {
            fmax,
            ..PackOptions::default()
        },
        lib,
        out,
    )
}

/// [`pack`] with every pack option ([`prepare_opts`]); also writes the OSP model
/// description beside the archive ([`super::osp::osp_path`]).
pub fn pack_opts(
    req: &PackRequest,
    popts: &PackOptions,
    lib: &Path,
    out: &Path,
) -> Result<Prepared, PackError> {
    pack_reporting(req, popts, lib, out, &mut |_, _| {})
}

/// [`pack_opts`], telling `progress` (bytes parsed, total) while the body file is read.
pub fn pack_reporting(
    req: &PackRequest,
    popts: &PackOptions,
    lib: &Path,
    out: &Path,
    progress: &mut dyn FnMut(u64, u64),
) -> Result<Prepared, PackError> {
    let mut inputs: Vec<(&str, &Path)> = vec![("body file", &req.body), ("library", lib)];
    if let Some(c) = &req.coords {
        inputs.push(("coordinate file", c));
    }
    refuse_overwrite(out, &inputs)?;
    let p = prepare_reporting(req, popts, progress)?;
    let lib_bytes = std::fs::read(lib).map_err(|source| PackError::ReadLib {
        path: lib.to_path_buf(),
        source,
    })?;
    let bytes = archive(&p, &lib_bytes)?;
    std::fs::write(out, bytes).map_err(|source| PackError::WriteFmu {
        path: out.to_path_buf(),
        source,
    })?;
    let osp = super::osp::osp_path(out, &p.options.name);
    std::fs::write(
        &osp,
        super::osp::osp_model_description(&p.table, &p.options),
    )
    .map_err(|source| PackError::WriteOsp { path: osp, source })?;
    Ok(p)
}
