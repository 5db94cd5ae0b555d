//! FMU state snapshots and their serialised form.
//!
//! Layout (little endian): magic `FXBSTATE`, format version u32, GUID length u32 and
//! bytes, payload length u64, payload, FNV-1a-64 checksum of everything before it. A
//! reader refuses bytes with a wrong magic, version, GUID, length or checksum, each with
//! its own message, so a state from another FMU or a damaged buffer is never loaded.

use super::hash::{FNV_OFFSET, fnv1a64};
use crate::num::num;
use crate::solver::{Method, State};

/// Why saved-state bytes or a decoded snapshot were refused.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SnapshotError {
    /// Too short to be a state, or another magic number.
    #[error("not an fxbody FMU state (wrong magic or too short)")]
    NotAState,
    /// Another format version.
    #[error("FMU state format version {0}, this library reads {VERSION}")]
    Version(u32),
    /// A state saved by another FMU.
    #[error("FMU state belongs to GUID {found}, this instance is {expected}")]
    Guid {
        /// The GUID in the bytes (lossily decoded).
        found: String,
        /// This instance's GUID.
        expected: String,
    },
    /// The payload length in the header is not the payload's.
    #[error("FMU state length mismatch: header says {header} payload bytes, found {found}")]
    Length {
        /// What the header says.
        header: usize,
        /// What there is.
        found: usize,
    },
    /// The checksum does not match.
    #[error("FMU state checksum mismatch: the bytes are corrupted")]
    Checksum,
    /// A field runs past the end of the bytes.
    #[error("serialized state truncated at byte {0}")]
    Truncated(usize),
    /// A length so large it overflows.
    #[error("serialized state: length overflow at byte {0}")]
    LengthOverflow(usize),
    /// An array length larger than the bytes could hold.
    #[error("serialized state: array length {0} exceeds the buffer")]
    ArrayTooLong(usize),
    /// A solver method code this library does not know.
    #[error("FMU state: unknown solver method {0}")]
    UnknownMethod(u32),
    /// Bytes after the payload.
    #[error("FMU state: trailing bytes after the payload")]
    Trailing,
    /// A decoded number no running model can hold.
    #[error("saved state: {0} holds a non-finite number")]
    NonFinite(&'static str),
    /// rho_inf outside [0, 1].
    #[error("saved state: rho_inf {} is not in [0, 1]", num(*.0))]
    RhoInf(f64),
    /// stopTime before startTime (or NaN).
    #[error("saved state: stopTime {} is before startTime {}", num(*.stop), num(*.start))]
    StopBeforeStart {
        /// stopTime.
        stop: f64,
        /// startTime.
        start: f64,
    },
}

const MAGIC: &[u8; 8] = b"FXBSTATE";
const VERSION: u32 = 1;

/// Everything that defines an instance's future: FMI phase, parameters, inputs and the
/// complete solver state.
#[derive(Debug, Clone, PartialEq)]
pub struct Snapshot {
    /// The FMI layer's state code.
    pub phase: u8,
    /// Method enumeration value.
    pub method: i32,
    /// rho_inf.
    pub rho_inf: f64,
    /// Gravity.
    pub gravity: [f64; 3],
    /// Initial velocity.
    pub v0: [f64; 3],
    /// Initial angular velocity.
    pub w0: [f64; 3],
    /// Start time.
    pub start_time: f64,
    /// Stop time, if defined.
    pub stop_time: Option<f64>,
    /// Current time.
    pub time: f64,
    /// Current loads (6 per exposed node).
    pub loads: Vec<f64>,
    /// Current input rates.
    pub rates: Vec<f64>,
    /// The solver's state, when a solver was built.
    pub solver: Option<State>,
}

struct Writer(Vec<u8>);

impl Writer {
    fn u32(&mut self, v: u32) {
        self.0.extend_from_slice(&v.to_le_bytes());
    }
    fn u64(&mut self, v: u64) {
        self.0.extend_from_slice(&v.to_le_bytes());
    }
    fn f64(&mut self, v: f64) {
        self.0.extend_from_slice(&v.to_bits().to_le_bytes());
    }
    fn f64s(&mut self, v: &[f64]) {
        self.u64(v.len() as u64);
        v.iter().for_each(|&x| self.f64(x));
    }
}

struct Reader<'a> {
    b: &'a [u8],
    p: usize,
}

impl Reader<'_> {
    fn take(&mut self, n: usize) -> Result<&[u8], SnapshotError> {
        let end = self
            .p
            .checked_add(n)
            .ok_or(SnapshotError::LengthOverflow(self.p))?;
        let s = self
            .b
            .get(self.p..end)
            .ok_or(SnapshotError::Truncated(self.p))?;
        self.p += n;
        Ok(s)
    }
    fn u32(&mut self) -> Result<u32, SnapshotError> {
        let s = self.take(4)?;
        Ok(u32::from_le_bytes([s[0], s[1], s[2], s[3]]))
    }
    fn u64(&mut self) -> Result<u64, SnapshotError> {
        let s = self.take(8)?;
        let mut a = [0; 8];
        a.copy_from_slice(s);
        Ok(u64::from_le_bytes(a))
    }
    fn f64(&mut self) -> Result<f64, SnapshotError> {
        Ok(f64::from_bits(self.u64()?))
    }
    fn f64s(&mut self) -> Result<Vec<f64>, SnapshotError> {
        let n = self.u64()? as usize;
        if n > self.b.len() / 8 {
            return Err(SnapshotError::ArrayTooLong(n));
        }
        (0..n).map(|_| self.f64()).collect()
    }
    fn v3(&mut self) -> Result<[f64; 3], SnapshotError> {
        Ok([self.f64()?, self.f64()?, self.f64()?])
    }
}

impl Snapshot {
    /// Serialise for an FMU with `guid`.
    pub fn to_bytes(&self, guid: &str) -> Vec<u8> {
        let mut p = Writer(Vec::new());
        p.u32(u32::from(self.phase));
        p.u32(self.method as u32);
        p.f64(self.rho_inf);
        self.gravity
            .iter()
            .chain(&self.v0)
            .chain(&self.w0)
            .for_each(|&x| p.f64(x));
        p.f64(self.start_time);
        p.u32(u32::from(self.stop_time.is_some()));
        p.f64(self.stop_time.unwrap_or(0.0));
        p.f64(self.time);
        p.f64s(&self.loads);
        p.f64s(&self.rates);
        match &self.solver {
            Some(s) => {
                p.u32(s.method as u32);
                p.f64s(&s.data);
            }
            None => p.u32(0),
        }
        let mut w = Writer(Vec::with_capacity(p.0.len() + 64));
        w.0.extend_from_slice(MAGIC);
        w.u32(VERSION);
        w.u32(guid.len() as u32);
        w.0.extend_from_slice(guid.as_bytes());
        w.u64(p.0.len() as u64);
        w.0.extend_from_slice(&p.0);
        let sum = fnv1a64(FNV_OFFSET, &w.0);
        w.u64(sum);
        w.0
    }

    /// Refuse a snapshot whose numbers no running model can hold (only reachable with
    /// hand-made bytes: the checksum stops accidental damage).
    pub fn check(&self) -> Result<(), SnapshotError> {
        let finite = |what, v: &[f64]| {
            if v.iter().all(|x| x.is_finite()) {
                Ok(())
            } else {
                Err(SnapshotError::NonFinite(what))
            }
        };
        finite("time", &[self.time, self.start_time])?;
        finite(
            "gravity, v0, w0",
            &[self.gravity, self.v0, self.w0].concat(),
        )?;
        finite("loads", &self.loads)?;
        finite("input rates", &self.rates)?;
        if !(0.0..=1.0).contains(&self.rho_inf) {
            return Err(SnapshotError::RhoInf(self.rho_inf));
        }
        if let Some(stop) = self.stop_time
            && (stop.is_nan() || stop < self.start_time)
        {
            return Err(SnapshotError::StopBeforeStart {
                stop,
                start: self.start_time,
            });
        }
        Ok(())
    }

    /// Read bytes written by [`Snapshot::to_bytes`] for the FMU with `guid`.
    pub fn from_bytes(bytes: &[u8], guid: &str) -> Result<Snapshot, SnapshotError> {
        if bytes.len() < 8 + 4 + 4 + 8 + 8 || &bytes[..8] != MAGIC {
            return Err(SnapshotError::NotAState);
        }
        let body = &bytes[..bytes.len() - 8];
        let mut sum = [0; 8];
        sum.copy_from_slice(&bytes[bytes.len() - 8..]);
        let mut r = Reader { b: body, p: 8 };
        let version = r.u32()?;
        if version != VERSION {
            return Err(SnapshotError::Version(version));
        }
        let glen = r.u32()? as usize;
        let g = r.take(glen)?;
        if g != guid.as_bytes() {
            return Err(SnapshotError::Guid {
                found: String::from_utf8_lossy(g).into_owned(),
                expected: guid.to_string(),
            });
        }
        let plen = r.u64()? as usize;
        if r.p.checked_add(plen) != Some(body.len()) {
            return Err(SnapshotError::Length {
                header: plen,
                found: body.len().saturating_sub(r.p),
            });
        }
        if fnv1a64(FNV_OFFSET, body) != u64::from_le_bytes(sum) {
            return Err(SnapshotError::Checksum);
        }
        let phase = r.u32()? as u8;
        let method = r.u32()? as i32;
        let rho_inf = r.f64()?;
        let gravity = r.v3()?;
        let v0 = r.v3()?;
        let w0 = r.v3()?;
        let start_time = r.f64()?;
        let has_stop = r.u32()? != 0;
        let stop = r.f64()?;
        let time = r.f64()?;
        let loads = r.f64s()?;
        let rates = r.f64s()?;
        let solver = match r.u32()? {
            0 => None,
            m => {
                let method = match m {
                    1 => Method::Explicit,
                    2 => Method::Implicit,
                    3 => Method::Exact,
                    4 => Method::Split,
                    _ => return Err(SnapshotError::UnknownMethod(m)),
                };
                Some(State {
                    method,
                    data: r.f64s()?,
                })
            }
        };
        if r.p != body.len() {
            return Err(SnapshotError::Trailing);
        }
        Ok(Snapshot {
            phase,
            method,
            rho_inf,
            gravity,
            v0,
            w0,
            start_time,
            stop_time: has_stop.then_some(stop),
            time,
            loads,
            rates,
            solver,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> Snapshot {
        Snapshot {
            phase: 3,
            method: 3,
            rho_inf: 0.8,
            gravity: [0.0, -9.81, 0.0],
            v0: [1.0, 2.0, 3.0],
            w0: [0.1, 0.2, 0.3],
            start_time: 0.0,
            stop_time: Some(2.0),
            time: 0.125,
            loads: vec![1.0, -2.5, f64::MIN_POSITIVE],
            rates: vec![0.0, 1e300, -0.0],
            solver: Some(State {
                method: Method::Exact,
                data: vec![1.0 / 3.0, -7.0],
            }),
        }
    }

    #[test]
    fn round_trip_is_bit_exact() {
        let s = sample();
        let b = s.to_bytes("{g}");
        let back = Snapshot::from_bytes(&b, "{g}").unwrap();
        assert_eq!(back, s);
        assert_eq!(back.rates[2].to_bits(), (-0.0f64).to_bits());
    }

    #[test]
    fn foreign_or_damaged_bytes_are_refused() {
        let b = sample().to_bytes("{g}");
        assert!(
            Snapshot::from_bytes(&b, "{h}")
                .unwrap_err()
                .to_string()
                .contains("GUID")
        );
        let mut c = b.clone();
        let mid = c.len() / 2;
        c[mid] ^= 1;
        assert!(
            Snapshot::from_bytes(&c, "{g}")
                .unwrap_err()
                .to_string()
                .contains("checksum")
        );
        assert!(Snapshot::from_bytes(&b[..b.len() - 3], "{g}").is_err());
        assert!(
            Snapshot::from_bytes(b"hello world, not a state at all", "{g}")
                .unwrap_err()
                .to_string()
                .contains("magic")
        );
    }
}
