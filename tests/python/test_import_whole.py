"""`fxbody import JOB.inp --fmax F`: a whole CalculiX model (the L-bracket of
tests/fe_models/bracket.py, 18,690 DOFs blocked, 18,696 free, two *RIGID BODY spiders)
imported, packed and run through the FMU with fmpy, against CalculiX's own results:

- blocked (spider A held by *BOUNDARY on its REF and ROT nodes, spider B the connection):
  a force and a moment held at spider B; the FMU (exact modal stepping, every mode
  critically damped, damping.ratio = 1) settles on its static solution, which must equal
  ccx's *STATIC displacement and rotation to 1e-6 relative; every frequency below fmax
  equals ccx's *FREQUENCY to its 7 printed digits;
- free: the frequencies from `fxbody info` equal ccx's to 7 digits; mass, centre of mass
  and inertia equal R^T M R of the full mass matrix (read here from free.mas with numpy,
  R the rigid motions with the spider reading) to 1e-10; a torque-free spin about a
  non-principal axis follows the rigid Euler path.

Needs ccx (scripts/setup-fe.sh) and gmsh; the model is generated once into
target/fe_models/bracket-6 (shared with crates/import/tests)."""

import json
import pathlib
import subprocess
import sys

import numpy as np
import pytest
import scipy.linalg as la
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from fmpy import extract

sys.path.insert(0, str(pathlib.Path(__file__).parent))
from conftest import EXE, REPO  # noqa: E402
from slave import Slave  # noqa: E402
from test_import import euler_reference  # noqa: E402

FMAX = 20000.0
EXACT, IMPLICIT = 3, 2


def printed(text):
    """A number as ccx printed it, and half a unit of its last printed digit."""
    mantissa, exp = text.upper().split("E")
    decimals = len(mantissa.split(".")[1]) if "." in mantissa else 0
    return float(text), 0.5 * 10.0 ** (int(exp) - decimals)


@pytest.fixture(scope="module")
def bracket():
    out = REPO / "target" / "fe_models" / "bracket-6"
    r = subprocess.run([sys.executable, str(REPO / "tests/fe_models/bracket.py"), str(out),
                        "--size", "6.0", "--modes", "24"], capture_output=True, text=True)
    assert r.returncode == 0, f"bracket.py failed (ccx and gmsh needed): {r.stdout}{r.stderr}"
    return out


def run(*args):
    r = subprocess.run([str(EXE), *map(str, args)], capture_output=True, text=True)
    assert r.returncode == 0, f"fxbody {' '.join(map(str, args))}: {r.stderr}"
    return r.stdout


def import_pack(bracket, case, tmp_path, *extra):
    body = tmp_path / f"{case}.fxb"
    out = run("import", bracket / f"{case}.inp", "--fmax", FMAX, "-o", body, "--report",
              tmp_path / f"{case}.json", *extra)
    fmu = tmp_path / f"{case}.fmu"
    run("pack", body, "--coords", tmp_path / f"{case}.nodes.csv", "-o", fmu)
    info = json.loads(run("info", "--json", body))
    report = json.loads((tmp_path / f"{case}.json").read_text())
    return out, fmu, info, report


def assert_ccx_frequencies(ours, printed_hz):
    theirs = [printed(t) for t in printed_hz]
    theirs = [(f, h) for f, h in theirs if f < FMAX]
    assert len(ours) == len(theirs), (ours, theirs)
    worst = 0.0
    # Half a unit of the printed digit, plus 1e-6 relative for ccx's own solver: its
    # ARPACK and SPOOLES round differently per machine, visible in the 7th digit (the free
    # bracket's 4th elastic mode prints 4.184974e3 Hz on one machine, 4.184973e3 on another).
    for k, (f, (g, half)) in enumerate(zip(ours, theirs)):
        assert abs(f - g) <= half + 1e-6 * g, f"mode {k + 1}: ours {f!r} Hz, ccx {g} +- {half}"
        worst = max(worst, abs(f - g) / g)
    return worst


def test_blocked_statics_and_frequencies_through_the_fmu(bracket, tmp_path):
    ref = json.loads((bracket / "reference.json").read_text())
    _, fmu, info, report = import_pack(bracket, "blocked", tmp_path)
    below = [f for f in info["frequencies_hz"] if f < FMAX]
    worst_f = assert_ccx_frequencies(below, ref["blocked_hz"])
    # The sparse eigen-solver's frequencies, to the body file's 10 significant digits
    # (the import itself checks them to 1e-8 before writing).
    model = report["whole_model"]["model_hz"]
    assert np.allclose(below, model, rtol=1e-8, atol=0), (below, model)
    st = ref["static"]
    u = fmu_static(fmu, tmp_path / "blocked_x", 900003, st["force"], st["moment"])
    for part, ours in (("ref", u[:3]), ("rot", u[3:])):
        theirs = np.array([printed(t)[0] for t in st[part]])
        half = np.array([printed(t)[1] for t in st[part]])
        err = np.abs(ours - theirs)
        rel = err.max() / np.abs(theirs).max()
        print(f"blocked static {part}: FMU {ours}, ccx {theirs}, rel {rel:.1e}")
        assert np.all(err <= np.maximum(1e-6 * np.abs(theirs).max(), half)), (ours, theirs)
    print(f"blocked: {len(below)} modes below {FMAX} Hz equal ccx's to {worst_f:.1e}")


def fmu_static(fmu, unzip, node, force, moment):
    """The displacement and rotation of `node` that the packed FMU settles on under
    `force` and `moment` held there (exact modal stepping, every mode critically damped,
    damping.ratio = 1): the body's static solution."""
    s = Slave(fmu, extract(str(fmu), str(unzip)), name="static").start(
        reals={"damping.ratio": 1.0}, ints={"method": EXACT})
    names = [f"node_{node}.{c}" for c in ("x", "y", "z", "rx", "ry", "rz")]
    x0 = s.get(*names)
    s.set(**{f"node_{node}__f{c}": v for c, v in zip("xyz", force)})
    s.set(**{f"node_{node}__m{c}": v for c, v in zip("xyz", moment)})
    # Critically damped modes: the slowest (467 Hz) is within e^-58 (1 + 58) of its
    # static value after 20 ms.
    h = 1e-4
    for k in range(200):
        s.s.doStep(k * h, h)
    u = s.get(*names) - np.concatenate([x0[:3], np.zeros(3)])
    s.free()
    return u


def triplets(bracket, case, matrix):
    """The stored terms of case.sti/.mas: 0-based rows, columns (upper triangle), values,
    and the number of equations."""
    n = len((bracket / f"{case}.dof").read_text().split())
    t = np.fromfile(bracket / f"{case}.{matrix}", sep=" ").reshape(-1, 3)
    return t[:, 0].astype(int) - 1, t[:, 1].astype(int) - 1, t[:, 2], n


def full_matrix(bracket, case, matrix, digits=None):
    """case.sti/.mas as a full symmetric scipy CSC matrix over the equations, its values
    rounded to `digits` significant digits if given (as a punch holds them)."""
    i, j, v, n = triplets(bracket, case, matrix)
    if digits:
        v = np.array([float(f"{x:.{digits - 1}E}") for x in v])
    upper = sp.coo_matrix((v, (i, j)), shape=(n, n)).tocsc()
    return (upper + upper.T - sp.diags(upper.diagonal())).tocsc()


def rigid_mass_properties(bracket, folder=None, case="free", rot=None):
    """Mass, centre of mass and inertia about it from R^T M R, M read from case.mas in
    `folder` (default: the bracket's; upper triangle, 1-based equations), R the rigid
    motions over case.dof with the spider reading (the ROT nodes `rot`, default the
    bracket's two, have directions 1-3 that are rotations)."""
    folder = folder or bracket
    dofs = [line.split(".") for line in (folder / f"{case}.dof").read_text().split()]
    ids = np.array([int(a) for a, _ in dofs])
    comp = np.array([int(b) for _, b in dofs])
    info = json.loads((bracket / "done.json").read_text())
    if rot is None:
        rot = {s["rot"] for s in info["spiders"].values()}
    xyz = {}
    for line in (bracket / "nodes.csv").read_text().split():
        f = line.split(",")
        xyz[int(f[0])] = [float(v) for v in f[1:]]
    n = len(ids)
    r = np.zeros((n, 6))
    for i in range(n):
        c = comp[i] - 1
        if ids[i] in rot:
            r[i, 3 + c] = 1.0
            continue
        p = np.array(xyz[ids[i]])
        r[i, c] = 1.0
        for k in range(3):
            r[i, 3 + k] = np.cross(np.eye(3)[k], p)[c]
    mr = r.T @ (full_matrix(folder, case, "mas") @ r)
    m = mr[0, 0]
    s = mr[:3, 3:] / m
    c = np.array([s[1, 2], s[2, 0], s[0, 1]])
    inertia = mr[3:, 3:] - m * (c @ c * np.eye(3) - np.outer(c, c))
    return m, c, inertia


def test_free_frequencies_mass_properties_and_spin_through_the_fmu(bracket, tmp_path):
    ref = json.loads((bracket / "reference.json").read_text())
    _, fmu, info, report = import_pack(bracket, "free", tmp_path)
    assert info["iblo"] == 0
    below = [f for f in info["frequencies_hz"] if f < FMAX]
    worst_f = assert_ccx_frequencies(below, ref["free_hz"][6:])
    m, c, inertia = rigid_mass_properties(bracket)
    got = report["mass"]
    em = abs(got["total_mass"] / m - 1)
    ec = np.abs(np.array(got["center_of_mass"]) - c).max() / np.abs(c).max()
    ei = np.abs(np.array(got["inertia"]) - inertia).max() / np.abs(inertia).max()
    print(f"free: {len(below)} modes equal ccx's to {worst_f:.1e}; R^T M R: mass {em:.1e}, "
          f"centre {ec:.1e}, inertia {ei:.1e}")
    assert max(em, ec, ei) < 1e-10, (em, ec, ei)
    # The body file keeps 10 significant digits; fxbody info sums M_R's blocks from it.
    assert abs(info["mass"] / m - 1) < 1e-6
    assert np.abs(np.array(info["inertia_at_cog"]) - inertia).max() < 1e-8 * np.abs(inertia).max()
    # Torque-free spin about a non-principal axis: the frame follows the rigid Euler
    # path with R^T M R's inertia.
    w0 = np.array([6.0, -4.0, 8.0])
    t_end, h, every = 2.0, 1e-3, 100
    path = euler_reference(inertia, w0, t_end, h / 10)
    s = Slave(fmu, extract(str(fmu), str(tmp_path / "free_x")), name="spin").start(
        reals={"w0.x": w0[0], "w0.y": w0[1], "w0.z": w0[2]}, ints={"method": IMPLICIT})
    pn = [f"frame.P{i}{j}" for i in (1, 2, 3) for j in (1, 2, 3)]
    worst = 0.0
    for step in range(1, int(round(t_end / h)) + 1):
        s.s.doStep((step - 1) * h, h)
        if step % every == 0:
            p = s.get(*pn).reshape(3, 3)
            worst = max(worst, np.abs(p - path[10 * step][:9].reshape(3, 3)).max())
    s.free()
    print(f"free spin {np.linalg.norm(w0) * t_end / (2 * np.pi):.1f} turns: attitude {worst:.1e}")
    # The implicit scheme's phase error, about (w h)^2/12 per radian turned (2e-4 here).
    assert worst < 5e-4, worst


def ccx_terms(bracket, case, matrix):
    """The upper-triangle terms of case.sti/.mas over six-DOF nodes: a spider's ROT node
    direction c becomes its REF node's direction c + 3 (how Abaqus and Nastran carry a
    reference node's rotations). Returns rows, cols as (node, dof) arrays and values."""
    info = json.loads((bracket / "done.json").read_text())
    rot_to_ref = {s["rot"]: s["ref"] for s in info["spiders"].values()}
    dofs = []
    for line in (bracket / f"{case}.dof").read_text().split():
        node, c = (int(x) for x in line.split("."))
        dofs.append((rot_to_ref[node], c + 3) if node in rot_to_ref else (node, c))
    dofs = np.array(dofs)
    i, j, v, _ = triplets(bracket, case, matrix)
    return dofs[i], dofs[j], v


def write_abaqus_whole(path, rows, cols, values):
    """Abaqus *MATRIX OUTPUT lines `node, dof, node, dof, value`, one per stored term."""
    with open(path, "w") as f:
        for (a, b), (c, d), v in zip(rows, cols, values):
            f.write(f"{c},{d}, {a},{b}, {v:.17e}\n")


def write_dmig_whole(path, mats):
    """Nastran punch DMIG (IFO=6, one triangle): a DMIG* card per column, then one `*`
    line per term with the value touching the component field (%16.9E: 10 digits)."""
    with open(path, "w") as f:
        for name, (rows, cols, values) in mats.items():
            n = len({tuple(x) for x in rows} | {tuple(x) for x in cols})
            f.write(f"{'DMIG':<8}{name:<8}{0:>8}{6:>8}{2:>8}{0:>8}{'':8}{n:>16}\n")
            last = None
            for (a, b), (c, d), v in zip(rows, cols, values):
                if (c, d) != last:
                    f.write(f"{'DMIG*':<8}{name:<16}{c:>16}{d:>16}\n")
                    last = (c, d)
                f.write(f"{'*':<8}{a:>16}{b:>16}{v:16.9E}\n")


@pytest.mark.parametrize("fmt", ["abaqus", "dmig"])
def test_whole_abaqus_and_dmig_models(bracket, tmp_path, fmt):
    """The bracket's ccx matrices rewritten as Abaqus *MATRIX OUTPUT lines (free, 17
    digits) and as a Nastran DMIG punch (blocked, 10 digits): no Abaqus or Nastran here,
    so the files are written from ccx's matrices in the documented layouts. Above 3,000
    DOFs the import takes the sparse route; the frequencies below fmax equal ccx's to
    its 7 printed digits."""
    case = "free" if fmt == "abaqus" else "blocked"
    k, m = (ccx_terms(bracket, case, x) for x in ("sti", "mas"))
    ref = json.loads((bracket / "reference.json").read_text())
    if fmt == "abaqus":
        write_abaqus_whole(tmp_path / "K.mtx", *k)
        write_abaqus_whole(tmp_path / "M.mtx", *m)
        src = ["--stiffness", tmp_path / "K.mtx", "--mass", tmp_path / "M.mtx",
               "--nodes", "900001,900003"]
        expected = ref["free_hz"][6:]
    else:
        write_dmig_whole(tmp_path / "model.pch", {"KAAX": k, "MAAX": m})
        src = [tmp_path / "model.pch", "--nodes", "900003"]
        expected = ref["blocked_hz"]
    out = run("import", *src, "--coords", bracket / "nodes.csv", "--fmax", FMAX, "-o",
              tmp_path / "body.fxb", "--report", tmp_path / "r.json")
    report = json.loads((tmp_path / "r.json").read_text())
    assert report["whole_model"]["equations"] > 3000, out
    assert report["free"] == (case == "free")
    below = [f for f in report["frequencies_hz"] if f < FMAX]
    if fmt == "abaqus":
        worst = assert_ccx_frequencies(below, expected)
        print(f"{fmt} ({case}): {len(below)} modes equal ccx's to {worst:.1e}")
        return
    # A punch keeps 10 digits, which moves a solid model's low eigenvalues by up to 1e-6
    # (K's norm is 1e6 times its lowest eigenvalue): the reference is the punched matrices'
    # own eigenvalues (scipy, shift-invert about 0), and ccx's to 1e-5.
    kp, mp = (full_matrix(bracket, case, x, digits=10) for x in ("sti", "mas"))
    lam = spla.eigsh(kp, k=len(below) + 2, M=mp, sigma=0, which="LM",
                     return_eigenvectors=False)
    ref_hz = np.sort(np.sqrt(lam) / (2 * np.pi))[: len(below)]
    worst = np.abs(np.array(below) / ref_hz - 1).max()
    theirs = np.array([float(t) for t in expected[: len(below)]])
    off = np.abs(np.array(below) / theirs - 1).max()
    print(f"{fmt} ({case}): {len(below)} modes equal the punched matrices' to {worst:.1e}, "
          f"ccx's to {off:.1e}")
    assert worst < 1e-7 and off < 1e-5, (worst, off)


def test_readme_whole_model_walkthrough(tmp_path):
    """The README's whole-model commands, run as written in a scratch folder that looks
    like the repository root: a 100 N push along x at spider B of the free bracket gives
    spider B, after 10 ms, the rigid body's velocity F t / m + (I^-1 (r x F) t) x r
    (mass properties from R^T M R of the matrices), to within the vibration the push
    starts (20%)."""
    from test_readme import section_blocks

    for name in ("target", "tests", ".venv"):
        (tmp_path / name).symlink_to(REPO / name)
    blocks = section_blocks("### A whole CalculiX model, from mesh to fmpy")[""]
    [(lang, script)] = blocks
    assert lang == "sh"
    r = subprocess.run(["bash", "-euo", "pipefail", "-c", script], cwd=tmp_path,
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    assert (tmp_path / "out/bracket/free.fmu").is_file()
    vx = float(r.stdout.strip().splitlines()[-1].split(":")[-1])
    mass, c, inertia = rigid_mass_properties(tmp_path / "out/bracket")
    info = json.loads((tmp_path / "out/bracket/done.json").read_text())
    arm = np.array(info["spiders"]["B"]["centre"]) - c
    f, t = np.array([100.0, 0.0, 0.0]), 0.01
    w = np.linalg.solve(inertia, np.cross(arm, f)) * t
    rigid = (f * t / mass + np.cross(w, arm))[0]
    print(f"README walkthrough: vx {vx:.4e} mm/s, rigid F t / m {rigid:.4e}")
    assert abs(vx / rigid - 1) < 0.2, (vx, rigid)


def test_craig_bampton_reduction_equals_scipy_craig_bampton(bracket, tmp_path):
    """`--reduction craig-bampton` on the blocked bracket (spider B the interface, fmax
    20 kHz): every frequency of the body equals that of the Craig-Bampton model built
    here independently with scipy (splu for the constraint modes, eigsh for the
    fixed-interface modes below fmax) to 1e-8."""
    run("import", bracket / "blocked.inp", "--fmax", FMAX, "--reduction", "craig-bampton",
        "-o", tmp_path / "cb.fxb", "--report", tmp_path / "cb.json")
    report = json.loads((tmp_path / "cb.json").read_text())
    k, m = full_matrix(bracket, "blocked", "sti"), full_matrix(bracket, "blocked", "mas")
    dofs = (bracket / "blocked.dof").read_text().split()
    conn = [dofs.index(f"{n}.{c}") for n in (900003, 900004) for c in (1, 2, 3)]
    inner = np.setdiff1d(np.arange(k.shape[0]), conn)
    kii, mii = k[inner][:, inner].tocsc(), m[inner][:, inner].tocsc()
    x = -spla.splu(kii).solve(k[inner][:, conn].toarray())
    lam, phi = spla.eigsh(kii, k=30, M=mii, sigma=0, which="LM")
    keep = np.sqrt(lam) / (2 * np.pi) < FMAX
    phi = phi[:, keep]
    t = np.zeros((k.shape[0], len(conn) + phi.shape[1]))
    t[conn, np.arange(len(conn))] = 1.0
    t[np.ix_(inner, np.arange(len(conn)))] = x
    t[inner, len(conn):] = phi
    kcb, mcb = t.T @ (k @ t), t.T @ (m @ t)
    ref = np.sqrt(la.eigvalsh(kcb, mcb)) / (2 * np.pi)
    ours = np.array(report["frequencies_hz"])
    assert len(ours) == len(ref) == 6 + int(keep.sum()), (len(ours), len(ref))
    err = np.abs(ours / ref - 1).max()
    print(f"Craig-Bampton ({int(keep.sum())} fixed-interface modes + 6): vs scipy {err:.1e}")
    assert err < 1e-8, err


def test_craig_bampton_error_estimates_at_octave_cutoffs(bracket, tmp_path):
    """`--reduction craig-bampton` on the blocked bracket (spider B the interface) at
    octave cut-offs of the fixed-interface spectrum (fmax = 1.001 f1, 2 f1, 4 f1, f1 its
    first frequency, from scipy's eigsh on K_ii, M_ii): the report's estimated frequency
    error of every mode is within 6% of the true error (the issue asks 15%), and not above
    it, the true error being f_body / f_full - 1, the full
    model's frequencies from scipy's shift-invert eigsh on the whole K and M. Modes whose
    true error is below 1e-8 (the body's frequencies equal the Craig-Bampton model's to
    1e-8, so below that the true error is round-off) are left out and counted."""
    k, m = full_matrix(bracket, "blocked", "sti"), full_matrix(bracket, "blocked", "mas")
    dofs = (bracket / "blocked.dof").read_text().split()
    conn = [dofs.index(f"{n}.{c}") for n in (900003, 900004) for c in (1, 2, 3)]
    inner = np.setdiff1d(np.arange(k.shape[0]), conn)
    kii, mii = k[inner][:, inner].tocsc(), m[inner][:, inner].tocsc()
    f1 = np.sqrt(spla.eigsh(kii, k=1, M=mii, sigma=0, which="LM",
                            return_eigenvectors=False)[0]) / (2 * np.pi)
    lam = spla.eigsh(k, k=40, M=m, sigma=0, which="LM", return_eigenvectors=False)
    full = np.sort(np.sqrt(lam) / (2 * np.pi))
    checked, skipped = 0, 0
    for octave in (1.001, 2.0, 4.0):
        report_path = tmp_path / f"cb{octave}.json"
        out = run("import", bracket / "blocked.inp", "--fmax", octave * f1, "--reduction",
                  "craig-bampton", "-o", tmp_path / "cb.fxb", "--report", report_path)
        assert "estimated frequency error" in out, out
        report = json.loads(report_path.read_text())
        ours = np.array(report["frequencies_hz"])
        est = np.array(report["whole_model"]["cb_error_estimates"])
        assert len(est) == len(ours) and len(ours) < len(full), (len(est), len(ours))
        true = ours / full[: len(ours)] - 1
        assert (true > -1e-8).all(), true
        for mode, (e, t) in enumerate(zip(est, true)):
            if t < 1e-8:
                skipped += 1
                continue
            checked += 1
            print(f"fmax {octave:g} f1, mode {mode + 1}: true {t:.3e}, estimate {e:.3e}")
            # The promise is 15%. The shipped enlargement (3 block steps) measures
            # 3.8% at worst; 2 steps give 9.4% and 1 step 31%, so the band is held at 6%,
            # where a shallower enlargement fails. Never above the true error (beyond the
            # body's 1e-8 agreement with the Craig-Bampton model): the enlarged basis's
            # Ritz values are upper bounds of the model's eigenvalues.
            assert abs(e / t - 1) < 0.06, (octave, mode + 1, e, t)
            assert e <= t + 2e-8, (octave, mode + 1, e, t)
    print(f"Craig-Bampton error estimates: {checked} within 6%, {skipped} below 1e-8 left out")
    assert checked >= 10, checked


def test_progress_on_a_terminal_only(bracket, tmp_path):
    """The stage display: on a terminal each stage (read, order and factor, eigen-solve,
    static modes, projection, body, write) is named; with --quiet, or when stderr is not
    a terminal, stderr stays empty."""
    import os
    import pty

    args = [str(EXE), "import", str(bracket / "free.inp"), "--fmax", str(FMAX), "-o",
            str(tmp_path / "p.fxb")]

    def stderr_on_terminal(extra):
        master, slave = pty.openpty()
        p = subprocess.Popen(args + extra, stdout=subprocess.DEVNULL, stderr=slave)
        os.close(slave)
        out = b""
        while True:
            try:
                chunk = os.read(master, 65536)
            except OSError:
                break
            if not chunk:
                break
            out += chunk
        assert p.wait() == 0
        os.close(master)
        return out.decode(errors="replace")

    shown = stderr_on_terminal([])
    for stage in ("read", "order and factor", "eigen-solve", "static modes", "projection",
                  "body", "write"):
        assert f"import: {stage}" in shown, (stage, shown[-2000:])
    assert stderr_on_terminal(["--quiet"]) == ""
    piped = subprocess.run(args, capture_output=True, text=True)
    assert piped.returncode == 0 and piped.stderr == "", piped.stderr


def test_whole_model_errors_name_the_cause(bracket, tmp_path):
    """Each refusal of the whole-model route says what is wrong and what to give."""
    def refused(*args):
        r = subprocess.run([str(EXE), "import", *map(str, args), "-o", str(tmp_path / "x.fxb")],
                           capture_output=True, text=True)
        assert r.returncode != 0, r.stdout
        return r.stderr

    free, blocked = bracket / "free.inp", bracket / "blocked.inp"
    assert "give --fmax" in refused(free)
    e = refused(free, "--fmax", FMAX, "--nodes", "900004")
    assert "node 900004 is the ROT node" in e and "give its REF node 900003" in e, e
    e = refused(blocked, "--fmax", FMAX, "--nodes", "900001")
    assert "node 900001 has no equation" in e, e
    e = refused(blocked, "--fmax", FMAX, "--free")
    assert "is not in K's null space" in e, e
    e = refused(free, "--fmax", FMAX, "--spider", "HOLEC:rigid")
    assert "no node set HOLEC" in e and "HOLEA" in e, e
    e = refused(free, "--fmax", FMAX, "--reduction", "guyan")
    assert "expected modes or craig-bampton" in e, e
    # A single three-DOF node cannot hold a free body's rotations.
    e = refused(free, "--fmax", FMAX, "--nodes", "1", "--reduction", "craig-bampton")
    assert "six rigid motions" in e, e
    bad = tmp_path / "bad.inp"
    bad.write_text("*INCLUDE, INPUT=" + str(bracket / "mesh.inp") + "\n*RIGID BODY, NSET=HOLEA\n")
    for ext in ("sti", "mas", "dof"):
        (tmp_path / f"bad.{ext}").symlink_to(bracket / f"free.{ext}")
    e = refused(bad, "--fmax", FMAX)
    assert "bad.inp:2: *RIGID BODY without REF NODE" in e, e
