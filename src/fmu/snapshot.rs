//! FMU state snapshots and their serialised form.
//!
//! Layout (little endian): magic `FXBSTATE`, format version u32, GUID length u32 and
//! bytes, payload length u64, payload, FNV-1a-64 checksum of everything before it. A
//! reader refuses bytes with a wrong magic, version, GUID, length or checksum, each with
//! its own message, so a state from another FMU or a damaged buffer is never loaded.

use super::hash::{FNV_OFFSET, fnv1a64};
use crate::solver::{Method, State};

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
    fn take(&mut self, n: usize) -> Result<&[u8], String> {
        let s = self
            .b
            .get(self.p..self.p.checked_add(n).ok_or("length overflow")?)
            .ok_or_else(|| format!("serialized state truncated at byte {}", self.p))?;
        self.p += n;
        Ok(s)
    }
    fn u32(&mut self) -> Result<u32, String> {
        let s = self.take(4)?;
        Ok(u32::from_le_bytes([s[0], s[1], s[2], s[3]]))
    }
    fn u64(&mut self) -> Result<u64, String> {
        let s = self.take(8)?;
        let mut a = [0; 8];
        a.copy_from_slice(s);
        Ok(u64::from_le_bytes(a))
    }
    fn f64(&mut self) -> Result<f64, String> {
        Ok(f64::from_bits(self.u64()?))
    }
    fn f64s(&mut self) -> Result<Vec<f64>, String> {
        let n = self.u64()? as usize;
        if n > self.b.len() / 8 {
            return Err(format!(
                "serialized state: array length {n} exceeds the buffer"
            ));
        }
        (0..n).map(|_| self.f64()).collect()
    }
    fn v3(&mut self) -> Result<[f64; 3], String> {
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

    /// Read bytes written by [`Snapshot::to_bytes`] for the FMU with `guid`.
    pub fn from_bytes(bytes: &[u8], guid: &str) -> Result<Snapshot, String> {
        if bytes.len() < 8 + 4 + 4 + 8 + 8 || &bytes[..8] != MAGIC {
            return Err("not an fxbody FMU state (wrong magic or too short)".into());
        }
        let body = &bytes[..bytes.len() - 8];
        let mut sum = [0; 8];
        sum.copy_from_slice(&bytes[bytes.len() - 8..]);
        let mut r = Reader { b: body, p: 8 };
        let version = r.u32()?;
        if version != VERSION {
            return Err(format!(
                "FMU state format version {version}, this library reads {VERSION}"
            ));
        }
        let glen = r.u32()? as usize;
        let g = r.take(glen)?;
        if g != guid.as_bytes() {
            return Err(format!(
                "FMU state belongs to GUID {}, this instance is {guid}",
                String::from_utf8_lossy(g)
            ));
        }
        let plen = r.u64()? as usize;
        if r.p.checked_add(plen) != Some(body.len()) {
            return Err(format!(
                "FMU state length mismatch: header says {plen} payload bytes, found {}",
                body.len().saturating_sub(r.p)
            ));
        }
        if fnv1a64(FNV_OFFSET, body) != u64::from_le_bytes(sum) {
            return Err("FMU state checksum mismatch: the bytes are corrupted".into());
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
                    _ => return Err(format!("FMU state: unknown solver method {m}")),
                };
                Some(State {
                    method,
                    data: r.f64s()?,
                })
            }
        };
        if r.p != body.len() {
            return Err("FMU state: trailing bytes after the payload".into());
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
                .contains("GUID")
        );
        let mut c = b.clone();
        let mid = c.len() / 2;
        c[mid] ^= 1;
        assert!(
            Snapshot::from_bytes(&c, "{g}")
                .unwrap_err()
                .contains("checksum")
        );
        assert!(Snapshot::from_bytes(&b[..b.len() - 3], "{g}").is_err());
        assert!(
            Snapshot::from_bytes(b"hello world, not a state at all", "{g}")
                .unwrap_err()
                .contains("magic")
        );
    }
}
