"""The README's master snippets run as written: the section "Using the FMU from fmpy,
libcosim, ecos and C" is read from README.md, its `sh` block packs the cantilever in a
scratch folder laid out like the repository, and each master's snippet runs there and
prints the peak tip deflection, checked against the full-FE reference. A snippet that
stops working fails here, so the README cannot rot."""

import os
import re
import subprocess
import sys

import numpy as np
import pytest

import masters
from conftest import REPO, reference

SECTION = "## Using the FMU from fmpy, libcosim, ecos and C"
# The method each snippet sets and its floor against the full-FE step response (the
# floors of test_fmu.py: 0.5% for exact and explicit at h = 0.2 ms).
SNIPPETS = {"fmpy": (3, 5e-3), "libcosim": (1, 5e-3), "ecos": (1, 5e-3)}
STOP = 0.4


def section_blocks(title, readme=REPO / "README.md"):
    """The fenced code blocks under the heading `title` (up to the next heading of the
    same or a higher level), as {subsection heading or '': [(language, code)]}."""
    level = len(title) - len(title.lstrip("#"))
    lines = readme.read_text().splitlines()
    try:
        start = lines.index(title)
    except ValueError:
        raise AssertionError(f"README.md has no heading {title!r}") from None
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


@pytest.fixture(scope="module")
def workdir(tmp_path_factory):
    """A scratch folder that looks like the repository root (target/ and fixtures/
    linked), where the README's pack block has run."""
    work = tmp_path_factory.mktemp("readme")
    for name in ("target", "fixtures", "include"):
        os.symlink(REPO / name, work / name)
    [(lang, script)] = section_blocks(SECTION)[""]
    assert lang == "sh"
    # scripts/test.sh has built everything: the block's cargo lines have nothing to do.
    script = "\n".join(line for line in script.splitlines() if not line.startswith("cargo "))
    run = subprocess.run(["bash", "-euo", "pipefail", "-c", script], cwd=work, capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    assert (work / "out" / "cantilever.fmu").is_file()
    return work


def test_the_section_has_a_snippet_per_master():
    subs = section_blocks(SECTION)
    for master in SNIPPETS:
        assert [lang for lang, _ in subs[f"### Using the FMU from {master}"]] == ["python"], master
    assert [lang for lang, _ in subs["### Using the FMU from C"]] == ["c", "sh"]


def check_peak(printed, floor):
    """The one peak the snippet printed, against the full-FE step response's peak."""
    found = re.findall(r"peak tip deflection (\S+) m", printed)
    assert len(found) == 1, printed
    got = float(found[0])
    resp = next(r for r in reference("cantilever")["responses"] if r["name"] == "step")
    t, uy = np.array(resp["t"]), np.array(resp["nodes"]["121"]["uy"])
    want = np.abs(uy[t <= STOP + 1e-12]).max()
    # The printed value has 5 significant digits: 1e-4 of rounding on top of the floor.
    assert abs(got - want) <= (floor + 1e-4) * want, (got, want)


def test_readme_c_master_builds_runs_and_follows_the_full_fe_reference(workdir):
    """The C section: master.c built against include/fxbody.h and the header of
    `pack --header`, linked with the FMU's library; explicit method, 0.5% floor."""
    helped = subprocess.run([str(workdir / "target/release/fxbody"), "pack", "--help"], capture_output=True, text=True)
    assert "--header" in helped.stdout, f"fxbody pack --help offers no --header:\n{helped.stdout}"
    [(c_lang, code), (sh_lang, script)] = section_blocks(SECTION)["### Using the FMU from C"]
    assert (c_lang, sh_lang) == ("c", "sh")
    assert "CANTILEVER_METHOD_EXPLICIT" in code
    (workdir / "master.c").write_text(code)
    run = subprocess.run(["bash", "-euo", "pipefail", "-c", script], cwd=workdir, capture_output=True, text=True)
    assert run.returncode == 0, run.stdout + run.stderr
    check_peak(run.stdout, 5e-3)


@pytest.mark.parametrize("master", SNIPPETS)
def test_readme_snippet_runs_and_follows_the_full_fe_reference(workdir, master):
    masters.require(master)
    method, floor = SNIPPETS[master]
    [(_, code)] = section_blocks(SECTION)[f"### Using the FMU from {master}"]
    assert f"{method})" in code or f": {method}" in code, f"the {master} snippet no longer sets method {method}"
    snippet = workdir / f"snippet_{master}.py"
    snippet.write_text(code)
    env = dict(os.environ)
    # As the README says for ecos: the venv's lib/ (PyPI tbb's libtbb.so.12) on the path.
    env["LD_LIBRARY_PATH"] = os.pathsep.join(filter(None, [os.path.join(sys.prefix, "lib"),
                                                           env.get("LD_LIBRARY_PATH")]))
    run = subprocess.run([sys.executable, str(snippet)], cwd=workdir, capture_output=True, text=True, env=env)
    assert run.returncode == 0, run.stdout + run.stderr
    if master == "fmpy":
        # fmpy stepped at output_interval (2e-4 s), not at a default of its own.
        assert "2000 steps of 0.0002 s" in run.stdout, run.stdout
    check_peak(run.stdout, floor)
