"""examples/dask_sweep.py on a LocalCluster of two worker processes: the 64 runs equal,
bit for bit, the same runs made one after the other in this process (so fmi2Reset returns
an instance to exactly its initial state, and where a run happens does not matter); each
worker made one FMU instance and reused it; the table follows the full-FE reference and
the laws a linear damped body obeys."""

import csv
import os
import shutil
import subprocess
import sys

import numpy as np
import pytest
from fmpy import read_model_description

from conftest import REPO, missing, pack_fmu, reference

sys.path.insert(0, str(REPO / "examples"))
import dask_sweep  # noqa: E402


@pytest.fixture(scope="module")
def tip_fmu(fmu_dir):
    fmu = pack_fmu(fmu_dir, "cantilever", "--nodes", "121", name="cantilever_sweep")
    names = {v.name for v in read_model_description(str(fmu)).modelVariables}
    assert "damping.ratio" in names, "the sweep needs the damping.ratio parameter"
    return fmu


@pytest.fixture(scope="module")
def cluster():
    """Two worker processes, one thread each, on this machine."""
    try:
        from dask.distributed import LocalCluster
    except ImportError as e:
        missing("dask.distributed", f"cannot be imported: {e}")
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as c:
        yield c


@pytest.fixture(scope="module")
def serial(tip_fmu):
    return dask_sweep.serial(str(tip_fmu))


def test_sweep_on_a_local_cluster_equals_the_serial_runs(tip_fmu, cluster, serial, tmp_path):
    from dask.distributed import Client

    with Client(cluster) as client:
        rows = dask_sweep.sweep(client, str(tip_fmu))
        stats = client.run(dask_sweep.worker_stats)
    assert len(rows) == len(serial) == 64
    for got, want in zip(rows, serial):
        assert got == want, (got, want)  # floats compared exactly: bit for bit

    # Each worker process loaded the FMU at most once (one instance per thread, one
    # thread per worker) and every run went through one of those instances.
    assert all(s["instances"] <= 1 for s in stats.values()), stats
    assert sum(s["runs"] for s in stats.values()) == 64, stats

    peak = {(r["amplitude_N"], r["damping_ratio"]): r["peak_tip_deflection_m"] for r in rows}
    # Undamped, 1 N: the full-FE tip response's peak over the same 0.2 s, within the
    # exact method's 0.5% floor (test_fmu.py).
    resp = next(r for r in reference("cantilever")["responses"] if r["name"] == "step")
    t, uy = np.array(resp["t"]), np.array(resp["nodes"]["121"]["uy"])
    want = np.abs(uy[t <= dask_sweep.H * dask_sweep.STEPS + 1e-12]).max()
    assert abs(peak[(1.0, 0.0)] - want) <= 5e-3 * want, (peak[(1.0, 0.0)], want)
    for ratio in dask_sweep.RATIOS:
        # Linear body: the peak is proportional to the load amplitude (round-off).
        per_newton = np.array([peak[(a, ratio)] / a for a in dask_sweep.AMPLITUDES])
        assert np.ptp(per_newton) <= 1e-12 * per_newton.max(), (ratio, per_newton)
    # More damping, a lower peak; from the undamped overshoot (about twice the static
    # deflection) down towards the static deflection itself.
    by_ratio = [peak[(1.0, r)] for r in sorted(dask_sweep.RATIOS)]
    assert all(a > b for a, b in zip(by_ratio, by_ratio[1:])), by_ratio
    static = next(s for s in reference("cantilever")["static"] if s["load_dof"] == "fy")["displacements"]["121"][1]
    assert 1.9 * static < by_ratio[0] < 2.05 * static and by_ratio[-1] < 1.3 * static, (by_ratio, static)

    dask_sweep.write_csv(rows, tmp_path / "sweep.csv")
    dask_sweep.write_svg(rows, tmp_path / "sweep.svg")
    with open(tmp_path / "sweep.csv") as f:
        back = list(csv.DictReader(f))
    assert [float(r["peak_tip_deflection_m"]) for r in back] == [r["peak_tip_deflection_m"] for r in rows]
    svg = (tmp_path / "sweep.svg").read_text()
    assert svg.count("<rect") == 64 and svg.rstrip().endswith("</svg>")


def test_readme_code_runs_against_a_scheduler_address(tip_fmu, cluster, serial, tmp_path):
    """The README's code for a multi-machine cluster, with its scheduler address
    (tcp://scheduler:8786) replaced by the LocalCluster's, run as a script from a folder
    laid out like the repository; and the command line with --scheduler. Both tables
    equal the serial runs."""
    from test_readme import section_blocks

    [(lang, code)] = section_blocks("## Parameter sweeps on a Dask cluster")[""]
    assert lang == "python" and "tcp://scheduler:8786" in code
    os.symlink(REPO / "examples", tmp_path / "examples")
    (tmp_path / "out").mkdir()
    shutil.copy(tip_fmu, tmp_path / "out" / "cantilever.fmu")
    (tmp_path / "snippet.py").write_text(code.replace("tcp://scheduler:8786", cluster.scheduler_address))
    run = subprocess.run([sys.executable, "snippet.py"], cwd=tmp_path, capture_output=True, text=True)
    assert run.returncode == 0, run.stdout + run.stderr

    dask_sweep.main([str(tip_fmu), "--scheduler", cluster.scheduler_address, "--out", str(tmp_path / "cli")])
    want = [repr(r["peak_tip_deflection_m"]) for r in serial]
    for table in (tmp_path / "sweep.csv", tmp_path / "cli" / "sweep.csv"):
        with open(table) as f:
            assert [r["peak_tip_deflection_m"] for r in csv.DictReader(f)] == want, table
    assert (tmp_path / "cli" / "sweep.svg").is_file()
