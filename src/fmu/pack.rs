//! `fxbody pack`: a body file, its coordinates and the options into an `.fmu` archive
//! with modelDescription.xml, the library, resources/ (the scene file, sized to the
//! scene, and the options) and documentation/.

use std::path::{Path, PathBuf};

use super::doc::index_html_for;
use super::fmi_version::FmiVersion;
use super::options::{SceneOptions, UnitSystem};
use super::vars::VarTable;
use super::xml::model_description;
use super::zip::{Entry, write};
use crate::body;
use crate::fxb::coords;
use crate::fxb::input::{
    Input, InputError, Limit, check_input, describe, read_bounded, read_input,
};
use crate::scene::Scene;
use crate::scene::file as scenefile;
use crate::scene::io::{
    OPTIONS_FILE, SCENE_FILE, SOURCE_FILE, coords_from_rigid_modes, guid, make_scene, summary,
};

mod error;
pub mod experiment;
mod note;
pub use error::{MAX_NAME, NameError, PackError, check_name, reserved};
pub use note::PackNote;

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
    /// Mode truncation (default: every mode kept). The scene (here and in the FMU, from
    /// the full file) keeps the modes up to it plus the residual flexibility of the rest
    /// ([`crate::scene::reduce`]).
    pub fmax: Option<Fmax>,
    /// The DefaultExperiment step size, s (and [`Fmax::Auto`]'s H); default derived
    /// from the lowest mode.
    pub step: Option<f64>,
    /// The DefaultExperiment stop time, s.
    pub stop: Option<f64>,
    /// The `method` parameter's start value.
    pub method: Option<crate::solver::Method>,
    /// Libraries built on other platforms, by FMI 2.0 platform name.
    pub binaries: Vec<(String, PathBuf)>,
    /// The FMI version of the model description (default 2.0).
    pub fmi: FmiVersion,
    /// The interfaces the FMU declares (default co-simulation).
    pub interface: super::interface::Interfaces,
}

/// Mode truncation asked of `pack` ([`PackOptions::fmax`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Fmax {
    /// Keep the modes up to this frequency, Hz.
    Hz(f64),
    /// Twice the Nyquist frequency 1/(2H) of the DefaultExperiment step H, i.e. 1/H.
    Auto,
}

/// Told (bytes parsed, total) while the body file is read
/// ([`body::LoadOptions::progress`]).
pub type Progress<'a> = Option<&'a mut dyn FnMut(u64, u64)>;

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
    /// Notes for the user (derived coordinates, truncation, warnings), as data.
    pub notes: Vec<PackNote>,
    /// Libraries for other platforms (`--binary`), by FMI 2.0 platform name.
    pub other_binaries: Vec<(String, Vec<u8>)>,
    /// The FMI version the description and the archive's layout follow.
    pub fmi: FmiVersion,
}

impl Prepared {
    /// The `binaries/` folders of the libraries added with `--binary`, in the FMU's
    /// version's names.
    pub fn added_platforms(&self) -> Vec<String> {
        self.other_binaries
            .iter()
            .flat_map(|(p, bytes)| self.fmi.platform_dirs(p, bytes))
            .collect()
    }
}

/// Read and check everything, and generate the description (no library needed): the
/// one way to a [`Prepared`] scene. The libraries of [`PackOptions::binaries`] are
/// checked here, before anything is written; `progress` is told while the body file is
/// read.
pub fn prepare(
    req: &PackRequest,
    popts: &PackOptions,
    progress: Progress<'_>,
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
            return Err(PackError::NativeBinary {
                platform: platform.clone(),
                path: path.clone(),
            });
        }
        if platforms.contains(platform) {
            return Err(refuse(format!("{platform} is given twice")));
        }
        let bytes = read_bounded(path, Limit::Library).map_err(|e| refuse(describe(&e)))?;
        super::platforms::check_library(platform, &bytes).map_err(refuse)?;
        platforms.push(platform.clone());
        other_binaries.push((platform.clone(), bytes));
    }
    let fmax = popts.fmax;
    let body_name = req.body.display().to_string();
    // The body file's bytes are kept only to be stored (--embed-source); otherwise it is
    // parsed as it is read, never whole in memory.
    let mut body_bytes = Vec::new();
    let body = body::load(
        &req.body,
        body::LoadOptions {
            keep_bytes: req.embed_source.then_some(&mut body_bytes),
            // Coerced to the load's shorter lifetime, which `keep_bytes` shares.
            progress: progress.map(|p| p as &mut dyn FnMut(u64, u64)),
        },
    )?;
    let mut notes: Vec<PackNote> = body.warnings.iter().cloned().map(PackNote::Body).collect();
    let xyz = match &req.coords {
        Some(p) => coords::read_coords(p).map_err(|e| match e {
            coords::CoordsError::Io { source, .. } => {
                InputError::new(Input::Coords, p, source).into()
            }
            e => PackError::from(e),
        })?,
        None => match coords_from_rigid_modes(&body) {
            Some(c) => {
                notes.push(PackNote::CoordsDerived);
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
        notes.push(PackNote::OriginPlaced {
            coords: c.clone(),
            origin: o,
        });
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
                    let bare = crate::scene::reduce::select_nodes(&body, &[]);
                    let probe = Scene::new(std::sync::Arc::new(bare), Vec::new(), Vec::new());
                    super::xml::default_experiment(&probe).1
                }
            };
            notes.push(PackNote::FmaxAuto {
                hz: 1.0 / h,
                step: h,
            });
            Some(1.0 / h)
        }
    };
    if let Some(f) = fmax {
        let basis = crate::scene::reduce::ModalBasis::of(&body);
        let kept = basis.count_below(f);
        let first = basis.frequencies_hz().first().copied().unwrap_or(0.0);
        if kept == 0 {
            notes.push(PackNote::FmaxBelowFirstMode { fmax: f, first });
        }
        if kept == body.nl() {
            notes.push(PackNote::FmaxKeepsAll { fmax: f, kept });
        } else {
            notes.push(PackNote::FmaxKeeps {
                fmax: f,
                kept,
                total: body.nl(),
            });
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
            notes.push(PackNote::NodeBlocked {
                id,
                body: body_name.clone(),
            });
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
        interface: popts.interface,
    };
    if req.name.is_none()
        && let Some(why) = reserved(&options.model_identifier())
    {
        return Err(PackError::StemReserved {
            body: body_name,
            id: options.model_identifier(),
            why,
        });
    }
    let options_text = options.to_text();
    let scene = make_scene(body, &map, &options, &body_name)?;
    let scene_file = scenefile::to_bytes(&scene);
    let guid = guid(scenefile::checksum_of(&scene_file), &options_text);
    let table = VarTable::for_options(&scene, &options);
    let (stop, step) = options.experiment(&scene);
    if step > stop {
        return Err(PackError::StepAfterStop {
            step,
            stop,
            stop_given: options.stop.is_some(),
        });
    }
    notes.extend(experiment::warnings(
        &scene,
        stop,
        step,
        options.step.is_some(),
        options.stop.is_some(),
    ));
    if all_exposed && table.vars.len() > 1000 {
        notes.push(PackNote::AllNodesExposed {
            nodes: scene.nodes.len(),
            variables: table.vars.len(),
        });
    }
    let mut p = Prepared {
        scene,
        table,
        options,
        guid,
        body_bytes,
        embed_source: req.embed_source,
        scene_file,
        options_text,
        notes,
        other_binaries,
        fmi: popts.fmi,
        xml: String::new(),
    };
    p.xml = match p.fmi {
        FmiVersion::Fmi2 => model_description(&p.scene, &p.table, &p.options, &p.guid),
        FmiVersion::Fmi3 => super::xml3::model_description(
            &p.scene,
            &p.table,
            &p.options,
            &p.guid,
            &p.added_platforms(),
        ),
    };
    Ok(p)
}

/// Refuse to write `out` over one of the `inputs` (`(what, path)`): the same file as the
/// platform identifies it (device and inode on Unix, volume and file index on Windows,
/// through `same-file`), so a link or a `./` spelling is caught too. An `out` that does
/// not exist yet is no input. Only regular files are compared (`same-file` opens them,
/// and opening a FIFO would wait; an input that is not a regular file is refused when it
/// is read).
pub fn refuse_overwrite(out: &Path, inputs: &[(&str, &Path)]) -> Result<(), PackError> {
    let handle = |p: &Path| {
        std::fs::metadata(p)
            .is_ok_and(|m| m.is_file())
            .then(|| same_file::Handle::from_path(p).ok())
            .flatten()
    };
    let Some(o) = handle(out) else {
        return Ok(());
    };
    for (what, p) in inputs {
        if handle(p).is_some_and(|h| h == o) {
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
/// running executable (a build's target/release/), one folder up (test executables in
/// `deps/`), or in `../lib/fxbody/` from it (an installed PREFIX/bin/fxbody with
/// PREFIX/lib/fxbody/libfxbody.so: scripts/install.sh). A path given
/// (option or variable) must be a regular file no larger than a library can be
/// ([`Limit::Library`]); the message says what it is instead.
pub fn find_library(explicit: Option<&Path>) -> Result<PathBuf, PackError> {
    if let Some(p) = explicit {
        check_input(Input::Library, p, Limit::Library)?;
        return Ok(p.to_path_buf());
    }
    if let Some(p) = std::env::var_os("FXBODY_LIB") {
        let p = PathBuf::from(p);
        check_input(Input::LibraryEnv, &p, Limit::Library)?;
        return Ok(p);
    }
    let exe = std::env::current_exe().map_err(PackError::Exe)?;
    let mut tried = Vec::new();
    let (here, up) = (exe.parent(), exe.parent().and_then(Path::parent));
    let candidates = [
        here.map(|d| d.join("libfxbody.so")),
        up.map(|d| d.join("libfxbody.so")),
        up.map(|d| d.join("lib").join("fxbody").join("libfxbody.so")),
    ];
    for p in candidates.into_iter().flatten() {
        if p.is_file() {
            return Ok(p);
        }
        tried.push(p.display().to_string());
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
            name: format!("binaries/{}/{id}.so", p.fmi.native_platform()),
            data: lib.to_vec(),
            mode: 0o755,
        },
    ];
    for (platform, data) in &p.other_binaries {
        for dir in p.fmi.platform_dirs(platform, data) {
            entries.push(Entry {
                name: format!(
                    "binaries/{dir}/{}",
                    super::platforms::library_name(platform, &id)
                ),
                data: data.clone(),
                mode: 0o755,
            });
        }
    }
    entries.extend(resource_entries(p));
    let page = index_html_for(
        &p.scene,
        &p.table,
        &p.options,
        &p.guid,
        p.fmi,
        &p.added_platforms(),
    );
    entries.push(Entry {
        name: "documentation/index.html".into(),
        data: page.into_bytes(),
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

/// Pack `req` with the options `popts` and the library at `lib` into `out` ([`prepare`]);
/// also writes the OSP model description beside the archive
/// ([`super::osp::osp_path`]), refusing before anything is written when that file
/// describes another FMU ([`super::osp::check_osp_target`]). Returns the prepared scene.
///
/// A program next to `libfxbody.so` finds it with [`find_library`]`(None)`; this
/// example, run by the tests from elsewhere, takes the one cargo built, and reads the
/// archive back with the workspace's FMU importer (`fxbody_host`, a dev-dependency).
///
/// ```
/// use std::path::Path;
///
/// use fxbody::fmu::pack::{PackOptions, PackRequest, pack};
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
/// let prepared = pack(&req, &PackOptions::default(), &lib, &dir.join("tip.fmu"), None)?;
/// assert!(prepared.table.vars.iter().any(|v| v.name == "node_121.fy"));
/// let files = fxbody_host::zip::read(&std::fs::read(dir.join("tip.fmu"))?)?;
/// let names: Vec<&str> = files.iter().map(|(name, _)| name.as_str()).collect();
/// assert!(names.contains(&"modelDescription.xml"));
/// assert!(names.contains(&"binaries/linux64/cantilever.so"));
/// std::fs::remove_dir_all(&dir)?;
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn pack(
    req: &PackRequest,
    popts: &PackOptions,
    lib: &Path,
    out: &Path,
    progress: Progress<'_>,
) -> Result<Prepared, PackError> {
    let mut inputs: Vec<(&str, &Path)> = vec![("body file", &req.body), ("library", lib)];
    if let Some(c) = &req.coords {
        inputs.push(("coordinate file", c));
    }
    refuse_overwrite(out, &inputs)?;
    let p = prepare(req, popts, progress)?;
    super::osp::check_osp_target(out, &p.options.name)?;
    let lib_bytes = read_input(Input::Library, lib, Limit::Library)?;
    super::platforms::check_library(super::platforms::NATIVE, &lib_bytes).map_err(|why| {
        InputError::new(
            Input::Library,
            lib,
            std::io::Error::new(std::io::ErrorKind::InvalidData, why),
        )
    })?;
    let bytes = archive(&p, &lib_bytes)?;
    std::fs::write(out, bytes).map_err(|source| PackError::WriteFmu {
        path: out.to_path_buf(),
        source,
    })?;
    let osp = super::osp::osp_path(out, &p.options.name);
    std::fs::write(
        &osp,
        super::osp::osp_model_description(&p.table, &p.options, out),
    )
    .map_err(|source| PackError::WriteOsp { path: osp, source })?;
    Ok(p)
}
