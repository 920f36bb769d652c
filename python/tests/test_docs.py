"""Docstrings, stubs and the README: help(Mesh.refine) covers the CLI's
options, the .pyi stubs match the compiled module, and the README's Python
commands and adaptive loop run as written."""

import ast
import inspect
import os
import re
import subprocess
import sys
from pathlib import Path

import tetrefine
from conftest import REPO

STUB = Path(tetrefine.__file__).with_name("__init__.pyi")

# CLI flags of `tetrefine refine` that name files; the Python API gives the
# same thing as an object instead.
FILE_FLAGS = {
    "--output": "write",
    "--histogram": "quality",
    "--features-out": "feature_edges",
    "--parent-map": "parent",
    "--help": None,
    "--version": None,
    # Mesh.write picks the format by extension and writes MSH 4.1 ASCII;
    # the 2.2 and binary variants are the CLI's only.
    "--msh-format": "write",
    # The memory guard is the CLI's (it estimates a process's peak from
    # /proc/meminfo); the package has none yet.
    "--max-memory": None,
}


def test_refine_help_covers_every_cli_flag(cli):
    flags = set(re.findall(r"--[a-z][a-z-]+", cli("refine", "--help")))
    doc = tetrefine.Mesh.refine.__doc__
    for flag in sorted(flags):
        if flag in FILE_FLAGS:
            target = FILE_FLAGS[flag]
            assert target is None or hasattr(tetrefine.Mesh, target), flag
        else:
            assert f"[{flag}]" in doc, f"help(Mesh.refine) does not mention {flag}"
    # It reads like --help: the usage line, a summary, one entry per option.
    assert str(inspect.signature(tetrefine.Mesh.refine)).startswith(
        "(self, steps=None, *, boundary='interpolating'"
    )
    assert doc.startswith("Refine with the √3 tetrahedral subdivision")
    assert "Options (the CLI flag in brackets):" in doc


def test_every_public_item_has_a_docstring():
    for name in ("read", "from_meshio", "Mesh"):
        assert getattr(tetrefine, name).__doc__, name
    for name, attr in vars(tetrefine.Mesh).items():
        if not name.startswith("_"):
            assert attr.__doc__, f"Mesh.{name} has no docstring"


def stub_tree():
    return ast.parse(STUB.read_text())


def test_stub_names_match_the_module():
    tree = stub_tree()
    mesh = next(n for n in tree.body if isinstance(n, ast.ClassDef) and n.name == "Mesh")
    stub_members = {n.name for n in mesh.body if isinstance(n, ast.FunctionDef)}
    real = {n for n in vars(tetrefine.Mesh) if not n.startswith("_")} | {"__init__"}
    assert stub_members == real
    funcs = {n.name for n in tree.body if isinstance(n, ast.FunctionDef)}
    assert funcs == {"read", "from_meshio", "mesh_surface"}


def test_stub_signatures_match_the_module():
    tree = stub_tree()
    mesh = next(n for n in tree.body if isinstance(n, ast.ClassDef) and n.name == "Mesh")
    for fn in mesh.body:
        if not isinstance(fn, ast.FunctionDef) or fn.name.startswith("_"):
            continue
        member = getattr(tetrefine.Mesh, fn.name)
        if isinstance(member, property) or not callable(member):
            continue
        sig = inspect.signature(member)
        a = fn.args
        stub_params = [x.arg for x in a.posonlyargs + a.args + a.kwonlyargs]
        assert stub_params == list(sig.parameters), fn.name
        stub_defaults = [ast.literal_eval(d) for d in a.defaults + [d for d in a.kw_defaults if d]]
        real_defaults = [p.default for p in sig.parameters.values()
                         if p.default is not inspect.Parameter.empty]
        assert stub_defaults == real_defaults, fn.name


def readme_python_section():
    text = (REPO / "README.md").read_text()
    start = text.index("## From Python")
    end = text.index("\n## ", start + 1)
    return text[start:end]


def test_readme_commands_run_verbatim():
    section = readme_python_section()
    first = re.search(r"```sh\n(.*?)```", section, re.S).group(1).strip().splitlines()
    assert first[0] == "pip install ./python"
    # The package is installed (this suite runs in it); the second command
    # runs verbatim in the repository with this interpreter as `python3`.
    assert first[1].startswith("python3 -c ")
    cmd = sys.executable + first[1][len("python3"):]
    r = subprocess.run(cmd, shell=True, cwd=REPO, capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    assert "tets" in r.stdout


def test_readme_adaptive_loop_runs(tmp_path):
    section = readme_python_section()
    blocks = re.findall(r"```python\n(.*?)```", section, re.S)
    assert blocks
    os.symlink(REPO / "meshes", tmp_path / "meshes")
    cwd = os.getcwd()
    os.chdir(tmp_path)
    try:
        env = {}
        for b in blocks:
            exec(compile(b, "README.md", "exec"), env)
    finally:
        os.chdir(cwd)
    # The loop's own claims: it refined and carried the fields over.
    assert env["mesh"].n_tets > 2799
    assert len(env["cell_field"]) == env["mesh"].n_tets
