//! Issue 16 item 1: the scene file (resources/scene.fxs). A model read back from the
//! packed resources runs bit for bit as the model built from the `.fxb` file (every
//! fixture, every method, with and without `--fmax`), holds only the exposed nodes' rows,
//! and every damaged file is refused at fmi2Instantiate with a logged reason.

use std::path::Path;

use crate::common::fixture;
use crate::common::fmu::{Slave, packed};
use fxbody::fmu::pack::{Fmax, PackOptions, PackRequest, Prepared, prepare, resource_entries};
use fxbody::fmu::simulation::{Phase, Simulation};
use fxbody::fmu::vars::Kind;
use fxbody::fmu::xml::default_experiment;
use fxbody::scene::io::{OPTIONS_FILE, SCENE_FILE};

/// Steps each pair of models runs.
const STEPS: usize = 300;

/// Write `p`'s resources/ under `dir` as the archive holds them.
fn write_resources(p: &Prepared, dir: &Path) {
    for e in resource_entries(p) {
        let path = dir.join(&e.name);
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        std::fs::write(path, &e.data).unwrap();
    }
}

/// The middle and the last node of `body`, packed with their deck, truncated at the
/// frequency of the middle mode when `fmax`.
fn prepared(body: &str, fmax: bool) -> Prepared {
    let req = |nodes| PackRequest {
        body: fixture(&format!("{body}.fxb")),
        coords: Some(fixture(&format!("{body}.nodes.rad"))),
        nodes,
        ..PackRequest::default()
    };
    let all = prepare(&req(None), &PackOptions::default(), None).unwrap();
    let ids = all.scene.body.node_ids();
    let nodes = vec![ids[ids.len() / 2], ids[ids.len() - 1]];
    let f = fmax.then(|| {
        let hz = all.scene.body.frequencies_hz();
        Fmax::Hz(hz[hz.len() / 2])
    });
    prepare(
        &req(Some(nodes)),
        &PackOptions {
            fmax: f,
            ..PackOptions::default()
        },
        None,
    )
    .unwrap()
}

/// Every value of every variable but `method` after each of [`STEPS`] steps under
/// time-varying loads on every input (and gravity and a spin for a free body), and the
/// refusal that ended the run early, if one did.
fn run(mut m: Simulation, method: i32, h: f64) -> (Vec<u64>, Option<String>) {
    let table = m.table.clone();
    let method_vr = table
        .vars
        .iter()
        .find(|v| v.kind == Kind::Method)
        .unwrap()
        .vr;
    m.set_integer(method_vr, method, Phase::Configuring)
        .unwrap();
    m.setup(0.0, None).unwrap();
    for v in &table.vars {
        let x = match v.kind {
            Kind::Gravity(2) => -9.81,
            Kind::W0(2) => 0.1,
            _ => continue,
        };
        m.set_real(v.vr, x, Phase::Configuring).unwrap();
    }
    let loads: Vec<(u32, usize)> = table
        .vars
        .iter()
        .filter_map(|v| match v.kind {
            Kind::Load { node, comp } => Some((v.vr, 6 * node + comp)),
            _ => None,
        })
        .collect();
    let read: Vec<u32> = table
        .vars
        .iter()
        .filter(|v| v.kind != Kind::Method)
        .map(|v| v.vr)
        .collect();
    let mut out = vec![0.0; read.len()];
    let mut bits = Vec::with_capacity(STEPS * read.len());
    for k in 0..STEPS {
        let t = k as f64 * h;
        for &(vr, i) in &loads {
            let f = 0.01 * (1.0 + (i % 6) as f64) * (300.0 * t + i as f64).cos();
            m.set_real(vr, f, Phase::Running).unwrap();
        }
        if let Err(e) = m.do_step(t, h) {
            return (bits, Some(e.to_string()));
        }
        m.get_reals(&read, &mut out).unwrap();
        bits.extend(out.iter().map(|x| x.to_bits()));
    }
    (bits, None)
}

#[test]
fn resources_run_bit_for_bit_as_the_fxb_on_every_fixture_and_method() {
    let dir = std::env::temp_dir().join(format!("fxbody_scenefile_{}", std::process::id()));
    let mut runs = 0;
    for body in ["cantilever", "cantilever_damped", "freefree", "truss"] {
        for fmax in [false, true] {
            let p = prepared(body, fmax);
            let _ = std::fs::remove_dir_all(&dir);
            write_resources(&p, &dir);
            let from_fxb = || Simulation::new(p.scene.clone(), p.guid.clone());
            let from_file = || Simulation::from_resources(&dir.join("resources")).unwrap();
            let m = from_file();
            assert_eq!(m.guid, p.guid, "{body}");
            // Only the exposed nodes' rows, only the kept modes.
            let (a, b) = (&p.scene.body, &m.scene().body);
            assert_eq!(b.node_ids(), p.options.nodes, "{body}");
            assert_eq!((b.m_l().len(), b.nr()), (a.nl(), a.nr()), "{body}");
            assert_eq!(b.phi_l().nrows(), 12, "{body}");
            assert_eq!(m.scene().residual.is_some(), fmax, "{body}");
            let h = default_experiment(&p.scene).1;
            for &method in m.table.methods() {
                let ((want, want_end), (got, got_end)) = (
                    run(from_fxb(), method as i32, h),
                    run(from_file(), method as i32, h),
                );
                // No run is refused (the truss truncated at its middle mode once was, by
                // an explicit step beyond its coupled modes' stable step).
                assert_eq!(want_end, None, "{body} fmax {fmax} {method:?}");
                assert_eq!(got_end, None, "{body} fmax {fmax} {method:?}");
                let steps = want.len() / (m.table.vars.len() - 1);
                assert_eq!(steps, STEPS, "{body} fmax {fmax} {method:?}");
                assert!(
                    want.iter().any(|&x| x != want[0]),
                    "{body}: the outputs move"
                );
                assert_eq!(want.len(), got.len());
                if let Some(k) = want.iter().zip(&got).position(|(a, b)| a != b) {
                    panic!(
                        "{body} fmax {fmax} {method:?}: value {k} differs: {} from the .fxb, {} from scene.fxs",
                        f64::from_bits(want[k]),
                        f64::from_bits(got[k])
                    );
                }
                runs += 1;
            }
        }
    }
    // 2 blocked bodies x 3 methods + 2 free x 3, each with and without fmax.
    assert_eq!(runs, 24);
    let _ = std::fs::remove_dir_all(&dir);
}

/// The log of an fmi2Instantiate of `fx` that must fail (`what` names the case).
fn refused_log(fx: &crate::common::fmu::Packed, what: &str) -> String {
    match Slave::try_new(fx, "damaged") {
        Ok(_) => panic!("{what}: instantiated"),
        Err(m) => m
            .iter()
            .map(|m| m.text.as_str())
            .collect::<Vec<_>>()
            .join("\n"),
    }
}

/// A file of the cantilever scene and how each damage to it is refused at
/// fmi2Instantiate: the logged error names the file and the cause.
#[test]
fn every_damaged_scene_file_is_refused_at_instantiation_with_its_reason() {
    let fx = packed("scenefile_damage");
    let path = fx.dir.join("resources").join(SCENE_FILE);
    let good = std::fs::read(&path).unwrap();
    let fnv = |payload: &[u8]| fxbody::fmu::hash::fnv1a64_words(payload).to_le_bytes();
    let damage: Vec<(&str, Vec<u8>, &str)> = vec![
        (
            "a payload bit flipped",
            {
                let mut b = good.clone();
                let k = b.len() - 100;
                b[k] ^= 0x10;
                b
            },
            "checksum mismatch: the header says",
        ),
        (
            "the stored checksum changed",
            {
                let mut b = good.clone();
                b[30] ^= 1;
                b
            },
            "checksum mismatch",
        ),
        ("truncated", good[..good.len() - 8].to_vec(), "truncated"),
        (
            "cut inside the header",
            good[..20].to_vec(),
            "the header needs 32",
        ),
        (
            "version 2",
            {
                let mut b = good.clone();
                b[12..16].copy_from_slice(&2u32.to_le_bytes());
                b
            },
            "scene format version 2: this FMU reads version 1 only",
        ),
        (
            "written big-endian",
            {
                let mut b = good.clone();
                b[8..12].copy_from_slice(&0x0102_0304u32.to_be_bytes());
                b
            },
            "this file was written big-endian",
        ),
        (
            "not a scene file",
            b"#RADIOSS FXBODY\n... some text that is no scene file at all".to_vec(),
            "not an fxbody scene file",
        ),
        (
            "a section length changed, checksum recomputed",
            {
                // PHIL (the 4th section) one word shorter: the checksum holds, the
                // layout does not.
                let mut b = good.clone();
                let mut at = 32;
                for _ in 0..3 {
                    let len = u64::from_le_bytes(b[at + 8..at + 16].try_into().unwrap());
                    at += 16 + len as usize;
                }
                assert_eq!(&b[at..at + 4], b"PHIL");
                let len = u64::from_le_bytes(b[at + 8..at + 16].try_into().unwrap());
                b[at + 8..at + 16].copy_from_slice(&(len - 8).to_le_bytes());
                let sum = fnv(&b[32..]);
                b[24..32].copy_from_slice(&sum);
                b
            },
            "section PHIL: ",
        ),
        (
            "a local mass made negative, checksum recomputed",
            {
                let mut b = good.clone();
                let mut at = 32;
                for _ in 0..4 {
                    let len = u64::from_le_bytes(b[at + 8..at + 16].try_into().unwrap());
                    at += 16 + len as usize;
                }
                assert_eq!(&b[at..at + 4], b"MASS");
                b[at + 16..at + 24].copy_from_slice(&(-1.0f64).to_le_bytes());
                let sum = fnv(&b[32..]);
                b[24..32].copy_from_slice(&sum);
                b
            },
            "section MASS (local mass m_L): every m_L must be > 0, found m_L(1) = -1",
        ),
        (
            "a negative Rayleigh beta, checksum recomputed",
            {
                // BODY word 9 (after the 32-byte header and BODY's 16-byte header).
                let mut b = good.clone();
                let at = 32 + 16 + 8 * 9;
                b[at..at + 8].copy_from_slice(&(-1e-4f64).to_le_bytes());
                let sum = fnv(&b[32..]);
                b[24..32].copy_from_slice(&sum);
                b
            },
            "section BODY: Rayleigh alpha 0, beta -0.0001 without the damping flag",
        ),
    ];
    for (what, bytes, want) in damage {
        std::fs::write(&path, &bytes).unwrap();
        let text = refused_log(&fx, what);
        println!("{what}: {text}");
        assert!(
            text.starts_with("fmi2Instantiate: ")
                && text.contains("scene.fxs")
                && text.contains(want),
            "{what}: {text}"
        );
    }
    // A missing scene file, and a scene.txt from another pack (other nodes).
    std::fs::remove_file(&path).unwrap();
    let text = format!("{:?}", Slave::try_new(&fx, "missing").err().unwrap());
    assert!(
        text.contains("cannot read") && text.contains("scene.fxs"),
        "{text}"
    );
    std::fs::write(&path, &good).unwrap();
    let options = fx.dir.join("resources").join(OPTIONS_FILE);
    let t = std::fs::read_to_string(&options).unwrap();
    std::fs::write(&options, t.replace("nodes = 121", "nodes = 111")).unwrap();
    let text = format!("{:?}", Slave::try_new(&fx, "other").err().unwrap());
    assert!(
        text.contains("scene.txt exposes the nodes 111, scene.fxs holds 121"),
        "{text}"
    );
    // Restored: it instantiates again.
    std::fs::write(&options, t).unwrap();
    assert!(Slave::try_new(&fx, "restored").is_ok());
}

/// docs/SCENE_FORMAT.md describes this version: its header constants and every section,
/// in the order the reader expects them.
#[test]
fn the_format_document_lists_every_section_in_file_order() {
    use fxbody::scene::file::{SECTIONS, VERSION};
    let doc = std::fs::read_to_string(crate::common::root().join("docs/SCENE_FORMAT.md")).unwrap();
    assert!(doc.starts_with(&format!(
        "# The scene file (`resources/scene.fxs`), format version {VERSION}"
    )));
    assert!(doc.contains("ASCII `FXBSCENE`") && doc.contains("bytes `04 03 02 01`"));
    let mut at = 0;
    for tag in SECTIONS {
        let row = format!("| `{}` |", String::from_utf8_lossy(tag));
        let k = doc[at..]
            .find(&row)
            .unwrap_or_else(|| panic!("{row} after byte {at}"));
        at += k + row.len();
    }
}

/// `--embed-source` adds the body file, byte for byte, as resources/source.fxb; without
/// it the archive's resources are the scene file and the options only, and the GUID is
/// the same either way (the source is never read).
#[test]
fn embed_source_adds_the_body_file_and_nothing_else_changes() {
    let lib = b"not a library";
    let names = |embed: bool| {
        let req = PackRequest {
            body: fixture("cantilever.fxb"),
            coords: Some(fixture("cantilever.nodes.rad")),
            nodes: Some(vec![121]),
            embed_source: embed,
            ..PackRequest::default()
        };
        let p = prepare(&req, &PackOptions::default(), None).unwrap();
        let files = fxbody_host::zip::read(&fxbody::fmu::pack::archive(&p, lib).unwrap()).unwrap();
        (p.guid, files)
    };
    let (g0, plain) = names(false);
    let (g1, embedded) = names(true);
    assert_eq!(g0, g1);
    let resources = |files: &[(String, Vec<u8>)]| {
        files
            .iter()
            .filter(|(n, _)| n.starts_with("resources/"))
            .map(|(n, _)| n.clone())
            .collect::<Vec<_>>()
    };
    assert_eq!(
        resources(&plain),
        ["resources/scene.fxs", "resources/scene.txt"]
    );
    assert_eq!(
        resources(&embedded),
        [
            "resources/scene.fxs",
            "resources/scene.txt",
            "resources/source.fxb"
        ]
    );
    let source = &embedded
        .iter()
        .find(|(n, _)| n == "resources/source.fxb")
        .unwrap()
        .1;
    assert_eq!(source, &std::fs::read(fixture("cantilever.fxb")).unwrap());
}

/// A packed scene edited through the crate's own reader and writer (so the checksum is
/// recomputed: the file is intact, its numbers are not), written into `dir`'s resources
/// in place of the packed one; the refusal `Simulation::from_resources` (what fmi2Instantiate
/// runs) gives, or `None` when the scene was accepted.
fn refusal_of(
    dir: &Path,
    good: &[u8],
    edit: impl FnOnce(&mut fxbody::scene::Scene, &mut fxbody::body::BodyParts),
) -> Option<String> {
    let mut scene = fxbody::scene::file::from_bytes(good, "good").unwrap().scene;
    let mut body = (*scene.body).clone().into_parts();
    edit(&mut scene, &mut body);
    let bytes = fxbody::scene::file::parts_to_bytes(&body, &scene.x0, scene.residual.as_deref());
    let path = dir.join("resources").join(SCENE_FILE);
    std::fs::write(&path, bytes).unwrap();
    Simulation::from_resources(&dir.join("resources"))
        .err()
        .map(|e| e.to_string())
}

/// Issue 28, point 7: a scene file whose checksum holds but whose numbers make no body
/// is refused at instantiation by the same physical checks as `pack` runs on a `.fxb`
/// file, each naming the section and the value: P0 a reflection (which every method
/// ran with), P0 = 0, sheared or 3 I; a negative Rayleigh coefficient; K_L indefinite (with its modes solved again, and
/// with the stored modes left as they were); an eigenvalue negative or subnormal in the
/// MODE section; the stored mode shapes scaled by 1e3; m_L = 5e-324; the stored Freq
/// four orders below the modes; on the free beam, the rigid-mode rows zero; on a
/// truncated cantilever, the residual flexibility negated, made asymmetric, or scaled
/// by 1e300; and a scene with no exposed node. Each edit is checked to be accepted
/// before it is applied (the unedited scene instantiates), and one refusal is read
/// through fmi2Instantiate's log as a master sees it.
#[test]
fn a_scene_file_is_checked_like_a_body_at_instantiation() {
    use nalgebra::Matrix3;
    let root = std::env::temp_dir().join(format!("fxbody_scene_physics_{}", std::process::id()));
    let setups = [
        ("cantilever", prepared("cantilever", false)),
        ("freefree", prepared("freefree", false)),
        ("cantilever cut", prepared("cantilever", true)),
    ];
    type Edit = Box<dyn Fn(&mut fxbody::scene::Scene, &mut fxbody::body::BodyParts)>;
    let mut checked = 0;
    for (name, p) in setups {
        let dir = root.join(name.replace(' ', "_"));
        write_resources(&p, &dir);
        let good = std::fs::read(dir.join("resources").join(SCENE_FILE)).unwrap();
        assert!(
            refusal_of(&dir, &good, |_, _| {}).is_none(),
            "{name}: the scene as packed is refused"
        );
        let mut cases: Vec<(&str, Edit, Vec<&str>)> = vec![
            (
                "P0 a reflection",
                Box::new(|_, b| {
                    let mut c = b.p0.column_mut(2);
                    c.neg_mut();
                }),
                vec!["section BODY (initial frame P0 and Freq)", "(a reflection)"],
            ),
            (
                "P0 = 0",
                Box::new(|_, b| b.p0 = Matrix3::zeros()),
                vec![
                    "section BODY",
                    "P0 must be a rotation",
                    "max |P0^T P0 - I| = 1",
                ],
            ),
            (
                "P0 sheared",
                Box::new(|_, b| b.p0[(0, 1)] += 0.1),
                vec!["section BODY", "P0 must be a rotation"],
            ),
            (
                "P0 = 3 I",
                Box::new(|_, b| b.p0 = Matrix3::identity() * 3.0),
                vec!["section BODY", "max |P0^T P0 - I| = 8"],
            ),
            (
                "a negative Rayleigh beta",
                Box::new(|_, b| {
                    b.damping = Some(fxbody::body::Rayleigh {
                        alpha: 0.0,
                        beta: -1e-4,
                    })
                }),
                vec!["section BODY (Rayleigh damping): beta must be >= 0, found beta = -0.0001"],
            ),
            (
                "m_L(1) = 5e-324",
                Box::new(|_, b| b.m_l[0] = 5e-324),
                vec![
                    "section MASS (local mass m_L)",
                    "m_L(1) = 5e-324 is too small",
                ],
            ),
            (
                "the stored mode shapes x 1e3",
                Box::new(|_, b| b.modal.shapes *= 1e3),
                vec!["section", "MODE", "S^T diag(m_L) S - I is"],
            ),
            (
                "a negative eigenvalue in MODE",
                Box::new(|_, b| {
                    let j = b.modal.ascending[0];
                    b.modal.lambda[j] = -b.modal.lambda[j];
                }),
                vec!["MODE", "S^T K_L S - Lambda is"],
            ),
            (
                "a subnormal eigenvalue in MODE",
                Box::new(|_, b| {
                    let j = b.modal.ascending[0];
                    b.modal.lambda[j] = 5e-324;
                }),
                vec!["MODE", "S^T K_L S - Lambda is"],
            ),
            (
                "K_L indefinite, modes left",
                Box::new(|_, b| {
                    let j = b.m_l.len() - 1;
                    b.k_l[(j, j)] = -b.k_l[(j, j)];
                }),
                vec!["MODE", "the stored modes are not the modes of (K_L, m_L)"],
            ),
            (
                "K_L indefinite, modes solved again",
                Box::new(|_, b| {
                    let j = b.m_l.len() - 1;
                    b.k_l[(j, j)] = -b.k_l[(j, j)];
                    b.solve_modes();
                }),
                vec![
                    "section STIF (local stiffness K_L)",
                    "K_L must be positive semi-definite, found the eigenvalue -",
                ],
            ),
            (
                "Freq four orders below the modes",
                Box::new(|_, b| b.freq_file = b.freq_max_hz() * 1e-4),
                vec![
                    "sections MASS and STIF",
                    "times the stored Freq",
                    "(more than 1000)",
                    "corrupt",
                ],
            ),
            (
                "no exposed node",
                Box::new(|s, b| {
                    s.nodes.clear();
                    s.x0.clear();
                    s.residual = None;
                    b.node_ids.clear();
                    b.phi_r = nalgebra::DMatrix::zeros(0, b.phi_r.ncols());
                    b.phi_l = nalgebra::DMatrix::zeros(0, b.phi_l.ncols());
                }),
                vec!["section NODE: no exposed node"],
            ),
        ];
        if name == "freefree" {
            cases.push((
                "rigid-mode rows zero",
                Box::new(|_, b| b.phi_r.fill(0.0)),
                vec!["section PHIR", "rigid mode 10, row 1, is 0, expected 1"],
            ));
        }
        if name == "cantilever cut" {
            use fxbody::scene::reduce::Residual;
            use std::sync::Arc;
            let edit_r = |f: fn(&mut nalgebra::DMatrix<f64>)| -> Edit {
                Box::new(move |s, _| {
                    let old = s.residual.as_ref().unwrap();
                    let mut r = old.r.clone();
                    f(&mut r);
                    s.residual = Some(Arc::new(Residual {
                        r,
                        dropped: old.dropped,
                    }));
                })
            };
            cases.push((
                "residual flexibility negated",
                edit_r(|r| r.neg_mut()),
                vec!["section RESI", "not positive semi-definite: eigenvalue -"],
            ));
            cases.push((
                "residual flexibility asymmetric",
                edit_r(|r| r[(0, 1)] += 0.5 * r.amax()),
                vec!["section RESI", "not symmetric"],
            ));
            cases.push((
                "residual flexibility x 1e300",
                edit_r(|r| *r *= 1e300),
                vec!["section RESI", "absurdly scaled"],
            ));
        }
        for (what, edit, says) in cases {
            let got = refusal_of(&dir, &good, |s, b| edit(s, b))
                .unwrap_or_else(|| panic!("{name}, {what}: accepted"));
            println!("{name}, {what}: {got}");
            for w in says {
                assert!(got.contains(w), "{name}, {what}: '{got}' lacks '{w}'");
            }
            checked += 1;
        }
    }
    assert_eq!(checked, 13 * 3 + 1 + 3);
    // The same refusal through the C ABI, as a master's log shows it.
    let fx = packed("scene_physics_abi");
    let path = fx.dir.join("resources").join(SCENE_FILE);
    let good = std::fs::read(&path).unwrap();
    refusal_of(&fx.dir, &good, |_, b| b.m_l[0] = 5e-324).unwrap();
    let text = refused_log(&fx, "m_L = 5e-324");
    assert!(
        text.starts_with("fmi2Instantiate: ")
            && text.contains("section MASS")
            && text.contains("5e-324"),
        "{text}"
    );
    let _ = std::fs::remove_dir_all(&root);
}
