#!/usr/bin/env python3
"""How long `fxbody import` takes against the size of the dense problem (not a test:
speed is never asserted). Writes a free grillage of frame members (fixtures/fe.py, six
DOFs a node, consistent mass) as Abaqus lines with its node list, runs the import, and
prints its wall time beside two same-run references for the machine's speed and load:
the time `awk` takes to read the same two matrix files, and the time LAPACK's generalised
symmetric eigen-solver (scipy.linalg.eigh(K, M), one thread, eigenvectors) takes on the
same matrices, the one step any dense import must do:

    .venv/bin/python tests/python/import_sizes.py [DOFS ...] [--fmax HZ] [--all-nodes]
    # default sizes 1000 2000 3000 4000

Four corner nodes are kept, as a reduction to an interface would; `--all-nodes` keeps
every grid point as an FXB node (the default of `import`, a larger file). `--fmax HZ`
imports with that cut (static modes for the nodes added). With FXBODY_IMPORT_TIMES set,
the import's own stage times follow each line."""

import pathlib
import subprocess
import sys
import tempfile
import time

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")

import numpy as np  # noqa: E402
import scipy.linalg as la  # noqa: E402

HERE = pathlib.Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
import import_models as im  # noqa: E402

EXE = HERE.parents[1] / "target" / "release" / "fxbody"


def grillage(dofs):
    """A free grillage of about `dofs` DOFs: nx x ny nodes, nx ~ 1.2 ny."""
    nodes = dofs // 6
    ny = max(2, int(round((nodes / 1.2) ** 0.5)))
    nx = max(2, int(round(nodes / ny)))
    sec = im.fe.rect_section(0.04, 0.03)
    xyz, k, m, _ = im.fe.grillage_model(nx, ny, 0.05 * (nx - 1), 0.05 * (ny - 1), im.E, im.G,
                                        im.RHO, sec)
    ids = list(range(1, nx * ny + 1))
    corners = [1, nx, nx * (ny - 1) + 1, nx * ny]
    return ids, xyz, k.toarray(), m.toarray(), corners


def main(argv):
    all_nodes = "--all-nodes" in argv
    fmax = argv[argv.index("--fmax") + 1] if "--fmax" in argv else None
    rest = [a for i, a in enumerate(argv) if not a.startswith("--")
            and not (i > 0 and argv[i - 1] == "--fmax")]
    sizes = [int(a) for a in rest] or [1000, 2000, 3000, 4000]
    print(f"DOFs   import_s  lapack_eigh_s  awk_read_s  bytes(K+M)  nodes  (fmax {fmax})")
    for n in sizes:
        ids, xyz, k, m, corners = grillage(n)
        with tempfile.TemporaryDirectory() as d:
            d = pathlib.Path(d)
            dofs = im.reduced_dofs(ids, ids)
            im.write_abaqus(d / "K.mtx", dofs, k)
            im.write_abaqus(d / "M.mtx", dofs, m)
            im.write_csv(d / "nodes.csv", ids, xyz)
            size = (d / "K.mtx").stat().st_size + (d / "M.mtx").stat().st_size
            t0 = time.perf_counter()
            subprocess.run(["awk", "-F,", "{s += $5} END {print s}", str(d / "K.mtx"),
                            str(d / "M.mtx")], check=True, capture_output=True)
            t_awk = time.perf_counter() - t0
            args = [str(EXE), "import", "--stiffness", str(d / "K.mtx"), "--mass",
                    str(d / "M.mtx"), "--coords", str(d / "nodes.csv"), "-o", str(d / "g.fxb")]
            if not all_nodes:
                args += ["--nodes", ",".join(map(str, corners))]
            if fmax:
                args += ["--fmax", fmax]
            t0 = time.perf_counter()
            r = subprocess.run(args, capture_output=True, text=True)
            t_imp = time.perf_counter() - t0
            status = "" if r.returncode == 0 else "  FAILED: " + r.stderr.strip()[:200]
            t0 = time.perf_counter()
            la.eigh(k, m)
            t_eigh = time.perf_counter() - t0
            print(f"{k.shape[0]:5d}  {t_imp:8.2f}  {t_eigh:13.2f}  {t_awk:10.2f}  {size:10d}  "
                  f"{'all' if all_nodes else 4}{status}", flush=True)
            for line in r.stderr.splitlines():
                if line.startswith("import stage"):
                    print("    " + line, flush=True)


if __name__ == "__main__":
    main(sys.argv[1:])
