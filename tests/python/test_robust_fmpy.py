"""A careless fmpy master (issue 9): illegal calls, NaN forces, bad steps, outputs set,
unknown value references, random and truncated serialised states, '%' in the instance
name, a finite but huge load and input rate whose step would be non-finite (issue 13), each refusal recovered by reset or setFMUstate, then a run with a state saved,
serialised and restored on the way. Reference: a clean instance in the same process
running the same loads, which the misused one must match bit for bit. The same careless
master drives the FMI 3.0 FMU (`pack --fmi 3`) through fmpy's FMU3Slave under FMI 2.0's
method names (`Fmi3Names`); FMI 3.0 has no input derivatives, so the huge input rate is
left out there.

Run as a script, it is the fmpy driver that scripts/robust-long.sh runs under valgrind:
    python tests/python/test_robust_fmpy.py FMU_OR_UNZIPPED_DIR --steps 20000
"""

import argparse
import math
import random
import struct
import subprocess
import sys
import zipfile
from pathlib import Path

H = 1e-4


def force(t):
    return math.sin(300.0 * t) + 0.25


class Fmi3Names:
    """fmpy's FMU3Slave under the FMU2Slave method names `drive` calls: the same
    careless master for both versions (FMI 3.0 takes the start time when entering
    initialisation, has Float64 for Real and spells FMUState with a capital S)."""

    def __init__(self, s):
        self.s, self.start = s, 0.0

    def __getattr__(self, name):
        return getattr(self.s, name)

    def setupExperiment(self, startTime):
        self.start = startTime

    def enterInitializationMode(self):
        return self.s.enterInitializationMode(startTime=self.start)

    def setReal(self, vr, values):
        return self.s.setFloat64(vr, values)

    def getReal(self, vr):
        return self.s.getFloat64(vr)

    def getFMUstate(self):
        return self.s.getFMUState()

    def setFMUstate(self, state):
        return self.s.setFMUState(state)

    def freeFMUstate(self, state):
        return self.s.freeFMUState(state)

    def serializeFMUstate(self, state):
        return self.s.serializeFMUState(state)

    def deSerializeFMUstate(self, data):
        return self.s.deserializeFMUState(data)


def slave(unzipped, md, name):
    """An instantiated FMU2Slave, or for an FMI 3.0 FMU an FMU3Slave in `Fmi3Names`."""
    from fmpy.fmi2 import FMU2Slave
    from fmpy.fmi3 import FMU3Slave

    three = md.fmiVersion.startswith("3")
    s = (FMU3Slave if three else FMU2Slave)(guid=md.guid, unzipDirectory=str(unzipped),
                                            modelIdentifier=md.coSimulation.modelIdentifier,
                                            instanceName=name)
    s.instantiate()
    return Fmi3Names(s) if three else s


def refused(call, *args):
    """The call must raise (fmpy raises on any status above Warning)."""
    try:
        call(*args)
    except Exception:  # fmpy raises FMICallException; anything else is a failure too
        return 1
    raise AssertionError(f"{call.__name__}{args!r} was accepted")


def huge_step(s, fy, how):
    """Issue 13: a finite but huge load (or input rate) whose step would be non-finite."""
    if how == "load":
        s.setReal([fy], [1.7976931348623157e308])
    else:
        s.setRealInputDerivatives([fy], [1], [1e308])
    s.doStep(0.0, H)


def drive(unzipped, steps, seed=1):
    """Run the misused and the clean instance; returns (misuse count, their outputs)."""
    from fmpy import read_model_description

    md = read_model_description(str(unzipped))
    vr = {v.name: v.valueReference for v in md.modelVariables}
    fy, y = vr["node_121.fy"], vr["node_121.y"]
    bad = slave(unzipped, md, "fmpy 100%s %n %d%%")
    clean = slave(unzipped, md, "clean")
    n = 0
    # Illegal in Instantiated: each refusal, then reset.
    for call, args in [(bad.doStep, (0.0, H)), (bad.getReal, ([y],)),
                       (bad.exitInitializationMode, ()), (bad.terminate, ())]:
        n += refused(call, *args)
        bad.reset()
    for s in (bad, clean):
        s.setupExperiment(startTime=0.0)
        s.enterInitializationMode()
        s.exitInitializationMode()
    saved = bad.getFMUstate()
    good_bytes = bad.serializeFMUstate(saved)
    rng = random.Random(seed)
    misuse = [
        (bad.setReal, ([fy], [float("nan")])),
        (bad.setReal, ([fy], [float("inf")])),
        (bad.setReal, ([fy, y], [1.0, 2.0])),
        (bad.setReal, ([10**6], [1.0])),
        (bad.getReal, ([10**6],)),
        (bad.doStep, (0.0, 0.0)),
        (bad.doStep, (0.0, -H)),
        (bad.doStep, (1.0, H)),
        (bad.doStep, (float("nan"), H)),
        (bad.doStep, (float("inf"), H)),
        (bad.enterInitializationMode, ()),
        (bad.deSerializeFMUstate, (b"",)),
        (bad.deSerializeFMUstate, (good_bytes[:-1],)),
        (bad.deSerializeFMUstate, (good_bytes[:len(good_bytes) // 2],)),
        (bad.deSerializeFMUstate, (b"FXBSTATE" + bytes(64),)),
        (huge_step, (bad, fy, "load")),
    ]
    if not isinstance(bad, Fmi3Names):
        misuse.append((huge_step, (bad, fy, "rate")))
    for k in range(0, len(good_bytes), 13):
        flipped = bytearray(good_bytes)
        flipped[k] ^= 0xFF
        misuse.append((bad.deSerializeFMUstate, (bytes(flipped),)))
    for _ in range(50):
        misuse.append((bad.deSerializeFMUstate,
                       (bytes(rng.getrandbits(8) for _ in range(rng.randrange(2048))),)))
    for call, args in misuse:
        n += refused(call, *args)
        bad.setFMUstate(saved)
    # nvr = 0 is fine.
    bad.setReal([], [])
    assert list(bad.getReal([])) == []
    out_bad, out_clean = [], []
    t = 0.0
    for k in range(steps):
        f = force(t)
        for s, out in ((bad, out_bad), (clean, out_clean)):
            s.setReal([fy], [f])
            s.doStep(t, H)
            out.append(s.getReal([y])[0])
        if k == steps // 2:
            # Save, serialise, step on, restore the bytes, redo the step: same bits.
            mid = bad.getFMUstate()
            copy = bad.deSerializeFMUstate(bad.serializeFMUstate(mid))
            bad.setReal([fy], [force(t + H)])
            bad.doStep(t + H, H)
            bad.setFMUstate(copy)
            bad.freeFMUstate(copy)
            bad.freeFMUstate(mid)
        t = (k + 1) * H
    bad.freeFMUstate(saved)
    for s in (bad, clean):
        s.terminate()
        s.freeInstance()
    return n, out_bad, out_clean


def unzip(fmu, where):
    with zipfile.ZipFile(fmu) as z:
        z.extractall(where)
    return Path(where)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("fmu", help="a packed .fmu (cantilever, tip node 121; FMI 2.0 or 3.0) or its unzipped folder")
    ap.add_argument("--steps", type=int, default=200)
    a = ap.parse_args(argv)
    path = Path(a.fmu)
    if path.is_file():
        import tempfile
        path = unzip(path, tempfile.mkdtemp(prefix="fxbody_robust_fmpy_"))
    n, out_bad, out_clean = drive(path, a.steps)
    same = all(struct.pack("<d", p) == struct.pack("<d", q) for p, q in zip(out_bad, out_clean))
    print(f"fmpy misuse cases refused: {n}; {a.steps} steps; misused == clean bit for bit: {same}")
    return 0 if same and len(out_bad) == a.steps else 1


def test_careless_fmpy_master(cantilever_tip, tmp_path):
    """In a child process, so that a crash shows as a signal rather than killing pytest."""
    fmu, _ = cantilever_tip
    careless(fmu, 17)


def test_careless_fmpy_master_fmi3(cantilever_tip, fmu_dir):
    """The same careless master on the FMI 3.0 FMU (FMU3Slave): every misuse refused,
    the misused instance equal to the clean one bit for bit."""
    from conftest import pack_fmu

    _, ref = cantilever_tip
    fmu = pack_fmu(fmu_dir, "cantilever", "--nodes", str(ref["tip_node"]), "--fmi", "3",
                   name="cantilever_careless_fmi3")
    careless(fmu, 16)


def careless(fmu, listed):
    """Run this file on `fmu` in a child process; `listed` misuse cases are in `drive`'s
    list besides the 4 illegal calls and the 50 random states."""
    run = subprocess.run([sys.executable, __file__, str(fmu), "--steps", "300"],
                         capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stdout + run.stderr
    assert "bit for bit: True" in run.stdout, run.stdout
    # Every misuse was refused (the count: 4 illegal calls, the listed, 50 random, flips).
    count = int(run.stdout.split("misuse cases refused: ")[1].split(";")[0])
    assert count >= 4 + listed + 50, run.stdout


if __name__ == "__main__":
    sys.exit(main())
