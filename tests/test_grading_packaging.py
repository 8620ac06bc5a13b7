"""What students install holds no answers; what instructors install holds the grader.

``mutext`` (the repository's ``pyproject.toml``) is the library and the
public, confined child of the grader (``mutext/grading``); ``mutext-grader``
(``instructor/pyproject.toml``) is the grader: reference solutions, the
exercise modules that draw the graded inputs and compute the answers.

The default run checks the package lists setuptools derives from the two
``pyproject.toml`` files, and that on a site where only ``mutext`` is
installed (its files, copied as setuptools would install them, and the
third-party libraries; no editable hook, no source checkout on the path)
``import mutext_grader`` fails and ``mutext grade`` points to ``mutext
check``.  The slow run builds both wheels from the files git tracks (as the
autograder zip packs them) and checks their contents, and the same import on
a site made of the ``mutext`` wheel.
"""
import hashlib
import importlib.machinery
import os
import re
import shutil
import subprocess
import sys
import sysconfig
import textwrap
import tomllib
import zipfile
from pathlib import Path

import pytest
from setuptools import find_packages

from grading_harness import ROOT
from mutext_grader.core import EXERCISES

INSTRUCTOR = ROOT / "instructor"
SOLUTIONS = INSTRUCTOR / "mutext_grader" / "solutions"
sys.path.insert(0, str(ROOT / "docs" / "gradescope"))
import make_autograder  # noqa: E402


def _packages(project: Path) -> list:
    """The packages setuptools installs for ``project`` (its ``[tool.setuptools.packages.find]``)."""
    conf = tomllib.loads((project / "pyproject.toml").read_text())["tool"]["setuptools"]["packages"]["find"]
    where = project / conf.get("where", ["."])[0]
    return sorted(find_packages(where=str(where), include=conf.get("include", ["*"]),
                                exclude=conf.get("exclude", [])))


def _digest(data: bytes) -> str:
    return hashlib.sha256(data.replace(b"\r\n", b"\n").strip()).hexdigest()


#: the content of every reference solution
SOLUTION_DIGESTS = {_digest(p.read_bytes()): p.name for p in SOLUTIONS.glob("*.py") if p.name != "__init__.py"}
#: the names of the grader's exercise modules (``ex01_two_mass_hinf.py``, ...)
GRADER_MODULES = {mod.rsplit(".", 1)[1] + ".py" for mod, _ in EXERCISES.values()}


def _student_problems(files: dict) -> list:
    """What in ``{path inside the distribution: content}`` must not reach a student."""
    bad = []
    for path, data in files.items():
        parts = path.split("/")
        if parts[0].startswith("mutext_grader") or "solutions" in parts:
            bad.append(f"{path}: the grader's package")
        elif parts[-1] in GRADER_MODULES:
            bad.append(f"{path}: a grader exercise module's name")
        elif _digest(data) in SOLUTION_DIGESTS:
            bad.append(f"{path}: the reference solution {SOLUTION_DIGESTS[_digest(data)]}")
        elif path.endswith(".py") and data.lstrip().startswith((b'r"""Reference solution', b'"""Reference solution')):
            bad.append(f"{path}: a reference solution")
    return bad


def _installed_files(project: Path) -> dict:
    """``{path: content}`` of the modules and package data setuptools installs for ``project``."""
    meta = tomllib.loads((project / "pyproject.toml").read_text())["tool"]["setuptools"]
    data_globs = meta.get("package-data", {})
    out = {}
    for pkg in _packages(project):
        d = project.joinpath(*pkg.split("."))
        for f in d.iterdir():
            if f.is_file() and f.suffix == ".py":
                out[str(f.relative_to(project)).replace(os.sep, "/")] = f.read_bytes()
        for pattern in data_globs.get(pkg, []):
            for f in d.glob(pattern):
                if f.is_file():
                    out[str(f.relative_to(project)).replace(os.sep, "/")] = f.read_bytes()
    return out


def test_student_package_list_has_no_grader():
    pkgs = _packages(ROOT)
    assert "mutext" in pkgs and "mutext.grading" in pkgs
    assert all(p == "mutext" or p.startswith("mutext.") for p in pkgs), pkgs
    files = _installed_files(ROOT)
    assert "mutext/grading/sandbox.py" in files and "mutext/grading/_runner.py" in files
    assert _student_problems(files) == []


def test_instructor_package_list_has_the_grader_and_its_solutions():
    pkgs = _packages(INSTRUCTOR)
    assert pkgs == sorted(["mutext_grader", "mutext_grader.solutions"]), pkgs
    files = _installed_files(INSTRUCTOR)
    for mod, _ in EXERCISES.values():
        name = mod.rsplit(".", 1)[1]
        assert f"mutext_grader/{name}.py" in files and f"mutext_grader/solutions/{name}.py" in files, name
    # the check itself catches them (so an empty result above means something)
    assert len(_student_problems(files)) >= 2 * len(EXERCISES)


def _site_without_mutext(dest: Path) -> Path:
    """The third-party libraries of this interpreter, without ``mutext``, ``mutext_grader``, editable
    hooks and ``.pth`` files: a directory of links to the entries of site-packages."""
    dest.mkdir()
    for sp in dict.fromkeys([sysconfig.get_paths()["purelib"], sysconfig.get_paths()["platlib"]]):
        for entry in Path(sp).iterdir():
            n = entry.name.lower()
            if n.startswith(("mutext", "__editable__", "_mutext")) or n.endswith(".pth") or (dest / entry.name).exists():
                continue
            (dest / entry.name).symlink_to(entry)
    return dest


#: run with ``python -I -S`` (no user site, no site-packages, no PYTHON* variables, no current directory),
#: sys.path = the stdlib, the site holding mutext only, the third-party libraries
PROBE = textwrap.dedent("""
    import contextlib, importlib.util, io, json, sys
    site, deps = sys.argv[1], sys.argv[2]
    sys.path[:] = [p for p in sys.path if "site-packages" not in p] + [site, deps]
    out = {}
    import mutext
    out["mutext"] = mutext.__file__
    out["find_spec"] = repr(importlib.util.find_spec("mutext_grader"))
    try:
        import mutext_grader
        out["import"] = mutext_grader.__file__
    except ModuleNotFoundError as exc:
        out["import"] = "ModuleNotFoundError: " + str(exc)
    from mutext.grading import sandbox
    out["grader_dir"] = repr(sandbox.GRADER_DIR)
    from mutext.cli import main
    err = io.StringIO()
    with contextlib.redirect_stderr(err):
        out["grade_rc"] = main(["grade", "ex03_free_decay", "x.py"])
    out["grade_err"] = err.getvalue()
    out["path"] = sys.path
    print(json.dumps(out))
""")


def _probe(site: Path, deps: Path, cwd: Path) -> dict:
    import json
    env = {"PATH": os.environ.get("PATH", "/usr/bin:/bin"), "HOME": str(cwd), "MPLBACKEND": "Agg"}
    res = subprocess.run([sys.executable, "-I", "-S", "-c", PROBE, str(site), str(deps)], cwd=cwd, env=env,
                         capture_output=True, text=True, timeout=300)
    assert res.returncode == 0, res.stderr[-3000:]
    return json.loads(res.stdout.strip().splitlines()[-1])


def _check_probe(out: dict, site: Path):
    assert out["mutext"].startswith(str(site)), out["mutext"]
    assert out["find_spec"] == "None" and out["import"].startswith("ModuleNotFoundError"), out
    assert out["grader_dir"] == "None"
    assert out["grade_rc"] == 2 and "mutext check EXERCISE FILE" in out["grade_err"]
    assert not any(str(ROOT) in p for p in out["path"]), out["path"]


def test_mutext_grader_cannot_be_imported_where_only_mutext_is_installed(tmp_path):
    site = tmp_path / "site"
    for path, data in _installed_files(ROOT).items():
        (site / path).parent.mkdir(parents=True, exist_ok=True)
        (site / path).write_bytes(data)
    deps = _site_without_mutext(tmp_path / "deps")
    assert importlib.machinery.PathFinder.find_spec("mutext_grader", [str(deps)]) is None
    assert importlib.machinery.PathFinder.find_spec("mutext", [str(deps)]) is None
    _check_probe(_probe(site, deps, tmp_path), site)


def _wheel(project: Path, out: Path) -> Path:
    """Build the wheel of ``project`` with pip (its build isolation) into ``out``."""
    res = subprocess.run([sys.executable, "-m", "pip", "wheel", str(project), "--no-deps", "-q", "-w", str(out)],
                         capture_output=True, text=True, timeout=600)
    if res.returncode != 0 and re.search(r"No matching distribution found for (setuptools|wheel)", res.stderr):
        pytest.skip("no build backend available offline: " + res.stderr.strip().splitlines()[-1])
    assert res.returncode == 0, res.stderr[-3000:]
    return next(out.glob("*.whl"))


@pytest.mark.slow
def test_wheels_students_get_no_answers_instructors_get_the_grader(tmp_path):
    # the files git tracks, as the autograder zip packs them: a build leaves the checkout alone
    src = tmp_path / "src"
    for f in make_autograder.packed_files():
        (src / f).parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(ROOT / f, src / f)
    student = _wheel(src, tmp_path / "student")
    instructor = _wheel(src / "instructor", tmp_path / "instructor")
    assert student.name.startswith("mutext-") and instructor.name.startswith("mutext_grader-")
    with zipfile.ZipFile(student) as z:
        files = {n: z.read(n) for n in z.namelist() if not n.endswith("/")}
    assert "mutext/grading/sandbox.py" in files and "mutext/lti/__init__.py" in files
    assert _student_problems(files) == []
    assert not any(n.startswith(("instructor/", "tests/", "exercises/")) for n in files)
    with zipfile.ZipFile(instructor) as z:
        names = set(z.namelist())
    for mod, _ in EXERCISES.values():
        name = mod.rsplit(".", 1)[1]
        assert f"mutext_grader/{name}.py" in names and f"mutext_grader/solutions/{name}.py" in names, name
    assert not any(n.startswith("mutext/") for n in names)          # the grader does not carry the library
    # a site made of the student's wheel alone
    site = tmp_path / "site"
    with zipfile.ZipFile(student) as z:
        z.extractall(site)
    _check_probe(_probe(site, _site_without_mutext(tmp_path / "deps"), tmp_path), site)
