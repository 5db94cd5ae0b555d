"""FMU2Slave loops over a packed cantilever: state rollback and serialisation, the call
sequence, the GUID check, independent instances, resource paths with spaces, variable
steps, input and output derivatives. References: the fixture's full-FE response, a
second run of the same FMU, linearity, or a finer-stepped run."""

import shutil

import numpy as np
import pytest
from fmpy import extract
from slave import Slave

H = 2e-4  # the reference's sampling step


@pytest.fixture(scope="module")
def tip(cantilever_tip, tmp_path_factory):
    fmu, ref = cantilever_tip
    return fmu, extract(str(fmu), str(tmp_path_factory.mktemp("unzipped"))), ref


def outputs(tip_id):
    return [f"node_{tip_id}.y", f"node_{tip_id}.vy", "energy.kinetic", "energy.strain"]


def run_steps(slave, t0, n, h, force, tip_id):
    rows = []
    t = t0
    for _ in range(n):
        slave.set(**{f"node_{tip_id}__fy": force(t)})
        slave.s.doStep(t, h)
        t += h
        rows.append(slave.get(*outputs(tip_id)))
    return t, np.array(rows)


def force(t):
    return np.sin(200.0 * t) + 0.5


def test_rollback_reproduces_outputs_bit_for_bit(tip):
    fmu, unz, ref = tip
    tid = ref["tip_node"]
    a = Slave(fmu, unz).start()
    t, _ = run_steps(a, 0.0, 100, H, force, tid)
    state = a.s.getFMUstate()
    t_end, first = run_steps(a, t, 150, H, force, tid)
    a.s.setFMUstate(state)
    _, again = run_steps(a, t, 150, H, force, tid)
    a.s.freeFMUstate(state)
    assert np.abs(first).max() > 0
    assert np.array_equal(first, again)
    a.free()


def test_serialized_state_moves_to_another_instance(tip, tmp_path):
    fmu, unz, ref = tip
    tid = ref["tip_node"]
    a = Slave(fmu, unz, "a").start()
    t, _ = run_steps(a, 0.0, 120, H, force, tid)
    blob = a.s.serializeFMUstate(a.s.getFMUstate())
    # A second unpacked copy: a different library file and resources folder.
    other = tmp_path / "copy"
    shutil.copytree(unz, other)
    b = Slave(fmu, other, "b").start()
    b.s.setFMUstate(b.s.deSerializeFMUstate(blob))
    _, ra = run_steps(a, t, 80, H, force, tid)
    _, rb = run_steps(b, t, 80, H, force, tid)
    assert np.abs(ra).max() > 0
    assert np.array_equal(ra, rb)
    a.free()
    b.free()


def test_corrupted_or_foreign_state_is_refused(tip, fmu_dir, capsys):
    from conftest import pack_fmu

    fmu, unz, ref = tip
    a = Slave(fmu, unz, "a").start()
    blob = bytearray(a.s.serializeFMUstate(a.s.getFMUstate()))
    blob[len(blob) // 2] ^= 0x40
    with pytest.raises(Exception):
        a.s.deSerializeFMUstate(bytes(blob))
    assert "checksum mismatch" in capsys.readouterr().out
    # A state from an FMU of another scene (two nodes exposed): refused by GUID.
    other = pack_fmu(fmu_dir, "cantilever", "--nodes", "121,111", name="two_nodes")
    o = Slave(other, extract(str(other)), "o").start()
    foreign = o.s.serializeFMUstate(o.s.getFMUstate())
    a.s.reset()
    with pytest.raises(Exception):
        a.s.deSerializeFMUstate(foreign)
    assert "FMU state belongs to GUID" in capsys.readouterr().out
    o.free()
    a.s.freeInstance()


def test_wrong_guid_fails_with_a_logged_reason(tip, capsys):
    fmu, unz, _ = tip
    bad = Slave(fmu, unz, guid="{00000000-0000-0000-0000-000000000000}")
    with pytest.raises(Exception, match="Failed to instantiate"):
        bad.s.instantiate()
    out = capsys.readouterr().out
    assert "GUID mismatch" in out and "{00000000-0000-0000-0000-000000000000}" in out, out


def test_illegal_sequences_return_errors_and_the_process_lives(tip, capsys):
    fmu, unz, ref = tip
    tid = ref["tip_node"]
    a = Slave(fmu, unz)
    a.s.instantiate()
    with pytest.raises(Exception):
        a.s.doStep(0.0, H)  # before initialisation
    assert "fmi2DoStep: illegal call in state Instantiated" in capsys.readouterr().out
    with pytest.raises(Exception):
        a.get(f"node_{tid}.y")  # after an error
    assert "fmi2GetReal: illegal call in state Error" in capsys.readouterr().out
    a.s.reset()  # the way out
    a.s.setupExperiment(startTime=0.0)
    a.s.enterInitializationMode()
    a.s.exitInitializationMode()
    with pytest.raises(Exception):
        a.set(**{f"node_{tid}__y": 1.0})  # an output
    assert f"node_{tid}.y is an output" in capsys.readouterr().out
    a.s.reset()
    a.s.setupExperiment(startTime=0.0)
    a.s.enterInitializationMode()
    a.s.exitInitializationMode()
    with pytest.raises(Exception):
        a.s.doStep(1.0, H)  # not the current time
    assert "is not the FMU's current time" in capsys.readouterr().out
    a.s.reset()
    a.s.setupExperiment(startTime=0.0)
    a.s.enterInitializationMode()
    a.s.exitInitializationMode()
    with pytest.raises(Exception):
        a.s.setDebugLogging(True, ["noSuchCategory"])
    assert "unknown log category 'noSuchCategory'" in capsys.readouterr().out
    a.s.freeInstance()


def test_two_instances_are_independent(tip):
    """Interleaved instances with loads 1 and 3 N: by linearity the second is exactly
    three times the first, and the first equals a run of its own."""
    fmu, unz, ref = tip
    tid = ref["tip_node"]
    alone = Slave(fmu, unz, "alone").start()
    _, r_alone = run_steps(alone, 0.0, 200, H, lambda t: 1.0, tid)
    alone.free()
    a = Slave(fmu, unz, "a").start()
    b = Slave(fmu, unz, "b").start()
    ya, yb = [], []
    t = 0.0
    for _ in range(200):
        a.set(**{f"node_{tid}__fy": 1.0})
        b.set(**{f"node_{tid}__fy": 3.0})
        a.s.doStep(t, H)
        b.s.doStep(t, H)
        t += H
        ya.append(a.get(f"node_{tid}.y")[0])
        yb.append(b.get(f"node_{tid}.y")[0])
    ya, yb = np.array(ya), np.array(yb)
    assert np.array_equal(ya, r_alone[:, 0])
    assert np.abs(yb - 3.0 * ya).max() <= 1e-12 * np.abs(yb).max()
    a.free()
    b.free()


def test_resource_path_with_spaces(tip, tmp_path):
    fmu, _, ref = tip
    tid = ref["tip_node"]
    odd = tmp_path / "a folder with spaces %20 and é"
    unz = extract(str(fmu), str(odd))
    s = Slave(fmu, unz).start()
    _, r = run_steps(s, 0.0, 10, H, lambda t: 1.0, tid)
    full = np.array(next(x for x in ref["responses"] if x["name"] == "step")["nodes"][str(tid)]["uy"])
    # Same bound as the whole step response: 0.5% of its peak.
    assert np.abs(r[:, 0] - full[1:11]).max() <= 5e-3 * np.abs(full).max()
    s.free()


def test_variable_step_size_follows_the_reference(tip):
    fmu, unz, ref = tip
    tid = ref["tip_node"]
    resp = next(x for x in ref["responses"] if x["name"] == "step")
    want = np.array(resp["nodes"][str(tid)]["uy"])
    s = Slave(fmu, unz).start()
    k, t, errs = 0, 0.0, []
    cycle = [1, 3, 2, 7, 1, 5]  # steps in reference samples: 0.2 .. 1.4 ms
    i = 0
    while k + cycle[i % len(cycle)] < len(want):
        n = cycle[i % len(cycle)]
        s.set(**{f"node_{tid}__fy": resp["amplitude"]})
        s.s.doStep(t, n * H)
        k += n
        t = k * H
        i += 1
        errs.append(s.get(f"node_{tid}.y")[0] - want[k])
    assert i > 300
    assert np.abs(errs).max() <= 5e-3 * np.abs(want).max()
    s.free()


def test_input_derivatives_make_a_ramp_exact(tip):
    """A ramp load F = 400 t over coarse 5 ms steps: with the slope given through
    fmi2SetRealInputDerivatives the exact method integrates it exactly, so it matches a
    run at 0.05 ms steps (held load, first-order error ~ 1e-3 of the response) far
    better than the same coarse steps with a held load."""
    fmu, unz, ref = tip
    tid = ref["tip_node"]
    name = f"node_{tid}.fy"
    k = 400.0
    big, small, n = 5e-3, 5e-5, 20

    def coarse(with_rates):
        s = Slave(fmu, unz, "c").start()
        t, ys = 0.0, []
        for _ in range(n):
            s.set(**{name.replace(".", "__"): k * t})
            if with_rates:
                s.s.setRealInputDerivatives([s.vr[name]], [1], [k])
            s.s.doStep(t, big)
            t += big
            ys.append(s.get(f"node_{tid}.y")[0])
        s.free()
        return np.array(ys)

    fine = Slave(fmu, unz, "f").start()
    t, ys = 0.0, []
    m = round(big / small)
    for j in range(n * m):
        # Midpoint value: second-order accurate for a held load.
        fine.set(**{name.replace(".", "__"): k * (t + small / 2)})
        fine.s.doStep(t, small)
        t = (j + 1) * small
        if (j + 1) % m == 0:
            ys.append(fine.get(f"node_{tid}.y")[0])
    fine.free()
    ref_y = np.array(ys)
    scale = np.abs(ref_y).max()
    err_rates = np.abs(coarse(True) - ref_y).max() / scale
    err_held = np.abs(coarse(False) - ref_y).max() / scale
    assert err_rates < 1e-4, err_rates
    assert err_held > 0.02 and err_held > 100 * err_rates, (err_held, err_rates)


def test_output_derivatives_are_velocity_and_acceleration(tip):
    fmu, unz, ref = tip
    tid = ref["tip_node"]
    s = Slave(fmu, unz).start()
    h = 1e-5
    vr_y = s.vr[f"node_{tid}.y"]
    t = 0.0
    vys = []
    for _ in range(300):
        s.set(**{f"node_{tid}__fy": 1.0})
        s.s.doStep(t, h)
        t += h
        vys.append(s.get(f"node_{tid}.vy")[0])
    # Three 1 us steps: a central difference of the velocity around the middle one
    # (error (w h)^2 / 6 ~ 1e-4 relative even for the 4.1 kHz top mode).
    dt = 1e-6
    v, acc = [], None
    for j in range(3):
        s.set(**{f"node_{tid}__fy": 1.0})
        s.s.doStep(t, dt)
        t += dt
        v.append(s.get(f"node_{tid}.vy")[0])
        if j == 1:
            d1 = s.s.getRealOutputDerivatives([vr_y], [1])[0]
            acc = s.s.getRealOutputDerivatives([vr_y], [2])[0]
            assert d1 == v[1]
    fd = (v[2] - v[0]) / (2 * dt)
    assert abs(fd) > 1.0
    assert abs(acc - fd) <= 1e-3 * abs(fd), (acc, fd)
    s.free()


def test_log_text_with_percent_signs_arrives_verbatim(tip, tmp_path, capsys):
    """Messages go through the variadic logger as ("%s", text): a folder named with
    '%20' and '%s' must appear literally in the GUID-mismatch message, not be expanded."""
    fmu, _, _ = tip
    odd = tmp_path / "pct %20 %s %n folder"
    unz = extract(str(fmu), str(odd))
    bad = Slave(fmu, unz, guid="{wrong}")
    with pytest.raises(Exception):
        bad.s.instantiate()
    out = capsys.readouterr().out
    assert "pct %20 %s %n folder" in out, out


def test_debug_logging_categories_switch_on_and_off(tip, capsys):
    fmu, unz, ref = tip
    s = Slave(fmu, unz).start()
    capsys.readouterr()
    s.s.doStep(0.0, H)
    assert "fmi2DoStep" not in capsys.readouterr().out
    s.s.setDebugLogging(True, ["logCalls"])
    s.s.doStep(H, H)
    assert "fmi2DoStep" in capsys.readouterr().out
    s.s.setDebugLogging(False, [])
    s.s.doStep(2 * H, H)
    assert "fmi2DoStep" not in capsys.readouterr().out
    s.free()
