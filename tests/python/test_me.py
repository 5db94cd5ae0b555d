"""Model Exchange (issue 26.2, 26.3, 26.4; `fxbody pack --interface me|both`) seen by fmpy:
its validator finds no problem in the me and both FMUs (FMI 2.0 and 3.0), and fmpy's
Model Exchange simulation with CVode reproduces the co-simulation exact method (driven
by hand through FMU2Slave, the load held over each step) on the cantilever's tip under
a step and a pulse of load, sampled at every communication point.

Reference: the co-simulation exact method (closed-form modal stepping, no
time-discretisation error), a second integration of the same equations. Tolerance:
1e-6 of the peak displacement at rtol 1e-8, the tolerance docs/MASTERS.md tells users
to pick. fmpy's CVode takes its absolute tolerance from the state nominals (atol = rtol x
nominal, re-read at each event), so the nominals decide whether CVode controls a mode's
error relatively: the pulse's peak is 14 times smaller than the step's, and with
nominals set to the static amplitude under a whole unit load (8e-4 on the mode that
carries the tip, which the pulse moves by 7.3e-5) the pulse was 5.8e-6 off at rtol 1e-8;
with a tenth of a unit load (solver::continuous::NOMINAL_LOAD) it is 2.8e-7, the step
1.8e-8. Nominals of 1 give 5.4e-4 (the seeded defect). With mode truncation (--fmax
1000: 14 modes kept, 6 as the residual correction) the positions carry the loads'
feed-through, read through the co-simulation output code. A free body's Model
Exchange is tested in test_me_free.py."""


import numpy as np
import pytest
from fmpy import extract, read_model_description, simulate_fmu
from fmpy.fmi2 import FMU2Slave
from fmpy.validation import validate_fmu

from conftest import pack_fmu

TIP = 121
H = 2e-4
N = 400
PULSE_STEPS = 10


@pytest.fixture(scope="module")
def fmus(fmu_dir):
    """The cantilever with its tip exposed, packed for co-simulation (FMI 2.0), and for
    Model Exchange and both, in FMI 2.0 and 3.0."""
    out = {"cs": pack_fmu(fmu_dir, "cantilever", "--nodes", str(TIP), name="me_cs"),
           # 14 of the 20 modes kept, the other 6 as the residual correction, whose
           # positions feed the loads through: one FMU for both interfaces.
           "fmax": pack_fmu(fmu_dir, "cantilever", "--nodes", str(TIP), "--fmax", "1000",
                            "--interface", "both", name="me_fmax")}
    for fmi in ("2", "3"):
        for interface in ("me", "both"):
            out[(fmi, interface)] = pack_fmu(
                fmu_dir, "cantilever", "--nodes", str(TIP), "--fmi", fmi,
                "--interface", interface, name=f"me_{interface}_{fmi}")
    return out


@pytest.mark.parametrize("fmi", ["2", "3"])
@pytest.mark.parametrize("interface", ["me", "both"])
def test_validate_fmu_passes_for_model_exchange(fmus, fmi, interface):
    fmu = str(fmus[(fmi, interface)])
    md = read_model_description(fmu)
    assert md.modelExchange is not None
    assert (md.coSimulation is not None) == (interface == "both")
    # The cantilever's 20 local modes: 20 amplitudes and 20 velocities.
    assert md.numberOfContinuousStates == 40
    assert md.numberOfEventIndicators == 0
    problems = validate_fmu(fmu)
    assert problems == [], problems


def cs_exact(fmu, pulse):
    """The tip's y at t = 0, H, ..., N H by the co-simulation exact method, the load
    fy = 1 held over each step (over the first PULSE_STEPS steps only for a pulse)."""
    md = read_model_description(str(fmu))
    vr = {v.name: v.valueReference for v in md.modelVariables}
    s = FMU2Slave(guid=md.guid, unzipDirectory=extract(str(fmu)),
                  modelIdentifier=md.coSimulation.modelIdentifier, instanceName="cs")
    s.instantiate()
    s.setupExperiment(startTime=0.0)
    s.enterInitializationMode()
    s.exitInitializationMode()
    # The first load before the first read: with --fmax the position feeds it through.
    s.setReal([vr[f"node_{TIP}.fy"]], [1.0])
    y = [s.getReal([vr[f"node_{TIP}.y"]])[0]]
    for k in range(N):
        s.setReal([vr[f"node_{TIP}.fy"]], [0.0 if pulse and k >= PULSE_STEPS else 1.0])
        s.doStep(k * H, H)
        y.append(s.getReal([vr[f"node_{TIP}.y"]])[0])
    s.terminate()
    s.freeInstance()
    return np.array(y)


def me_cvode(fmu, pulse, rtol):
    """The tip's y at t = 0, H, ..., N H by fmpy's Model Exchange with CVode at `rtol`,
    the load a step (or a pulse ending at PULSE_STEPS H: an input event)."""
    t1, stop = PULSE_STEPS * H, N * H
    after = 0.0 if pulse else 1.0
    signal = np.array([(0.0, 1.0), (t1, 1.0), (t1, after), (stop, after)],
                      dtype=[("time", float), (f"node_{TIP}.fy", float)])
    r = simulate_fmu(str(fmu), fmi_type="ModelExchange", solver="CVode",
                     relative_tolerance=rtol, start_time=0.0, stop_time=stop,
                     output_interval=H, input=signal, output=[f"node_{TIP}.y"])
    # The event at t1 is recorded twice (before and after): one row per sample time.
    rows = [int(np.argmin(np.abs(r["time"] - k * H))) for k in range(N + 1)]
    assert np.max(np.abs(r["time"][rows] - H * np.arange(N + 1))) < 1e-12
    return r[f"node_{TIP}.y"][rows]


@pytest.mark.parametrize("fmi", ["2", "3"])
@pytest.mark.parametrize("load", ["step", "pulse"])
def test_cvode_reproduces_the_exact_method(fmus, fmi, load, rtol=1e-8, tol=1e-6):
    pulse = load == "pulse"
    ref = cs_exact(fmus["cs"], pulse)
    y = me_cvode(fmus[(fmi, "me")], pulse, rtol)
    peak = np.max(np.abs(ref - ref[0]))
    gap = np.max(np.abs(y - ref)) / peak
    print(f"FMI {fmi} {load}, CVode rtol {rtol:g}: gap {gap:.2e} of the peak {peak:.3e}")
    assert peak > 1e-5, "the tip did not move"
    assert gap < tol, f"{load}: Model Exchange off the exact method by {gap:.2e} of the peak"


@pytest.mark.parametrize("load", ["step", "pulse"])
def test_cvode_reproduces_the_exact_method_with_the_residual_feed_through(fmus, load):
    """The truncated cantilever (--fmax): positions carry the residual correction's
    R f, read in Model Exchange through the co-simulation output code."""
    pulse = load == "pulse"
    ref = cs_exact(fmus["fmax"], pulse)
    y = me_cvode(fmus["fmax"], pulse, 1e-8)
    peak = np.max(np.abs(ref - ref[0]))
    gap = np.max(np.abs(y - ref)) / peak
    print(f"--fmax 1000 {load}, CVode rtol 1e-8: gap {gap:.2e} of the peak {peak:.3e}")
    assert gap < 1e-6, f"{load}: Model Exchange off the exact method by {gap:.2e} of the peak"


def test_the_both_fmu_serves_both_interfaces_alike(fmus):
    """One FMU, both interfaces: its co-simulation instance is the CS FMU's (same
    numbers), its Model Exchange instance the ME FMU's."""
    both = fmus[("2", "both")]
    assert np.array_equal(cs_exact(both, True), cs_exact(fmus["cs"], True))
    np.testing.assert_allclose(me_cvode(both, False, 1e-8), me_cvode(fmus[("2", "me")], False, 1e-8),
                               rtol=0, atol=1e-15)


def test_an_interface_not_packed_is_refused_at_instantiation(fmus, capfd):
    """fmi2Instantiate for Model Exchange on a co-simulation FMU (and the other way
    round) returns NULL with a logged reason naming --interface; fmpy's own check of the
    description is bypassed by instantiating through the other class."""
    from fmpy.fmi2 import FMU2Model
    for fmu, cls, ident in [(fmus["cs"], FMU2Model, "coSimulation"),
                            (fmus[("2", "me")], FMU2Slave, "modelExchange")]:
        md = read_model_description(str(fmu))
        f = cls(guid=md.guid, unzipDirectory=extract(str(fmu)),
                modelIdentifier=getattr(md, ident).modelIdentifier, instanceName="x")
        with pytest.raises(Exception, match="Failed to instantiate"):
            f.instantiate(loggingOn=True)
        out = capfd.readouterr()
        assert "--interface" in out.out + out.err, out
