"""``mutext check EXERCISE FILE``: the local check of a student's file (mutext.grading.check, .spec).

It runs the file confined on sample inputs and says per function whether it
runs and returns the right kind and shape of value, never whether the value
is right: no reference value may appear in what it prints.

The default run checks confined the reference solution of ex03, a file without isolation, and the
files whose functions loop, raise or import a blocked module; the stubs and the files of wrong values
or kinds go through the same ``check`` with their functions run in this process
(tests/grading_harness.py; confined with ``-m slow``).
"""
import ast
import json
import math
import re
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np
import pytest

from grading_harness import check_here
from mutext.cli import main
from mutext.grading.check import CheckError, check
from mutext.grading.spec import EXERCISES, get_exercise

ROOT = Path(__file__).resolve().parents[1]
STUBS = ROOT / "exercises"
SOLUTIONS = ROOT / "instructor" / "mutext_grader" / "solutions"
#: the exercise whose reference solution is checked in the fast suite (the others are slow)
FAST_SOLUTION = "ex03_free_decay"
#: the exercises whose grader builds its questions quickly (the others draw rotor sweeps or solve LMIs)
FAST_QUESTIONS = ("ex02_mu", "ex03_free_decay", "ex04_beam_element", "ex05_diagnose")

FLOAT = re.compile(r"(?<![\w.])[-+]?(?:\d+\.\d*(?:[eE][-+]?\d+)?|\.\d+(?:[eE][-+]?\d+)?|\d+[eE][-+]?\d+)")


def _floats(text):
    """The decimal numbers in ``text`` (equation numbers such as "eq. 3.1" in titles left out)."""
    return [float(m) for m in FLOAT.findall(re.sub(r"eq\. \d+\.\d+", "eq.", text))]


def _json_without_seconds(report):
    d = report.to_dict()
    d.pop("seconds")
    return json.dumps(d)


# ----------------------------------------------------------------------------------------------------------
# the description of the exercises
# ----------------------------------------------------------------------------------------------------------

def test_sample_calls_are_fresh_cheap_and_json():
    import time
    for ex in EXERCISES.values():
        t0 = time.process_time()        # CPU time: the same on a busy machine
        a = [q.sample_calls(np.random.default_rng(1)) for q in ex.questions]
        assert time.process_time() - t0 < 2.0, ex.name
        b = [q.sample_calls(np.random.default_rng(2)) for q in ex.questions]
        for q, ca, cb in zip(ex.questions, a, b):
            assert ca and all(isinstance(args, list) and isinstance(kw, dict) for args, kw in ca), (ex.name, q.id)
            json.dumps(ca)
            if q.function != "controller":      # the only function without arguments
                assert json.dumps(ca) != json.dumps(cb), (ex.name, q.id)


def test_exercise_names_and_prefixes():
    assert get_exercise("ex04").name == "ex04_beam_element"
    with pytest.raises(LookupError, match="ex01_two_mass_hinf"):
        get_exercise("ex9")
    with pytest.raises(LookupError):
        get_exercise("ex0")          # not unique


# ----------------------------------------------------------------------------------------------------------
# stubs, reference solutions, wrong files
# ----------------------------------------------------------------------------------------------------------

def _assert_stubs_not_implemented(reports):
    for name, r in reports.items():
        assert r.imported and not r.ok, name
        assert [f.function for f in r.functions] == [q.function for q in EXERCISES[name].questions]
        for f in r.functions:
            assert f.status == "not_implemented", (name, f.function, f.status, f.messages)
            assert f.messages == [f"{f.function}() is not implemented yet (it raises NotImplementedError)"]
        text = r.text()
        assert f"0 of {len(r.functions)} functions run and return the right kind of value; the grader decides " \
               "whether they are right." in text
        assert "not implemented" in text and "score" not in text.lower() and "point" not in text.lower()


def test_stubs_are_reported_not_implemented_per_function():
    """The stubs' functions run in this process; that the stubs import nothing their exercise blocks
    (which only the confined run would see) is read from their source."""
    _assert_stubs_not_implemented({n: check_here(n, STUBS / f"{n}.py", 60, seed=1) for n in EXERCISES})
    for name, ex in EXERCISES.items():
        tree = ast.parse((STUBS / f"{name}.py").read_text())
        imported = {a.name for node in ast.walk(tree) if isinstance(node, ast.Import) for a in node.names}
        imported |= {node.module or "" for node in ast.walk(tree) if isinstance(node, ast.ImportFrom)}
        never = (*ex.blocked_modules, "mutext_grader", "mutext.grading", "mutext.examples", "mutext.demos")
        blocked = [m for m in imported for b in never if m == b or m.startswith(b + ".")]
        assert not blocked, (name, imported)


@pytest.mark.slow
def test_stubs_are_reported_not_implemented_per_function_confined():
    with ThreadPoolExecutor(max_workers=3) as pool:
        reports = dict(zip(EXERCISES, pool.map(lambda n: check(n, STUBS / f"{n}.py", 60), EXERCISES)))
    _assert_stubs_not_implemented(reports)


def _solution_params():
    return [pytest.param(n, marks=() if n == FAST_SOLUTION else pytest.mark.slow) for n in EXERCISES]


def _keep_reports(monkeypatch, checker):
    import mutext.grading.check as chk
    made = []

    def keep(*args, **kwargs):
        made.append(checker(*args, **kwargs))
        return made[-1]
    monkeypatch.setattr(chk, "check", keep)
    return made


@pytest.fixture
def reports(monkeypatch):
    """The reports that ``mutext check`` made (the command prints them; the test reads them too)."""
    return _keep_reports(monkeypatch, check)


@pytest.fixture
def reports_here(monkeypatch):
    """As ``reports``, with the file's functions run in this process (:func:`grading_harness.check_here`)."""
    return _keep_reports(monkeypatch, check_here)


@pytest.mark.parametrize("name", _solution_params())
def test_reference_solutions_pass_the_check(name, capsys, reports):
    code = main(["check", name, str(SOLUTIONS / f"{name}.py")])
    text = capsys.readouterr().out
    r, = reports
    bad = [(f.function, f.status, f.messages) for f in r.functions if not f.ok]
    assert code == 0 and r.ok and not bad, bad
    n = len(EXERCISES[name].questions)
    assert f"{n} of {n} functions run and return the right kind of value" in text
    # the report of a right file prints no value at all
    assert _floats(text) == [], text


def test_a_laptop_without_isolation_still_checks(monkeypatch, capsys):
    """Not confined (no Landlock, an old kernel, macOS): the check says so and does not fail on it."""
    from mutext.grading import sandbox
    monkeypatch.setattr(sandbox, "FORCE_MODE", "user")
    monkeypatch.setattr(sandbox, "SKIP", ("landlock", "seccomp"))
    assert main(["check", "ex04", str(SOLUTIONS / "ex04_beam_element.py")]) == 0
    text = capsys.readouterr().out
    assert "Isolation: none (your file was not confined on this machine" in text
    assert "4 of 4 functions run and return the right kind of value" in text


WRONG_EX04 = '''
import numpy as np

def element_matrices(E, I, rho, A, L):
    return np.eye(4)                      # K only: the pair (K, M) is asked for

def assemble(n_elements, length, E, I, rho, A, support):
    return "K and M"

def natural_frequencies(n_elements, length, E, I, rho, A, support, n_modes):
    return np.ones(n_modes)               # the right kind and size

# relative_errors is missing
'''

WRONG_EX01 = '''
import control as ct

def mechanical_model(m1, m2, k1, k2):
    return ct.ss([[-1.0]], [[1.0]], [[1.0]], [[0.0]])     # 1 input, 1 output

def generalized_plant(**kw):
    return 1 / 0

def hinf_norm(sys):
    return [1.0, 2.0]

def controller():
    while True:
        pass
'''


def test_wrong_kinds_and_shapes_are_reported(tmp_path):
    (tmp_path / "wrong04.py").write_text(WRONG_EX04)
    (tmp_path / "wrong01.py").write_text(WRONG_EX01)
    (tmp_path / "wrong06.py").write_text(WRONG_EX06)
    # wrong04's functions only return the wrong things: run in this process; the others need the child
    # (an endless loop, a blocked import)
    with ThreadPoolExecutor(max_workers=2) as pool:
        r01 = pool.submit(check, "ex01", tmp_path / "wrong01.py", 4)
        r06 = pool.submit(check, "ex06", tmp_path / "wrong06.py", 30)
        r = check_here("ex04", tmp_path / "wrong04.py", 30)
    st = {f.function: f for f in r.functions}
    assert st["element_matrices"].status == "wrong_kind"
    assert st["element_matrices"].messages == [
        "element_matrices() returned an array of shape (4, 4); expected shape (2, 4, 4)"]
    assert st["assemble"].status == "wrong_kind" and "expected a numpy array" in st["assemble"].messages[0]
    assert st["natural_frequencies"].ok
    assert st["relative_errors"].status == "missing"
    assert st["relative_errors"].messages == ["your file defines no function relative_errors() (the name must be "
                                              "exactly this)"]
    assert "1 of 4 functions run and return the right kind of value" in r.text() and not r.ok

    r = r01.result()
    st = {f.function: f for f in r.functions}
    assert st["mechanical_model"].status == "wrong_kind"
    assert "1 input(s) and 1 output(s); expected 2 input(s) and 2 output(s)" in st["mechanical_model"].messages[0]
    assert st["generalized_plant"].status == "raises"
    assert "ZeroDivisionError" in st["generalized_plant"].messages[0]
    assert "line 8" in st["generalized_plant"].messages[0]
    assert st["hinf_norm"].status == "wrong_kind" and "expected a single float" in st["hinf_norm"].messages[0]
    assert st["controller"].status == "timeout" and "time limit of 4 s" in st["controller"].messages[0]
    assert r.n_ok == 0

    r = r06.result()
    st = {f.function: f for f in r.functions}
    assert st["sideband_frequencies"].status == "blocked"
    assert "tried importing mutext.rotor" in st["sideband_frequencies"].messages[0]
    assert st["sideband_size"].status == "wrong_kind"
    assert "expected a float" in st["sideband_size"].messages[0]
    assert st["classify"].status == "wrong_kind"
    assert st["classify"].messages == ["classify() returned a number that is not one of 0, 1, 2 (an index, see the "
                                       "docstring)"]


WRONG_EX06 = '''
import numpy as np

def sideband_frequencies(natural_frequencies_hz, speed_hz, orders, f_min, f_max):
    import mutext.rotor                   # blocked in this exercise
    return np.zeros(3)

def sideband_size(freq_hz, re, im, f_candidate, half_width_hz):
    return np.ones((2, 2))

def classify(freq_hz, re, im, natural_frequencies_hz, speed_hz, noise):
    return 7
'''


RIGHT_SHAPE_WRONG_VALUES = '''
import numpy as np

def natural_frequency(t, y, cycles):
    return 12.5

def damping_ratio(t, y, cycles):
    return 0.125

def cart_mass(omega_bare, omega_weighted, m_w):
    return 3.25

def stiffness(omega_bare, m_c):
    return 42.75

def damping_coefficient(zeta, m_c, omega):
    return float("nan")

def identify_cart(t_bare, y_bare, t_w, y_w, m_w):
    return np.array([1.5, 2.5, 3.5])
'''


def test_output_holds_no_number_but_what_the_file_returned(tmp_path, capsys, reports_here):
    reports = reports_here
    p = tmp_path / "values.py"
    p.write_text(RIGHT_SHAPE_WRONG_VALUES)
    code = main(["check", "ex03", str(p), "--seed", "5"])
    text = capsys.readouterr().out
    assert code == 1                     # one function returns nan
    returned = {12.5, 0.125, 3.25, 42.75, 1.5, 2.5, 3.5}
    assert set(_floats(text)) <= returned, text
    assert "seed 5" in text
    assert "5 of 6 functions run and return the right kind of value" in text
    assert "damping_coefficient() returned nan; a finite float is expected" in text
    assert set(_floats(_json_without_seconds(reports[0]))) <= returned


# ----------------------------------------------------------------------------------------------------------
# the command line
# ----------------------------------------------------------------------------------------------------------

def test_cli_misuse_and_list(tmp_path, capsys):
    assert main(["check", "--list"]) == 0
    out = capsys.readouterr().out
    assert all(n in out for n in EXERCISES) and "element_matrices" in out
    assert main(["check", "ex9", str(STUBS / "ex04_beam_element.py")]) == 2
    err = capsys.readouterr().err
    assert "unknown exercise 'ex9'" in err and all(n in err for n in EXERCISES)
    assert main(["check", "ex04", str(tmp_path / "nope.py")]) == 2
    assert "file not found" in capsys.readouterr().err
    (tmp_path / "answer.txt").write_text("x")
    assert main(["check", "ex04", str(tmp_path / "answer.txt")]) == 2
    assert "(.py)" in capsys.readouterr().err
    assert main(["check", "ex04"]) == 2
    assert main(["check", "ex04", str(STUBS / "ex04_beam_element.py"), "--time-limit", "0"]) == 2
    assert main(["check", "ex04", str(STUBS / "ex04_beam_element.py"), "--bogus"]) == 2
    capsys.readouterr()
    assert main(["--help"]) == 0
    assert "check EXERCISE FILE" in capsys.readouterr().out
    with pytest.raises(CheckError):
        check("ex04", STUBS / "ex04_beam_element.py", time_limit=math.inf)


# ----------------------------------------------------------------------------------------------------------
# the public description agrees with the instructor's grader
# ----------------------------------------------------------------------------------------------------------

def _grader():
    return pytest.importorskip("mutext_grader.core")


def test_spec_names_stubs_blocked_modules_and_points_match_the_grader():
    import importlib
    core = _grader()
    assert list(EXERCISES) == list(core.EXERCISES)
    for name, ex in EXERCISES.items():
        mod = importlib.import_module(core.EXERCISES[name][0])
        g = mod.EXERCISE
        assert (ex.title, ex.stub) == (g.title, g.stub), name
        assert tuple(ex.blocked_modules) == tuple(g.blocked_modules), name
        assert (ROOT / ex.stub).is_file()
        points = getattr(mod, "POINTS", None)
        if points is not None:
            assert {q.id: q.points for q in ex.questions} == dict(points), name


def _question_params():
    return [pytest.param(n, marks=() if n in FAST_QUESTIONS else pytest.mark.slow) for n in EXERCISES]


@pytest.mark.parametrize("name", _question_params())
def test_spec_questions_match_the_grader(name):
    core = _grader()
    g = core.get_exercise(name)
    ref = [(q.id, q.function, q.kind, float(q.points)) for q in g.questions(np.random.default_rng(7))]
    assert [(q.id, q.function, q.kind, q.points) for q in EXERCISES[name].questions] == ref
