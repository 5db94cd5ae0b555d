"""The packed FMUs seen by independent FMI tools: fmpy's validator, the
fmu-manipulation-toolbox checker, fmpy's simulate_fmu against the full-FE reference, and
the fmucontainer wrapper as a second FMI caller."""

import json
import subprocess
import sys
import pathlib

import numpy as np
import pytest
from fmpy import simulate_fmu
from fmpy.validation import validate_fmu

from conftest import BODIES, FIXTURES, reference

VENV_BIN = pathlib.Path(sys.executable).parent


@pytest.mark.parametrize("body", BODIES)
def test_validate_fmu_finds_no_problem(packed, body):
    assert body in packed, f"fixtures/{body}.fxb missing"
    problems = validate_fmu(str(packed[body]))
    assert problems == [], problems


@pytest.mark.parametrize("body", BODIES)
def test_fmutool_check_passes(packed, body):
    tool = VENV_BIN / "fmutool"
    run = subprocess.run([str(tool), "-input", str(packed[body]), "-check"], capture_output=True, text=True)
    out = run.stdout + run.stderr
    assert run.returncode == 0, out
    assert "seems to be compliant with FMI-2.0" in out, out
    assert "No semantic error" in out, out
    assert not any(line.startswith(("ERROR", "WARNING")) for line in out.splitlines()), out


def deck_position(body, node):
    """The node's coordinates in the fixture's /NODE deck, read with the fixture
    generator's own reader (fixtures/fxbread.py), not through fxbody."""
    sys.path.insert(0, str(FIXTURES))
    from fxbread import read_nodes

    ids, xyz = read_nodes((FIXTURES / f"{body}.nodes.rad").read_text())
    return np.asarray(xyz)[list(ids).index(int(node))]


def step_input(name, amplitude, stop):
    return np.array([(0.0, amplitude), (stop, amplitude)], dtype=[("time", float), (name, float)])


def pulse_input(name, amplitude, duration, stop):
    # A repeated time stamp is a discontinuity for fmpy: the later row holds from there on.
    rows = [(0.0, amplitude), (duration, amplitude), (duration, 0.0), (stop, 0.0)]
    return np.array(rows, dtype=[("time", float), (name, float)])


@pytest.mark.parametrize("body", ["cantilever", "cantilever_damped"])
@pytest.mark.parametrize("case", ["step", "pulse"])
def test_tip_response_matches_full_fe_reference(fmu_dir, body, case):
    """Exact method, held load: the only error left is the modal reduction (20 of the FE
    model's modes; Rayleigh damping for the damped one). Tolerance 0.5% of the peak
    (issue 6 / the solver issue's bound)."""
    from conftest import pack_fmu

    ref = reference(body)
    fmu = pack_fmu(fmu_dir, body, "--nodes", str(ref["tip_node"]), name=f"{body}_tip_{case}")
    tip = str(ref["tip_node"])
    resp = next(r for r in ref["responses"] if r["name"] == case)
    t = np.array(resp["t"])
    h = t[1] - t[0]
    stop = t[-1]
    name = f"node_{tip}.{resp['load_dof']}"
    if resp["shape"] == "step":
        signal = step_input(name, resp["amplitude"], stop)
    else:
        signal = pulse_input(name, resp["amplitude"], resp["duration"], stop)
    res = simulate_fmu(str(fmu), start_time=0.0, stop_time=stop, step_size=h, output_interval=h,
                       input=signal, output=[f"node_{tip}.y"])
    assert np.allclose(res["time"], t, atol=1e-12 * stop)
    # Displacement from the node's position in the /NODE deck, not from the FMU's own
    # first output: an FMU whose outputs start off the node (a wrong frame origin, an
    # output offset) fails here.
    uy = res[f"node_{tip}.y"] - deck_position(body, tip)[1]
    want = np.array(resp["nodes"][tip]["uy"])
    peak = np.abs(want).max()
    err = np.abs(uy - want).max()
    assert err <= 5e-3 * peak, f"{case}: max error {err:.3e} vs peak {peak:.3e} ({err / peak:.2%})"


def test_fmucontainer_gives_the_same_results(cantilever_tip, tmp_path):
    """The same FMU wrapped by fmucontainer (its own C FMI caller) and run by fmpy."""
    fmu, ref = cantilever_tip
    tip = ref["tip_node"]
    local = tmp_path / "tip.fmu"
    local.write_bytes(fmu.read_bytes())
    h = 2e-4
    (tmp_path / "wrap.json").write_text(json.dumps({"name": "wrapped.fmu", "fmu": ["tip.fmu"], "step_size": h}))
    run = subprocess.run([str(VENV_BIN / "fmucontainer"), "-container", "wrap.json", "-fmu-directory", str(tmp_path)],
                         capture_output=True, text=True, cwd=tmp_path)
    wrapped = tmp_path / "wrapped.fmu"
    assert run.returncode == 0 and wrapped.is_file(), run.stdout + run.stderr
    signal = step_input(f"node_{tip}.fy", 1.0, 0.1)
    out = [f"node_{tip}.y", f"node_{tip}.vy"]
    direct = simulate_fmu(str(local), stop_time=0.1, step_size=h, output_interval=h, input=signal, output=out)
    contained = simulate_fmu(str(wrapped), stop_time=0.1, step_size=h, output_interval=h, input=signal, output=out)
    assert len(direct) == len(contained) == 501
    for name in out:
        scale = np.abs(direct[name]).max()
        assert scale > 0
        # Both drive the same library with the same inputs: equal to round-off.
        assert np.abs(direct[name] - contained[name]).max() <= 1e-12 * scale, name


def test_units_declared_only_on_request(fmu_dir):
    from conftest import pack_fmu
    from fmpy import read_model_description

    plain = read_model_description(str(pack_fmu(fmu_dir, "cantilever", "--nodes", "121", name="plain")))
    assert plain.unitDefinitions == []
    assert all(v.unit is None for v in plain.modelVariables)
    si = pack_fmu(fmu_dir, "cantilever", "--nodes", "121", "--units", "SI", name="si")
    assert validate_fmu(str(si)) == []
    md = read_model_description(str(si))
    units = {v.name: v.unit for v in md.modelVariables}
    assert units["node_121.fy"] == "N" and units["node_121.my"] == "N.m"
    assert units["node_121.y"] == "m" and units["node_121.vy"] == "m/s" and units["energy.strain"] == "J"


@pytest.mark.parametrize("method,rho_inf,tol", [(1, 0.9, 5e-3), (2, 0.9, 1e-2), (2, 0.5, 1e-2)])
def test_method_and_rho_inf_parameters_reach_the_solver(cantilever_tip, method, rho_inf, tol):
    """The Integer `method` and `rho_inf`, set as start values, select the solver:
    explicit (sub-cycled central difference) and implicit (generalised-alpha) also follow
    the full-FE step response (bounds: 0.5% and 1% of the peak at h = 0.2 ms)."""
    fmu, ref = cantilever_tip
    tip = str(ref["tip_node"])
    resp = next(r for r in ref["responses"] if r["name"] == "step")
    t = np.array(resp["t"])
    want = np.array(resp["nodes"][tip]["uy"])
    out = f"node_{tip}.y"
    run = lambda m, rho: simulate_fmu(str(fmu), stop_time=t[-1], step_size=t[1], output_interval=t[1],
                                      input=step_input(f"node_{tip}.fy", 1.0, t[-1]), output=[out],
                                      start_values={"method": m, "rho_inf": rho})[out]
    got = run(method, rho_inf)
    assert np.abs(got - want).max() <= tol * np.abs(want).max()
    exact = run(3, rho_inf)
    # A different method gives a different (if close) history, and rho_inf matters to
    # the implicit method (its high-frequency damping).
    assert np.abs(got - exact).max() > 1e-9 * np.abs(want).max()
    if method == 2:
        other = run(2, 1.4 - rho_inf)
        assert np.abs(got - other).max() > 1e-4 * np.abs(want).max()


@pytest.mark.parametrize("body", BODIES)
def test_archive_layout_and_documentation(packed, body):
    """The archive holds the description, the library under its modelIdentifier, the
    resources and documentation/index.html; the page lists every variable and the body's
    eigenfrequencies, which agree with the fixture's reduced-model frequencies (1e-6)."""
    import re
    import zipfile

    from fmpy import read_model_description

    md = read_model_description(str(packed[body]))
    with zipfile.ZipFile(packed[body]) as z:
        names = set(z.namelist())
        assert z.testzip() is None
        html = z.read("documentation/index.html").decode()
    assert {"modelDescription.xml", f"binaries/linux64/{md.coSimulation.modelIdentifier}.so",
            "resources/scene.fxs", "resources/scene.txt",
            "documentation/index.html"} <= names
    assert all(f"<td>{v.name}</td>" in html for v in md.modelVariables)
    block = html.split("Eigenfrequencies of the kept local modes (Hz)</h2>\n<p>")[1].split("</p>")[0]
    ours = np.array([float(x) for x in re.findall(r"[-0-9.e+]+", block)])
    want = np.array(reference(body)["frequencies_hz"]["reduced"])
    assert ours.shape == want.shape
    assert np.allclose(ours, want, rtol=1e-6, atol=1e-6), (ours, want)


def test_method_is_an_integer_parameter_with_its_range(fmu_dir):
    """Issue 15: `method` is an Integer (libcosim and ecos ignore Enumerations) with
    min 1, max 4 and a description naming each value; fmpy reads it so."""
    from conftest import pack_fmu
    from fmpy import read_model_description

    md = read_model_description(str(pack_fmu(fmu_dir, "cantilever", "--nodes", "121", name="mint")))
    v = next(v for v in md.modelVariables if v.name == "method")
    assert (v.type, v.causality, v.variability) == ("Integer", "parameter", "fixed")
    assert (int(v.min), int(v.max), int(v.start)) == (1, 4, 3)
    for item in ("1 = explicit", "2 = implicit", "3 = exact", "4 = split"):
        assert item in v.description
    assert md.typeDefinitions == []
