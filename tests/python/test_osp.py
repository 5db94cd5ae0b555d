"""The OSP model description that `fxbody pack` writes beside the .fmu
(<model>_OspModelDescription.xml: per exposed node a LinearMechanicalPort of force and
linear velocity and, with rotational DOFs, an AngularMechanicalPort of torque and angular
velocity), loaded through libcosim's system-structure support: an OspSystemStructure.xml
with two cantilevers, body `a` under a held tip load and body `b` driven through a
variable-group connection from a's velocity group to b's force group (a one-way damper
of 1 N s/m: b's tip force is a's tip velocity). libcosim finds the variables of each group
in our file; the run equals the same coupling made by hand in fmpy, step for step (the
fixed-step algorithm hands each step's outputs to the next step's inputs)."""

import os
import xml.etree.ElementTree as ET

import numpy as np
import pytest

import masters
from conftest import pack_fmu
from masters import Instance

NODE = "node_121"
H, STEPS = 2e-4, 1000
LOAD = 1.0


def local(tag):
    return tag.rsplit("}", 1)[-1]


def groups(osp_file):
    """{group element name: (group type, [variable refs])} for every group at any depth."""
    out = {}
    for el in ET.parse(osp_file).getroot().iter():
        refs = [v.get("ref") for v in el if local(v.tag) == "Variable"]
        if refs and el.get("name"):
            out[el.get("name")] = (local(el.tag), refs)
    return out


@pytest.fixture(scope="module")
def osp_pair(tmp_path_factory):
    """The cantilever packed (tip exposed) into a folder of its own with its OSP model
    description, under its model name (libcosim looks for <modelName>_OspModelDescription.xml
    beside the FMU)."""
    masters.require("libcosim")
    work = tmp_path_factory.mktemp("osp")
    fmu = pack_fmu(work, "cantilever", "--nodes", "121", name="cantilever")
    work = fmu.parent
    osp = work / "cantilever_OspModelDescription.xml"
    assert osp.is_file(), f"fxbody pack wrote no {osp.name} beside {fmu.name}: {sorted(os.listdir(work))}"
    return work, fmu, osp


def port_group(found, kind, axes_names):
    """The name of the group of type `kind` whose variables are exactly `axes_names`."""
    names = [n for n, (k, refs) in found.items() if k == kind and refs == axes_names]
    assert len(names) == 1, f"no single {kind} group of {axes_names} in {found}"
    return names[0]


def test_osp_description_has_a_port_pair_per_exposed_node(osp_pair):
    """The linear port always; the angular port where the FMU has the angular-velocity
    outputs to pair with the moment inputs."""
    from fmpy import read_model_description

    _, fmu, osp = osp_pair
    names = {v.name for v in read_model_description(str(fmu)).modelVariables}
    found = groups(osp)
    root = ET.parse(osp).getroot()
    ports = {local(el.tag): el for el in root.iter() if local(el.tag).endswith("MechanicalPort")}
    assert "LinearMechanicalPort" in ports
    members = {local(g.tag) for g in ports["LinearMechanicalPort"]}
    assert members == {"Force", "LinearVelocity"}, members
    port_group(found, "Force", [f"{NODE}.f{a}" for a in "xyz"])
    port_group(found, "LinearVelocity", [f"{NODE}.v{a}" for a in "xyz"])
    if f"{NODE}.wx" in names:
        assert {local(g.tag) for g in ports["AngularMechanicalPort"]} == {"Torque", "AngularVelocity"}
        port_group(found, "Torque", [f"{NODE}.m{a}" for a in "xyz"])
        port_group(found, "AngularVelocity", [f"{NODE}.w{a}" for a in "xyz"])
    else:
        assert "AngularMechanicalPort" not in ports
    # Every variable a group names is a variable of the FMU.
    assert {r for _, refs in found.values() for r in refs} <= names


def system_structure(fmu_name, velocity_group, force_group, method):
    initial = (f'<InitialValue variable="method"><Integer value="{method}"/></InitialValue>')
    return f"""<?xml version="1.0" encoding="utf-8"?>
<OspSystemStructure xmlns="http://opensimulationplatform.com/MSMI/OSPSystemStructure" version="0.1">
  <StartTime>0.0</StartTime>
  <BaseStepSize>{H}</BaseStepSize>
  <Algorithm>fixedStep</Algorithm>
  <Simulators>
    <Simulator name="a" source="{fmu_name}">
      <InitialValues>
        {initial}
        <InitialValue variable="{NODE}.fy"><Real value="{LOAD}"/></InitialValue>
      </InitialValues>
    </Simulator>
    <Simulator name="b" source="{fmu_name}">
      <InitialValues>{initial}</InitialValues>
    </Simulator>
  </Simulators>
  <Connections>
    <VariableGroupConnection>
      <VariableGroup simulator="a" name="{velocity_group}"/>
      <VariableGroup simulator="b" name="{force_group}"/>
    </VariableGroupConnection>
  </Connections>
</OspSystemStructure>
"""


def by_hand(fmu, method):
    """The same coupling in fmpy: each step, b's force is a's velocity after the previous step."""
    import tempfile

    from fmpy import extract

    from slave import Slave

    outs = [f"{NODE}.{q}" for q in ("y", "vx", "vy", "vz")]
    with tempfile.TemporaryDirectory() as unz:
        extract(str(fmu), unz)
        a = Slave(fmu, unz, name="a").start(reals={f"{NODE}.fy": LOAD}, ints={"method": method})
        b = Slave(fmu, unz, name="b").start(ints={"method": method})
        va = [0.0, 0.0, 0.0]
        ya, yb = [], []
        for k in range(STEPS):
            b.s.setReal([b.vr[f"{NODE}.f{x}"] for x in "xyz"], va)
            a.s.doStep(k * H, H)
            b.s.doStep(k * H, H)
            ra, rb = a.get(*outs), b.get(*outs)
            va = list(ra[1:])
            ya.append(ra[0])
            yb.append(rb[0])
        a.free()
        b.free()
    return np.array(ya), np.array(yb)


@pytest.mark.parametrize("method", [1, 3])
def test_libcosim_runs_two_bodies_connected_by_ports(osp_pair, method):
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
    from libcosimpy.CosimObserver import CosimObserver

    work, fmu, osp = osp_pair
    log_output_level(CosimLogLevel.WARNING)
    found = groups(osp)
    velocity = port_group(found, "LinearVelocity", [f"{NODE}.v{a}" for a in "xyz"])
    force = port_group(found, "Force", [f"{NODE}.f{a}" for a in "xyz"])
    structure = work / f"OspSystemStructure_{method}.xml"
    structure.write_text(system_structure(fmu.name, velocity, force, method))
    ex = CosimExecution.from_osp_config_file(str(structure))
    obs = CosimObserver.create_last_value()
    ex.add_observer(obs)
    idx = {name: ex.slave_index_from_instance_name(name) for name in ("a", "b")}
    vr = {v.name.decode(): v.reference for v in ex.slave_variables(idx["a"])}
    ya, yb = [], []
    for _ in range(STEPS):
        assert ex.step()
        ya.append(obs.last_real_values(idx["a"], [vr[f"{NODE}.y"]])[0])
        yb.append(obs.last_real_values(idx["b"], [vr[f"{NODE}.y"]])[0])
    want_a, want_b = by_hand(fmu, method)
    # b moves only through the connection (measured: a quarter of a's peak deflection).
    assert np.abs(want_b).max() > 1e-4 * np.abs(want_a).max()
    for got, want in ((np.array(ya), want_a), (np.array(yb), want_b)):
        scale = np.abs(want).max()
        assert np.abs(got - want).max() <= 1e-12 * scale, np.abs(got - want).max() / scale

