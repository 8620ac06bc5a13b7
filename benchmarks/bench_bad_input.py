"""Benchmark: the bad inputs of the last review round, each run in a child process and classified.

Every probe is one call a user could make with input that is wrong (shapes, non-numbers, NaN,
absurd scales, unwritable paths, a malformed model file, a count without bound).  Each runs in
its own Python process under a time limit and is classified by what it did:

``named error``
    a :class:`mutext.errors.MutextError` (or a command-line exit with a one-line message and no
    traceback);
``right``
    a result, and the probe's own independent check of that result holds (an analytic value,
    an exit code, files not written where they must not be);
``traceback``
    any other exception, or a traceback printed by the command line;
``silent``
    a result that the probe's check refutes;
``hang``
    still running at the time limit.

The column ``before`` is what the review found on the code it read (the issue's list); ``after``
is what this run finds.  Run: ``python benchmarks/bench_bad_input.py [--timeout 120]``.
"""
from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import textwrap

PRELUDE = """
import numpy as np, warnings, os, sys, tempfile
warnings.simplefilter("ignore")
from mutext.errors import MutextError
from mutext.lti import ss, hinf_norm, freqresp, stability
G1 = ss([[-1.0]], [[1.0]], [[1.0]], [[0.0]])
def cli(*args):
    import subprocess
    r = subprocess.run([sys.executable, "-m", "mutext.cli", *args], capture_output=True, text=True)
    if "Traceback" in r.stderr:
        raise RuntimeError("traceback printed: " + r.stderr.strip().splitlines()[-1])
    return r
"""

# (name, before, code).  ``code`` either raises, or ends with ``ok = <bool>`` (the independent check).
PROBES = [
    ("ss: A 2x3", "traceback", "ss(np.zeros((2, 3)), np.zeros((2, 1)), np.zeros((1, 2)), np.zeros((1, 1)))"),
    ("ss: B rows mismatched", "traceback", "ss(np.eye(2), np.zeros((3, 1)), np.zeros((1, 2)), 0)"),
    ("ss: C columns mismatched", "traceback", "ss(np.eye(2), np.zeros((2, 1)), np.zeros((1, 3)), 0)"),
    ("ss: D shape mismatched", "traceback", "ss(np.eye(2), np.zeros((2, 1)), np.zeros((1, 2)), np.zeros((2, 2)))"),
    ("ss: 1-D A", "traceback", "ss(np.ones(2), np.zeros((2, 1)), np.zeros((1, 2)), 0)"),
    ("ss: strings", "traceback", "ss('a', 'b', 'c', 'd')"),
    ("ss: [[None]]", "silent", "ss([[None]], [[1.0]], [[1.0]], [[0.0]])"),
    ("hinf_norm rtol=nan", "traceback", "hinf_norm(G1, rtol=float('nan'))"),
    ("hinf_norm of a system at 1e-160", "traceback",
     "r = hinf_norm(ss([[-1.0]], [[1e-120]], [[1e-40]], [[0.0]])); ok = abs(r.value / 1e-160 - 1) < 1e-8"),
    ("hinf_norm of a system at 5e299", "silent",
     "r = hinf_norm(ss([[-1.0]], [[5e224]], [[1e75]], [[0.0]])); ok = abs(r.value / 5e299 - 1) < 1e-8"),
    ("hinf_norm of an improper tf", "traceback", "import control as ct; hinf_norm(ct.tf([1, 0, 0], [1, 1]))"),
    ("freqresp: undamped pole on the grid", "traceback",
     "freqresp(ss([[0, 1], [-1, 0]], [[0], [1]], [[1, 0]], [[0]]), [0.5, 1.0, 2.0])"),
    ("freqresp: 2-D frequencies", "traceback", "freqresp(G1, np.ones((2, 2)))"),
    ("freqresp: NaN in C", "silent", "freqresp(ss([[-1.0]], [[1.0]], [[np.nan]], [[0.0]]), [1.0])"),
    ("freqresp: omega = inf", "silent", "freqresp(G1, [1.0, np.inf])"),
    ("freqresp: omega = nan", "silent", "freqresp(G1, [1.0, np.nan])"),
    ("stability margin=nan", "silent", "stability(G1, margin=float('nan'))"),
    ("chain with k = 1e308", "traceback", """
from mutext.rotor.model import loads_model
m = loads_model('[[mass]]\\nname="m1"\\nmass=1.0\\n[[mass]]\\nname="m2"\\nmass=1.0\\n'
                '[[spring]]\\nname="k1"\\nstiffness=1e308\\nbetween=["m1","m2"]\\n'
                '[[spring]]\\nname="k2"\\nstiffness=1.0\\nbetween=["m2","ground"]\\n')
m.natural_frequencies()
"""),
    ("chain with m = 1e-300, k = 1e300", "silent", """
from mutext.rotor.model import loads_model
m = loads_model('[[mass]]\\nname="m1"\\nmass=1e-300\\n[[mass]]\\nname="m2"\\nmass=1.0\\n'
                '[[spring]]\\nname="k1"\\nstiffness=1e300\\nbetween=["m1","m2"]\\n'
                '[[spring]]\\nname="k2"\\nstiffness=1.0\\nbetween=["m2","ground"]\\n')
m.natural_frequencies()
"""),
    ("bearing k = -1e8 through values=", "silent", """
from mutext.examples.cracked_rotor import healthy_rotor
healthy_rotor().natural_frequencies(values={"bearing2.k": -1e8})
"""),
    ("read_uff58 mapping={'a': 1}", "traceback", """
from mutext.uff import read_uff58
p = os.path.join(tempfile.mkdtemp(), 'x.uff'); open(p, 'w').write('    -1\\n    58\\n')
read_uff58(p, mapping={'a': 1})
"""),
    ("read_frfs([None])", "traceback", "from mutext.rig import read_frfs; read_frfs([None])"),
    ("mbi_plant(Ww='abc')", "traceback", """
from mutext.mbi import mbi_plant
from mutext.examples import two_mass
G = two_mass.plant()
mbi_plant(G, G, excitation='w', measurement='y', control_input='u', control_output='y', Ww='abc')
"""),
    ("mbi_plant(regularization=nan)", "silent", """
from mutext.mbi import mbi_plant
from mutext.examples import two_mass
G = two_mass.plant()
mbi_plant(G, G, excitation='w', measurement='y', control_input='u', control_output='y', regularization=float('nan'))
"""),
    ("identify(dk_options={'bogus': 1})", "traceback", """
from mutext.examples import three_mass as tm
from mutext.mbi import identify
identify(**tm.mbi_arguments(tm.TRIALS["1a"]), dk_options={"bogus": 1}, max_tries=1)
"""),
    ("relative_error: weight of the wrong length", "traceback", """
from mutext.mbi import relative_error
relative_error(G1, np.ones(5, complex), np.linspace(1, 5, 5), weight=np.ones(3))
"""),
    ("BlockStructure.from_spec([[1]])", "traceback", "from mutext.mu import BlockStructure; BlockStructure.from_spec([[1]])"),
    ("BlockStructure.from_spec([[1.7, 0]])", "silent", "from mutext.mu import BlockStructure; BlockStructure.from_spec([[1.7, 0]])"),
    ("write_frf station 12.7", "silent", """
from mutext.rig import FRF, write_frf
f = FRF(freq_hz=np.array([1.0, 2.0]), response=np.ones(2) + 0j, input_station=1, output_station=12.7)
write_frf(os.path.join(tempfile.mkdtemp(), 'x.csv'), f)
"""),
    ("hinfsyn: w only in the measurement, jw pole", "silent", """
from mutext.hinf import hinfsyn
A = np.array([[0.0, 1.0], [-1.0, 0.0]]); B = np.array([[0.0, 0.0], [0.0, 1.0]])
C = np.array([[1.0, 0.0], [0.0, 0.0], [1.0, 0.0]]); D = np.array([[0.0, 0.0], [0.0, 1.0], [1.0, 0.0]])
r = hinfsyn(ss(A, B, C, D), 1, 1)
ok = r.stable and r.gamma <= r.closed_loop_norm * (1 + 1e-9) <= r.gamma * (1 + 1e-4) and r.gamma > 0.99
"""),
    ("rig hide --example malformed model", "traceback", """
d = tempfile.mkdtemp(); p = os.path.join(d, 'bad.toml'); open(p, 'w').write('[[mass]]\\nname = "m1"\\n')
r = cli('rig', 'hide', '--seed', '1', '--example', p, '--out', os.path.join(d, 'o'))
ok = r.returncode == 1 and 'bad.toml' in r.stderr
"""),
    ("rig hide --out an existing file", "traceback", """
d = tempfile.mkdtemp(); p = os.path.join(d, 'f'); open(p, 'w').write('x')
r = cli('rig', 'hide', '--seed', '1', '--out', p); ok = r.returncode == 1 and 'not a directory' in r.stderr
"""),
    ("rig hide --out under /proc", "traceback", """
r = cli('rig', 'hide', '--seed', '1', '--out', '/proc/mutext-probe'); ok = r.returncode == 1 and '--out' in r.stderr
"""),
    ("rig hide --out ''", "silent", """
d = tempfile.mkdtemp(); os.chdir(d)
r = cli('rig', 'hide', '--seed', '1', '--out', ''); ok = r.returncode == 1 and not os.listdir(d)
"""),
    ("rig hide --count 1000000000", "hang", """
d = tempfile.mkdtemp()
r = cli('rig', 'hide', '--seed', '1', '--count', '1000000000', '--out', os.path.join(d, 'o'))
ok = r.returncode == 2 and not os.path.exists(os.path.join(d, 'o'))
"""),
    ("diagnose --out an existing file", "traceback", """
from mutext.rotor import data_path
d = tempfile.mkdtemp(); cli('rig', 'hide', '--seed', '2', '--out', os.path.join(d, 'case'))
data = sorted(os.listdir(os.path.join(d, 'case', 'measured')))[0]
p = os.path.join(d, 'f'); open(p, 'w').write('x')
r = cli('diagnose', data_path('three_mass.toml'), os.path.join(d, 'case', 'measured', data), '--out', p, '--quiet')
ok = r.returncode == 1 and 'not a directory' in r.stderr
"""),
    ("diagnose --batch, every set fails", "silent", """
d = tempfile.mkdtemp(); os.makedirs(os.path.join(d, 'b', 'case1'))
open(os.path.join(d, 'b', 'case1', 'model.toml'), 'w').write('[[mass]\\n')
r = cli('diagnose', '--batch', os.path.join(d, 'b'), '--quiet'); ok = r.returncode != 0
"""),
    ("demo two-mass-hinf --plots /dev/null/x", "traceback", """
r = cli('demo', 'two-mass-hinf', '--plots', '/dev/null/x'); ok = r.returncode != 0 and '--plots' in r.stderr
"""),
]


def run_probe(code: str, timeout: float) -> tuple[str, str]:
    src = PRELUDE + textwrap.dedent(code) + """
"""
    wrapper = textwrap.dedent("""
        import sys, traceback
        src = sys.stdin.read()
        ns = {}
        try:
            exec(compile(src, "<probe>", "exec"), ns)
        except Exception as exc:
            from mutext.errors import MutextError
            kind = "named error" if isinstance(exc, MutextError) else "traceback"
            print("RESULT", kind, "|", type(exc).__name__, str(exc).splitlines()[0][:110] if str(exc) else "")
        else:
            if "ok" in ns:
                print("RESULT", "right" if ns["ok"] else "silent", "|", "checked")
            else:
                print("RESULT", "silent", "|", "returned without an error")
    """)
    env = dict(os.environ, OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1", MPLBACKEND="Agg")
    try:
        r = subprocess.run([sys.executable, "-c", wrapper], input=src, capture_output=True, text=True,
                           timeout=timeout, env=env, cwd=tempfile.gettempdir())
    except subprocess.TimeoutExpired:
        return "hang", f"still running after {timeout:.0f} s"
    line = next((ln for ln in r.stdout.splitlines() if ln.startswith("RESULT")), None)
    if line is None:
        return "traceback", (r.stderr.strip().splitlines() or ["no output"])[-1][:110]
    kind, _, what = line[len("RESULT "):].partition(" | ")
    return kind, what


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--timeout", type=float, default=180.0, help="seconds per probe (default 180)")
    ap.add_argument("-k", default="", help="only probes whose name contains this text")
    args = ap.parse_args(argv)
    probes = [p for p in PROBES if args.k in p[0]]
    cats = ("right", "named error", "traceback", "silent", "hang")
    before = {c: 0 for c in cats}
    after = {c: 0 for c in cats}
    print(f"| probe | before | after | what |\n|---|---|---|---|")
    for name, was, code in probes:
        kind, what = run_probe(code, args.timeout)
        before[was] += 1
        after[kind] += 1
        print(f"| {name} | {was} | {kind} | {what.replace('|', '/')} |", flush=True)
    print()
    print("| | tried | " + " | ".join(cats) + " |\n|---|---|" + "---|" * len(cats))
    for label, tally in (("before", before), ("after", after)):
        print(f"| {label} | {len(probes)} | " + " | ".join(str(tally[c]) for c in cats) + " |")
    return 0 if after["traceback"] + after["silent"] + after["hang"] == 0 else 1


if __name__ == "__main__":
    sys.exit(main())
