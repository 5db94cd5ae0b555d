"""The numpy loop a Python user would write for the benchmark scene: the exact discrete
state space of the modal equations (zero-order hold), stepped one sample at a time.
usage: fmi_numpy.py MATRICES.json STEPS H  -> prints 'ns_per_step X' and 'y_final Y'"""

import json
import sys
import time

import numpy as np
from scipy.linalg import expm

d = json.load(open(sys.argv[1]))
steps, h = int(sys.argv[2]), float(sys.argv[3])
K = np.array(d["k_l"])
m = np.array(d["m_l"])
phi_in = np.array(d["phi_in"])    # modal load vector of the input
C_out = np.array(d["phi_out"])    # modal rows of the outputs (positions minus x0)
n = len(m)
A = np.zeros((2 * n, 2 * n))
A[:n, n:] = np.eye(n)
A[n:, :n] = -K / m[:, None]
B = np.zeros((2 * n, 1))
B[n:, 0] = phi_in / m
aug = np.zeros((2 * n + 1, 2 * n + 1))
aug[:2 * n, :2 * n] = A
aug[:2 * n, 2 * n:] = B
E = expm(aug * h)
Ad, Bd = E[:2 * n, :2 * n], E[:2 * n, 2 * n]
C = np.hstack([C_out, np.zeros_like(C_out)])
x = np.zeros(2 * n)
force = float(d["force"])
t0 = time.perf_counter()
for k in range(steps):
    u = force * np.sin(1e-3 * k)
    x = Ad @ x + Bd * u
    y = C @ x
ns = (time.perf_counter() - t0) / steps * 1e9
print(f"ns_per_step {ns:.1f}")
print(f"y_final {float(y[0])!r}")
