"""The README runs as written. Every fenced block of README.md is either run here, in
document order, in a scratch folder laid out like the repository (target/, fixtures/,
include/, examples/, tests/, scripts/ and .venv linked, HOME a scratch folder), or named
below as run by another test; a block that fails fails `test_every_readme_block_runs`.
What each block prints is then checked against an independent reference: the masters'
peak tip deflection against the full finite-element step response, the import's printout
against the lines the README shows, the spinning bracket's kinetic energy against
1/2 w.I w from the inertia the import printed.

What is not run literally, and why:
- `cargo run --release -- ARGS` runs `target/release/fxbody ARGS`: scripts/test.sh built
  it, and that is the binary cargo would run.
- `bash scripts/install.sh PREFIX` runs with `--no-build` (scripts/test.sh built it) and
  HOME set to the scratch folder, so `~/.local` is a scratch prefix.
- `bash scripts/test.sh` is the suite that runs this test: checked to be exactly what
  `.ci/run` executes.
- `text` blocks show output or a synopsis: the command synopsis is checked against each
  command's `--help`, the import printout against the import's output.
- DELEGATED blocks are run by the named test (the CalculiX walkthrough needs ccx and gmsh
  and a minute of meshing and solving)."""

import os
import re
import subprocess
import sys
from dataclasses import dataclass

import numpy as np
import pytest

import masters
from conftest import REPO, missing, reference

README = REPO / "README.md"
# Issue 25: the README is for users, at most ~250 lines.
MAX_LINES = 260
# Blocks run by another test: heading -> (test file, test function).
DELEGATED = {"### A whole CalculiX model, from mesh to fmpy":
             ("tests/python/test_import_whole.py", "test_readme_whole_model_walkthrough")}
SUITE = "bash scripts/test.sh"
MASTERS = "## Using the FMU from FMI masters"
NASTRAN = "### A Nastran punch"
STOP = 0.4
# The floor of every master's peak against the full-FE step response (test_fmu.py's
# floors: 0.5% for exact, implicit and explicit at h = 0.2 ms).
FLOOR = 5e-3


@dataclass
class Block:
    """One fenced block: its level-2 and level-3 headings, language, code and line."""

    section: str
    sub: str
    lang: str
    code: str
    line: int


def readme_blocks(readme=README):
    """Every fenced block of `readme`, in order."""
    blocks, section, sub, fence, code, start = [], "", "", None, [], 0
    for n, line in enumerate(readme.read_text().splitlines(), 1):
        if fence is None:
            if line.startswith("## "):
                section, sub = line, ""
            elif line.startswith("### "):
                sub = line
            elif line.startswith("```"):
                fence, code, start = line[3:].strip(), [], n
        elif line.startswith("```"):
            blocks.append(Block(section, sub, fence, "\n".join(code) + "\n", start))
            fence = None
        else:
            code.append(line)
    assert fence is None, f"{readme}: unclosed fence"
    return blocks


def section_blocks(title, readme=README):
    """The fenced code blocks under the heading `title` (up to the next heading of the
    same or a higher level), as {subsection heading or '': [(language, code)]}."""
    level = len(title) - len(title.lstrip("#"))
    lines = readme.read_text().splitlines()
    try:
        start = lines.index(title)
    except ValueError:
        raise AssertionError(f"{readme.name} has no heading {title!r}") from None
    blocks, sub, fence, code = {"": []}, "", None, []
    for line in lines[start + 1:]:
        if fence is None:
            heading = re.match(r"^(#+) ", line)
            if heading and len(heading.group(1)) <= level:
                break
            if heading:
                sub = line
                blocks[sub] = []
            elif line.startswith("```"):
                fence, code = line[3:].strip(), []
        elif line.startswith("```"):
            blocks[sub].append((fence, "\n".join(code) + "\n"))
            fence = None
        else:
            code.append(line)
    return blocks


def delegated(block):
    return DELEGATED.get(block.sub) or DELEGATED.get(block.section)


def translate(script):
    """A README sh block as this test runs it (the module docstring says why)."""
    out = []
    for line in script.splitlines():
        line = re.sub(r"^cargo run --release -- ", "target/release/fxbody ", line)
        line = re.sub(r"^bash scripts/install\.sh ", "bash scripts/install.sh --no-build ", line)
        out.append(line)
    return "\n".join(out) + "\n"


def master_of(code):
    """The master a Python block needs, if not fmpy (which every test here needs)."""
    return "libcosim" if "libcosimpy" in code else "ecos" if "ecospy" in code else None


def importable(master):
    try:
        masters.require(master)
    except BaseException as e:  # pytest's skip or fail outcome
        return str(e) or type(e).__name__
    return None


@pytest.fixture(scope="module")
def walk(tmp_path_factory):
    """Run every block not delegated, in order; {block line: CompletedProcess or the
    reason it could not run (a master not installed)}."""
    work = tmp_path_factory.mktemp("readme")
    for name in ("target", "fixtures", "include", "examples", "tests", "scripts", ".venv"):
        os.symlink(REPO / name, work / name)
    (work / "home").mkdir()
    env = dict(os.environ, HOME=str(work / "home"))
    # As the README says for ecos: the venv's lib/ (PyPI tbb's libtbb.so.12) on the path.
    env["LD_LIBRARY_PATH"] = os.pathsep.join(filter(None, [os.path.join(sys.prefix, "lib"),
                                                           env.get("LD_LIBRARY_PATH")]))
    results = {}
    for b in readme_blocks():
        if b.lang == "text" or delegated(b) or b.code.strip() == SUITE:
            continue
        if b.lang == "sh":
            script = translate(b.code)
            if "scripts/install.sh" in script:
                # The installed command, found on the PATH the block sets.
                script += 'command -v fxbody\nfxbody --version\n'
            argv = ["bash", "-euo", "pipefail", "-c", script]
        elif b.lang == "python":
            master = master_of(b.code)
            why = master and importable(master)
            if why:
                results[b.line] = why
                continue
            snippet = work / f"snippet_{b.line}.py"
            snippet.write_text(b.code)
            argv = [sys.executable, str(snippet)]
        else:
            raise AssertionError(f"README.md:{b.line}: a ```{b.lang} block: only sh, python and "
                                 f"text blocks are known to this test")
        results[b.line] = subprocess.run(argv, cwd=work, env=env, capture_output=True, text=True)
    return work, results


def output_of(walk, block):
    _, results = walk
    r = results[block.line]
    if isinstance(r, str):
        missing(master_of(block.code), r)
    assert r.returncode == 0, f"README.md:{block.line} failed:\n{block.code}\n{r.stdout}{r.stderr}"
    return r.stdout


def the_block(pred, what):
    found = [b for b in readme_blocks() if pred(b)]
    assert len(found) == 1, f"README.md: expected one {what}, found {len(found)}"
    return found[0]


def test_readme_is_short():
    n = len(README.read_text().splitlines())
    assert n < MAX_LINES, f"README.md has {n} lines; the rest belongs in docs/"


def test_every_readme_block_runs(walk):
    """Every sh and python block ran and exited 0, or is delegated to a test that exists
    and reads that heading."""
    _, results = walk
    failed, skipped = [], []
    for b in readme_blocks():
        if b.lang == "text" or b.code.strip() == SUITE:
            continue
        who = delegated(b)
        if who:
            path, name = who
            text = (REPO / path).read_text()
            assert f"def {name}(" in text and (b.sub or b.section) in text, (b.line, who)
            continue
        r = results[b.line]
        if isinstance(r, str):
            skipped.append(f"README.md:{b.line}: {r}")
        elif r.returncode != 0:
            failed.append(f"README.md:{b.line} exit {r.returncode}:\n{b.code}{r.stdout}{r.stderr}")
    assert not failed, "\n\n".join(failed)
    if skipped:
        missing("a master of the README", "; ".join(skipped))


def test_setup_commands_are_the_demo_and_the_suite(walk):
    """Two set-up blocks: the demo, which runs and follows the full-FE reference, and the
    suite, exactly what .ci/run executes."""
    setup = [b for b in readme_blocks() if b.section.startswith("## Set-up")]
    assert [b.code.strip() for b in setup] == ["cargo run --release -- demo", SUITE]
    ci = [line for line in (REPO / ".ci" / "run").read_text().splitlines() if line.startswith("exec ")]
    assert ci == [f"exec {SUITE}"], ci
    out = output_of(walk, setup[0])
    assert "5 minutes on 2 cores" in README.read_text()
    work, _ = walk
    for name in ("cantilever.fmu", "cantilever_tip.csv", "cantilever_tip.svg"):
        assert (work / "out" / name).is_file(), (name, out)
    tip = np.genfromtxt(work / "out" / "cantilever_tip.csv", delimiter=",", names=True)
    # The FMU's tip deflection against the full-FE step response read here, not the
    # demo's own copy of it (0.5%, check_peak's floor; the exact method is at 0.07%).
    resp = next(r for r in reference("cantilever")["responses"] if r["name"] == "step")
    t, uy = np.array(resp["t"]), np.array(resp["nodes"]["121"]["uy"])
    assert len(tip) > 100 and tip["time"][-1] <= t[-1] + 1e-12, tip["time"][-1]
    want = np.interp(tip["time"], t, uy)
    err = np.abs(tip["uy_fmu"] - want).max() / np.abs(want).max()
    assert err <= FLOOR, err


def test_install_puts_fxbody_on_the_path(walk):
    block = the_block(lambda b: "scripts/install.sh" in b.code, "install block")
    work, _ = walk
    out = output_of(walk, block)
    assert f"{work}/home/.local/bin/fxbody" in out.splitlines(), out
    assert re.search(r"^fxbody \d+\.\d+", out, re.M), out


def test_command_summary_matches_the_commands():
    """Each command of the synopsis exists (its --help runs), and the synopsis lists every
    command `fxbody --help` offers."""
    block = the_block(lambda b: b.section == "## Commands" and b.lang == "text", "command synopsis")
    shown = [line.split()[:2] for line in block.code.splitlines() if line.startswith("fxbody")]
    exe = REPO / "target" / "release"
    for cmd in shown:
        argv = [str(exe / cmd[0])] + ([cmd[1]] if cmd[0] == "fxbody" else []) + ["--help"]
        r = subprocess.run(argv, capture_output=True, text=True)
        assert r.returncode == 0, (cmd, r.stderr)
    helped = subprocess.run([str(exe / "fxbody"), "--help"], capture_output=True, text=True).stdout
    offered = re.findall(r"^  (\w+)  ", helped.split("Commands:")[1].split("Options:")[0], re.M)
    assert sorted(set(offered) - {"help"}) == sorted(c[1] for c in shown if c[0] == "fxbody"), helped
    assert any(c[0] == "fxbody-study" for c in shown)


def check_peak(got):
    """A printed peak tip deflection against the full-FE step response's peak over 0.4 s."""
    resp = next(r for r in reference("cantilever")["responses"] if r["name"] == "step")
    t, uy = np.array(resp["t"]), np.array(resp["nodes"]["121"]["uy"])
    want = np.abs(uy[t <= STOP + 1e-12]).max()
    # The printed value has 5 significant digits: 1e-4 of rounding on top of the floor.
    assert abs(got - want) <= (FLOOR + 1e-4) * want, (got, want)
    return want


def peaks(printed):
    return [float(x) for x in re.findall(r"peak tip deflection (\S+) m", printed)]


def test_readme_states_the_full_fe_peak():
    stated = re.findall(r"deflection: (\S+) m in the full finite-element model", README.read_text())
    assert len(stated) == 1
    want = check_peak(float(stated[0]))
    assert float(f"{want:.4e}") == float(stated[0]), (want, stated)  # to its 5 digits


MASTER_BLOCKS = {"### fmpy (FMI 2.0 and 3.0) and the fmu-manipulation-toolbox container": 3,
                 "### libcosim": 1, "### ecos": 1, "### C": 1}


def test_master_blocks_follow_the_full_fe_reference(walk):
    """Each master's block prints its peak tip deflection(s), within 0.5% of the full-FE
    model; fmpy stepped at output_interval (2e-4 s) for each of its three FMUs."""
    for sub, count in MASTER_BLOCKS.items():
        [block] = [b for b in readme_blocks() if b.section == MASTERS and b.sub == sub and b.lang != "text"]
        if master_of(block.code) and importable(master_of(block.code)):
            continue  # test_every_readme_block_runs reports it
        out = output_of(walk, block)
        found = peaks(out)
        assert len(found) == count, (sub, out)
        for got in found:
            check_peak(got)
        if sub.startswith("### fmpy"):
            assert out.count("2000 steps of 0.0002 s") == 3, out


def test_c_master_uses_the_generated_header():
    code = (REPO / "examples" / "master.c").read_text()
    for name in ("CANTILEVER_GUID", "CANTILEVER_VR_NODE_121_FY", "CANTILEVER_METHOD_EXPLICIT"):
        assert name in code, name
    [pack] = [b for b in readme_blocks() if b.section == MASTERS and b.sub == ""]
    assert "--header out/cantilever.h" in pack.code


def test_nastran_walkthrough_prints_what_the_readme_shows(walk):
    """The import's printout holds every line the README shows (a line ending in '...'
    as its beginning), and the spun bracket starts with the kinetic energy 1/2 w.I w of
    the inertia the import printed, and keeps it over the second (implicit method)."""
    blocks = [b for b in readme_blocks() if b.sub == NASTRAN]
    assert [b.lang for b in blocks] == ["sh", "text", "python"]
    run, shown, spin = blocks
    printed = output_of(walk, run).splitlines()
    for line in shown.code.splitlines():
        if line.endswith("..."):
            assert any(p.startswith(line[:-3].rstrip()) for p in printed), (line, printed)
        else:
            assert line in printed, (line, printed)
    k = printed.index("inertia about the centre of mass:")
    inertia = np.array([[float(x) for x in printed[k + i].split()] for i in (1, 2, 3)])
    w = np.array([6.0, -4.0, 8.0])
    assert all(f'"w0.{a}": {v}' in spin.code for a, v in zip("xyz", w))
    e0, e1 = (float(x) for x in re.findall(r"([-+.\de]+) J at", output_of(walk, spin)))
    want = 0.5 * w @ inertia @ w
    # The printed inertia has 10 significant digits; the energy is printed with 7.
    assert abs(e0 / want - 1) < 1e-6, (e0, want)
    assert abs(e1 / e0 - 1) < 1e-3, (e0, e1)


def test_fmax_auto_is_one_over_the_step(tmp_path):
    """The README: `--fmax auto` takes 1/H for the default communication step H."""
    assert "`--fmax auto` takes 1/H" in README.read_text()
    fx = REPO / "fixtures"
    r = subprocess.run([str(REPO / "target" / "release" / "fxbody"), "pack", str(fx / "cantilever.fxb"),
                        "--coords", str(fx / "cantilever.nodes.rad"), "--nodes", "121", "--step", "2.5e-3",
                        "--fmax", "auto", "-o", str(tmp_path / "c.fmu")], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    [hz] = re.findall(r"--fmax auto: (\S+) Hz", r.stderr)
    assert abs(float(hz) / 400.0 - 1) < 1e-12, r.stderr


def test_readme_commands_write_only_into_out(walk):
    """The blocks run here write nothing but out/ (and the install's scratch HOME) into
    the folder they run in (issue 25: the walkthrough left files in the repository)."""
    work, _ = walk
    links = {"target", "fixtures", "include", "examples", "tests", "scripts", ".venv"}
    made = {p.name for p in work.iterdir()} - links - {"home"}
    assert made == {"out"} | {p.name for p in work.glob("snippet_*.py")}, made

