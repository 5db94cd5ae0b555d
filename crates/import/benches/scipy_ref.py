"""scipy's reference for crates/import/benches/sparse.rs: the core of a Hurty-Craig-Bampton
import as Exudyn's FEMinterface does it, on the same CalculiX matrices.

    python scipy_ref.py JOB SIGMA K_MODES CONN_EQUATIONS

`JOB.sti`/`JOB.mas`: `row col value` upper triangles (1-based). Times, on one line of JSON:
reading the files with numpy; `eigsh` in shift-invert mode at SIGMA for K_MODES eigenpairs
(SuperLU factorisation of K - SIGMA M inside); `splu` of K - SIGMA M and a solve for the
comma-separated 0-based connection equations (the static modes' factor and solves). Also
the CPU time after reading and the process's peak resident memory.
"""

import json
import resource
import sys
import time

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as sla


def read(path, n=None):
    with open(path, "rb") as f:
        data = np.array(f.read().split(), dtype=np.float64).reshape(-1, 3)
    r = data[:, 0].astype(np.int64) - 1
    c = data[:, 1].astype(np.int64) - 1
    v = data[:, 2]
    n = n or int(max(r.max(), c.max())) + 1
    upper = sp.coo_matrix((v, (r, c)), shape=(n, n)).tocsc()
    return upper + sp.triu(upper, 1).T.tocsc()


def main():
    job, sigma, k_modes, conn = sys.argv[1], float(sys.argv[2]), int(sys.argv[3]), sys.argv[4]
    conn = [int(x) for x in conn.split(",")]
    t = time.perf_counter()
    K = read(job + ".sti")
    M = read(job + ".mas", K.shape[0])
    t_read = time.perf_counter() - t
    usage = resource.getrusage(resource.RUSAGE_SELF)
    cpu0 = usage.ru_utime + usage.ru_stime
    t = time.perf_counter()
    vals, _ = sla.eigsh(K, k=k_modes, M=M, sigma=sigma, which="LM")
    t_eig = time.perf_counter() - t
    t = time.perf_counter()
    lu = sla.splu((K - sigma * M).tocsc())
    rhs = np.zeros((K.shape[0], len(conn)))
    for j, e in enumerate(conn):
        rhs[e, j] = 1.0
    lu.solve(rhs)
    t_static = time.perf_counter() - t
    usage = resource.getrusage(resource.RUSAGE_SELF)
    peak = usage.ru_maxrss / 1024.0
    cpu = usage.ru_utime + usage.ru_stime - cpu0
    print(json.dumps({
        "read": t_read, "eigsh": t_eig, "splu_static": t_static,
        "lambda": sorted(float(x) for x in vals), "peak_mb": peak, "cpu": cpu,
    }))


if __name__ == "__main__":
    main()
