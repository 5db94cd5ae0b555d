//! The scene file (`resources/scene.fxs`): what one scene's solver needs, and nothing
//! more, in a binary format of our own that the FMU reads in one pass at instantiation.
//!
//! A packed scene is its body restricted to the exposed nodes ([`select_nodes`]: their
//! rows of the rigid and local modes, every mode-space matrix whole), the modes kept by
//! `--fmax` with their residual flexibility, the exposed nodes' coordinates, and the
//! modes of (K_L, m_L) as the body already solved them ([`crate::body::Modal`]), so
//! that the FMU neither parses the `.fxb` text nor solves an eigenproblem, and runs bit
//! for bit what a scene built from the `.fxb` file runs. docs/SCENE_FORMAT.md describes
//! every byte:
//! a 32-byte header (magic, byte-order mark, version, payload length, checksum), then
//! eleven sections in a fixed order, each a 16-byte header (tag, length) and its data,
//! all little-endian, all 8-byte words. Every refusal names the file and what was
//! expected.

use nalgebra::DMatrix;

use crate::body::BodyParts;
use crate::fmu::hash::fnv1a64_words;
use crate::scene::Scene;
use crate::scene::reduce::{Residual, select_nodes};

/// The first eight bytes of every scene file.
pub const MAGIC: [u8; 8] = *b"FXBSCENE";
/// The format version this build writes and reads.
pub const VERSION: u32 = 1;
/// The byte-order mark: this value written little-endian (bytes `04 03 02 01`).
pub const BYTE_ORDER_MARK: u32 = 0x0102_0304;
/// Bytes of the file header.
pub const HEADER_LEN: usize = 32;
/// Bytes of a section header (tag, 4 zero bytes, data length).
pub const SECTION_HEADER_LEN: usize = 16;
/// The sections, in file order.
pub const SECTIONS: [&[u8; 4]; 11] = [
    b"BODY", b"NODE", b"PHIR", b"PHIL", b"MASS", b"STIF", b"MRIG", b"MCPL", b"KCPL", b"MODE",
    b"RESI",
];
/// Words of the BODY section.
const BODY_WORDS: usize = 19;
/// K_L stored dense, all `nL x nL` values column by column.
const STIF_DENSE: u64 = 0;
/// K_L stored as the `.fxb` file stores it: the `nbstat` static rows from the diagonal
/// on, then the diagonal of the rest (every other entry is zero).
const STIF_RADIOSS: u64 = 1;

/// Why a scene file was refused; each names the file.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum SceneFileError {
    /// Shorter than its header, or than the payload length the header states.
    #[error(
        "{file}: truncated: {found} bytes, the {what} needs {expected}; the FMU's resources are incomplete: pack it again"
    )]
    Truncated {
        /// The file.
        file: String,
        /// "header" or "payload".
        what: &'static str,
        /// Bytes needed.
        expected: u64,
        /// Bytes present.
        found: u64,
    },
    /// Not a scene file.
    #[error("{file}: not an fxbody scene file: expected the magic 'FXBSCENE', found {found:?}")]
    Magic {
        /// The file.
        file: String,
        /// The first eight bytes, escaped.
        found: String,
    },
    /// Written big-endian (the mark reads byte-swapped) or the mark is damaged.
    #[error(
        "{file}: byte-order mark {found:#010x}: expected {BYTE_ORDER_MARK:#010x} (little-endian){}",
        if *.found == BYTE_ORDER_MARK.swap_bytes() { "; this file was written big-endian, which this format does not allow" } else { "; the header is damaged" }
    )]
    ByteOrder {
        /// The file.
        file: String,
        /// The mark as read little-endian.
        found: u32,
    },
    /// Another format version.
    #[error(
        "{file}: scene format version {found}: this FMU reads version {VERSION} only; pack the body again with this fxbody"
    )]
    Version {
        /// The file.
        file: String,
        /// The version found.
        found: u32,
    },
    /// Bytes after the stated payload, or a payload that is not whole words.
    #[error("{file}: {what}")]
    Length {
        /// The file.
        file: String,
        /// What is wrong, with the figures.
        what: String,
    },
    /// The payload's checksum differs from the header's.
    #[error(
        "{file}: checksum mismatch: the header says {stored:#018x}, the payload gives {computed:#018x}; the file is corrupt: pack the FMU again"
    )]
    Checksum {
        /// The file.
        file: String,
        /// Checksum in the header.
        stored: u64,
        /// Checksum of the payload.
        computed: u64,
    },
    /// A body whose numbers fail a physical check (the same as a `.fxb` file's at load);
    /// the message names the file, the section and the value.
    #[error("{0}")]
    Physics(String),
    /// A section out of place, of the wrong length, or with values no body has (a file
    /// whose checksum holds but that was not written by `pack`).
    #[error("{file}: section {section}: {what}")]
    Section {
        /// The file.
        file: String,
        /// The section tag.
        section: String,
        /// What is wrong, with the figures.
        what: String,
    },
}

/// A scene read back from its file.
#[derive(Debug, Clone)]
pub struct Stored {
    /// The scene: a body of the exposed nodes only, `nodes = 0..m`.
    pub scene: Scene,
    /// The payload checksum (it identifies the content: the GUID is derived from it).
    pub checksum: u64,
}

/// The bytes of the scene file for `scene` (a scene of any body: only its exposed
/// nodes' rows are written).
pub fn to_bytes(scene: &Scene) -> Vec<u8> {
    let body = select_nodes(&scene.body, &scene.nodes).into_parts();
    parts_to_bytes(&body, &scene.x0, scene.residual.as_deref())
}

/// The bytes of a scene file holding `body` as given (every node of it, at `x0`) and the
/// residual flexibility `residual`: written as they are, unchecked, which is what a test
/// of the reader's checks needs; the reader checks them ([`from_bytes`]).
pub fn parts_to_bytes(body: &BodyParts, x0: &[[f64; 3]], residual: Option<&Residual>) -> Vec<u8> {
    let (m, nl, nr) = (body.node_ids.len(), body.m_l.len(), body.phi_r.ncols());
    let mut w = Writer::default();
    let stif = stif_radioss(&body.k_l, body.nbstat);
    let flags = u64::from(body.irot)
        | u64::from(body.support.iblo()) << 1
        | u64::from(body.ifile) << 2
        | u64::from(body.damping.is_some()) << 3
        | u64::from(residual.is_some()) << 4;
    let damping = body.damping.unwrap_or_default();
    w.section(b"BODY", |s| {
        for v in [m, nl, nr, body.nbstat] {
            s.u64(v as u64);
        }
        s.u64(flags);
        s.u64(if stif.is_some() {
            STIF_RADIOSS
        } else {
            STIF_DENSE
        });
        s.u64(residual.map_or(0, |r| r.dropped as u64));
        s.f64s(&[body.freq_file, damping.alpha, damping.beta]);
        for r in 0..3 {
            for c in 0..3 {
                s.f64(body.p0[(r, c)]);
            }
        }
    });
    w.section(b"NODE", |s| {
        body.node_ids.iter().for_each(|&id| s.u64(id as u64));
        x0.iter().for_each(|x| s.f64s(x));
    });
    w.section(b"PHIR", |s| s.f64s(body.phi_r.as_slice()));
    w.section(b"PHIL", |s| s.f64s(body.phi_l.as_slice()));
    w.section(b"MASS", |s| s.f64s(body.m_l.as_slice()));
    w.section(b"STIF", |s| match &stif {
        Some(v) => s.f64s(v),
        None => s.f64s(body.k_l.as_slice()),
    });
    w.section(b"MRIG", |s| s.f64s(body.m_r.as_slice()));
    w.section(b"MCPL", |s| {
        body.m_c.iter().for_each(|b| s.f64s(b.as_slice()))
    });
    w.section(b"KCPL", |s| {
        body.k_c.iter().for_each(|b| s.f64s(b.as_slice()))
    });
    w.section(b"MODE", |s| {
        s.f64s(body.modal.lambda.as_slice());
        s.f64s(body.modal.shapes.as_slice());
        body.modal.ascending.iter().for_each(|&j| s.u64(j as u64));
    });
    w.section(b"RESI", |s| {
        if let Some(r) = residual {
            s.f64s(r.r.as_slice());
        }
    });
    let payload = w.0;
    let mut out = Vec::with_capacity(HEADER_LEN + payload.len());
    out.extend_from_slice(&MAGIC);
    out.extend_from_slice(&BYTE_ORDER_MARK.to_le_bytes());
    out.extend_from_slice(&VERSION.to_le_bytes());
    out.extend_from_slice(&(payload.len() as u64).to_le_bytes());
    out.extend_from_slice(&fnv1a64_words(&payload).to_le_bytes());
    out.extend_from_slice(&payload);
    out
}

/// K_L in the `.fxb` storage (static rows from the diagonal on, then the diagonal), when
/// that storage gives back every bit of it; `None` otherwise (then it is stored dense).
fn stif_radioss(k_l: &DMatrix<f64>, nbstat: usize) -> Option<Vec<f64>> {
    let (nl, ns) = (k_l.nrows(), nbstat.min(k_l.nrows()));
    let mut v = Vec::new();
    for r in 0..ns {
        v.extend((r..nl).map(|c| k_l[(r, c)]));
    }
    v.extend((ns..nl).map(|r| k_l[(r, r)]));
    let back = k_l_from_radioss(&v, nl, ns);
    let same = back
        .iter()
        .zip(k_l.iter())
        .all(|(a, b)| a.to_bits() == b.to_bits());
    same.then_some(v)
}

/// The symmetric K_L from its `.fxb` storage (as [`Body::from_fxb`] builds it).
fn k_l_from_radioss(v: &[f64], nl: usize, ns: usize) -> DMatrix<f64> {
    let mut k = DMatrix::zeros(nl, nl);
    let mut i = 0;
    for r in 0..ns {
        for c in r..nl {
            k[(r, c)] = v[i];
            k[(c, r)] = v[i];
            i += 1;
        }
    }
    for r in ns..nl {
        k[(r, r)] = v[i];
        i += 1;
    }
    k
}

/// The section payload being written.
#[derive(Default)]
struct Writer(Vec<u8>);

impl Writer {
    fn section(&mut self, tag: &[u8; 4], fill: impl FnOnce(&mut Writer)) {
        let mut s = Writer::default();
        fill(&mut s);
        self.0.extend_from_slice(tag);
        self.0.extend_from_slice(&[0; 4]);
        self.0.extend_from_slice(&(s.0.len() as u64).to_le_bytes());
        self.0.extend_from_slice(&s.0);
    }
    fn u64(&mut self, v: u64) {
        self.0.extend_from_slice(&v.to_le_bytes());
    }
    fn f64(&mut self, v: f64) {
        self.0.extend_from_slice(&v.to_le_bytes());
    }
    fn f64s(&mut self, v: &[f64]) {
        self.0.reserve(8 * v.len());
        v.iter().for_each(|&x| self.f64(x));
    }
}

mod check;
mod read;

pub use read::{ReadError, checksum_of, from_bytes, read};
