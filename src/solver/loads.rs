//! The caller's load model, one for every solver: per exposed node six values (fx fy fz mx
//! my mz, global frame) held from the time `t_set` they were set, plus rates, so that the
//! load at time t is `values + rates (t - t_set)`. The blocked methods project it onto
//! their modes ([`super::nodes::Exposed`]), the free methods onto the moving frame
//! (`free::FreeScene::project_loads`) and the residual correction multiplies it by the
//! dropped modes' flexibility; all three read the same held value and rate from here.
//! Sized at build time: nothing here allocates after [`Loads::new`].

use super::SolverError;

/// Check loads or rates given by the caller: `n` values (6 per exposed node), all
/// finite. `what` names them in the message. The one check every solver makes before
/// taking a load.
pub fn check(what: &'static str, v: &[f64], n: usize) -> Result<(), SolverError> {
    if v.len() != n {
        return Err(SolverError::BadLength {
            what,
            expected: n,
            found: v.len(),
        });
    }
    if v.iter().any(|x| !x.is_finite()) {
        return Err(SolverError::BadInput(super::BadInput::NotFinite(what)));
    }
    Ok(())
}

/// Held nodal loads with rates (see the module notes).
#[derive(Debug, Clone)]
pub struct Loads {
    /// Values at `t_set`, 6 per exposed node.
    pub values: Vec<f64>,
    /// Rates (per second), 6 per exposed node; zeros mean held loads.
    pub rates: Vec<f64>,
    /// Time at which `values` holds.
    pub t_set: f64,
}

impl Loads {
    /// `n` zero loads and rates, set at time 0.
    pub fn new(n: usize) -> Loads {
        Loads {
            values: vec![0.0; n],
            rates: vec![0.0; n],
            t_set: 0.0,
        }
    }

    /// Number of load components.
    pub fn len(&self) -> usize {
        self.values.len()
    }

    /// Whether there are no load components (no exposed node).
    pub fn is_empty(&self) -> bool {
        self.values.is_empty()
    }

    /// Load component `i` at time `t`.
    #[inline]
    pub fn at(&self, i: usize, t: f64) -> f64 {
        self.values[i] + self.rates[i] * (t - self.t_set)
    }

    /// New values holding from time `t`; the rates are kept. `values` has been checked
    /// for length and finiteness.
    pub fn set(&mut self, values: &[f64], t: f64) {
        self.values.copy_from_slice(values);
        self.t_set = t;
    }

    /// New rates from time `t`, keeping the load continuous: the values are re-anchored
    /// at `t` first. `rates` has been checked for length and finiteness.
    pub fn set_rates(&mut self, rates: &[f64], t: f64) {
        for i in 0..rates.len() {
            self.values[i] = self.at(i, t);
        }
        self.t_set = t;
        self.rates.copy_from_slice(rates);
    }

    /// Take the values, rates and time of `other` (same length), without allocating.
    pub fn copy_from(&mut self, other: &Loads) {
        self.values.copy_from_slice(&other.values);
        self.rates.copy_from_slice(&other.rates);
        self.t_set = other.t_set;
    }

    /// Number of state values (either layout).
    pub fn state_len(&self) -> usize {
        2 * self.values.len() + 1
    }

    /// Push into a state vector: values, rates, `t_set` (the free solvers' layout).
    pub fn save(&self, out: &mut Vec<f64>) {
        out.extend_from_slice(&self.values);
        out.extend_from_slice(&self.rates);
        out.push(self.t_set);
    }

    /// Read back what [`Loads::save`] wrote (length already checked).
    pub fn load(&mut self, data: &[f64]) {
        let n = self.values.len();
        self.values.copy_from_slice(&data[..n]);
        self.rates.copy_from_slice(&data[n..2 * n]);
        self.t_set = data[2 * n];
    }

    /// Push into a state vector: `t_set`, values, rates (the blocked solvers' and the
    /// residual correction's layout, which saved states and tests index).
    pub fn save_time_first(&self, out: &mut Vec<f64>) {
        out.push(self.t_set);
        out.extend_from_slice(&self.values);
        out.extend_from_slice(&self.rates);
    }

    /// Read back what [`Loads::save_time_first`] wrote (length already checked).
    pub fn load_time_first(&mut self, data: &[f64]) {
        let n = self.values.len();
        self.t_set = data[0];
        self.values.copy_from_slice(&data[1..1 + n]);
        self.rates.copy_from_slice(&data[1 + n..1 + 2 * n]);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A ramp set at t = 1 and re-rated at t = 3 stays continuous and linear (values
    /// checked against the hand-computed ramp).
    #[test]
    fn rates_keep_the_load_continuous() {
        let mut l = Loads::new(2);
        l.set(&[1.0, -2.0], 1.0);
        l.set_rates(&[0.5, 0.25], 1.0);
        assert_eq!(l.at(0, 3.0), 2.0);
        assert_eq!(l.at(1, 3.0), -1.5);
        l.set_rates(&[-1.0, 0.0], 3.0);
        assert_eq!((l.values[0], l.values[1], l.t_set), (2.0, -1.5, 3.0));
        assert_eq!(l.at(0, 4.0), 1.0);
        assert_eq!(l.at(1, 10.0), -1.5);
        // A new value keeps the rates.
        l.set(&[0.0, 0.0], 4.0);
        assert_eq!(l.at(0, 5.0), -1.0);
    }

    /// Wrong length and non-finite values are refused with the cause named.
    #[test]
    fn check_names_the_cause() {
        assert!(check("loads", &[0.0; 6], 6).is_ok());
        let e = check("loads", &[0.0; 5], 6).unwrap_err();
        assert!(matches!(
            e,
            SolverError::BadLength {
                expected: 6,
                found: 5,
                ..
            }
        ));
        let e = check("load rates", &[0.0, f64::NAN], 2).unwrap_err();
        assert_eq!(
            e,
            SolverError::BadInput(crate::solver::BadInput::NotFinite("load rates"))
        );
        assert!(
            e.to_string().contains("load rates: values must be finite"),
            "{e}"
        );
    }

    /// Both state layouts round-trip every field.
    #[test]
    fn both_layouts_round_trip() {
        let mut a = Loads::new(3);
        a.set(&[1.0, 2.0, 3.0], 0.5);
        a.set_rates(&[4.0, 5.0, 6.0], 0.5);
        let (mut s1, mut s2) = (Vec::new(), Vec::new());
        a.save(&mut s1);
        a.save_time_first(&mut s2);
        assert_eq!(s1.len(), a.state_len());
        assert_eq!(s2[0], 0.5);
        assert_eq!(s1[6], 0.5);
        let (mut b, mut c) = (Loads::new(3), Loads::new(3));
        b.load(&s1);
        c.load_time_first(&s2);
        for l in [&b, &c] {
            assert_eq!(l.values, a.values);
            assert_eq!(l.rates, a.rates);
            assert_eq!(l.t_set, a.t_set);
        }
    }
}
