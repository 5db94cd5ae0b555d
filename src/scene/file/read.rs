//! Reading a scene file back: the header checks (magic, byte order, version, length,
//! checksum), then each section in its place, in one pass over the bytes.

use std::path::Path;
use std::sync::Arc;

use nalgebra::{DMatrix, DVector, Matrix3};

use super::{
    BODY_WORDS, BYTE_ORDER_MARK, HEADER_LEN, MAGIC, SECTION_HEADER_LEN, SECTIONS, STIF_DENSE,
    STIF_RADIOSS, SceneFileError, Stored, VERSION, k_l_from_radioss,
};
use crate::body::{Body, BodyParts, Modal, Places, Rayleigh, Support};
use crate::fmu::hash::fnv1a64_words;
use crate::scene::Scene;
use crate::scene::reduce::Residual;

/// Read a scene file: [`from_bytes`] of the file's bytes.
pub fn read(path: &Path) -> Result<Stored, ReadError> {
    let bytes = crate::fxb::input::read_regular(path).map_err(|source| ReadError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    Ok(from_bytes(&bytes, &path.display().to_string())?)
}

/// Why [`read`] failed: the file could not be read, or was refused.
#[derive(Debug, thiserror::Error)]
pub enum ReadError {
    /// The file could not be read.
    #[error("cannot read {}: {source}", .path.display())]
    Io {
        /// The file.
        path: std::path::PathBuf,
        /// The reader's error.
        source: std::io::Error,
    },
    /// The bytes were refused.
    #[error(transparent)]
    Format(#[from] SceneFileError),
}

/// The scene in `bytes` (a scene file's whole content), after checking the header, the
/// checksum, every section's place and length, that the numbers make a body (finite,
/// m_L > 0, the mode order a permutation), and the body's physical checks (`check`: the
/// same as a `.fxb` file's at load); `file` names it in messages.
pub fn from_bytes(bytes: &[u8], file: &str) -> Result<Stored, SceneFileError> {
    let payload = check_header(bytes, file)?;
    let checksum = u64_at(bytes, 24);
    let mut r = Reader {
        rest: payload,
        file,
    };
    let b = r.section(b"BODY", Some(BODY_WORDS))?;
    let count = |k: usize| b.u64(k);
    let (m, nl, nr, nbstat) = (
        r.count(count(0), "BODY", "node count")?,
        r.count(count(1), "BODY", "local mode count")?,
        r.count(count(2), "BODY", "rigid mode count")?,
        r.count(count(3), "BODY", "static mode count")?,
    );
    let flags = count(4);
    if flags >> 5 != 0 {
        return Err(r.bad("BODY", format!("flags {flags:#x}: bits above 4 must be 0")));
    }
    let bit = |k: u32| flags >> k & 1 == 1;
    let stif_kind = count(5);
    let dropped = r.count(count(6), "BODY", "dropped mode count")?;
    let [freq_file, alpha, beta] = [b.f64(7), b.f64(8), b.f64(9)];
    let p0 = Matrix3::from_fn(|i, j| b.f64(10 + 3 * i + j));
    if let Some(v) = (7..BODY_WORDS).map(|k| b.f64(k)).find(|v| !v.is_finite()) {
        return Err(r.bad(
            "BODY",
            format!("value {}: expected finite", crate::num::num(v)),
        ));
    }
    if !bit(3) && (alpha != 0.0 || beta != 0.0) {
        return Err(r.bad(
            "BODY",
            format!(
                "Rayleigh alpha {}, beta {} without the damping flag (bit 3): expected 0 (the physical check of the coefficients runs when the flag is set)",
                crate::num::num(alpha),
                crate::num::num(beta)
            ),
        ));
    }
    if nbstat > nl || ![0, 12, 15].contains(&nr) {
        return Err(r.bad(
            "BODY",
            format!("{nbstat} static of {nl} local modes, {nr} rigid modes (expected 0, 12 or 15)"),
        ));
    }
    let rows = 6 * m;
    let node = r.section(b"NODE", Some(4 * m))?;
    let node_ids: Vec<i64> = (0..m).map(|k| node.u64(k) as i64).collect();
    let x0: Vec<[f64; 3]> = (0..m)
        .map(|k| [0, 1, 2].map(|c| node.f64(m + 3 * k + c)))
        .collect();
    if let Some(v) = x0.iter().flatten().find(|v| !v.is_finite()) {
        return Err(r.bad(
            "NODE",
            format!("coordinate {}: expected finite", crate::num::num(*v)),
        ));
    }
    if let Some(k) = (1..m).find(|&k| node_ids[..k].contains(&node_ids[k])) {
        return Err(r.bad("NODE", format!("node {} is listed twice", node_ids[k])));
    }
    let phi_r = r.matrix(b"PHIR", rows, nr)?;
    let phi_l = r.matrix(b"PHIL", rows, nl)?;
    let m_l = DVector::from_vec(r.section(b"MASS", Some(nl))?.f64s());
    let k_l = match stif_kind {
        STIF_DENSE => r.matrix(b"STIF", nl, nl)?,
        STIF_RADIOSS => {
            let len = nbstat * (2 * nl - nbstat + 1) / 2 + (nl - nbstat);
            k_l_from_radioss(&r.section(b"STIF", Some(len))?.f64s(), nl, nbstat)
        }
        other => {
            return Err(r.bad("BODY", format!("K_L storage {other}: expected 0 or 1")));
        }
    };
    let m_r = r.matrix(b"MRIG", nr, nr)?;
    let m_c = r.blocks(b"MCPL", nr, nl)?;
    let k_c = r.blocks(b"KCPL", nr, nl)?;
    let mode = r.section(b"MODE", Some(nl * (nl + 2)))?;
    let lambda = DVector::from_fn(nl, |j, _| mode.f64(j));
    let shapes = DMatrix::from_fn(nl, nl, |i, j| mode.f64(nl + j * nl + i));
    let ascending: Vec<usize> = (0..nl)
        .map(|j| mode.u64(nl + nl * nl + j) as usize)
        .collect();
    let mut seen = vec![false; nl];
    for &j in &ascending {
        if j >= nl || std::mem::replace(&mut seen[j], true) {
            return Err(r.bad(
                "MODE",
                format!("mode order: {j} is not a free index below {nl}"),
            ));
        }
    }
    let residual = if bit(4) {
        Some(Arc::new(Residual {
            r: r.matrix(b"RESI", rows, rows)?,
            dropped,
        }))
    } else {
        r.section(b"RESI", Some(0))?;
        None
    };
    let modal = Modal {
        lambda,
        shapes,
        ascending,
    };
    let support = Support::from_iblo(bit(1));
    if nr != support.rigid_modes(bit(0)) {
        return Err(r.bad(
            "BODY",
            format!(
                "blocked flag {} and rotation flag {} with {nr} rigid modes: expected {}",
                u8::from(bit(1)),
                u8::from(bit(0)),
                support.rigid_modes(bit(0))
            ),
        ));
    }
    let parts = BodyParts {
        node_ids,
        nbstat,
        irot: bit(0),
        support,
        ifile: bit(2),
        p0,
        freq_file,
        damping: bit(3).then_some(Rayleigh { alpha, beta }),
        phi_r,
        phi_l,
        m_l,
        k_l,
        m_r,
        m_c,
        k_c,
        modal,
    };
    let body = Body::from_parts_at(parts, file, &Places::SCENE)
        .map_err(|e| SceneFileError::Physics(e.to_string()))?;
    let mut scene = Scene::new(Arc::new(body), (0..m).collect(), x0);
    scene.residual = residual;
    super::check::check_scene(&scene, file)?;
    Ok(Stored { scene, checksum })
}

/// The payload after checking the header: magic, byte order, version, length, checksum.
fn check_header<'a>(bytes: &'a [u8], file: &str) -> Result<&'a [u8], SceneFileError> {
    let file = file.to_string();
    if bytes.len() < HEADER_LEN {
        // A file too short to hold the magic is no scene file of ours in any version.
        if bytes.len() < MAGIC.len() || bytes[..MAGIC.len()] != MAGIC {
            return Err(SceneFileError::Magic {
                file,
                found: bytes[..bytes.len().min(8)].escape_ascii().to_string(),
            });
        }
        return Err(SceneFileError::Truncated {
            file,
            what: "header",
            expected: HEADER_LEN as u64,
            found: bytes.len() as u64,
        });
    }
    if bytes[..8] != MAGIC {
        return Err(SceneFileError::Magic {
            file,
            found: bytes[..8].escape_ascii().to_string(),
        });
    }
    let mark = u32::from_le_bytes([bytes[8], bytes[9], bytes[10], bytes[11]]);
    if mark != BYTE_ORDER_MARK {
        return Err(SceneFileError::ByteOrder { file, found: mark });
    }
    let version = u32::from_le_bytes([bytes[12], bytes[13], bytes[14], bytes[15]]);
    if version != VERSION {
        return Err(SceneFileError::Version {
            file,
            found: version,
        });
    }
    let stated = u64_at(bytes, 16);
    let present = (bytes.len() - HEADER_LEN) as u64;
    if present < stated {
        return Err(SceneFileError::Truncated {
            file,
            what: "payload",
            expected: stated + HEADER_LEN as u64,
            found: bytes.len() as u64,
        });
    }
    if present > stated || !stated.is_multiple_of(8) {
        return Err(SceneFileError::Length {
            file,
            what: format!(
                "the header states a payload of {stated} bytes (whole 8-byte words), the file holds {present} after the header"
            ),
        });
    }
    let payload = &bytes[HEADER_LEN..];
    let (stored, computed) = (u64_at(bytes, 24), fnv1a64_words(payload));
    if stored != computed {
        return Err(SceneFileError::Checksum {
            file,
            stored,
            computed,
        });
    }
    Ok(payload)
}

/// The payload checksum a scene file's header states (0 for bytes too short to hold
/// one); [`from_bytes`] checks it against the payload.
pub fn checksum_of(bytes: &[u8]) -> u64 {
    if bytes.len() < HEADER_LEN {
        return 0;
    }
    u64_at(bytes, 24)
}

fn u64_at(bytes: &[u8], at: usize) -> u64 {
    let mut b = [0u8; 8];
    b.copy_from_slice(&bytes[at..at + 8]);
    u64::from_le_bytes(b)
}

/// The sections not yet read.
struct Reader<'a> {
    rest: &'a [u8],
    file: &'a str,
}

/// One section's data, whole 8-byte words.
struct Words<'a>(&'a [u8]);

impl Words<'_> {
    fn u64(&self, k: usize) -> u64 {
        u64_at(self.0, 8 * k)
    }
    fn f64(&self, k: usize) -> f64 {
        f64::from_bits(self.u64(k))
    }
    fn f64s(&self) -> Vec<f64> {
        (0..self.0.len() / 8).map(|k| self.f64(k)).collect()
    }
}

impl<'a> Reader<'a> {
    fn bad(&self, section: &str, what: String) -> SceneFileError {
        SceneFileError::Section {
            file: self.file.to_string(),
            section: section.to_string(),
            what,
        }
    }

    /// A count small enough to size a matrix of this file (no count can exceed the
    /// payload's word count).
    fn count(&self, v: u64, section: &str, what: &str) -> Result<usize, SceneFileError> {
        let limit = (self.rest.len() / 8) as u64 + 16;
        if v > limit {
            return Err(self.bad(
                section,
                format!("{what} {v}: more than the file could hold ({limit})"),
            ));
        }
        Ok(v as usize)
    }

    /// The next section, which must be `tag` with `words` words when given; its values
    /// are checked finite (every section holds finite numbers or counts).
    fn section(
        &mut self,
        tag: &[u8; 4],
        words: Option<usize>,
    ) -> Result<Words<'a>, SceneFileError> {
        let name = String::from_utf8_lossy(tag).into_owned();
        if self.rest.len() < SECTION_HEADER_LEN {
            return Err(self.bad(
                &name,
                format!(
                    "missing: the payload ends {} bytes before this section's header",
                    SECTION_HEADER_LEN - self.rest.len()
                ),
            ));
        }
        let (head, rest) = self.rest.split_at(SECTION_HEADER_LEN);
        if &head[..4] != tag || head[4..8] != [0; 4] {
            return Err(self.bad(
                &name,
                format!(
                    "expected here (sections in the order {}), found '{}'",
                    SECTIONS
                        .map(|t| String::from_utf8_lossy(t).into_owned())
                        .join(" "),
                    head[..8].escape_ascii()
                ),
            ));
        }
        let len = u64_at(head, 8);
        let want = words.map(|w| 8 * w as u64);
        if want.is_some_and(|w| w != len) || !len.is_multiple_of(8) || len > rest.len() as u64 {
            return Err(self.bad(
                &name,
                format!(
                    "{len} bytes, expected {} ({} left in the payload)",
                    want.map_or("whole 8-byte words".to_string(), |w| w.to_string()),
                    rest.len()
                ),
            ));
        }
        let (data, rest) = rest.split_at(len as usize);
        self.rest = rest;
        let words = Words(data);
        // BODY and NODE hold integers beside their numbers: checked where read.
        if tag != b"BODY"
            && tag != b"NODE"
            && let Some(k) = (0..data.len() / 8).find(|&k| !words.f64(k).is_finite())
        {
            return Err(self.bad(
                &name,
                format!(
                    "value {k} is {}: expected finite",
                    crate::num::num(words.f64(k))
                ),
            ));
        }
        Ok(words)
    }

    /// A `rows x cols` matrix stored column by column in section `tag`.
    fn matrix(
        &mut self,
        tag: &[u8; 4],
        rows: usize,
        cols: usize,
    ) -> Result<DMatrix<f64>, SceneFileError> {
        let s = self.section(tag, Some(rows * cols))?;
        Ok(DMatrix::from_vec(rows, cols, s.f64s()))
    }

    /// Nine `rows x cols` blocks one after the other in section `tag`.
    fn blocks(
        &mut self,
        tag: &[u8; 4],
        rows: usize,
        cols: usize,
    ) -> Result<Vec<DMatrix<f64>>, SceneFileError> {
        let n = rows * cols;
        let s = self.section(tag, Some(9 * n))?.f64s();
        Ok((0..9)
            .map(|b| DMatrix::from_column_slice(rows, cols, &s[b * n..(b + 1) * n]))
            .collect())
    }
}
