"""A solid L-bracket meshed with second-order tetrahedra (gmsh), two CalculiX `*RIGID BODY`
spiders, the whole-model matrices ccx writes (`*FREQUENCY, SOLVER=MATRIXSTORAGE`), and ccx's
own results to check a solver against.

    python tests/fe_models/bracket.py OUT_DIR [--size 6.0] [--modes 30] [--no-reference]

Writes into OUT_DIR (skipped when OUT_DIR/done.json already holds the same parameters):
- `nodes.csv`: `id,x,y,z` of every node, the spider nodes included (mm);
- `blocked.sti/.mas/.dof` and `free.sti/.mas/.dof`: K, M and the DOF map, spider A clamped
  (its REF and ROT nodes fixed) or nothing fixed;
- `reference.json` (unless `--no-reference`): ccx `*FREQUENCY` results of both cases
  (frequencies in Hz, as printed), and the `*STATIC` displacement of spider B's REF and ROT
  nodes under a force and a moment at spider B in the blocked case (as printed);
- `done.json`: the parameters, node and DOF counts, the spiders' node numbers and centres.

Units: mm, t, s, N (steel: E = 210000 MPa, nu = 0.3, rho = 7.85e-9 t/mm^3), so frequencies
are in Hz. The part: a 120 x 60 x 10 base and an 80-high wall, a hole of diameter 16 through
each; spider A on the base hole's surface, spider B on the wall hole's.
"""

import argparse
import json
import os
import re
import subprocess
import sys

# The spiders: REF node (translations), ROT node (its translations are the rotations).
SPIDERS = {
    "A": {"ref": 900001, "rot": 900002, "centre": (90.0, 30.0, 5.0)},
    "B": {"ref": 900003, "rot": 900004, "centre": (5.0, 30.0, 55.0)},
}
# The static load at spider B: force on its REF node, moment on its ROT node (N, N mm).
FORCE = (120.0, -80.0, 250.0)
MOMENT = (3000.0, 1500.0, -2200.0)
# gmsh's 10-node tetrahedron orders its last two edge nodes (2-3, 1-3) the other way round
# from Abaqus/CalculiX C3D10 (1-3, 2-3).
GMSH_TO_CCX_TET10 = [0, 1, 2, 3, 4, 5, 6, 7, 9, 8]


def mesh(size):
    """Nodes {id: (x, y, z)}, C3D10 connectivity and the node sets of the two hole surfaces."""
    import gmsh

    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.option.setNumber("General.NumThreads", 1)
    occ = gmsh.model.occ
    base = occ.addBox(0, 0, 0, 120, 60, 10)
    wall = occ.addBox(0, 0, 0, 10, 60, 80)
    part, _ = occ.fuse([(3, base)], [(3, wall)])
    hole_a = occ.addCylinder(90, 30, -1, 0, 0, 12, 8)
    hole_b = occ.addCylinder(-1, 30, 55, 12, 0, 0, 8)
    occ.cut(part, [(3, hole_a), (3, hole_b)])
    occ.synchronize()
    gmsh.option.setNumber("Mesh.CharacteristicLengthMax", size)
    gmsh.option.setNumber("Mesh.ElementOrder", 2)
    gmsh.option.setNumber("Mesh.HighOrderOptimize", 0)
    # Edge nodes at the middle of straight edges: nodes snapped to the curved hole surfaces
    # can give elements a non-positive Jacobian, which ccx refuses.
    gmsh.option.setNumber("Mesh.SecondOrderLinear", 1)
    gmsh.option.setNumber("Mesh.RandomSeed", 1.0)
    gmsh.model.mesh.generate(3)

    tags, xyz, _ = gmsh.model.mesh.getNodes()
    nodes = {int(t): (xyz[3 * k], xyz[3 * k + 1], xyz[3 * k + 2]) for k, t in enumerate(tags)}
    elements = []
    types, _, conn = gmsh.model.mesh.getElements(3)
    for etype, c in zip(types, conn):
        if etype != 11:  # 10-node tetrahedron
            raise SystemExit(f"unexpected gmsh element type {etype}")
        for k in range(0, len(c), 10):
            e = c[k : k + 10]
            elements.append([int(e[i]) for i in GMSH_TO_CCX_TET10])
    sets = {"A": set(), "B": set()}
    for dim, tag in gmsh.model.getEntities(2):
        if gmsh.model.getType(dim, tag) != "Cylinder":
            continue
        lo = gmsh.model.getBoundingBox(dim, tag)
        centre = [(lo[i] + lo[i + 3]) / 2 for i in range(3)]
        for name, s in SPIDERS.items():
            if all(abs(centre[i] - s["centre"][i]) < 1e-6 for i in range(3)):
                t, _, _ = gmsh.model.mesh.getNodes(dim, tag, includeBoundary=True)
                sets[name].update(int(x) for x in t)
    gmsh.finalize()
    for name, s in sets.items():
        if not s:
            raise SystemExit(f"no nodes found on the surface of hole {name}")
    return nodes, elements, sets


def node_lines(nodes, sep):
    """`id, x, y, z` of every mesh node, then the spiders' REF and ROT nodes at their
    centres, with `sep` between the fields (coordinates to the last bit)."""
    rows = [(n, *nodes[n]) for n in sorted(nodes)]
    rows += [(s[k], *s["centre"]) for s in SPIDERS.values() for k in ("ref", "rot")]
    return "".join(sep.join([str(n)] + [f"{v:.17g}" for v in xyz]) + "\n" for n, *xyz in rows)


def write_mesh(path, nodes, elements, sets):
    """The model without a step: nodes, elements, material, the two spiders."""
    with open(path, "w") as f:
        f.write("*NODE, NSET=NALL\n")
        f.write(node_lines(nodes, ", "))
        f.write("*ELEMENT, TYPE=C3D10, ELSET=EALL\n")
        for k, e in enumerate(elements, 1):
            f.write(f"{k}, " + ", ".join(map(str, e)) + "\n")
        for name, s in sets.items():
            f.write(f"*NSET, NSET=HOLE{name}\n")
            ids = sorted(s)
            for k in range(0, len(ids), 10):
                f.write(", ".join(map(str, ids[k : k + 10])) + "\n")
        f.write("*NSET, NSET=SPIDERS\n")
        f.write(", ".join(str(s[k]) for s in SPIDERS.values() for k in ("ref", "rot")) + "\n")
        f.write(
            "*MATERIAL, NAME=STEEL\n*ELASTIC\n210000., 0.3\n*DENSITY\n7.85e-9\n"
            "*SOLID SECTION, ELSET=EALL, MATERIAL=STEEL\n"
        )
        for name, s in SPIDERS.items():
            f.write(f"*RIGID BODY, NSET=HOLE{name}, REF NODE={s['ref']}, ROT NODE={s['rot']}\n")


def deck(path, blocked, step):
    """A job that includes the mesh, clamps spider A when `blocked`, and runs `step`."""
    a = SPIDERS["A"]
    with open(path, "w") as f:
        f.write("*INCLUDE, INPUT=mesh.inp\n")
        if blocked:
            f.write(f"*BOUNDARY\n{a['ref']}, 1, 3\n{a['rot']}, 1, 3\n")
        f.write(f"*STEP\n{step}*END STEP\n")


def run_ccx(out, job):
    """Run ccx on OUT/job.inp; its log goes to OUT/job.log."""
    env = dict(os.environ, OMP_NUM_THREADS="2")
    with open(os.path.join(out, job + ".log"), "w") as log:
        r = subprocess.run(["ccx", "-i", job], cwd=out, stdout=log, stderr=subprocess.STDOUT, env=env)
    text = open(os.path.join(out, job + ".log")).read()
    if r.returncode != 0 or "*ERROR" in text:
        raise SystemExit(f"ccx failed on {job}.inp (see {out}/{job}.log)")


def frequencies(dat):
    """The `cycles/time` column of every eigenvalue table in a ccx .dat file, as printed."""
    out = []
    in_table = False
    for line in open(dat):
        if "E I G E N V A L U E   O U T P U T" in line:
            in_table = True
            continue
        if in_table:
            f = line.split()
            if len(f) == 5 and f[0].isdigit():
                out.append(f[3])
            elif out and not line.strip():
                in_table = False
    return out


def displacements(dat):
    """{node: [ux, uy, uz] as printed} from the last `displacements` block of a ccx .dat."""
    out = {}
    block = False
    for line in open(dat):
        if line.strip().startswith("displacements"):
            block, out = True, {}
            continue
        f = line.split()
        if block and len(f) == 4 and re.fullmatch(r"\d+", f[0]):
            out[int(f[0])] = f[1:]
    return out


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("out")
    p.add_argument("--size", type=float, default=6.0, help="largest element edge, mm")
    p.add_argument("--modes", type=int, default=30, help="modes ccx's *FREQUENCY computes")
    p.add_argument("--no-reference", action="store_true", help="matrices only (the bench)")
    a = p.parse_args()
    params = {"size": a.size, "modes": a.modes, "reference": not a.no_reference, "version": 1}
    os.makedirs(a.out, exist_ok=True)
    done = os.path.join(a.out, "done.json")
    if os.path.exists(done) and json.load(open(done)).get("params") == params:
        return
    nodes, elements, sets = mesh(a.size)
    write_mesh(os.path.join(a.out, "mesh.inp"), nodes, elements, sets)
    with open(os.path.join(a.out, "nodes.csv"), "w") as f:
        f.write(node_lines(nodes, ","))
    for case, blocked in (("blocked", True), ("free", False)):
        deck(os.path.join(a.out, case + ".inp"), blocked, "*FREQUENCY, SOLVER=MATRIXSTORAGE\n")
        run_ccx(a.out, case)
    reference = {}
    if not a.no_reference:
        b = SPIDERS["B"]
        for case, blocked in (("blocked", True), ("free", False)):
            job = case + "_freq"
            deck(os.path.join(a.out, job + ".inp"), blocked, f"*FREQUENCY\n{a.modes}\n")
            run_ccx(a.out, job)
            reference[case + "_hz"] = frequencies(os.path.join(a.out, job + ".dat"))
        load = "".join(f"{b['ref']}, {i + 1}, {v!r}\n" for i, v in enumerate(FORCE))
        load += "".join(f"{b['rot']}, {i + 1}, {v!r}\n" for i, v in enumerate(MOMENT))
        deck(
            os.path.join(a.out, "static.inp"),
            True,
            f"*STATIC\n*CLOAD\n{load}*NODE PRINT, NSET=SPIDERS\nU\n",
        )
        run_ccx(a.out, "static")
        u = displacements(os.path.join(a.out, "static.dat"))
        reference["static"] = {
            "force": FORCE,
            "moment": MOMENT,
            "ref": u[b["ref"]],
            "rot": u[b["rot"]],
        }
        json.dump(reference, open(os.path.join(a.out, "reference.json"), "w"), indent=1)
    info = {
        "params": params,
        "nodes": len(nodes),
        "elements": len(elements),
        "spiders": SPIDERS,
        "hole_nodes": {k: len(v) for k, v in sets.items()},
    }
    json.dump(info, open(done, "w"), indent=1)


if __name__ == "__main__":
    sys.exit(main())
