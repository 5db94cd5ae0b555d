"""A parameter sweep of a packed body on Dask (dask.distributed): runs over a grid of load
amplitudes and modal damping ratios, spread over the cluster's workers.

Each run applies a step load (one input of one exposed node, `--node` and `--load`) from
rest and records the peak of the matching motion output (`fy` -> `y`, `mz` -> `rz`).
Each worker thread loads the FMU once (one fmi2Instantiate) and reuses that instance for
every run it is given, returning it to its initial state with fmi2Reset; the FMU's bytes
travel to the workers through the cluster (no shared file system needed). The results
are gathered into one table (CSV) and a heat map of the peak deflection over the two
parameters (SVG, written without a plotting library).

    python examples/dask_sweep.py cantilever.fmu                           # a LocalCluster here
    python examples/dask_sweep.py cantilever.fmu --scheduler tcp://scheduler:8786
    python examples/dask_sweep.py body.fmu --node 111 --load fz \\
        --amplitudes 1,2,4 --ratios 0,0.05 --step 1e-4 --steps 2000

The defaults sweep the shipped cantilever's tip: `fxbody pack fixtures/cantilever.fxb
--coords fixtures/cantilever.nodes.rad --nodes 121 -o cantilever.fmu`, 8 amplitudes
(0.5 to 4 N on node_121.fy) times 8 damping ratios (0 to 0.5), 1000 steps of 0.2 ms.
Every worker needs fmpy and numpy; this file is shipped to the workers by `sweep`
(Client.upload_file)."""

import argparse
import csv
import hashlib
import os
import shutil
import sys
import tempfile
import threading
import zipfile
from dataclasses import dataclass


AMPLITUDES = (0.5, 1.0, 1.5, 2.0, 2.5, 3.0, 3.5, 4.0)  # default load amplitudes, N (or N m)
RATIOS = (0.0, 0.01, 0.02, 0.05, 0.1, 0.2, 0.3, 0.5)  # default damping.ratio, on every mode
H, STEPS = 2e-4, 1000  # default: 0.2 s, more than a period of the cantilever's first mode (6.7 Hz)
# The motion output each load input drives.
OUTPUT_OF = {"fx": "x", "fy": "y", "fz": "z", "mx": "rx", "my": "ry", "mz": "rz"}
COLUMNS = ["amplitude", "damping_ratio", "peak_deflection", "time_of_peak_s"]


@dataclass(frozen=True)
class Sweep:
    """What one sweep runs: the node and load input, the grid, the step and its count."""

    node: int = 121
    load: str = "fy"
    amplitudes: tuple = AMPLITUDES
    ratios: tuple = RATIOS
    step: float = H
    steps: int = STEPS

    def __post_init__(self):
        if self.load not in OUTPUT_OF:
            raise ValueError(f"load {self.load!r}: expected one of {', '.join(OUTPUT_OF)}")
        if not (self.amplitudes and self.ratios) or self.steps < 1 or not self.step > 0:
            raise ValueError(f"an empty grid or no time to run: {self}")

    @property
    def load_var(self):
        return f"node_{self.node}.{self.load}"

    @property
    def out_var(self):
        return f"node_{self.node}.{OUTPUT_OF[self.load]}"

    def grid(self):
        return [(a, r) for r in self.ratios for a in self.amplitudes]


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
        self.slave = FMU2Slave(guid=md.guid, unzipDirectory=where, modelIdentifier=md.coSimulation.modelIdentifier,
                               instanceName=f"sweep-{os.getpid()}-{threading.get_ident()}")
        self.slave.instantiate()
        self.used = False
        self.runs = 0
        _made.append(self)

    def run(self, amplitude, ratio, sweep):
        """One run from rest: the step load `amplitude` on `sweep`'s load input, damping
        ratio `ratio`; returns the peak of the matching output's change and its time."""
        missing = [n for n in (sweep.load_var, sweep.out_var, "damping.ratio") if n not in self.vr]
        if missing:
            nodes = sorted({n.split(".")[0] for n in self.vr if n.startswith("node_")})
            raise ValueError(f"the FMU has no variable {', '.join(missing)}: its nodes are "
                             f"{', '.join(nodes) or 'none'}; choose one with --node, or pack "
                             f"the body with --nodes {sweep.node}")
        s = self.slave
        H, STEPS = sweep.step, sweep.steps
        if self.used:
            s.reset()
        self.used = True
        s.setReal([self.vr["damping.ratio"]], [ratio])
        s.setupExperiment(startTime=0.0, stopTime=H * STEPS)
        s.enterInitializationMode()
        s.exitInitializationMode()
        y0 = s.getReal([self.vr[sweep.out_var]])[0]
        s.setReal([self.vr[sweep.load_var]], [amplitude])
        peak, when = 0.0, 0.0
        for k in range(STEPS):
            s.doStep(k * H, H)
            u = abs(s.getReal([self.vr[sweep.out_var]])[0] - y0)
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


def run_one(amplitude, ratio, fmu_bytes, digest, sweep=Sweep()):
    """One table row (the task each worker runs)."""
    peak, when = body(fmu_bytes, digest).run(amplitude, ratio, sweep)
    return {"amplitude": amplitude, "damping_ratio": ratio, "peak_deflection": peak, "time_of_peak_s": when}


def worker_stats():
    """How many FMU instances this worker process made and how many runs they made
    (client.run(worker_stats) asks every worker)."""
    return {"instances": len(_made), "runs": sum(b.runs for b in list(_made))}


def sweep(client, fmu_path, config=Sweep()):
    """The runs of `config` on the cluster behind `client`; rows in config.grid() order."""
    client.upload_file(__file__)
    data = open(fmu_path, "rb").read()
    digest = hashlib.sha256(data).hexdigest()[:16]
    [shared] = client.scatter([data], broadcast=True)
    amps, ratios = zip(*config.grid())
    futures = client.map(run_one, amps, ratios, fmu_bytes=shared, digest=digest, sweep=config, pure=False)
    return client.gather(futures)


def serial(fmu_path, config=Sweep()):
    """The same runs, one after the other in this process."""
    data = open(fmu_path, "rb").read()
    digest = hashlib.sha256(data).hexdigest()[:16]
    return [run_one(a, r, data, digest, config) for a, r in config.grid()]


def write_csv(rows, path):
    with open(path, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=COLUMNS)
        w.writeheader()
        for row in rows:
            w.writerow({k: repr(row[k]) for k in COLUMNS})


def write_svg(rows, path, config=Sweep()):
    """Heat map of the peak deflection: amplitude across, damping ratio down."""
    amps = sorted({r["amplitude"] for r in rows})
    ratios = sorted({r["damping_ratio"] for r in rows})
    peak = {(r["amplitude"], r["damping_ratio"]): r["peak_deflection"] for r in rows}
    top = max(peak.values()) or 1.0
    cw, ch, left, head = 78, 34, 120, 60
    width, height = left + cw * len(amps) + 20, head + ch * len(ratios) + 50
    out = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="{height}" '
           f'font-family="sans-serif" font-size="12">',
           f'<text x="{width / 2}" y="20" text-anchor="middle" font-size="14">Peak {config.out_var} change '
           f'(x 1e-3), step load on {config.load_var}, {config.steps * config.step:g} s</text>',
           f'<text x="{left + cw * len(amps) / 2}" y="{height - 10}" text-anchor="middle">load amplitude</text>',
           f'<text x="14" y="{head + ch * len(ratios) / 2}" transform="rotate(-90 14 {head + ch * len(ratios) / 2})" '
           f'text-anchor="middle">damping.ratio</text>']
    for j, r in enumerate(ratios):
        y = head + j * ch
        out.append(f'<text x="{left - 8}" y="{y + ch / 2 + 4}" text-anchor="end">{r:g}</text>')
        for i, a in enumerate(amps):
            x = left + i * cw
            v = peak[(a, r)] / top
            fill = f"rgb({int(255 * v)},{int(80 + 100 * (1 - v))},{int(255 * (1 - v))})"
            out.append(f'<rect x="{x}" y="{y}" width="{cw - 2}" height="{ch - 2}" fill="{fill}"/>')
            out.append(f'<text x="{x + cw / 2 - 1}" y="{y + ch / 2 + 4}" text-anchor="middle" fill="white">'
                       f'{peak[(a, r)] * 1e3:.3f}</text>')
    for i, a in enumerate(amps):
        out.append(f'<text x="{left + i * cw + cw / 2}" y="{head - 8}" text-anchor="middle">{a:g}</text>')
    out.append("</svg>")
    with open(path, "w") as f:
        f.write("\n".join(out) + "\n")


def numbers(text):
    """A command-line list of numbers: `0.5,1,2` (commas and/or blanks)."""
    try:
        values = tuple(float(t) for t in text.replace(",", " ").split())
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected numbers separated by commas, found {text!r}") from None
    if not values:
        raise argparse.ArgumentTypeError("expected at least one number")
    return values


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("fmu", help="the packed body (default grid: the cantilever with tip node 121 exposed)")
    p.add_argument("--node", type=int, default=Sweep.node, help=f"exposed node ID to load (default {Sweep.node})")
    p.add_argument("--load", choices=sorted(OUTPUT_OF), default=Sweep.load,
                   help=f"the node's load input; the matching motion is recorded (default {Sweep.load})")
    p.add_argument("--amplitudes", type=numbers, default=AMPLITUDES,
                   help="load amplitudes, N or N m, comma-separated (default 0.5,1,...,4)")
    p.add_argument("--ratios", type=numbers, default=RATIOS,
                   help="damping.ratio values, comma-separated (default 0,0.01,0.02,0.05,0.1,0.2,0.3,0.5)")
    p.add_argument("--step", type=float, default=H, help=f"communication step, s (default {H:g})")
    p.add_argument("--steps", type=int, default=STEPS, help=f"steps per run (default {STEPS})")
    p.add_argument("--scheduler", help="address of a running Dask scheduler (default: a LocalCluster here)")
    p.add_argument("--workers", type=int, default=2, help="LocalCluster worker processes (default 2)")
    p.add_argument("--out", default="sweep", help="output folder for sweep.csv and sweep.svg (default ./sweep)")
    args = p.parse_args(argv)
    try:
        config = Sweep(node=args.node, load=args.load, amplitudes=args.amplitudes, ratios=args.ratios,
                       step=args.step, steps=args.steps)
    except ValueError as e:
        p.error(str(e))
    from dask.distributed import Client, LocalCluster

    if args.scheduler:
        client = Client(args.scheduler)
        cluster = None
    else:
        cluster = LocalCluster(n_workers=args.workers, threads_per_worker=1, processes=True, dashboard_address=None)
        client = Client(cluster)
    try:
        rows = sweep(client, args.fmu, config)
    finally:
        client.close()
        if cluster is not None:
            cluster.close()
    os.makedirs(args.out, exist_ok=True)
    write_csv(rows, os.path.join(args.out, "sweep.csv"))
    write_svg(rows, os.path.join(args.out, "sweep.svg"), config)
    worst = max(rows, key=lambda r: r["peak_deflection"])
    print(f"{len(rows)} runs; largest peak {config.out_var} change {worst['peak_deflection']:.4e} "
          f"({worst['amplitude']:g} on {config.load_var}, damping ratio {worst['damping_ratio']:g}); "
          f"{args.out}/sweep.csv, {args.out}/sweep.svg")


if __name__ == "__main__":
    # Run as the module `dask_sweep`, so that the workers find its functions by name.
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    import dask_sweep

    dask_sweep.main()
