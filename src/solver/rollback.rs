//! The one rollback of every method: what makes [`Solver::step`] all or nothing, and what
//! [`Solver::checkpoint`] and [`Solver::rewind`] give a caller that refuses a step of
//! its own accord (the FMU refuses a step whose outputs overflow although the state is
//! finite).
//!
//! A method holds one [`Rollback`]: one buffer for its complete state (the layout
//! `set_state` reads), sized at build, so that saving and restoring never allocate. A
//! step that can fail after it changed the state (the free explicit and split methods:
//! a frame that is no longer a rotation, numbers that overflow) saves the state into it
//! first, unless a checkpoint taken just before already holds it; a step that can only
//! fail before it changes anything (the blocked methods: a bad step size or a step too
//! long for the budget, refused before any work) saves nothing, so the exact method's
//! step copies nothing; a step that keeps a copy of its own for its work puts itself
//! back from it (the free implicit method, whose Newton iteration starts a split step
//! again from the state before it) and saves nothing here either. Either way a refused
//! step leaves the state bit for bit as it was.
//!
//! A checkpoint serves the one step after it: a step refused after a checkpoint goes
//! back to it (the loads and rates set since then included), and [`Solver::rewind`]
//! after that step, accepted or refused, goes back to it as well. The next step, or a
//! state set with `set_state`, ends it.
//!
//! A caller that checks each step (the FMU's guard) measures the state after it
//! ([`Solver::state_below`], a copy into a second buffer) and takes a checkpoint before
//! the next: when nothing changed the state in between, that copy is the checkpoint,
//! and the two buffers swap instead of the state being copied again. Every change of the
//! state outside a step (loads, rates, a state set, the continuous states of Model
//! Exchange) marks the measured copy stale ([`Rollback::touch`]), so a checkpoint then
//! copies the state afresh.

use super::{Method, Solver, SolverError, State};

/// The state a method can go back to (see the module notes).
#[derive(Debug, Clone)]
pub(crate) struct Rollback {
    saved: State,
    /// Where [`Rollback::state_below`] writes the state it measures (the checkpoint must
    /// stay as it is), sized like `saved`.
    scratch: Vec<f64>,
    /// `scratch` holds the complete state as it is now: written by
    /// [`Rollback::state_below`], and nothing changed the state since.
    current: bool,
    mark: Mark,
}

/// Whether a checkpoint holds the state before the coming (or the last) step: the
/// bookkeeping of [`Rollback`], apart for a decorator that keeps part of its state
/// beside its inner solver's ([`super::residual::Residual`]).
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Mark {
    /// A checkpoint was taken, valid for the one step after it.
    checkpoint: bool,
    /// A step ran since the checkpoint.
    stepped: bool,
}

impl Mark {
    /// A checkpoint was taken now.
    pub(crate) fn set(&mut self) {
        (self.checkpoint, self.stepped) = (true, false);
    }

    /// A step begins: whether a checkpoint holds the state before it (a checkpoint
    /// serves the one step after it).
    #[inline]
    pub(crate) fn step(&mut self) -> bool {
        if self.stepped {
            self.checkpoint = false;
        }
        self.stepped = true;
        self.checkpoint
    }

    /// Whether there is a checkpoint to go back to; after going back it serves the next
    /// step again.
    pub(crate) fn rewind(&mut self) -> bool {
        self.stepped = false;
        self.checkpoint
    }

    /// The state was set wholesale: no checkpoint.
    pub(crate) fn forget(&mut self) {
        self.checkpoint = false;
    }
}

/// The refusal of [`Solver::rewind`] without a checkpoint.
pub(crate) fn no_checkpoint() -> SolverError {
    SolverError::BadState(super::BadState::NoCheckpoint)
}

/// A method with a [`Rollback`]: how it writes its complete state.
pub(crate) trait Restorable: Solver {
    /// The method's rollback.
    fn rollback(&mut self) -> &mut Rollback;
    /// Write the complete state into `out` (cleared first): the layout `set_state` reads.
    fn write_state(&self, out: &mut Vec<f64>);
    /// The length of the complete state.
    fn state_len(&self) -> usize;
}

impl Rollback {
    /// An empty rollback for `method`, its buffer sized for `len` numbers.
    pub(crate) fn new(method: Method, len: usize) -> Rollback {
        Rollback {
            saved: State {
                method,
                data: Vec::with_capacity(len),
            },
            scratch: Vec::with_capacity(len),
            current: false,
            mark: Mark::default(),
        }
    }

    /// The state was set wholesale (`set_state`): a checkpoint taken before no longer
    /// belongs to it.
    pub(crate) fn forget(&mut self) {
        self.mark.forget();
        self.current = false;
    }

    /// The state changed outside a step (loads, rates, the continuous states): the copy
    /// [`Rollback::state_below`] measured no longer holds it.
    #[inline]
    pub(crate) fn touch(&mut self) {
        self.current = false;
    }

    /// [`Solver::checkpoint`]: save the complete state now; when the copy the last
    /// [`Rollback::state_below`] measured still holds it, that copy becomes the
    /// checkpoint (the buffers swap, nothing is copied).
    pub(crate) fn checkpoint<S: Restorable>(s: &mut S) {
        let r = s.rollback();
        if r.current {
            std::mem::swap(&mut r.saved.data, &mut r.scratch);
            r.current = false;
        } else {
            save(s);
        }
        s.rollback().mark.set();
    }

    /// [`Solver::rewind`]: back to the checkpoint.
    pub(crate) fn rewind<S: Restorable>(s: &mut S) -> Result<(), SolverError> {
        let mut mark = s.rollback().mark;
        if !mark.rewind() {
            return Err(no_checkpoint());
        }
        s.rollback().current = false;
        restore(s)?;
        s.rollback().mark = mark;
        Ok(())
    }

    /// [`Solver::state_below`]: the complete state written into the scratch buffer (no
    /// allocation once it has held one state) and measured there.
    pub(crate) fn state_below<S: Restorable>(s: &mut S, bound: f64) -> bool {
        let mut data = std::mem::take(&mut s.rollback().scratch);
        s.write_state(&mut data);
        let below = squares_below(&data, bound);
        let r = s.rollback();
        r.scratch = data;
        r.current = true;
        below
    }

    /// Run one step of `s` all or nothing. `partway`: the step can fail after it changed
    /// the state, which must then be saved first (unless a checkpoint holds it).
    #[inline]
    pub(crate) fn step<S: Restorable, T>(
        s: &mut S,
        partway: bool,
        step: impl FnOnce(&mut S) -> Result<T, SolverError>,
    ) -> Result<T, SolverError> {
        let r = s.rollback();
        r.current = false;
        let held = r.mark.step();
        if partway && !held {
            save(s);
        }
        let out = step(s);
        if out.is_err() && (held || partway) {
            restore(s)?;
        }
        out
    }
}

/// Whether every entry of `data` is certainly below `bound` in magnitude: the sum of
/// their squares is below `bound^2` (NaN or overflow to infinity compare false). Stricter
/// than testing each entry by at most a factor `sqrt(data.len())`, which only sends a
/// state that is already near the bound to the caller's full check.
#[inline]
pub(crate) fn squares_below(data: &[f64], bound: f64) -> bool {
    sum_squares(data) < bound * bound
}

/// The sum of squares behind [`squares_below`] (NaN if an entry is NaN, infinite if an
/// entry or the sum overflows). Four accumulators, read four entries at a time, so that
/// the loop vectorises into independent sums (no long chain of dependent additions).
#[inline]
fn sum_squares(data: &[f64]) -> f64 {
    let mut acc = [0.0f64; 4];
    let mut chunks = data.chunks_exact(4);
    for c in &mut chunks {
        for k in 0..4 {
            acc[k] += c[k] * c[k];
        }
    }
    // Neighbours first: lanes (0, 1) and (2, 3) stay two vector registers.
    let mut sum = (acc[0] + acc[2]) + (acc[1] + acc[3]);
    for x in chunks.remainder() {
        sum += x * x;
    }
    sum
}

/// Write the state of `s` into its rollback buffer (taken out and put back: no
/// allocation once it has held one state).
fn save<S: Restorable>(s: &mut S) {
    let mut data = std::mem::take(&mut s.rollback().saved.data);
    s.write_state(&mut data);
    s.rollback().saved.data = data;
}

/// Put the saved state back into `s`, keeping the rollback's mark (which the method's
/// `set_state` clears).
#[cold]
#[inline(never)]
fn restore<S: Restorable>(s: &mut S) -> Result<(), SolverError> {
    let r = s.rollback();
    let (mark, method) = (r.mark, r.saved.method);
    let saved = std::mem::replace(
        &mut r.saved,
        State {
            method,
            data: Vec::new(),
        },
    );
    let restored = s.set_state(&saved);
    let r = s.rollback();
    r.saved = saved;
    r.mark = mark;
    restored
}

/// The [`Solver`] items every method answers through its [`Rollback`]: the complete
/// state, the checkpoint, the rewind and the state's size. Invoked inside each method's `impl Solver`,
/// which also implements [`Restorable`].
macro_rules! rollback_items {
    () => {
        fn state(&self) -> $crate::solver::State {
            let mut data = Vec::with_capacity(
                <Self as $crate::solver::rollback::Restorable>::state_len(self),
            );
            <Self as $crate::solver::rollback::Restorable>::write_state(self, &mut data);
            $crate::solver::State {
                method: self.method(),
                data,
            }
        }

        fn checkpoint(&mut self) {
            $crate::solver::rollback::Rollback::checkpoint(self);
        }

        fn rewind(&mut self) -> Result<(), $crate::solver::SolverError> {
            $crate::solver::rollback::Rollback::rewind(self)
        }

        fn state_below(&mut self, bound: f64) -> bool {
            $crate::solver::rollback::Rollback::state_below(self, bound)
        }
    };
}
pub(crate) use rollback_items;
