#!/usr/bin/env python3
"""Writes the FE-reader fixtures of crates/import/tests/all/readers.rs (standard library only).

    python3 tests/data/fe/make_fixtures.py [OUT_DIR]   # default: this folder

An independent writer: it formats each layout from the format descriptions (Nastran DMIG
punch, pyNastran-style large field, small and free field; Abaqus MATRIX INPUT; CalculiX
matrix storage; GRID, /NODE, *NODE and CSV coordinates) and records the matrix it meant
to write, at full precision, in expected_*.csv (`gi,ci,gj,cj,value`, one triangle, no
zeros). The Rust tests read each file back and compare with the expected file.

pyn_written.bdf is written by pyNastran itself (make_pynastran.py); not here.
"""
import os
import random

HERE = os.path.dirname(os.path.abspath(__file__))
OUT = HERE  # where write() puts files; main() sets it from the command line

# DOFs: grid 21 (all six), grid 22 (translations), grid 105 (all six), scalar points
# 900001..900003 (e.g. Craig-Bampton modal coordinates). Matrix order: grids by (id,
# comp), then scalar points.
DOFS = ([(21, c) for c in range(1, 7)] + [(22, c) for c in (1, 2, 3)]
        + [(105, c) for c in range(1, 7)] + [(900001 + k, 0) for k in range(3)])


def matrix(seed, scale):
    """A symmetric matrix over DOFS, upper triangle {(i, j): value}, with varied
    magnitudes and signs and a few structural zeros."""
    rnd = random.Random(seed)
    n = len(DOFS)
    a = {}
    for j in range(n):
        for i in range(j + 1):
            if i != j and rnd.random() < 0.15:
                continue  # structural zero: not written
            mag = scale * 10 ** rnd.uniform(-3, 0) if i != j else scale * rnd.uniform(1, 3)
            a[(i, j)] = mag * (rnd.choice((-1, 1)) if i != j else 1)
    return a


def short(a, digits=3):
    """The same pattern with values of few significant digits, so that 8-column small
    fields hold them exactly."""
    return {k: float(f"{v:.{digits - 1}e}") for k, v in a.items()}


def write(name, text):
    with open(os.path.join(OUT, name), "w", newline="\n") as f:
        f.write(text)


def write_expected(name, a):
    lines = ["gi,ci,gj,cj,value"]
    for (i, j), v in sorted(a.items()):
        if v == 0.0:
            continue
        (gi, ci), (gj, cj) = DOFS[i], DOFS[j]
        lines.append(f"{gi},{ci},{gj},{cj},{v!r}")
    write(name, "\n".join(lines) + "\n")


def columns(a, lower):
    """Entries grouped by column j: rows i <= j (upper) or i >= j (lower)."""
    n = len(DOFS)
    cols = {}
    for (i, j), v in a.items():
        (r, c) = (j, i) if lower else (i, j)
        cols.setdefault(c, []).append((r, v))
    return [(c, sorted(cols[c])) for c in sorted(cols)] if n else []


# --- Nastran -----------------------------------------------------------------------

def punch(name, a, tin=2, ifo=6):
    """The real punch layout: small-field header, `DMIG*` column cards, one `*` line per
    entry, value %16.9E touching the component field when negative."""
    cols = columns(a, lower=False)
    out = [f"{'DMIG':<8}{name:<8}{0:>8}{ifo:>8}{tin:>8}{0:>8}{'':>8}{'':>8}{len(cols):>8}"]
    for j, entries in cols:
        gj, cj = DOFS[j]
        out.append(f"{'DMIG*':<8}{name:<16}{gj:>16}{cj:>16}")
        for i, v in entries:
            gi, ci = DOFS[i]
            out.append(f"{'*':<8}{gi:>16}{ci:>16}{v:16.9E}")
    return out


def d16(v):
    """A double in 16 columns with a D exponent, as pyNastran writes large-field double."""
    s = f"{v:.10E}" if v >= 0 else f"{v:.9E}"
    return s.replace("E", "D")


def pyn_style(name, a):
    """pyNastran's large-field layout: `DMIG*` header with `*` continuation, then one
    column card per entry (name right-justified)."""
    cols = columns(a, lower=False)
    out = [f"{'DMIG*':<8}{name:>16}{0:>16}{6:>16}{2:>16}",
           f"{'*':<8}{0:>16}{'':>16}{'':>16}{len(cols):>16}"]
    for j, entries in cols:
        gj, cj = DOFS[j]
        for i, v in entries:
            gi, ci = DOFS[i]
            out.append(f"{'DMIG*':<8}{name:>16}{gj:>16}{cj:>16}")
            out.append(f"{'*':<8}{gi:>16}{ci:>16}{d16(v):>16}")
    return out


def nreal8(v, k):
    """A short value in Nastran syntax, cycling through the variants: 1.25E+03,
    1.25+3 (bare-sign exponent), 1.25D3, and .5-style leading point when possible."""
    m, e = f"{v:.2e}".split("e")
    e = int(e)
    style = k % 4
    if style == 0:
        s = f"{m}E{e:+d}"
    elif style == 1:
        s = f"{m}{e:+d}"
    elif style == 2:
        s = f"{m}D{e}"
    else:
        # .mmm form: move the point left, one more exponent.
        neg = m.startswith("-")
        digits = m.lstrip("-").replace(".", "")
        s = ("-" if neg else "") + "." + digits + f"{e + 1:+d}"
    assert len(s) <= 8, s
    return s


def small(name, a):
    """Small field, lower triangle, two entries per continuation line."""
    out = [f"{'DMIG':<8}{name:<8}{0:>8}{6:>8}{1:>8}{0:>8}"]
    k = 0
    for j, entries in columns(a, lower=True):
        gj, cj = DOFS[j]
        fields = [name, str(gj), str(cj), ""]
        for i, v in entries:
            gi, ci = DOFS[i]
            # Scalar points with a blank component on odd rows: blank means 0.
            fields += [str(gi), "" if (ci == 0 and k % 2) else str(ci), nreal8(v, k), ""]
            k += 1
        line, cont = "DMIG    ", 0
        for n, f in enumerate(fields):
            if n and n % 8 == 0:
                out.append(line + f"+C{cont:<6}")
                line = f"+C{cont:<6}"
                cont += 1
            line += f"{f:>8}"
        out.append(line)
    return out


def pointed(v):
    """repr(v) with a decimal point, which a Nastran real needs (1e-05 -> 1.e-05)."""
    s = repr(v)
    if "." not in s:
        s = s.replace("e", ".e") if "e" in s else s + "."
    return s


def free(name, a):
    """Free field (commas), upper triangle, one entry per continuation line."""
    out = [f"DMIG,{name},0,6,2,0,,{len(columns(a, False))}"]
    for j, entries in columns(a, lower=False):
        gj, cj = DOFS[j]
        first = entries[0]
        gi, ci = DOFS[first[0]]
        out.append(f"DMIG,{name},{gj},{cj},,{gi},{ci},{pointed(first[1])},")
        for i, v in entries[1:]:
            gi, ci = DOFS[i]
            out.append(f",{gi},{ci},{pointed(v)},,,,,")
    return out


# --- Abaqus and CalculiX -------------------------------------------------------------

GRID_DOFS = [d for d in DOFS if d[1] != 0]


def grid_matrix(seed, scale):
    n = len(GRID_DOFS)
    a = matrix(seed, scale)
    return {k: v for k, v in a.items() if k[0] < n and k[1] < n}


def abaqus(a, full):
    out = ["** ASSEMBLED MATRIX, FORMAT=MATRIX INPUT (fixture)"]
    for (i, j), v in sorted(a.items(), key=lambda t: (t[0][1], t[0][0])):
        (gi, ci), (gj, cj) = GRID_DOFS[i], GRID_DOFS[j]
        out.append(f"{gj},{cj}, {gi},{ci},  {v:.17e}")
        if full and i != j:
            out.append(f"{gi},{ci}, {gj},{cj},  {v:.17e}")
    return out


def calculix(a):
    # Equations in an order of CalculiX's own (not sorted by node): the reader must map
    # through .dof, not assume an order.
    order = sorted(range(len(GRID_DOFS)), key=lambda k: (GRID_DOFS[k][1], -GRID_DOFS[k][0]))
    eq = {k: n + 1 for n, k in enumerate(order)}
    dof = [f"{GRID_DOFS[k][0]}.{GRID_DOFS[k][1]}" for k in order]
    terms = []
    for (i, j), v in a.items():
        r, c = sorted((eq[i], eq[j]))
        terms.append((c, r, v))
    lines = [f"{r} {c} {v:20.13e}" for c, r, v in sorted(terms)]
    return dof, lines


# --- coordinates ---------------------------------------------------------------------

NODES = {21: (0.0, -1.5, 2.25), 22: (1000.0, 0.125, -3.5), 105: (-2.5e-3, 7.0, 1.0e4)}


def nreal(v, width):
    s = repr(float(v))
    if "e" in s:
        m, e = s.split("e")
        s = f"{m}{int(e):+d}"
    assert len(s) <= width, s
    return s


def coords_files():
    ids = sorted(NODES)
    g = []
    # small field, large field, free field: one GRID each
    x = NODES[ids[0]]
    g.append(f"{'GRID':<8}{ids[0]:>8}{'':>8}" + "".join(f"{nreal(v, 8):>8}" for v in x))
    x = NODES[ids[1]]
    g.append(f"{'GRID*':<8}{ids[1]:>16}{0:>16}{nreal(x[0], 16):>16}{nreal(x[1], 16):>16}")
    g.append(f"{'*':<8}{nreal(x[2], 16):>16}{0:>16}")
    x = NODES[ids[2]]
    g.append(f"GRID,{ids[2]},," + ",".join(nreal(v, 16) for v in x) + ",0")
    write("grids.bdf", "$ GRID cards in small, large and free field\nBEGIN BULK\n"
          + "\n".join(g) + "\nENDDATA\n")
    rad = ["#RADIOSS STARTER", "/NODE"]
    for i in ids:
        rad.append(f"{i:>10}" + "".join(f"{v:>20.12g}" for v in NODES[i]))
    rad.append("/END")
    write("nodes.rad", "\n".join(rad) + "\n")
    inp = ["*Heading", "** nodes of the fixture", "*Node, nset=ALL"]
    inp += [f"{i}, " + ", ".join(repr(v) for v in NODES[i]) for i in ids]
    inp += ["*Element, type=B31", "1, 21, 22"]
    write("nodes.inp", "\n".join(inp) + "\n")
    write("nodes.csv", "id,x,y,z\n" + "".join(
        f"{i},{','.join(repr(v) for v in NODES[i])}\n" for i in ids))
    write("expected_nodes.csv", "id,x,y,z\n" + "".join(
        f"{i},{','.join(repr(v) for v in NODES[i])}\n" for i in ids))


# --- error fixtures ------------------------------------------------------------------

def errors():
    hdr = "DMIG    KAAX           0       6       2       0                       1"
    col = "DMIG*   KAAX                          21               1"

    def ent(g, c, v):
        return f"{'*':<8}{g:>16}{c:>16}{v:>16}"
    write("err_names.pch", "\n".join([
        "DMIG    K2GG           0       6       2       0                       1",
        "DMIG*   K2GG                          21               1",
        ent(21, 1, "1.000000000E+00"),
        "DMIG    MAAX           0       6       2       0                       1",
        "DMIG*   MAAX                          21               1",
        ent(21, 1, "1.000000000E+00")]) + "\n")
    write("err_ifo9.pch", "DMIG    KAAX           0       9       2       0"
          "                       1\n" + col + "\n" + ent(21, 1, "1.0") + "\n")
    write("err_tin3.pch", "DMIG    KAAX           0       6       3       0"
          "                       1\n" + col + "\n" + ent(21, 1, "1.0") + "\n")
    write("err_real.pch", "\n".join([hdr, col, ent(21, 1, "1.000000000E+00"),
                                     ent(22, 3, "1.2.3")]) + "\n")
    write("err_twice.pch", "\n".join([hdr, col, ent(21, 1, "1.000000000E+00"),
                                      ent(22, 3, "-2.500000000E+02"),
                                      ent(21, 1, "1.000000000E+00")]) + "\n")
    write("err_comp0and3.pch", "\n".join([hdr, col, ent(21, 1, "1.0"), ent(12, 0, "2.0"),
                                          ent(12, 3, "3.0")]) + "\n")
    write("err_dof7.pch", "\n".join([hdr, col, ent(21, 1, "1.0"), ent(12, 7, "2.0")]) + "\n")
    write("err_nonsym.pch", "\n".join([
        hdr, col, ent(21, 1, "1.0"), ent(40, 1, "2.1E+05"),
        "DMIG*   KAAX                          40               1",
        ent(21, 1, "2.0E+05")]) + "\n")
    write("err_cd5.bdf", "\n".join([
        "BEGIN BULK",
        f"{'GRID':<8}{11:>8}{'':>8}{'0.':>8}{'0.':>8}{'0.':>8}",
        f"{'GRID':<8}{12:>8}{'':>8}{'1.':>8}{'0.':>8}{'0.':>8}{5:>8}",
        "ENDDATA"]) + "\n")
    write("err_negative.mtx", "1,1, 1,1, 1.0\n-7,1, 1,1, 2.0\n")
    write("err_dof7.mtx", "1,1, 1,1, 1.0\n12,7, 1,1, 2.0\n")
    write("err_nonsym.mtx", "12,3, 12,3, 1.0\n12,3, 40,1, 2.1e5\n40,1, 12,3, 2.0e5\n")
    write("err_coordinate.mtx", "1 , 1, 2.5\n")
    write("err_temperature.dof", "12.1\n12.2\n12.0\n")
    write("err_eq.dof", "12.1\n12.2\n")
    write("err_eq.sti", "1 1 1.0\n1 2 0.5\n2 3 0.5\n")
    write("err_missing_mirror.mtx", "1,1, 1,1, 1.0\n1,1, 2,1, 0.5\n2,1, 1,1, 0.5\n"
          "1,1, 3,1, 0.25\n")


def main(out=None):
    global OUT
    OUT = out or HERE
    k = matrix(17, 2.0e8)
    m = matrix(18, 1.0)
    write("punch.pch", "\n".join(["$ DMIG punch layout (EXTSEOUT DMIGPCH), KAAX and MAAX"]
                                 + punch("KAAX", k) + punch("MAAX", m)) + "\n")
    write_expected("expected_punch_kaax.csv", k)
    write_expected("expected_punch_maax.csv", m)
    write("pyn_style.bdf", "\n".join(["BEGIN BULK"] + pyn_style("KAAX", k) + ["ENDDATA"]) + "\n")
    ks = short(k)
    write("small.bdf", "\n".join(small("KAAX", ks)) + "\n")
    write_expected("expected_small.csv", ks)
    write("free.bdf", "\n".join(free("KAAX", k)) + "\n")
    ka, ma = grid_matrix(19, 3.0e5), grid_matrix(20, 2.0e-3)

    def expected_grid(name, a):
        lines = ["gi,ci,gj,cj,value"]
        for (i, j), v in sorted(a.items()):
            (gi, ci), (gj, cj) = GRID_DOFS[i], GRID_DOFS[j]
            lines.append(f"{gi},{ci},{gj},{cj},{v!r}")
        write(name, "\n".join(lines) + "\n")
    write("model_STIF1.mtx", "\n".join(abaqus(ka, full=False)) + "\n")
    write("model_MASS1.mtx", "\n".join(abaqus(ma, full=True)) + "\n")
    expected_grid("expected_abaqus_stif.csv", ka)
    expected_grid("expected_abaqus_mass.csv", ma)
    dof, sti = calculix(ka)
    _, mas = calculix(ma)
    write("job.dof", "\n".join(dof) + "\n")
    write("job.sti", "\n".join(sti) + "\n")
    write("job.mas", "\n".join(mas) + "\n")
    coords_files()
    errors()


if __name__ == "__main__":
    import sys
    main(sys.argv[1] if len(sys.argv) > 1 else None)
