"""Craig-Bampton models against the full FE model: issue 17's criterion "with every
fixed-interface mode up to a cut-off F kept, the frequencies below F/2 within 1e-3 of the
full model's", measured, explained, and shown not to be a property of the reduction.

What the import owns is checked in every case: the imported body's frequencies equal the
Craig-Bampton model's (as punched) to 1e-8. How close that model comes to the full one is
the reduction's business, and the Craig-Bampton reduction here (import_models.py) is
checked for what could make it wrong: the interface DOFs are all six DOFs of the interface
nodes, the constraint modes are -K_ii^-1 K_ib, the mass coupling is T^T M T whole (M_ib and
M_ii T_c), the cut-off is the fixed-interface frequency in Hz, the full model is the same
mesh with the same support, frequencies are paired in ascending order after the six rigid
modes of a free body (the full model's and the body's counted), every frequency is an
upper bound of the full model's, with every fixed-interface mode the reduction is the full
model, and each measured error is the second-order share of the fixed-interface modes left
out (im.truncation_estimate) to within 15% (measured 0.99 to 1.09; leaving M_ib out of the
coupling, or constraint modes 0.1% off, puts that ratio out by 55% and 97%): nothing else
is missing. The uniform bar shows in closed form that the criterion needs a cut-off far above
the first frequency even for the simplest structure: the error of the mode just below F/2
falls only like 1/(number of modes below F/2), and 1e-3 holds at every cut-off only from
F = 20.5 f1."""

import pathlib
import sys

import numpy as np
import pytest
import scipy.linalg as la

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
import import_models as im  # noqa: E402
from test_import import as_punched, body_hz, hz, read, run_import  # noqa: E402

REFINE = 4  # 36 elements, 37 nodes, 222 DOFs
TOL = 1e-3


class CriterionMissed(AssertionError):
    """The 1e-3 criterion missed (and only that): a strict xfail expects this exception
    and no other, so a failure of the import's part is never taken as the expected one."""


@pytest.fixture(scope="module")
def users_models():
    """The two bodies a user of the bracket would reduce, full K and M, their full models'
    frequencies (ascending, rigid modes excluded) and interface rows:
    - clamped: bolted at its base node (clamped before reduction, a blocked body),
      coupled to the system at its tip only, where the part it carries is attached: one
      interface node, its six DOFs;
    - free: the same bracket as a free link between two joints, coupled at its two ends:
      two interface nodes, twelve DOFs, six rigid modes.
    The mesh is the bracket's refined 4x (36 elements): the full model's frequencies below
    2 kHz move by at most 1.4e-3 when refined 8x, a real FE model rather than one element
    a corner."""
    ids, xyz, k, m = im.bracket(REFINE)
    base, tip = ids[0], ids[-1]
    kc, mc = k[6:, 6:], m[6:, 6:]
    f = hz(la.eigvalsh(kc, mc))
    assert f[0] > 1.0  # clamped: no zero-energy mode
    models = {"clamped": (ids[1:], xyz[1:], kc, mc, [tip], f)}
    f = hz(la.eigvalsh(k, m))
    assert f[5] < 1e-3 * f[6], "a free body has exactly six rigid modes"
    models["free"] = (ids, xyz, k, m, [base, tip], f[6:])
    out = {}
    for support, (ids_, xyz_, k_, m_, iface, f_full) in models.items():
        # the fixed-interface modes once a model (the cut-offs only choose how many to keep)
        fixed = im.fixed_interface(k_, m_, im.dof_index(ids_, iface))
        i, _, _, tc = fixed
        # constraint modes: the interior in equilibrium under unit interface motions
        assert np.abs(k_[i] @ tc).max() < 1e-9 * np.abs(k_).max() * np.abs(tc).max()
        # with every fixed-interface mode, the reduction is the full model, to round-off
        # (the pencil's eigenvalues span 9 decades: 2e-8 on the lowest frequency)
        ka, ma, _, _ = im.craig_bampton(k_, m_, im.dof_index(ids_, iface), len(i), fixed)
        rigid = 6 if support == "free" else 0
        assert np.abs(hz(la.eigvalsh(ka, ma))[rigid:] / f_full - 1).max() < 1e-7
        out[support] = (ids_, xyz_, k_, m_, iface, f_full, fixed)
    return out


def _case(support, cutoff, missed=None):
    marks = ([pytest.mark.xfail(strict=True, raises=CriterionMissed, reason=missed)]
             if missed else [])
    return pytest.param(support, cutoff, marks=marks, id=f"{support}-{cutoff:.0f}Hz")


# Octave cut-offs, fixed before measuring (F / f1 = 57 to 460 clamped, 12 to 95 free).
# The figures in the reasons are this test's own measurement.
@pytest.mark.parametrize("support,cutoff", [
    _case("clamped", 500.0, "1.04e-3 at 110 Hz (8 modes kept, 8 judged); dropped modes' "
                            "share 1.04e-3"),
    _case("clamped", 1000.0),
    _case("clamped", 2000.0, "2.6e-3 at 938 Hz (21 modes kept, 15 judged); dropped modes' "
                             "share 2.8e-3"),
    _case("clamped", 4000.0, "2.7e-3 at 1715 Hz (34 modes kept, 24 judged); dropped modes' "
                             "share 2.7e-3"),
    _case("free", 500.0, "2.8e-3 at 195 Hz (8 modes kept, 5 judged); dropped modes' share "
                         "2.9e-3"),
    _case("free", 1000.0, "6.1e-3 at 397 Hz (12 modes kept, 8 judged); dropped modes' share "
                          "6.6e-3"),
    _case("free", 2000.0, "4.0e-3 at 667 Hz (21 modes kept, 13 judged); dropped modes' share "
                          "4.0e-3"),
    _case("free", 4000.0, "3.3e-3 at 1705 Hz (34 modes kept, 21 judged); dropped modes' "
                          "share 3.3e-3"),
])
def test_craig_bampton_against_the_full_model(users_models, tmp_path, support, cutoff):
    ids, xyz, k, m, iface, f_full, fixed = users_models[support]
    rigid = 6 if support == "free" else 0
    b = im.dof_index(ids, iface)
    kc, mc, nm, dropped = im.craig_bampton_upto(k, m, b, cutoff, fixed)
    im.write_punch(tmp_path / "cb.pch", {"KAAX": kc, "MAAX": mc}, im.reduced_dofs(ids, iface, nm))
    im.write_csv(tmp_path / "nodes.csv", ids, xyz)
    extra = ["--free", "--coords", tmp_path / "nodes.csv"] if rigid else ["--blocked"]
    run_import(tmp_path / "cb.pch", *extra, "-o", tmp_path / "cb.fxb")
    fb = body_hz(read(tmp_path / "cb.fxb"))
    # the import's part: the body is the Craig-Bampton model as punched
    assert len(fb) == len(kc) - rigid
    ei = np.abs(fb / hz(la.eigvalsh(as_punched(kc), as_punched(mc)))[rigid:] - 1).max()
    assert ei < 1e-8, f"imported frequencies off the Craig-Bampton model's by {ei:.2e}"
    # the reduction's part: upper bounds, and the error is the dropped modes' share
    lam, x = la.eigh(kc, mc)
    lam, x = lam[rigid:], x[: len(b), rigid:]
    e = hz(lam) / f_full[: len(lam)] - 1
    assert e.min() > -1e-9, f"a Craig-Bampton frequency below the full model's: {e.min():.1e}"
    low = fb < cutoff / 2
    assert low.sum() >= 3 and np.array_equal(low, hz(lam) < cutoff / 2)
    est = im.truncation_estimate(lam, x, dropped)
    worst = int(np.argmax(np.where(low, e, -1.0)))
    judged = low & (e > 1e-6)  # every judged mode but those near the round-off (2e-8)
    ratio = est[judged] / e[judged]
    print(f"CB {support}, F = {cutoff:.0f} Hz ({nm} modes kept), {low.sum()} judged below "
          f"{cutoff / 2:.0f} Hz: worst {e[worst]:.2e} at {hz(lam[worst]):.0f} Hz, dropped "
          f"modes' share {est[worst]:.2e} (ratio {ratio.min():.2f}..{ratio.max():.2f}); "
          f"below F/4 {e[fb < cutoff / 4].max():.2e}; import vs CB {ei:.1e}")
    assert np.abs(ratio - 1).max() < 0.15, f"error not explained by the dropped modes: {ratio}"
    # the criterion, on the imported body's frequencies
    ec = np.abs(fb[low] / f_full[: low.sum()] - 1).max()
    if ec >= TOL:
        raise CriterionMissed(f"CB vs full below {cutoff / 2:.0f} Hz: {ec:.2e}")


def test_craig_bampton_error_of_a_uniform_bar():
    """The textbook case in closed form (im.bar_craig_bampton_exact): a uniform free bar
    in axial motion coupled at one end, every fixed-interface mode up to F kept. The FE
    bar's Craig-Bampton errors equal the closed form's to 2%, and the closed form says how
    far the criterion is from a property of the reduction. The worst error below F/2 is
    that of the mode just below it: with F just above 2 f_n, mode n is 1.0e-2 / n off (9.0e-3
    for n = 1), the inertia it shares with the fixed-interface modes above 2 f_n falling
    like 1/n. So 1e-3 below F/2 holds at every cut-off only from F = 20.5 f1, ten modes
    below F/2: 9.0e-3 at F = 2.4 f1, 2.4e-3 at 5 f1, 1.2e-3 at 10 f1, 7.8e-4 at 20 f1."""
    assert np.abs(im.bar_craig_bampton_exact(100000, 3) - [1, 2, 3]).max() < 1e-4
    for n in (1, 2, 4, 8, 16):
        kept = 2 * n  # F = 2 n + 0.4 (f1): fixed-interface modes at (j - 1/2) f1 <= F
        e = im.bar_craig_bampton_exact(kept, n)[-1] / n - 1
        assert 0.89e-2 < n * e < 1.01e-2, f"mode {n} with F = {2 * n + 0.4} f1: {e:.2e}"
    k, m = im.bar(400)
    fixed = im.fixed_interface(k, m, np.array([0]))
    w2 = la.eigvalsh(k, m)
    f_full = np.sqrt(w2[1:]) / (2 * np.pi)
    f1 = f_full[0]
    worst = {}
    for ratio in (2.4, 5.0, 10.0, 20.0):
        kc, mc, nm, _ = im.craig_bampton_upto(k, m, np.array([0]), ratio * f1, fixed)
        kept = int(np.floor(ratio + 0.5))
        assert nm == kept
        f_cb = np.sqrt(np.clip(la.eigvalsh(kc, mc)[1:], 0.0, None)) / (2 * np.pi)
        n = int((f_cb < ratio * f1 / 2).sum())
        fe_err = f_cb[:n] / f_full[:n] - 1
        exact_err = im.bar_craig_bampton_exact(kept, n) / np.arange(1, n + 1) - 1
        d = np.abs(fe_err / exact_err - 1).max()
        worst[ratio] = exact_err.max()
        print(f"bar, F = {ratio} f1: {kept} modes kept, {n} judged, worst {exact_err.max():.2e}"
              f" (FE {fe_err.max():.2e}, off the closed form by {d:.1e})")
        assert d < 2e-2, f"FE Craig-Bampton errors off the closed form by {d:.1e}"
    assert worst[2.4] > 5e-3 and worst[5.0] > 2e-3 and worst[10.0] > TOL > worst[20.0]
