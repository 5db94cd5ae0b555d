"""Spiders built by `fxbody import --spider NSET:KIND` on the bracket of
test_import_whole.py without its spider B (the *RIGID BODY on hole B and its REF and ROT
nodes removed), against CalculiX:

- rigid (RBE2-like): the frequencies equal those of ccx's own *RIGID BODY model;
- distributing (RBE3-like, the weighted least-squares rigid motion of the hole's nodes,
  weights their share of the area of the hole's element faces): it adds no stiffness and
  no mass, so every frequency below fmax equals ccx's *FREQUENCY of the model with a
  *COUPLING + *DISTRIBUTING on the hole's faces (7 printed digits); statics: the
  displacement and rotation the packed FMU settles on under a force and a moment at the
  spider node equal G u, u ccx's *STATIC displacement under the distributed loads G^T
  [F; M] (G, the spider's equations, built here with numpy from the mesh), to 1e-6; under
  a force alone, ccx's own *DISTRIBUTING coupling moves the hole exactly as those loads do
  (so the weights are ccx's); free, the six rigid motions stay in K's null space, mass,
  centre of mass and inertia equal R^T M R of ccx's matrices to 1e-10, and the
  frequencies equal scipy's eigsh on those matrices to 1e-8 (ccx's free-free ones are
  good to their printed digits plus about 1e-7, and vary by machine: checked to 1e-6)."""

import json
import subprocess
import sys

import numpy as np
import pytest
import scipy.sparse.linalg as spla

from conftest import EXE, REPO
from test_import_whole import (FMAX, assert_ccx_frequencies, bracket, fmu_static,  # noqa: F401
                               full_matrix, import_pack, printed, rigid_mass_properties, run)

sys.path.insert(0, str(REPO / "tests" / "fe_models"))
from bracket import displacements, frequencies  # noqa: E402

# Spider A clamped (blocked case), as in the bracket's blocked.inp.
HOLD_A = "*BOUNDARY\n900001, 1, 3\n900002, 1, 3\n"
FORCE = np.array([120.0, -80.0, 250.0])
MOMENT = np.array([3000.0, 1500.0, -2200.0])
# The spider node: numbered after the largest node left (900002, spider A's ROT node).
NODE = 900003
# C3D10 faces (corner indices) and mid-side nodes of each edge, in CalculiX's order.
TET_FACES = [(0, 1, 2), (0, 3, 1), (1, 3, 2), (2, 3, 0)]
TET_MID = {(0, 1): 4, (1, 2): 5, (0, 2): 6, (0, 3): 7, (1, 3): 8, (2, 3): 9}


def ccx(folder, job, text):
    """Write folder/job.inp and run ccx on it."""
    (folder / f"{job}.inp").write_text(text)
    r = subprocess.run(["ccx", "-i", job], cwd=folder, capture_output=True, text=True)
    assert r.returncode == 0 and "*ERROR" not in r.stdout, r.stdout[-2000:]
    return folder / f"{job}.dat"


@pytest.fixture(scope="module")
def nob(bracket, tmp_path_factory):  # noqa: F811
    """The bracket's mesh without spider B, its matrices (nob_free, nob_blocked) and its
    elements, hole B's node set and the node coordinates."""
    d = tmp_path_factory.mktemp("nob")
    lines, skip = [], False
    elements, hole_b, block = [], [], None
    for line in (bracket / "mesh.inp").read_text().splitlines():
        upper = line.upper()
        if line.startswith("*"):
            skip = upper.startswith("*NSET, NSET=SPIDERS")
            block = ("E" if upper.startswith("*ELEMENT") else
                     "B" if upper.startswith("*NSET, NSET=HOLEB") else None)
            if skip or (upper.startswith("*RIGID BODY") and "HOLEB" in upper):
                continue
        elif skip or line.split(",")[0].strip() in ("900003", "900004"):
            continue
        elif block == "E":
            elements.append([int(x) for x in line.split(",")][1:])
        elif block == "B":
            hole_b += [int(x) for x in line.split(",") if x.strip()]
        lines.append(line)
    (d / "mesh.inp").write_text("\n".join(lines) + "\n")
    for case, hold in (("nob_free", ""), ("nob_blocked", HOLD_A)):
        ccx(d, case, f"*INCLUDE, INPUT=mesh.inp\n{hold}*STEP\n"
                     "*FREQUENCY, SOLVER=MATRIXSTORAGE\n*END STEP\n")
    xyz = {}
    for line in (bracket / "nodes.csv").read_text().split():
        f = line.split(",")
        xyz[int(f[0])] = np.array([float(v) for v in f[1:]])
    return {"dir": d, "elements": elements, "hole": set(hole_b), "xyz": xyz}


def hole_faces(nob):
    """The C3D10 faces whose six nodes all lie on hole B: (element, face number 1-4,
    nodes corners then mid-sides)."""
    out = []
    for k, e in enumerate(nob["elements"], 1):
        for s, c in enumerate(TET_FACES, 1):
            nodes = [e[i] for i in c] + [e[TET_MID[tuple(sorted((c[i], c[(i + 1) % 3])))]]
                                         for i in range(3)]
            if all(n in nob["hole"] for n in nodes):
                out.append((k, s, nodes))
    return out


def spider_equations(nob):
    """G (6 x 3n) of the distributing spider on hole B over its weighted nodes (x, y, z
    each), those nodes, and the weighted centre: weights integral N_i dA over the hole's
    quadratic triangles (three-point rule, exact on these flat faces)."""
    area = {}
    gauss = [(1 / 6, 1 / 6), (2 / 3, 1 / 6), (1 / 6, 2 / 3)]
    for _, _, nodes in hole_faces(nob):
        x = np.array([nob["xyz"][n] for n in nodes])
        for r, s in gauss:
            t = 1 - r - s
            n = np.array([t * (2 * t - 1), r * (2 * r - 1), s * (2 * s - 1), 4 * t * r,
                          4 * r * s, 4 * s * t])
            dr = np.array([1 - 4 * t, 4 * r - 1, 0, 4 * (t - r), 4 * s, -4 * s])
            ds = np.array([1 - 4 * t, 0, 4 * s - 1, -4 * r, 4 * r, 4 * (t - s)])
            da = np.linalg.norm(np.cross(dr @ x, ds @ x)) / 6
            for node, ni in zip(nodes, n):
                area[node] = area.get(node, 0.0) + da * ni
    top = max(abs(a) for a in area.values())
    nodes = sorted(n for n, a in area.items() if abs(a) > 1e-9 * top)
    w = np.array([area[n] for n in nodes])
    w /= w.sum()
    x = np.array([nob["xyz"][n] for n in nodes])
    c = w @ x
    p = x - c
    j = sum(wi * (pi @ pi * np.eye(3) - np.outer(pi, pi)) for wi, pi in zip(w, p))
    g = np.zeros((6, 3 * len(nodes)))
    for i, (wi, pi) in enumerate(zip(w, p)):
        for k in range(3):
            g[k, 3 * i + k] = wi
            g[3:, 3 * i + k] = np.linalg.solve(j, wi * np.cross(pi, np.eye(3)[k]))
    return g, nodes, c


def static_under_loads(nob, job, g, nodes, load):
    """G u, u ccx's *STATIC displacement of hole B's weighted nodes (blocked) under the
    nodal loads G^T load, and its bound from ccx's printed digits (|G| times half a unit
    of each printed digit)."""
    f = g.T @ load
    cload = "".join(f"{n}, {k + 1}, {float(f[3 * i + k])!r}\n" for i, n in enumerate(nodes)
                    for k in range(3))
    dat = ccx(nob["dir"], job, f"*INCLUDE, INPUT=mesh.inp\n{HOLD_A}*STEP\n*STATIC\n"
                               f"*CLOAD\n{cload}*NODE PRINT, NSET=HOLEB\nU\n*END STEP\n")
    u = displacements(dat)
    vals = np.array([printed(t) for n in nodes for t in u[n]])
    return g @ vals[:, 0], np.abs(g) @ vals[:, 1], u


def test_rigid_spider_built_from_a_node_set(bracket, nob, tmp_path):  # noqa: F811
    """The free bracket without spider B's *RIGID BODY; `--spider HOLEB:rigid` builds
    the spider on the hole's node set. The six rigid motions stay in K's null space, and
    the frequencies below fmax equal those of ccx's own *RIGID BODY model (the free.inp
    import, and ccx's printed *FREQUENCY) to 1e-7."""
    run("import", nob["dir"] / "nob_free.inp", "--spider", "HOLEB:rigid", "--fmax", FMAX,
        "-o", tmp_path / "nob.fxb", "--report", tmp_path / "nob.json")
    built = json.loads((tmp_path / "nob.json").read_text())
    run("import", bracket / "free.inp", "--fmax", FMAX, "-o", tmp_path / "free.fxb",
        "--report", tmp_path / "free.json")
    spider = json.loads((tmp_path / "free.json").read_text())
    assert built["free"] and built["nodes"] == 2
    residual = built["whole_model"]["rigid_residual"]
    assert residual < 1e-13, residual
    a, b = (np.array(x["whole_model"]["model_hz"]) for x in (built, spider))
    assert len(a) == len(b) == 14
    diff = np.abs(a / b - 1).max()
    ref = json.loads((bracket / "reference.json").read_text())
    worst = assert_ccx_frequencies([f for f in built["frequencies_hz"] if f < FMAX],
                                   ref["free_hz"][6:])
    print(f"built rigid spider: |K r|/(|K||r|) {residual:.1e}, frequencies vs ccx's "
          f"*RIGID BODY model {diff:.1e} (vs its printed ones {worst:.1e})")
    assert diff < 1e-7, diff


def coupling_deck(nob, hold, step):
    """The mesh with ccx's own distributing coupling on hole B's faces (REF node at the
    weighted centre, DOFs 1-6), `hold`, then `step`."""
    _, _, c = spider_equations(nob)
    surf = "".join(f"{k}, S{s}\n" for k, s, _ in hole_faces(nob))
    return (f"*INCLUDE, INPUT=mesh.inp\n*NODE\n{NODE}, {float(c[0])!r}, {float(c[1])!r}, {float(c[2])!r}\n"
            f"*SURFACE, NAME=SB, TYPE=ELEMENT\n{surf}"
            f"*COUPLING, REF NODE={NODE}, SURFACE=SB, CONSTRAINT NAME=CB\n"
            f"*DISTRIBUTING\n1, 6\n{hold}*STEP\n{step}*END STEP\n")


def test_distributing_spider_blocked_statics_and_frequencies(nob, tmp_path):
    """Blocked (spider A clamped), `--spider HOLEB:distributing`: frequencies below fmax
    equal ccx's *FREQUENCY with its *COUPLING + *DISTRIBUTING on the hole (7 digits); the
    FMU's static displacement and rotation of the spider node under a force and a moment
    equal G u from ccx's *STATIC under G^T [F; M] to 1e-6; under the force alone, ccx's
    own coupling gives the hole the displacements of those loads (printed digits)."""
    d = nob["dir"]
    _, fmu, info, report = import_pack(d, "nob_blocked", tmp_path, "--spider",
                                       "HOLEB:distributing")
    assert report["nodes"] == 1 and not report["free"]
    g, nodes, c = spider_equations(nob)
    placed = np.loadtxt(tmp_path / "nob_blocked.nodes.csv", delimiter=",", ndmin=2, skiprows=1)
    assert np.abs(placed[0, 1:] - c).max() < 1e-12 * np.abs(c).max(), (placed, c)
    dat = ccx(d, "coupled_freq", coupling_deck(nob, HOLD_A, "*FREQUENCY\n24\n"))
    below = [f for f in info["frequencies_hz"] if f < FMAX]
    worst_f = assert_ccx_frequencies(below, frequencies(dat))
    ours = fmu_static(fmu, tmp_path / "x", NODE, FORCE, MOMENT)
    theirs, bound, _ = static_under_loads(nob, "spread", g, nodes,
                                          np.concatenate([FORCE, MOMENT]))
    for part, sl in (("translation", slice(0, 3)), ("rotation", slice(3, 6))):
        err = np.abs(ours[sl] - theirs[sl])
        rel = err.max() / np.abs(theirs[sl]).max()
        print(f"distributing static {part}: FMU {ours[sl]}, ccx G u {theirs[sl]}, rel {rel:.1e}")
        assert np.all(err <= np.maximum(1e-6 * np.abs(theirs[sl]).max(), bound[sl])), \
            (part, ours[sl], theirs[sl], bound[sl])
    # ccx's own distributing coupling under the force alone: the same hole displacements
    # as the loads w_i F, so ccx weighs the nodes as we do.
    _, _, spread = static_under_loads(nob, "spread_f", g, nodes,
                                      np.concatenate([FORCE, np.zeros(3)]))
    own = displacements(ccx(d, "coupled_static", coupling_deck(
        nob, HOLD_A, f"*STATIC\n*CLOAD\n" + "".join(f"{NODE}, {k + 1}, {float(FORCE[k])!r}\n"
                                                     for k in range(3))
        + "*NODE PRINT, NSET=HOLEB\nU\n")))
    worst = 0.0
    for n in nob["hole"]:
        for a, b in zip(own[n], spread[n]):
            (x, hx), (y, hy) = printed(a), printed(b)
            assert abs(x - y) <= hx + hy, (n, own[n], spread[n])
            worst = max(worst, abs(x - y))
    print(f"distributing: {len(below)} modes equal ccx's coupled model to {worst_f:.1e}; "
          f"ccx's coupling vs our weights: hole displacements within {worst:.1e} mm")


def test_distributing_spider_free_null_space_mass_and_frequencies(bracket, nob,  # noqa: F811
                                                                  tmp_path):
    """Free, `--spider HOLEB:distributing` (with spider A's *RIGID BODY the two
    connections): the rigid motions stay in K's null space, mass, centre of mass and
    inertia equal R^T M R of ccx's matrices (the spider adds no mass) to 1e-10, and the
    frequencies below fmax equal scipy's eigsh on ccx's matrices to 1e-8 and ccx's
    *FREQUENCY with its own coupling to its printed digits plus 1e-6 (ccx's free-free
    eigen-solution, across machines; scipy's agrees with ours to 1e-8)."""
    d = nob["dir"]
    _, _, info, report = import_pack(d, "nob_free", tmp_path, "--spider",
                                     "HOLEB:distributing")
    assert report["free"] and report["nodes"] == 2
    residual = report["whole_model"]["rigid_residual"]
    m, c, inertia = rigid_mass_properties(bracket, d, "nob_free", rot={900002})
    got = report["mass"]
    em = abs(got["total_mass"] / m - 1)
    ec = np.abs(np.array(got["center_of_mass"]) - c).max() / np.abs(c).max()
    ei = np.abs(np.array(got["inertia"]) - inertia).max() / np.abs(inertia).max()
    dat = ccx(d, "coupled_free", coupling_deck(nob, "", "*FREQUENCY\n30\n"))
    below = np.array([f for f in info["frequencies_hz"] if f < FMAX])
    theirs = np.array([printed(t) for t in frequencies(dat)[6:]])
    theirs = theirs[theirs[:, 0] < FMAX]
    # ccx's free-free eigenvalues are a little less accurate than its printed digits (its
    # third mode prints 3788.092 where scipy's eigsh on the same matrices, and we, have
    # 3788.0926), and its ARPACK rounds differently per machine (the 7th digit moves): to
    # 1e-8 against scipy, and to ccx's printed digits plus 1e-6.
    k, m = (full_matrix(d, "nob_free", x) for x in ("sti", "mas"))
    lam = spla.eigsh(k, k=len(below) + 6, M=m, sigma=-1e4, which="LM",
                     return_eigenvectors=False)
    exact = np.sort(np.sqrt(np.abs(lam)) / (2 * np.pi))[6:]
    assert len(below) == len(theirs) == len(exact), (below, theirs, exact)
    off_scipy = np.abs(below / exact - 1).max()
    off_ccx = (np.maximum(np.abs(below - theirs[:, 0]) - theirs[:, 1], 0) / below).max()
    print(f"distributing free: |K r|/(|K||r|) {residual:.1e}; R^T M R: mass {em:.1e}, "
          f"centre {ec:.1e}, inertia {ei:.1e}; {len(below)} modes equal scipy's to "
          f"{off_scipy:.1e}, ccx's coupled model's to its printed digits + {off_ccx:.1e}")
    assert residual < 1e-12, residual
    assert max(em, ec, ei) < 1e-10, (em, ec, ei)
    assert off_scipy < 1e-8 and off_ccx < 1e-6, (off_scipy, off_ccx)


def test_distributing_spider_refusals(nob, tmp_path):
    """A set on no element face (two nodes of the hole), or not in the deck, is refused
    with what is wrong."""
    d = nob["dir"]
    few = sorted(nob["hole"])[:2]
    (tmp_path / "few.inp").write_text(f"*INCLUDE, INPUT={d / 'mesh.inp'}\n*NSET, NSET=FEW\n"
                                      f"{few[0]}, {few[1]}\n")
    for ext in ("sti", "mas", "dof"):
        (tmp_path / f"few.{ext}").symlink_to(d / f"nob_free.{ext}")

    def refused(spider):
        r = subprocess.run([str(EXE), "import", str(tmp_path / "few.inp"), "--fmax", str(FMAX),
                            "--spider", spider, "-o", str(tmp_path / "x.fxb")],
                           capture_output=True, text=True)
        assert r.returncode != 0, r.stdout
        return r.stderr

    e = refused("FEW:distributing")
    assert "no element face of" in e and "has all its nodes in set FEW" in e, e
    e = refused("NOPE:distributing")
    assert "no node set NOPE" in e, e
