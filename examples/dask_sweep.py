"""A parameter sweep of the packed cantilever on Dask (dask.distributed): 64 runs over the
tip load amplitude and the modal damping ratio, spread over the cluster's workers.

Each worker thread loads the FMU once (one fmi2Instantiate) and reuses that instance for
every run it is given, returning it to its initial state with fmi2Reset; the FMU's bytes
travel to the workers through the cluster (no shared file system needed). The results
are gathered into one table (CSV) and a heat map of the peak tip deflection over the two
parameters (SVG, written without a plotting library).

    python examples/dask_sweep.py cantilever.fmu                           # a LocalCluster here
    python examples/dask_sweep.py cantilever.fmu --scheduler tcp://scheduler:8786

The FMU: `fxbody pack fixtures/cantilever.fxb --coords fixtures/cantilever.nodes.rad
--nodes 121 -o cantilever.fmu`. Every worker needs fmpy and numpy; this file is shipped
to the workers by `sweep` (Client.upload_file)."""

import argparse
import csv
import hashlib
import os
import shutil
import sys
import tempfile
import threading
import zipfile

import numpy as np

AMPLITUDES = [0.5 * k for k in range(1, 9)]  # tip load, N (node_121.fy)
RATIOS = [0.0, 0.01, 0.02, 0.05, 0.1, 0.2, 0.3, 0.5]  # damping.ratio, on every mode
TIP = "node_121"
LOAD = f"{TIP}.fy"
OUT = f"{TIP}.y"
H, STEPS = 2e-4, 1000  # 0.2 s: more than a period of the first mode (6.7 Hz)
COLUMNS = ["amplitude_N", "damping_ratio", "peak_tip_deflection_m", "time_of_peak_s"]

# Per worker thread: its instance of each FMU (by content digest); and every instance
# this process made, for worker_stats.
_local = threading.local()
_made = []


class Body:
    """One instance of the FMU, instantiated once and reset (fmi2Reset) between runs."""

    def __init__(self, fmu_bytes, digest):
        from fmpy import read_model_description
        from fmpy.fmi2 import FMU2Slave

        where = os.path.join(tempfile.gettempdir(), f"fxbody_sweep_{digest}")
        if not os.path.isdir(where):
            # Unpack beside, then rename: other threads or processes of this machine
            # may be unpacking the same FMU at the same time.
            tmp = tempfile.mkdtemp(prefix=f"fxbody_sweep_{digest}_")
            fmu = os.path.join(tmp, "body.fmu")
            with open(fmu, "wb") as f:
                f.write(fmu_bytes)
            with zipfile.ZipFile(fmu) as z:
                z.extractall(os.path.join(tmp, "unzipped"))
            try:
                os.rename(os.path.join(tmp, "unzipped"), where)
            except OSError:
                if not os.path.isdir(where):
                    raise
            finally:
                shutil.rmtree(tmp, ignore_errors=True)
        md = read_model_description(where)
        self.vr = {v.name: v.valueReference for v in md.modelVariables}
        for name in (LOAD, OUT, "damping.ratio"):
            if name not in self.vr:
                raise ValueError(f"the FMU has no variable {name}: pack the cantilever with "
                                 f"--nodes 121 with an fxbody that has the damping.ratio parameter")
        self.slave = FMU2Slave(guid=md.guid, unzipDirectory=where, modelIdentifier=md.coSimulation.modelIdentifier,
                               instanceName=f"sweep-{os.getpid()}-{threading.get_ident()}")
        self.slave.instantiate()
        self.used = False
        self.runs = 0
        _made.append(self)

    def run(self, amplitude, ratio):
        """One run from rest: the step load `amplitude` on the tip, damping ratio `ratio`;
        returns the peak tip deflection and its time."""
        s = self.slave
        if self.used:
            s.reset()
        self.used = True
        s.setReal([self.vr["damping.ratio"]], [ratio])
        s.setupExperiment(startTime=0.0, stopTime=H * STEPS)
        s.enterInitializationMode()
        s.exitInitializationMode()
        y0 = s.getReal([self.vr[OUT]])[0]
        s.setReal([self.vr[LOAD]], [amplitude])
        peak, when = 0.0, 0.0
        for k in range(STEPS):
            s.doStep(k * H, H)
            u = abs(s.getReal([self.vr[OUT]])[0] - y0)
            if u > peak:
                peak, when = u, (k + 1) * H
        self.runs += 1
        return peak, when


def body(fmu_bytes, digest):
    """This thread's instance of the FMU, created on first use."""
    bodies = getattr(_local, "bodies", None)
    if bodies is None:
        bodies = _local.bodies = {}
    if digest not in bodies:
        bodies[digest] = Body(fmu_bytes, digest)
    return bodies[digest]


def run_one(amplitude, ratio, fmu_bytes, digest):
    """One table row (the task each worker runs)."""
    peak, when = body(fmu_bytes, digest).run(amplitude, ratio)
    return {"amplitude_N": amplitude, "damping_ratio": ratio, "peak_tip_deflection_m": peak, "time_of_peak_s": when}


def worker_stats():
    """How many FMU instances this worker process made and how many runs they made
    (client.run(worker_stats) asks every worker)."""
    return {"instances": len(_made), "runs": sum(b.runs for b in list(_made))}


def grid():
    return [(a, r) for r in RATIOS for a in AMPLITUDES]


def sweep(client, fmu_path):
    """The 64 runs on the cluster behind `client`; rows in grid() order."""
    client.upload_file(__file__)
    data = open(fmu_path, "rb").read()
    digest = hashlib.sha256(data).hexdigest()[:16]
    [shared] = client.scatter([data], broadcast=True)
    amps, ratios = zip(*grid())
    futures = client.map(run_one, amps, ratios, fmu_bytes=shared, digest=digest, pure=False)
    return client.gather(futures)


def serial(fmu_path):
    """The same runs, one after the other in this process."""
    data = open(fmu_path, "rb").read()
    digest = hashlib.sha256(data).hexdigest()[:16]
    return [run_one(a, r, data, digest) for a, r in grid()]


def write_csv(rows, path):
    with open(path, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=COLUMNS)
        w.writeheader()
        for row in rows:
            w.writerow({k: repr(row[k]) for k in COLUMNS})


def write_svg(rows, path):
    """Heat map of the peak tip deflection: amplitude across, damping ratio down."""
    peak = {(r["amplitude_N"], r["damping_ratio"]): r["peak_tip_deflection_m"] for r in rows}
    top = max(peak.values())
    cw, ch, left, head = 78, 34, 120, 60
    width, height = left + cw * len(AMPLITUDES) + 20, head + ch * len(RATIOS) + 50
    out = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="{height}" '
           f'font-family="sans-serif" font-size="12">',
           f'<text x="{width / 2}" y="20" text-anchor="middle" font-size="14">Peak tip deflection (mm), '
           f'cantilever, step load on node 121, {STEPS * H:g} s</text>',
           f'<text x="{left + cw * len(AMPLITUDES) / 2}" y="{height - 10}" text-anchor="middle">tip load amplitude (N)</text>',
           f'<text x="14" y="{head + ch * len(RATIOS) / 2}" transform="rotate(-90 14 {head + ch * len(RATIOS) / 2})" '
           f'text-anchor="middle">damping.ratio</text>']
    for j, r in enumerate(RATIOS):
        y = head + j * ch
        out.append(f'<text x="{left - 8}" y="{y + ch / 2 + 4}" text-anchor="end">{r:g}</text>')
        for i, a in enumerate(AMPLITUDES):
            x = left + i * cw
            v = peak[(a, r)] / top
            fill = f"rgb({int(255 * v)},{int(80 + 100 * (1 - v))},{int(255 * (1 - v))})"
            out.append(f'<rect x="{x}" y="{y}" width="{cw - 2}" height="{ch - 2}" fill="{fill}"/>')
            out.append(f'<text x="{x + cw / 2 - 1}" y="{y + ch / 2 + 4}" text-anchor="middle" fill="white">'
                       f'{peak[(a, r)] * 1e3:.3f}</text>')
    for i, a in enumerate(AMPLITUDES):
        out.append(f'<text x="{left + i * cw + cw / 2}" y="{head - 8}" text-anchor="middle">{a:g}</text>')
    out.append("</svg>")
    with open(path, "w") as f:
        f.write("\n".join(out) + "\n")


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("fmu", help="the packed cantilever (tip node 121 exposed)")
    p.add_argument("--scheduler", help="address of a running Dask scheduler (default: a LocalCluster here)")
    p.add_argument("--workers", type=int, default=2, help="LocalCluster worker processes (default 2)")
    p.add_argument("--out", default="sweep", help="output folder for sweep.csv and sweep.svg (default ./sweep)")
    args = p.parse_args(argv)
    from dask.distributed import Client, LocalCluster

    if args.scheduler:
        client = Client(args.scheduler)
        cluster = None
    else:
        cluster = LocalCluster(n_workers=args.workers, threads_per_worker=1, processes=True, dashboard_address=None)
        client = Client(cluster)
    try:
        rows = sweep(client, args.fmu)
    finally:
        client.close()
        if cluster is not None:
            cluster.close()
    os.makedirs(args.out, exist_ok=True)
    write_csv(rows, os.path.join(args.out, "sweep.csv"))
    write_svg(rows, os.path.join(args.out, "sweep.svg"))
    worst = max(rows, key=lambda r: r["peak_tip_deflection_m"])
    print(f"{len(rows)} runs; largest peak tip deflection {worst['peak_tip_deflection_m']:.4e} m "
          f"({worst['amplitude_N']:g} N, damping ratio {worst['damping_ratio']:g}); "
          f"{args.out}/sweep.csv, {args.out}/sweep.svg")


if __name__ == "__main__":
    # Run as the module `dask_sweep`, so that the workers find its functions by name.
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    import dask_sweep

    dask_sweep.main()
