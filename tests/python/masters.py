"""One way to drive a packed FMU through each of three independent FMI masters: fmpy
(FMU2Slave called step by step), libcosim (DNV's Open Simulation Platform engine, through
libcosimpy) and ecos (through ecospy). Every master runs the same experiment, an
`Instance` list: parameters set before initialisation, one load input set before every
step from a function of the step's start time, and outputs read after every step; the
result is, per instance, an array (steps, outputs) of what the master read back.

A master that cannot be imported makes the calling test skip with the import error
(`require`), never pass; under FXBODY_REQUIRE_ALL=1 (CI) it fails instead."""

import os
import sys
from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from conftest import missing

MASTERS = ["fmpy", "libcosim", "ecos"]
# ecos's log level; ecos 0.7 shows the FMU's error messages at "debug" only.
ECOS_LOG = "warn"


@dataclass
class Instance:
    """One FMU instance of an experiment."""

    name: str
    outputs: list
    load: str = None  # the Real input set before every step
    load_at: Callable = None  # step start time -> load value
    ints: dict = field(default_factory=dict)  # Integer parameters (e.g. method)
    reals: dict = field(default_factory=dict)  # Real parameters


class Refused(Exception):
    """The master reported that the FMU (or the master itself) refused a call."""


def require(master):
    """Import a master's Python package, or skip the calling test with the reason (fail
    it under FXBODY_REQUIRE_ALL=1: conftest.missing)."""
    try:
        if master == "fmpy":
            import fmpy  # noqa: F401
        elif master == "libcosim":
            import libcosimpy.CosimExecution  # noqa: F401
        elif master == "ecos":
            import ecospy  # noqa: F401
        else:
            raise ValueError(f"unknown master {master}")
    except (ImportError, OSError) as e:
        hint = ""
        if master == "ecos" and "libtbb" in str(e):
            hint = (f" (ecos needs PyPI tbb's libtbb.so.12 on LD_LIBRARY_PATH: "
                    f"{os.path.join(sys.prefix, 'lib')}; scripts/test.sh exports it)")
        missing(master, f"cannot be imported: {type(e).__name__}: {e}{hint}")


def method_variable(fmu):
    """The `method` parameter of the FMU's model description (fmpy's reading)."""
    from fmpy import read_model_description

    md = read_model_description(str(fmu))
    return next(v for v in md.modelVariables if v.name == "method")


def versions():
    """The master packages' versions, for messages and the report."""
    from importlib.metadata import version
    return {m: version(p) for m, p in [("fmpy", "fmpy"), ("libcosim", "libcosimpy"), ("ecos", "ecospy")]}


def run(master, fmu, h, n, instances):
    """Run `n` steps of size `h` of every instance in one execution of `master`;
    returns {instance name: array (n, len(outputs))}."""
    require(master)
    return {"fmpy": _fmpy, "libcosim": _libcosim, "ecos": _ecos}[master](str(fmu), h, n, instances)


def _fmpy(fmu, h, n, instances):
    import tempfile

    from fmpy import extract

    from slave import Slave

    from fmpy.fmi1 import FMICallException

    with tempfile.TemporaryDirectory() as unz:
        extract(fmu, unz)
        slaves = []
        try:
            for i in instances:
                slaves.append(Slave(fmu, unz, name=i.name))
                slaves[-1].start(reals=i.reals, ints=i.ints)
            out = {i.name: np.empty((n, len(i.outputs))) for i in instances}
            for k in range(n):
                t = k * h
                for i, s in zip(instances, slaves):
                    if i.load:
                        s.s.setReal([s.vr[i.load]], [i.load_at(t)])
                    s.s.doStep(t, h)
                    out[i.name][k] = s.s.getReal([s.vr[o] for o in i.outputs])
        except FMICallException as e:
            raise Refused(f"fmpy: {e}") from e
        finally:
            for s in slaves:
                s.s.freeInstance()
    return out


def _libcosim(fmu, h, n, instances):
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
    from libcosimpy.CosimManipulator import CosimManipulator
    from libcosimpy.CosimObserver import CosimObserver
    from libcosimpy.CosimSlave import CosimLocalSlave
    from libcosimpy._internal import get_last_error_message

    log_output_level(CosimLogLevel.WARNING)
    ns = round(h * 1e9)
    if abs(ns - h * 1e9) > 1e-6 * ns:
        raise ValueError(f"libcosim steps in whole nanoseconds; h = {h} s is not one")
    ex = CosimExecution.from_step_size(ns)
    man = CosimManipulator.create_override()
    obs = CosimObserver.create_last_value()
    ex.add_manipulator(man)
    ex.add_observer(obs)
    keep, idx, vrs = [], {}, {}
    for i in instances:
        slave = CosimLocalSlave(fmu_path=fmu, instance_name=i.name)
        keep.append(slave)
        idx[i.name] = ex.add_local_slave(slave)
        assert idx[i.name] >= 0, f"libcosim refused {fmu} as {i.name}"
        vrs[i.name] = vr = {v.name.decode(): v.reference for v in ex.slave_variables(idx[i.name])}
        for values, setter in [(i.ints, ex.integer_initial_value), (i.reals, ex.real_initial_value)]:
            for name, value in values.items():
                if name not in vr:
                    raise KeyError(f"libcosim does not list variable {name} of {fmu} (it drops the "
                                   f"variable types it does not support)")
                if not setter(idx[i.name], vr[name], value):
                    raise Refused(f"libcosim: initial value {name} = {value}: {get_last_error_message()}")
    out = {i.name: np.empty((n, len(i.outputs))) for i in instances}
    for k in range(n):
        t = k * h
        for i in instances:
            if i.load:
                assert man.slave_real_values(idx[i.name], [vrs[i.name][i.load]], [i.load_at(t)])
        if not ex.step():
            raise Refused(f"libcosim: step {k} failed: {get_last_error_message()}")
        for i in instances:
            out[i.name][k] = obs.last_real_values(idx[i.name], [vrs[i.name][o] for o in i.outputs])
    del ex, keep
    return out


def _ecos(fmu, h, n, instances):
    from ecospy import EcosLib, EcosSimulation, EcosSimulationStructure

    EcosLib.set_log_level(ECOS_LOG)
    ss = EcosSimulationStructure()
    params = {}
    for i in instances:
        ss.add_model(i.name, fmu)
        params.update({f"{i.name}::{k}": int(v) for k, v in i.ints.items()})
        params.update({f"{i.name}::{k}": float(v) for k, v in i.reals.items()})
    if params:
        assert ss.add_parameter_set("start", params), EcosLib.get_last_error()
    sim = EcosSimulation(structure=ss, step_size=h)
    try:
        if not sim.init(parameter_set="start" if params else None):
            raise Refused(f"ecos: init failed: {EcosLib.get_last_error()}")
        out = {i.name: np.empty((n, len(i.outputs))) for i in instances}
        for k in range(n):
            t = k * h
            for i in instances:
                if i.load:
                    sim.set_real(f"{i.name}::{i.load}", i.load_at(t))
            sim.step(1)
            for i in instances:
                out[i.name][k] = [sim.get_real(f"{i.name}::{o}") for o in i.outputs]
        sim.terminate()
    finally:
        sim.free()
        ss.free()
    return out
