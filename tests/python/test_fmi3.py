"""The FMI 3.0 co-simulation FMU (`fxbody pack --fmi 3`, issue 26.1 and 26.4) seen by
independent FMI 3.0 tools: fmpy's validator and the fmu-manipulation-toolbox checker
find no problem; its model description, read by fmpy, declares the FMI 2.0 FMU's
variables (names, value references, causality, variability, start, unit, description);
fmpy runs it (simulate_fmu and FMU3Slave) for every method and fixture with the same
results as the FMI 2.0 FMU, bit for bit: one library serves both versions, and only
the boundary differs."""

import pathlib
import shutil
import subprocess
import sys
import zipfile

import numpy as np
import pytest
from fmpy import extract, read_model_description, simulate_fmu
from fmpy.fmi2 import FMU2Slave
from fmpy.fmi3 import FMU3Slave
from fmpy.validation import validate_fmu

from conftest import BODIES, pack_fmu

VENV_BIN = pathlib.Path(sys.executable).parent


@pytest.fixture(scope="session")
def packed3(fmu_dir):
    """Every shipped body packed for FMI 3.0 with default options (all nodes exposed)."""
    return {b: pack_fmu(fmu_dir, b, "--fmi", "3", name=f"{b}_fmi3") for b in BODIES}


@pytest.mark.parametrize("body", BODIES)
def test_validate_fmu_finds_no_problem(packed3, body):
    assert read_model_description(str(packed3[body])).fmiVersion == "3.0"
    problems = validate_fmu(str(packed3[body]))
    assert problems == [], problems


@pytest.mark.parametrize("body", BODIES)
def test_fmutool_check_passes(packed3, body):
    """The fmu-manipulation-toolbox checker supports FMI 3.0 (schema and semantics)."""
    run = subprocess.run([str(VENV_BIN / "fmutool"), "-input", str(packed3[body]), "-check"],
                         capture_output=True, text=True)
    out = run.stdout + run.stderr
    assert run.returncode == 0, out
    assert "seems to be compliant with FMI-3.0" in out, out
    assert "No semantic error" in out, out
    assert not any(line.startswith(("ERROR", "WARNING")) for line in out.splitlines()), out


@pytest.mark.parametrize("body", BODIES)
def test_fmi3_description_declares_the_fmi2_variables(packed, packed3, body):
    """Read by fmpy's parser: the same variables as the FMI 2.0 FMU, Real as Float64 and
    Integer as Int32, plus FMI 3.0's independent variable `time` after the last value
    reference; the same outputs in ModelStructure; the co-simulation capabilities; the
    library under binaries/x86_64-linux/ (FMI 3.0's platform tuple) and a documentation
    page saying FMI 3.0."""
    md2 = read_model_description(str(packed[body]))
    md3 = read_model_description(str(packed3[body]))
    assert md3.guid == md2.guid
    kinds = {"Real": "Float64", "Integer": "Int32"}
    fields = ("name", "valueReference", "causality", "variability", "initial", "start", "unit",
              "description", "min", "max")
    want = [(kinds[v.type],) + tuple(getattr(v, f) for f in fields) for v in md2.modelVariables]
    got = [(v.type,) + tuple(getattr(v, f) for f in fields) for v in md3.modelVariables]
    time = got.pop(0)
    assert time[:5] == ("Float64", "time", len(want), "independent", "continuous")
    assert got == want
    assert ([u.variable.valueReference for u in md3.outputs]
            == [u.variable.valueReference for u in md2.outputs])
    assert ([u.variable.valueReference for u in md3.initialUnknowns]
            == [u.variable.valueReference for u in md2.initialUnknowns])
    cs = md3.coSimulation
    assert cs.modelIdentifier == md2.coSimulation.modelIdentifier == body
    assert cs.canGetAndSetFMUstate and cs.canSerializeFMUstate  # fmpy's spelling
    assert cs.canHandleVariableCommunicationStepSize
    assert not cs.providesIntermediateUpdate and not cs.hasEventMode
    assert not cs.mightReturnEarlyFromDoStep
    assert md3.modelExchange is None and md3.scheduledExecution is None
    with zipfile.ZipFile(packed3[body]) as z:
        names = set(z.namelist())
        html = z.read("documentation/index.html").decode()
    assert f"binaries/x86_64-linux/{body}.so" in names
    assert not any(n.startswith("binaries/linux64/") for n in names)
    assert "FMI 3.0 co-simulation unit" in html and "x86_64-linux" in html


def load_signal(md, stop):
    """Every load input of the description's last node with loads (the cantilever's
    tip; its first node is clamped): each its own
    sinusoid (frequency and amplitude per component), sampled finely enough that fmpy's
    linear interpolation gives a varying load."""
    loads = [v.name for v in md.modelVariables if v.causality == "input"]
    node = loads[-1].split(".")[0]
    names = [n for n in loads if n.startswith(node + ".")]
    t = np.linspace(0.0, stop, 41)
    rows = [(ti, *[(1.0 + 0.5 * k) * np.cos((200.0 + 70.0 * k) * ti + 0.3 * k)
                   for k in range(len(names))]) for ti in t]
    return np.array(rows, dtype=[("time", float)] + [(n, float) for n in names])


def methods(md):
    """The methods a body offers: explicit, implicit and exact (blocked) or split
    (free: the body's frame is an output)."""
    free = any(v.name == "frame.x" for v in md.modelVariables)
    return [1, 2, 4] if free else [1, 2, 3]


@pytest.mark.parametrize("body", BODIES)
def test_simulate_fmu_fmi3_equals_fmi2_for_every_method(packed, packed3, body):
    """simulate_fmu (fmpy's FMI 3.0 co-simulation master) against its FMI 2.0 master on
    the same body: every output equal bit for bit, for every method the body offers,
    with loads on every component of a node. Each method must give its own history (the
    `method` start value reached the solver through fmi3SetInt32)."""
    md = read_model_description(str(packed[body]))
    stop, h = 0.01, 2e-4
    signal = load_signal(md, stop)
    outs = [v.name for v in md.modelVariables if v.causality == "output"]
    seen = []
    offered = methods(md)
    assert len(offered) == 3
    for m in offered:
        kw = dict(start_time=0.0, stop_time=stop, output_interval=h, input=signal, output=outs,
                  start_values={"method": m}, fmi_type="CoSimulation")
        r2 = simulate_fmu(str(packed[body]), **kw)
        r3 = simulate_fmu(str(packed3[body]), **kw)
        assert len(r2) == len(r3) == round(stop / h) + 1
        assert np.array_equal(r2["time"], r3["time"])
        peak = max(np.abs(r2[n]).max() for n in outs)
        assert peak > 0.0
        for n in outs:
            assert np.array_equal(r2[n], r3[n]), f"{body}, method {m}, {n}"
        motion = np.concatenate([r2[n] - r2[n][0] for n in outs])
        assert np.abs(motion).max() > 0.0, f"{body}, method {m}: no response"
        assert all(not np.array_equal(motion, s) for s in seen), f"{body}, method {m}"
        seen.append(motion)


def slave_run(cls, fmu, tmp, m):
    """Drive one slave by hand (fmpy's FMU2Slave or FMU3Slave): method m, 40 steps with a
    load on the tip's fy, a state saved after 20 and restored (in place and serialised),
    output derivatives at the end. Returns everything read."""
    md = read_model_description(str(fmu))
    d = extract(str(fmu), unzipdir=str(tmp))
    vr = {v.name: v.valueReference for v in md.modelVariables}
    s = cls(guid=md.guid, unzipDirectory=d, modelIdentifier=md.coSimulation.modelIdentifier,
            instanceName="hand")
    s.instantiate()
    three = cls is FMU3Slave
    (s.setInt32 if three else s.setInteger)([vr["method"]], [m])
    if three:
        s.enterInitializationMode(startTime=0.0)
    else:
        s.setupExperiment(startTime=0.0)
        s.enterInitializationMode()
    s.exitInitializationMode()
    get = s.getFloat64 if three else s.getReal
    put = s.setFloat64 if three else s.setReal
    out = [vr["node_121.y"], vr["node_121.vy"], vr["node_121.rz"]]
    h, got, saved = 1e-4, [], None

    def steps(k0, n):
        for k in range(k0, k0 + n):
            t = k * h
            put([vr["node_121.fy"]], [np.cos(300.0 * t)])
            flags = s.doStep(t, h)
            if three:
                assert flags == (False, False, False, t + h), flags
            got.extend(get(out))

    steps(0, 20)
    saved = s.getFMUState()
    steps(20, 20)
    blob = s.serializeFMUState(saved)
    s.setFMUState(saved)
    steps(20, 20)
    s.setFMUState(s.deserializeFMUState(blob))
    steps(20, 20)
    got.extend((s.getOutputDerivatives if three else s.getRealOutputDerivatives)(out[:1], [1]))
    s.terminate()
    s.freeInstance()
    return np.array(got)


@pytest.mark.parametrize("method", [1, 2, 3])
def test_fmu3slave_by_hand_equals_fmu2slave(cantilever_tip, fmu_dir, tmp_path, method):
    """FMU3Slave driven by hand (instantiate, initialise, set, step, get, FMU state saved,
    restored and serialised, output derivatives) against FMU2Slave doing the same on the
    FMI 2.0 FMU: the same numbers bit for bit, a restored state replaying the same
    steps, and fmi3DoStep's flags saying no event, no early return, end time t + h."""
    fmu2, ref = cantilever_tip
    fmu3 = pack_fmu(fmu_dir, "cantilever", "--nodes", str(ref["tip_node"]), "--fmi", "3",
                    name="cantilever_tip_fmi3")
    a = slave_run(FMU2Slave, fmu2, tmp_path / "v2", method)
    b = slave_run(FMU3Slave, fmu3, tmp_path / "v3", method)
    assert np.abs(a).max() > 0
    assert np.array_equal(a, b)
    # The restored states replayed the same 20 steps, three times over.
    block = a[60:120]
    assert np.array_equal(block, a[120:180]) and np.array_equal(block, a[180:240])


def test_fmi3_refusals_raise_in_fmpy_and_the_instance_recovers(fmu_dir, cantilever_tip):
    """fmpy raises on fmi3Error (a step before initialisation, a Float32 read of a
    Float64, nValues not matching), fmpy's Python survives, and after fmi3Reset the
    instance runs: its first step matches a fresh instance's."""
    from fmpy.fmi1 import FMICallException

    _, ref = cantilever_tip
    fmu = pack_fmu(fmu_dir, "cantilever", "--nodes", str(ref["tip_node"]), "--fmi", "3",
                   name="cantilever_refuse_fmi3")
    md = read_model_description(str(fmu))
    d = extract(str(fmu))
    vr = {v.name: v.valueReference for v in md.modelVariables}
    messages = []
    s = FMU3Slave(guid=md.guid, unzipDirectory=d, modelIdentifier=md.coSimulation.modelIdentifier,
                  instanceName="refuse")
    s.instantiate(loggingOn=True, logMessage=lambda env, status, cat, msg: messages.append(msg.decode()))
    with pytest.raises(FMICallException):
        s.doStep(0.0, 1e-4)
    assert any("fmi3DoStep: illegal call in state Instantiated" in m for m in messages), messages
    s.reset()
    s.enterInitializationMode(startTime=0.0)
    s.exitInitializationMode()
    with pytest.raises(FMICallException):
        s.getFloat32([vr["node_121.y"]])
    assert any("Float32" in m for m in messages), messages
    s.reset()
    s.enterInitializationMode(startTime=0.0)
    s.exitInitializationMode()
    with pytest.raises(FMICallException):
        s.getFloat64([vr["node_121.y"]], nValues=2)
    assert any("nValues is 2" in m for m in messages), messages
    s.reset()
    s.enterInitializationMode(startTime=0.0)
    s.exitInitializationMode()
    s.setFloat64([vr["node_121.fy"]], [1.0])
    s.doStep(0.0, 1e-4)
    y = s.getFloat64([vr["node_121.y"]])
    s.terminate()
    s.freeInstance()
    fresh = FMU3Slave(guid=md.guid, unzipDirectory=d, modelIdentifier=md.coSimulation.modelIdentifier,
                      instanceName="fresh")
    fresh.instantiate()
    fresh.enterInitializationMode(startTime=0.0)
    fresh.exitInitializationMode()
    fresh.setFloat64([vr["node_121.fy"]], [1.0])
    fresh.doStep(0.0, 1e-4)
    assert fresh.getFloat64([vr["node_121.y"]]) == y
    fresh.terminate()
    fresh.freeInstance()
    shutil.rmtree(d, ignore_errors=True)
