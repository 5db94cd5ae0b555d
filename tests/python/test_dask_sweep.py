"""examples/dask_sweep.py on a LocalCluster of two worker processes: the 64 runs equal,
bit for bit, the same runs made one after the other in this process (so fmi2Reset returns
an instance to exactly its initial state, and where a run happens does not matter); each
worker made one FMU instance and reused it; the table follows the full-FE reference and
the laws a linear damped body obeys. And the sweep is not hard-wired to the cantilever's
tip: on a second FMU exposing node 111 (mid-span), with its own load and grid given on
the command line, it follows beam theory there."""

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

    peak = {(r["amplitude"], r["damping_ratio"]): r["peak_deflection"] for r in rows}
    # Undamped, 1 N: the full-FE tip response's peak over the same 0.2 s, within the
    # exact method's 0.5% floor (test_fmu.py).
    resp = next(r for r in reference("cantilever")["responses"] if r["name"] == "step")
    t, uy = np.array(resp["t"]), np.array(resp["nodes"]["121"]["uy"])
    want = np.abs(uy[t <= dask_sweep.H * dask_sweep.STEPS + 1e-12]).max()
    assert len(rows) == len(dask_sweep.AMPLITUDES) * len(dask_sweep.RATIOS)
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
    assert [float(r["peak_deflection"]) for r in back] == [r["peak_deflection"] for r in rows]
    svg = (tmp_path / "sweep.svg").read_text()
    assert svg.count("<rect") == 64 and svg.rstrip().endswith("</svg>")


def test_readme_code_runs_against_a_scheduler_address(tip_fmu, cluster, serial, tmp_path):
    """docs/MASTERS.md's code for a multi-machine cluster, with its scheduler address
    (tcp://scheduler:8786) replaced by the LocalCluster's, run as a script from a folder
    laid out like the repository; and the command line with --scheduler. Both tables
    equal the serial runs."""
    from test_readme import section_blocks

    [(lang, code)] = section_blocks("## Parameter sweeps on a Dask cluster", REPO / "docs" / "MASTERS.md")[""]
    assert lang == "python" and "tcp://scheduler:8786" in code
    os.symlink(REPO / "examples", tmp_path / "examples")
    (tmp_path / "out").mkdir()
    shutil.copy(tip_fmu, tmp_path / "out" / "cantilever.fmu")
    (tmp_path / "snippet.py").write_text(code.replace("tcp://scheduler:8786", cluster.scheduler_address))
    run = subprocess.run([sys.executable, "snippet.py"], cwd=tmp_path, capture_output=True, text=True)
    assert run.returncode == 0, run.stdout + run.stderr

    dask_sweep.main([str(tip_fmu), "--scheduler", cluster.scheduler_address, "--out", str(tmp_path / "cli")])
    want = [repr(r["peak_deflection"]) for r in serial]
    for table in (tmp_path / "sweep.csv", tmp_path / "cli" / "sweep.csv"):
        with open(table) as f:
            assert [r["peak_deflection"] for r in csv.DictReader(f)] == want, table
    assert (tmp_path / "cli" / "sweep.svg").is_file()


@pytest.fixture(scope="module")
def mid_fmu(fmu_dir):
    """A second FMU of the cantilever: node 111, at mid-span (x = 0.5 m), only."""
    return pack_fmu(fmu_dir, "cantilever", "--nodes", "111", name="cantilever_mid")


def test_sweep_takes_the_node_the_load_and_the_grid(mid_fmu, cluster, tmp_path):
    """The command line on the mid-span FMU: node 111, load fy, a grid of 2 amplitudes x
    3 ratios, 1500 steps of 0.2 ms. Against beam theory at node 111, P a^3 / (3 E Iz)
    (a = 0.5 m; the body's static modes are at the tip, so its own static deflection at
    111 is 2.8e-4 off, tests/all/cli/info.rs): undamped, the step response overshoots to
    about twice it (1.9 to 2.05 x, as at the tip: the first mode dominates); at damping
    ratio 0.5 it stays below 1.3 x; the peak is linear in the load (round-off). The
    cluster's table equals the serial runs bit for bit."""
    from dask.distributed import Client

    out = tmp_path / "mid"
    dask_sweep.main([str(mid_fmu), "--node", "111", "--load", "fy", "--amplitudes", "1,3",
                     "--ratios", "0, 0.05,0.5", "--step", "2e-4", "--steps", "1500",
                     "--scheduler", cluster.scheduler_address, "--out", str(out)])
    with open(out / "sweep.csv") as f:
        rows = [{k: float(v) for k, v in r.items()} for r in csv.DictReader(f)]
    assert [(r["amplitude"], r["damping_ratio"]) for r in rows] == [
        (a, z) for z in (0.0, 0.05, 0.5) for a in (1.0, 3.0)]
    config = dask_sweep.Sweep(node=111, load="fy", amplitudes=(1.0, 3.0), ratios=(0.0, 0.05, 0.5),
                              step=2e-4, steps=1500)
    assert [r["peak_deflection"] for r in rows] == [
        r["peak_deflection"] for r in dask_sweep.serial(str(mid_fmu), config)]
    with Client(cluster) as client:
        assert dask_sweep.sweep(client, str(mid_fmu), config) == dask_sweep.serial(str(mid_fmu), config)

    model = reference("cantilever")["model"]
    static = 0.5 ** 3 / (3 * model["E"] * model["section"]["Iz"])
    peak = {(r["amplitude"], r["damping_ratio"]): r["peak_deflection"] for r in rows}
    assert 1.9 * static < peak[(1.0, 0.0)] < 2.05 * static, (peak, static)
    assert peak[(1.0, 0.5)] < 1.3 * static, (peak, static)
    for z in (0.0, 0.05, 0.5):
        assert abs(peak[(3.0, z)] / (3 * peak[(1.0, z)]) - 1) < 1e-12, peak
    assert "node_111.y" in (out / "sweep.svg").read_text()


def test_sweep_on_a_node_the_fmu_does_not_expose_names_the_nodes_it_has(mid_fmu):
    with pytest.raises(ValueError, match="its nodes are node_111; choose one with --node"):
        dask_sweep.serial(str(mid_fmu), dask_sweep.Sweep(node=121, amplitudes=(1.0,), ratios=(0.0,), steps=1))
    with pytest.raises(SystemExit):
        dask_sweep.main([str(mid_fmu), "--amplitudes", "1,x"])
