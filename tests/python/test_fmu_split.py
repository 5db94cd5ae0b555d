"""The split free-body method (method value 4) through the packed FMU under fmpy: the
state saved with fmi2GetFMUstate, and serialised into a fresh instance, continues bit
for bit like the uninterrupted run, under a pulse on a tumbling free-free beam."""

import numpy as np
from fmpy import extract

from conftest import pack_fmu, reference
from slave import Slave

SPLIT = 4


def test_state_save_restore_and_serialisation_are_bit_for_bit(fmu_dir, tmp_path_factory):
    ref = reference("freefree")
    fmu = pack_fmu(fmu_dir, "freefree", name="freefree_split")
    unz = extract(str(fmu), str(tmp_path_factory.mktemp("split")))
    tip = str(next(r for r in ref["responses"] if r["name"] == "pulse")["load_node"])
    outs = [f"node_{n}.{a}" for n in ref["node_ids"] for a in ("x", "y", "vz")]
    outs += ["frame.P12", "energy.kinetic", "energy.strain"]
    spin = {"w0.x": 2.0, "w0.y": 5.0, "w0.z": 20.0}
    h = 1e-3

    def steps(s, k0, n):
        got = []
        for k in range(k0, k0 + n):
            s.set(**{f"node_{tip}__fy": 0.1 if k < 2 else 0.0})
            s.s.doStep(k * h, h)
            got.append(s.get(*outs))
        return np.array(got)

    a = Slave(fmu, unz, name="a").start(reals=spin, ints={"method": SPLIT})
    steps(a, 0, 10)
    state = a.s.getFMUstate()
    data = a.s.serializeFMUstate(state)
    first = steps(a, 10, 20)
    a.s.setFMUstate(state)
    again = steps(a, 10, 20)
    assert first.tobytes() == again.tobytes()
    assert np.abs(first).max() > 0.0
    b = Slave(fmu, unz, name="b").start(reals=spin, ints={"method": SPLIT})
    b.s.setFMUstate(b.s.deSerializeFMUstate(data))
    assert steps(b, 10, 20).tobytes() == first.tobytes()
    a.s.freeFMUstate(state)
    a.free()
    b.free()
