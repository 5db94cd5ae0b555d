"""The frequencies of an imported body against a second implementation: a 1,200-DOF
grillage of frame members (fixtures/fe.py, six DOFs a node, consistent mass), free and
clamped at one node, imported whole (no --fmax) and cut (--fmax), and its lowest
frequencies compared with ARPACK's shift-invert Lanczos on the sparse K and M
(scipy.sparse.linalg.eigsh with a shift near the lowest elastic eigenvalue, factored by
SuperLU): to 1e-8 relative, for the lowest 20 modes without --fmax and for every kept mode
with it. Stiff grillages are where a dense solver loses the low modes' relative accuracy
(the lowest eigenvalue is 1e-7 of the largest free, 1e-9 clamped)."""

import json
import pathlib
import subprocess
import sys

import numpy as np
import pytest
import scipy.linalg as la
import scipy.sparse.linalg as sla

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
import import_models as im  # noqa: E402
from conftest import EXE, FIXTURES  # noqa: E402

sys.path.insert(0, str(FIXTURES))
import fxbread  # noqa: E402

NX, NY = 20, 10  # 200 nodes, 1,200 DOFs
LOWEST = 20


def hz(w2):
    return np.sqrt(np.clip(w2, 0.0, None)) / (2 * np.pi)


@pytest.fixture(scope="module", params=["free", "clamped"])
def grillage(request):
    sec = im.fe.rect_section(0.04, 0.03)
    xyz, k, m, _ = im.fe.grillage_model(NX, NY, 0.05 * (NX - 1), 0.05 * (NY - 1), im.E, im.G,
                                        im.RHO, sec)
    ids = list(range(1, NX * NY + 1))
    if request.param == "clamped":
        keep = np.arange(6, k.shape[0])
        k, m, grid = k[keep][:, keep], m[keep][:, keep], ids[1:]
    else:
        grid = ids
    return request.param, ids, xyz, grid, k.tocsc(), m.tocsc()


def reference(k, m, rigid, count):
    """The lowest `count` elastic eigenvalues by shift-invert Lanczos. A shift near zero
    makes K - sigma M nearly singular for a free body (its factor then costs digits:
    measured 1e-7), so a first pass gives the lowest elastic eigenvalue and the second
    shifts to half of it; a third, shifted to the other side of it, must agree."""
    v0 = np.ones(k.shape[0])
    rough = np.sort(sla.eigsh(k, k=rigid + 1, M=m, sigma=-1.0, v0=v0)[0])[rigid]
    runs = [np.sort(sla.eigsh(k, k=rigid + count, M=m, sigma=s * rough, v0=v0, tol=0)[0])[rigid:]
            for s in (-0.5, 0.5)]
    spread = np.abs(runs[1] / runs[0] - 1).max()
    assert spread < 1e-10, f"the reference's two shifts disagree by {spread:.1e}"
    return runs[0]


def run_import(tmp_path, kind, ids, xyz, grid, k, m, extra):
    dofs = im.reduced_dofs(grid, grid)
    im.write_abaqus(tmp_path / "K.mtx", dofs, k.toarray())
    im.write_abaqus(tmp_path / "M.mtx", dofs, m.toarray())
    im.write_csv(tmp_path / "nodes.csv", ids, xyz)
    corners = [NX, NX * (NY - 1) + 1, NX * NY]
    args = [EXE, "import", "--stiffness", tmp_path / "K.mtx", "--mass", tmp_path / "M.mtx",
            "--coords", tmp_path / "nodes.csv", "--nodes", ",".join(map(str, corners)),
            "--free" if kind == "free" else "--blocked", "-o", tmp_path / "g.fxb",
            "--report", tmp_path / "g.json", *extra]
    r = subprocess.run([str(a) for a in args], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    rep = json.loads((tmp_path / "g.json").read_text())
    body = fxbread.read_fxb((tmp_path / "g.fxb").read_text())
    return rep, body


@pytest.mark.parametrize("cut", [False, True])
def test_frequencies_equal_shift_invert_reference(grillage, tmp_path, cut):
    kind, ids, xyz, grid, k, m = grillage
    rigid = 6 if kind == "free" else 0
    ref = reference(k, m, rigid, LOWEST + 5)
    # a cut between the 15th and 16th elastic modes: 15 eigenmodes kept, statics added
    fmax = float(hz(np.sqrt(ref[14] * ref[15]))) if cut else None
    rep, body = run_import(tmp_path, kind, ids, xyz, grid, k, m,
                           ["--fmax", repr(fmax)] if cut else [])
    assert rep["eigenmodes"] == (15 if cut else k.shape[0] - rigid)
    count = 15 if cut else LOWEST
    # the written file (10 significant digits) and the report (full precision)
    # the static modes lie in the dropped modes' span: their frequencies are above the cut
    f_file = hz(la.eigvalsh(body["k_l"], np.diag(body["m_l"])))[:count]
    f_rep = np.sort(np.array(rep["frequencies_hz"]))[:count]
    want = hz(ref[:count])
    e_rep = np.abs(f_rep / want - 1).max()
    e_file = np.abs(f_file / want - 1).max()
    print(f"{kind} {'--fmax' if cut else 'whole'}: lowest {count} frequencies off the "
          f"shift-invert reference by {e_rep:.1e} (report), {e_file:.1e} (file)")
    assert e_rep < 1e-8 and e_file < 1e-8, (e_rep, e_file)
