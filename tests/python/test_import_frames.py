"""`fxbody import` on realistic full FE models (import_frames.py: 3D frames of 20 to 500
consistent-mass elements, held or free, up to the dense size limit of 3000 DOFs, lowest
eigenvalue down to 4e-14 of the largest), against scipy's `eigh` of the same matrices;
the same models scaled by 10^(+-100), with absurd entries, with coordinates in other
units or rounded: each imports to the same body (scaled back) or is refused for its true
reason, named.

Frequency bound: a symmetric eigen-solver gives each eigenvalue to round-off of the
largest (`eps lambda_max` absolute: the bound of LAPACK's and of ours), and the .fxb keeps
10 significant digits of K_L and m_L. So mode j is compared at
`2e-9 + 4 eps lambda_max / lambda_j` relative in eigenvalue: measured up to 0.8 of
`1e-9 + eps lambda_max / lambda_j` on every size (the lowest mode of the 500-element
frame: about 1e-5)."""

import json
import pathlib
import subprocess
import sys

import numpy as np
import pytest
import scipy.linalg as la

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
import import_frames as fr  # noqa: E402
import import_models as im  # noqa: E402
from conftest import EXE, FIXTURES  # noqa: E402

sys.path.insert(0, str(FIXTURES))
import fxbread  # noqa: E402

EPS = np.finfo(float).eps


def write(tmp, k, m, dofs, ids, xyz, punch=False):
    """The matrices (Abaqus lines at 17 digits, or a Nastran punch at 10) and the
    coordinates (CSV): the import's arguments without -o."""
    im.write_csv(tmp / "nodes.csv", ids, xyz)
    if punch:
        im.write_punch(tmp / "m.pch", {"KAAX": k, "MAAX": m}, dofs)
        return [tmp / "m.pch", "--coords", tmp / "nodes.csv"]
    im.write_abaqus(tmp / "K.mtx", dofs, k)
    im.write_abaqus(tmp / "M.mtx", dofs, m)
    return ["--stiffness", tmp / "K.mtx", "--mass", tmp / "M.mtx", "--coords", tmp / "nodes.csv"]


def run(args, out=None, ok=True):
    if not EXE.is_file():
        pytest.fail(f"{EXE} is missing: run `cargo build --release` first")
    extra = ["-o", str(out)] if out else ["-o", "/dev/null/never.fxb"]
    r = subprocess.run([str(EXE), "import", *map(str, args), *extra], capture_output=True, text=True)
    assert (r.returncode == 0) == ok, f"exit {r.returncode}: {r.stderr}{r.stdout}"
    return r


def eigenvalues(path):
    f = fxbread.read_fxb(pathlib.Path(path).read_text())
    return f, la.eigvalsh(f["k_l"], np.diag(f["m_l"]))


def check_against_scipy(path, k, m, free):
    """Every eigenvalue of the body against scipy's eigh of (K, M) at the module's
    bound; returns the largest error as a fraction of the bound."""
    f, got = eigenvalues(path)
    want = la.eigh(k, m, eigvals_only=True)
    if free:
        want = want[6:]
    assert len(got) == len(want), f"{len(got)} modes, scipy {len(want)}"
    rel = np.abs(got / want - 1)
    bound = 2e-9 + 4 * EPS * want.max() / want
    assert (rel <= bound).all(), (
        f"mode {np.argmax(rel / bound)}: {rel.max():.2e} (bound there "
        f"{bound[np.argmax(rel / bound)]:.2e}); lowest/largest {want[0] / want[-1]:.1e}")
    assert abs(f["freq"] / (np.sqrt(want.max()) / (2 * np.pi)) - 1) < 1e-9
    return float((rel / (1e-9 + EPS * want.max() / want)).max()), want[0] / want[-1]


@pytest.mark.parametrize("n_el,held", [(20, True), (20, False), (60, True), (60, False),
                                       (200, True), (200, False), (500, True), (499, False)])
def test_frames_import_with_scipys_frequencies(tmp_path, n_el, held):
    """Held and free frames up to the size limit (500 elements held, 499 free: 3000
    DOFs), support detected from K: all frequencies are scipy's to the eigen-solvers'
    accuracy. (Before: refused from 60 elements held, "K is singular", and from 200
    free, "K has 8 zero-energy modes (6 expected): mechanism".)"""
    ids, xyz, k, m = fr.frame(n_el, held)
    args = write(tmp_path, k, m, fr.dofs(ids, held), ids, xyz)
    run([*args, "--report", tmp_path / "r.json"], out=tmp_path / "f.fxb")
    rep = json.loads((tmp_path / "r.json").read_text())
    assert rep["free"] is (not held)
    assert rep["dofs"] == k.shape[0]
    worst, spread = check_against_scipy(tmp_path / "f.fxb", k, m, not held)
    print(f"{n_el} elements {'held' if held else 'free'}: {k.shape[0]} DOFs, lowest/largest "
          f"eigenvalue {spread:.1e}, worst error {worst:.2f} of eps lambda_max/lambda + 1e-9")


@pytest.mark.parametrize("n_el,held", [(60, True), (200, False)])
def test_punched_frames_import(tmp_path, n_el, held):
    """The same frames as a Nastran punch (10 significant digits), support given: the
    frequencies of the punched matrices, by scipy."""
    ids, xyz, k, m = fr.frame(n_el, held)
    kp, mp = [np.vectorize(lambda v: float(f"{v:16.9E}"))(a) for a in (k, m)]
    args = write(tmp_path, k, m, fr.dofs(ids, held), ids, xyz, punch=True)
    run([*args, "--blocked" if held else "--free"], out=tmp_path / "p.fxb")
    check_against_scipy(tmp_path / "p.fxb", kp, mp, not held)


def test_held_frame_with_a_cut(tmp_path):
    """The held 60-element frame with --blocked --fmax 500: the eigenmodes kept are
    scipy's up to 500 Hz (bound as above), static modes added for the nodes, and the
    static response at the tip to a unit force is the full model's (the static modes
    carry the dropped modes' share) to 1e-8 of the largest displacement (measured 5e-9:
    the file's 10 digits, summed over modes that partly cancel)."""
    ids, xyz, k, m = fr.frame(60, True)
    args = write(tmp_path, k, m, fr.dofs(ids, True), ids, xyz)
    run([*args, "--blocked", "--fmax", "500"], out=tmp_path / "c.fxb")
    f = fxbread.read_fxb((tmp_path / "c.fxb").read_text())
    want = la.eigh(k, m, eigvals_only=True)
    ns = f["nbstat"]
    kept = np.sort(np.diag(f["k_l"])[ns:] / f["m_l"][ns:])
    assert ns > 0 and len(kept) == int((np.sqrt(want) / (2 * np.pi) <= 500.0).sum())
    rel = np.abs(kept / want[: len(kept)] - 1)
    assert (rel <= 2e-9 + 4 * EPS * want.max() / want[: len(kept)]).all(), rel.max()
    # a unit force along y at the tip (last node), every node's displacement
    tip = 6 * (len(ids) - 2) + 1
    load = np.zeros(k.shape[0])
    load[tip] = 1.0
    u_full = la.solve(k, load)
    phi = f["local"]  # the FXB nodes are the matrices' grid points, in their order
    u_body = phi @ la.solve(f["k_l"], phi[tip])
    err = np.abs(u_body - u_full).max() / np.abs(u_full).max()
    assert err < 1e-8, f"tip statics off by {err:.1e}"


def test_punched_free_frame_asked_held(tmp_path):
    """The free 200-element frame as a 10-digit punch, asked --blocked: the rounding
    leaves K definite (its rigid modes at 1e-15 of the largest instead of 0). With
    coordinates K does not resist their rigid motions: refused, "did you mean --free?";
    without them nothing can tell, and the body is imported with a warning that says
    how little its lowest eigenvalue is determined and what to do if it is free."""
    ids, xyz, k, m = fr.frame(200, False)
    args = write(tmp_path, k, m, fr.dofs(ids, False), ids, xyz, punch=True)
    msg = run([*args, "--blocked"], ok=False).stderr
    assert "did you mean --free?" in msg, msg
    out = run([args[0], "--blocked"], out=tmp_path / "h.fxb").stdout
    assert "double precision guarantees it only to about" in out, out
    # The advice is data in the library's report; the command names the options.
    assert ("if the body is free, its six lowest modes may be rigid motions the rounding left "
            "slightly stiff: give its coordinates (--coords) and --free") in out, out


def blocks(path):
    f = fxbread.read_fxb(pathlib.Path(path).read_text())
    return {key: np.asarray(f[key], float) for key in
            ("local", "rigid", "m_l", "k_l", "m_r", "m_c", "k_c", "freq")}


@pytest.mark.parametrize("n_el,held", [(60, True), (200, False)])
def test_scaled_copies_are_the_same_body(tmp_path, n_el, held):
    """K or M times 10^100 or 10^-100 (and K times 10^-300): the same body, its mass
    blocks (m_L, M_R, M_C) times the mass factor, its stiffness blocks (K_L, K_C) times
    the stiffness factor, Freq times their square roots' ratio, the modes unchanged. To
    what double precision resolves: 10^100 is no power of two, so every entry is
    rounded anew, and a mode's shape moves by up to `eps lambda_max / lambda_j` under
    such a change (its frequency's bound, per mode; 1e-9 for the rigid mass and Freq)."""
    ids, xyz, k, m = fr.frame(n_el, held)
    dofs = fr.dofs(ids, held)
    run(write(tmp_path, k, m, dofs, ids, xyz), out=tmp_path / "ref.fxb")
    ref = blocks(tmp_path / "ref.fxb")
    lam = np.diag(ref["k_l"]) / ref["m_l"]
    per_mode = 2e-9 + 4 * EPS * lam.max() / lam
    for sk, sm in [(1e100, 1.0), (1e-100, 1.0), (1.0, 1e100), (1.0, 1e-100), (1e-300, 1.0)]:
        run(write(tmp_path, k * sk, m * sm, dofs, ids, xyz), out=tmp_path / "s.fxb")
        got = blocks(tmp_path / "s.fxb")
        factor = {"m_l": sm, "m_r": sm, "m_c": sm, "k_l": sk, "k_c": sk,
                  "freq": np.sqrt(sk / sm), "local": 1.0, "rigid": 1.0}
        for key, want in ref.items():
            if want.size == 0:
                continue
            diff = np.abs(got[key] / factor[key] - want) / np.abs(want).max()
            if key in ("m_l", "local", "k_l", "m_c", "k_c"):
                # the last axis is the mode (k_l: its diagonal carries the eigenvalues)
                worst = np.moveaxis(diff, -1, 0).reshape(len(lam), -1).max(axis=1) / per_mode
                assert worst.max() < 1, f"K x {sk:g}, M x {sm:g}: {key}, mode {worst.argmax()}"
            else:
                assert diff.max() < 1e-9, f"K x {sk:g}, M x {sm:g}: {key} off by {diff.max():.1e}"


@pytest.mark.parametrize("n_el,held", [(60, True), (200, False)])
def test_absurd_entries_are_refused_naming_the_entry(tmp_path, n_el, held):
    """A diagonal entry 1e300 times off (M(0,0) = 1e-320 or 1e308, K(0,0) = 1e308) is
    refused naming the DOF, both entries and the spread; a subnormal off-diagonal M
    entry changes nothing and imports the same body."""
    ids, xyz, k, m = fr.frame(n_el, held)
    dofs = fr.dofs(ids, held)
    first = f"{dofs[0][0]}.{dofs[0][1]}"
    for which, value, shown in [("M", 1e-320, "M({0}, {0}) = 1e-320"),
                                ("M", 1e308, "M({0}, {0}) = 1e308"),
                                ("K", 1e308, "K({0}, {0}) = 1e308")]:
        kk, mm = k.copy(), m.copy()
        (mm if which == "M" else kk)[0, 0] = value
        r = run(write(tmp_path, kk, mm, dofs, ids, xyz), ok=False)
        msg = r.stderr
        assert shown.format(first) in msg, msg
        assert "the ratios K_ii/M_ii of the DOFs span 1e" in msg and "check that entry" in msg, msg
    run(write(tmp_path, k, m, dofs, ids, xyz), out=tmp_path / "ref.fxb")
    mm = m.copy()
    mm[0, 1] = mm[1, 0] = 1e-320
    run(write(tmp_path, k, mm, dofs, ids, xyz), out=tmp_path / "sub.fxb")
    a, b = blocks(tmp_path / "ref.fxb"), blocks(tmp_path / "sub.fxb")
    for key in a:
        assert np.array_equal(a[key], b[key]), key


def test_coordinates_that_contradict_the_null_space_are_said_first(tmp_path):
    """The free 200-element frame with coordinates in mm for matrices in m: whatever the
    flag, the message says first that the coordinates are 1000 times what fits K's
    zero-energy modes (before supports or --free); rounded to 4 decimals (0.1 mm), that
    K has a free body's six zero-energy modes but not the coordinates' rigid motions."""
    ids, xyz, k, m = fr.frame(200, False)
    dofs = fr.dofs(ids, False)
    args = write(tmp_path, k, m, dofs, ids, xyz * 1000.0)
    for flag in ([], ["--free"]):
        msg = run([*args, *flag], ok=False).stderr
        assert "is not in K's null space" in msg, msg
        assert "units? the coordinates are 1000 times what fits K's zero-energy modes (ratio 1e3" in msg, msg
    msg = run([*args, "--blocked"], ok=False).stderr
    assert msg.index("units? the coordinates divided by 1000") < msg.index(
        "K is singular (6 zero-energy modes)"), msg
    args = write(tmp_path, k, m, dofs, ids, np.round(xyz, 4))
    msg = run(args, ok=False).stderr
    assert "K has 6 zero-energy modes, as a free body has, but not these" in msg, msg
    assert "rounded" in msg and "units?" not in msg, msg


def test_support_flags_and_mechanisms(tmp_path):
    """The held 60-element frame asked --free: K has no zero-energy mode; the free
    200-element frame asked --blocked: its zero modes are exactly rigid motions; the free
    frame cut in two: a mechanism, twelve zero-energy modes."""
    ids, xyz, k, m = fr.frame(60, True)
    msg = run([*write(tmp_path, k, m, fr.dofs(ids, True), ids, xyz), "--free"], ok=False).stderr
    # The library gives "held" as data; the command names the option (issue 27.6).
    assert "K has no zero-energy mode: the matrices are of a held body (import them without --free)" in msg, msg
    ids, xyz, k, m = fr.frame(200, False)
    dofs = fr.dofs(ids, False)
    msg = run([*write(tmp_path, k, m, dofs, ids, xyz), "--blocked"], ok=False).stderr
    assert "K is singular (6 zero-energy modes)" in msg and "did you mean --free?" in msg, msg
    # cut the element between the frame's nodes 51 and 52 (on the x leg): two free pieces
    sec = fr.fe.rect_section(0.04, 0.03)
    length = np.linalg.norm(xyz[51] - xyz[50])
    ke, _ = fr.fe.frame_element_oriented(length, fr.E, fr.G, fr.RHO, sec, fr.AXES["x"])
    kk = k.copy()
    rows = np.r_[6 * 50 : 6 * 52]
    kk[np.ix_(rows, rows)] -= ke
    kk[np.abs(kk) < 1e-9 * np.abs(k).max()] = 0.0
    msg = run(write(tmp_path, kk, m, dofs, ids, xyz), ok=False).stderr
    assert "K has 12 zero-energy modes (6 expected): mechanism" in msg, msg
