"""Benchmark: D-K iteration (mutext.dk.dk_iteration) against dkpy.

mutext runs with its defaults (``mutext default``: D fits to 0.05 %, iterating
while a step gains 0.1 % (patience 2, at most 20 iterations), a K-step plant of
at most ``n + 32`` states, the best loop's K step redone 0.01 % above the scaled
plant's optimal level), with the budget of ``mutext demo two-mass-mu``
(``mutext demo``: ``n + 16``) and with that budget plus the same fits and
patience (``mutext tight``: ``fit_tol=5e-4, rel_improvement=1e-3, max_iter=20,
patience=2``); ``mutext big`` (``n + 20``) and ``mutext patient``
(``fit_tol=2e-4, rel_improvement=1e-4, patience=4, max_order=5``, ``n + 40``)
on request (``--tools``), as are ``mutext dgk`` and ``mutext dgk-demo``
(:func:`mutext.dk.dgk_iteration`, real parameters kept real, with the
options of ``default`` and ``demo``; its ``mu (own)`` is its D-G bound) and
``mutext dgk-refine`` (``dgk-demo``'s controller then refined by 80 steps,
or ``--refine-steps``, of
:func:`mutext.dk.refine_controller`, the D-G scalings of every frequency;
any configuration followed by ``-refine`` is refined likewise).  mutext's
K step is its own (:func:`mutext.hinf.hinfsyn`); slycot only as a verified
fallback.

Problems: the two-mass robust-performance problem of the thesis (sec. 2.3.2,
+/- 2 % on m1, m2, k1, k2) at ``x_max`` = 0.035 m and 0.041 m, and the
distillation-column example that ships with dkpy (Skogestad and Postlethwaite,
Table 8.1, ``dkpy.example_skogestad2006_p325``; its performance weight has
poles at -1e-6 rad/s).

dkpy handles complex blocks only, so the real parameters of the two-mass
problem are given to it as complex 1x1 blocks; that is also how the D-K
iterations of both tools treat them.  dkpy is run in two documented
configurations: automatic fit order (``DkIterAutoOrder``, at most 4
iterations and order 4) and fixed order 4 for 3 iterations
(``DkIterFixedOrder``), both with slycot's H-infinity synthesis, its LMI mu
bound and its SLICOT D fit, on 61 log-spaced frequencies (the band of
mutext's default grid for the two-mass plant, 1e-3..1e3 rad/s for the
distillation column, as in dkpy's documentation; mutext gets the same grid
there).  ``n_jobs=1`` keeps dkpy on one process: mutext runs single-threaded.

Every synthesis runs in its own child process under a time limit.  Every
controller is then judged by ``benchmarks/_independent.py``, not by mutext's
numerics (the table prints what was used): the loop closed by python-control,
stability from 40-digit eigenvalues, responses by dense LU solves, and the
peak of SLICOT AB13MD's upper bound on a common grid (1.5 decades beyond the
pole magnitudes of all stable loops of that problem, 300 points plus the
frequencies of lightly damped poles), its four largest local peaks refined.
Columns: ``mu`` AB13MD with the real parameters real (D-G scalings), ``mu C``
with them complex, ``mu (own)`` what the tool reported, ``s`` wall-clock
seconds of the synthesis, ``order`` controller states.  A closed loop that is
not stable gets ``mu = inf`` whatever the tool reported.

Measured in one run on 2 cores shared with other work (one process per
synthesis; dkpy 0.1.9): on the distillation column ``mutext tight`` reaches
1.0280 with 18 states in 7.5 s, its defaults 1.0501 (18 states, 2.2 s).  dkpy's
loops are stable (the verdict "unstable" of this benchmark's earlier,
mutext-based check is not reproduced by the independent one), but it reports 1.0339 (auto, 22 states, 34 s) and
1.0360 (fixed, 22 states, 23 s) where AB13MD finds 1.0492 and 1.0786: both
peaks lie near 1e-6..1e-7 rad/s, below dkpy's grid (1e-3..1e3), where the
weight's near-integrator sets mu.  mutext's final analysis reaches 1.5 decades
below those poles (see ``mutext.dk``).  On the two-mass problem dkpy's
solver panicked (Clarabel ``Eigval error``) at 0.035 m in both configurations
and at 0.041 m in the automatic one; its fixed-order run reached 1.0142 with 36
states in 64.5 s against mutext's 1.0160 with 20 states in 4.1 s (``demo``;
1.0186 with 16 by default); at 0.035 m mutext reaches 1.1427.  A later run
(``--problems two-mass-0.035 two-mass-0.041 --tools "mutext default" "mutext
demo" "mutext patient" "dkpy fixed"``) gave ``mutext patient`` 1.0147 with 34
states in 9.3 s at 0.041 m (dkpy fixed 1.0142, 36 states, 55.8 s) and 1.1413
with 32 states in 8.5 s at 0.035 m (dkpy panicked again).  For every D-K loop of the two-mass problem the
real bound (``mu``) is within 1e-4 of the complex one.  With ``--tools "mutext
dgk" "mutext dgk-demo"`` added (one run, 2 cores): D-G-K reached 1.0148 (16
states, 35 s) and 1.0131 (20 states, 47 s) at 0.041 m, 1.1422 (16, 26 s) and
1.1395 (20, 38 s) at 0.035 m, with complex bounds 0.4-0.8 % higher: those
controllers use the parameters' realness.  Refining them (``mutext
dgk-refine``) with ``--refine-steps 300`` gave, with the same 20 states,
0.9896 at 0.041 m (267 s in all) and 1.1165 at 0.035 m (411 s), the refined
loops' own reports equal to these verdicts (dkpy fixed in the same run:
1.0142, 36 states, 51 s, and its panic at 0.035 m).  Any configuration can
be followed by the refinement (``mutext default-refine``, ``mutext
tight-refine``, ...): on the distillation column ``--tools "mutext default"
"mutext tight" "mutext default-refine" "dkpy auto" "dkpy fixed"`` gave
1.0501 (2.5 s), 1.0282 (5.7 s), **0.9943** (80 steps, 260 s), 1.0492 and
1.0786 (dkpy reports 1.0339 and 1.0360; 50 s and 30 s), with 18, 18, 18,
22 and 22 states.

With the defaults of 27 November 2026 (fits to 0.05 %, patience 2, ``n + 32``
states, the best K step redone 0.01 % above the optimum), ``--problems
skogestad two-mass-0.041 two-mass-0.035 --tools "mutext default" "dkpy auto"
"dkpy fixed"`` (one run, 2 cores shared with other work, wall-clock seconds):

=============== ============== ======== ======== ====== =======
problem         tool           mu       mu (own) s      states
=============== ============== ======== ======== ====== =======
skogestad       mutext default 1.0273   1.0273   13.9   18
skogestad       dkpy auto      1.1689   1.0377   102.8  22
skogestad       dkpy fixed     1.0360   1.0360   52.8   22
two-mass-0.041  mutext default 1.0138   1.0138   26.1   32
two-mass-0.041  dkpy fixed     1.0142   1.0143   106.4  36
two-mass-0.035  mutext default 1.1402   1.1402   21.2   30
two-mass-0.035  dkpy fixed     1.1408   1.1408   86.5   36
=============== ============== ======== ======== ====== =======

dkpy auto's solver panicked on both two-mass problems.

Usage::

    python benchmarks/bench_dk.py [--timeout 600] [--problems two-mass-0.035 two-mass-0.041 skogestad]
"""
from __future__ import annotations

import argparse
import multiprocessing as mp
import sys
import time

import numpy as np

try:
    from benchmarks import _independent as indep
except ImportError:          # run as a script: benchmarks/ is on sys.path
    import _independent as indep

GRID_N = 61
#: ``mutext tight``: finer D fits and patience for slowly converging scalings
TIGHT = {"fit_tol": 5e-4, "rel_improvement": 1e-3, "max_iter": 20, "patience": 2}
#: ``mutext patient``: finer still, fits up to order 5 and a K-step plant of n + 40 states
PATIENT = {"fit_tol": 2e-4, "rel_improvement": 1e-4, "max_iter": 20, "patience": 4, "max_order": 5}


def problem(name):
    """(plant, nmeas, ncon, mutext structure, dkpy block spec, dkpy's grid, mutext's grid or None for its own)."""
    if name.startswith("two-mass-"):
        from mutext.dk import _default_dk_grid
        from mutext.examples import two_mass_uncertain as tmu
        P = tmu.plant(float(name.split("-")[-1]))
        g = _default_dk_grid(P, 80)
        omega = np.logspace(np.log10(g.min()), np.log10(g.max()), GRID_N)
        return P, 1, 1, tmu.structure(), [(1, 1)] * 4 + [(2, 2)], omega, None
    if name == "skogestad":
        # the same interconnection as dkpy.example_skogestad2006_p325 (tests/test_dk.py checks it
        # against the textbook's transfer functions)
        from mutext.examples import distillation
        omega = np.logspace(-3, 3, GRID_N)
        return distillation.plant(), 2, 2, distillation.structure(), [(1, 1), (1, 1), (2, 2)], omega, omega
    raise SystemExit(f"unknown problem {name!r}")


#: steps of refine_controller in the ``-refine`` tools (``--refine-steps``)
REFINE_STEPS = 80


def run_mutext(name, config):
    from mutext.dk import dgk_iteration, dk_iteration
    P, ny, nu, S, _, _, omega = problem(name)
    config = {"dgk-refine": "dgk-demo-refine"}.get(config, config)
    refine = config.endswith("-refine")
    config = config.removesuffix("-refine")
    real = config.startswith("dgk")
    if real and not S.has_real:
        raise RuntimeError("no real blocks: D-G-K is plain D-K here")
    config = {"dgk": "default", "dgk-demo": "demo"}.get(config, config)
    opts = {"default": {}, "demo": {"max_states": P.nstates + 16}, "big": {"max_states": P.nstates + 20},
            "tight": {"max_states": P.nstates + 16, **TIGHT},
            "patient": {"max_states": P.nstates + 40, **PATIENT}}[config]
    t0 = time.perf_counter()
    res = (dgk_iteration if real else dk_iteration)(P, S, ny, nu, omega=omega, out=None, **opts)
    note = f"{len(res.history)} iterations, orders {res.history[res.best_iteration - 1]['orders']}"
    if refine:
        from mutext.dk import refine_controller
        before = res.mu_upper_dg
        ref = refine_controller(P, S, res.K, ny, nu, max_steps=REFINE_STEPS)
        scale = f"c = {res.real_scale:.3f}, " if real else ""
        note = (f"{scale}from {before:.5f}; refined: "
                f"{sum(h['accepted'] for h in ref.history)}/{len(ref.history)} steps accepted")
        return ref.K, ref.mu_upper_dg, time.perf_counter() - t0, note
    sec = time.perf_counter() - t0
    if real:
        note = f"c = {res.real_scale:.3f} after {len(res.tries)} D-K runs; " + note
        return res.K, res.mu_upper_dg, sec, note
    if res.notes:
        note += "; " + res.notes[-1][:60]
    return res.K, res.mu_upper, sec, note


def run_dkpy(name, config):
    import dkpy
    from threadpoolctl import threadpool_limits
    P, ny, nu, S, spec, omega, _ = problem(name)
    import control as ct
    P = ct.ss(P.A, P.B, P.C, P.D)
    blocks = [dkpy.ComplexFullBlock(r, c) for r, c in spec]
    parts = dict(controller_synthesis=dkpy.HinfSynSlicot(),
                 structured_singular_value=dkpy.SsvLmiBisection(n_jobs=1),
                 d_scale_fit=dkpy.DScaleFitSlicot())
    if config == "auto":
        it = dkpy.DkIterAutoOrder(**parts, max_mu=1, max_mu_fit_error=1e-2, max_iterations=4, max_fit_order=4)
    else:
        it = dkpy.DkIterFixedOrder(**parts, n_iterations=3, fit_order=4)
    t0 = time.perf_counter()
    with threadpool_limits(1):
        K, _, mu, _, _ = it.synthesize(P, ny, nu, omega, blocks)
    sec = time.perf_counter() - t0
    if K is None:
        raise RuntimeError("dkpy returned no controller (its H-infinity step failed)")
    return K, float(mu), sec, f"{config} order"


def _child(tool, name, conn):
    try:
        with np.errstate(all="ignore"):
            config = tool.split()[-1]
            run = run_mutext if tool.startswith("mutext") else run_dkpy
            K, mu, sec, note = run(name, config)
        conn.send(("ok", (np.asarray(K.A), np.asarray(K.B), np.asarray(K.C), np.asarray(K.D)), mu, sec, note))
    except BaseException as exc:    # dkpy's solver can raise a Rust panic (a BaseException)
        conn.send(("error", None, np.nan, np.nan, f"{type(exc).__name__}: {str(exc).splitlines()[0][:70]}"))
    conn.close()


def synthesize(tool, name, timeout):
    parent, child = mp.Pipe(duplex=False)
    proc = mp.get_context("fork").Process(target=_child, args=(tool, name, child))
    t0 = time.perf_counter()
    proc.start()
    child.close()
    if not parent.poll(timeout):
        proc.kill()
        proc.join()
        return "timeout", None, np.nan, time.perf_counter() - t0, f"no answer within {timeout:g} s"
    try:
        msg = parent.recv()
    except EOFError:
        msg = ("error", None, np.nan, np.nan, f"process died (exit code {proc.exitcode})")
    proc.join()
    return msg


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--timeout", type=float, default=600.0, help="seconds per synthesis (default 600)")
    ap.add_argument("--problems", nargs="+", default=["two-mass-0.035", "two-mass-0.041", "skogestad"])
    ap.add_argument("--tools", nargs="+", help="a subset of the tools (e.g. 'mutext demo' 'dkpy auto')")
    ap.add_argument("--refine-steps", type=int, default=80,
                    help="steps of refine_controller in the '-refine' tools (default 80)")
    args = ap.parse_args(argv)
    global REFINE_STEPS
    REFINE_STEPS = args.refine_steps
    from mutext.lti import ss
    try:
        import dkpy  # noqa: F401
        have_dkpy = True
    except ImportError:
        have_dkpy = False
        print("note: dkpy is not installed (pip install dkpy); its columns are skipped", file=sys.stderr)
    tools = ["mutext default", "mutext demo", "mutext tight", "dkpy auto", "dkpy fixed"]
    if args.tools:
        configs = ["default", "demo", "tight", "big", "patient", "dgk", "dgk-demo"]
        # '-refine' after the configuration's own run; 'dgk-refine' refines 'dgk-demo'
        known = (tools + [f"mutext {c}" for c in configs]
                 + [f"mutext {c}-refine" for c in configs if not c.startswith("dgk")] + ["mutext dgk-refine"])
        unknown = [t for t in args.tools if t not in known]
        if unknown:
            raise SystemExit(f"unknown tools {unknown}; known: {sorted(set(known))}")
        tools = [t for t in dict.fromkeys(known) if t in args.tools]
    if not have_dkpy:
        tools = [t for t in tools if not t.startswith("dkpy")]
    rows = []
    for name in args.problems:
        P, ny, nu, S, _, _, _ = problem(name)
        results = []
        for tool in tools:
            print(f"[{name}] {tool} ...", file=sys.stderr, flush=True)
            status, mats, own, sec, note = synthesize(tool, name, args.timeout)
            results.append((tool, status, None if mats is None else ss(*mats), own, sec, note))
        print(f"[{name}] independent verdicts ...", file=sys.stderr, flush=True)
        rows += verdicts(name, P, ny, nu, S, results)
    print(f"verdicts: {indep.USED}")
    print("mu: AB13MD peak with the real parameters real (D-G scalings); mu C: with them complex "
          "(what the D-K iterations minimise); inf = closed loop not stable")
    print(f"{'problem':<16} {'tool':<21} {'mu':>8} {'mu C':>8} {'mu (own)':>9} {'s':>7} {'order':>6}  note")
    for name, tool, mu, mu_c, own, sec, order, note in rows:
        o = "-" if order is None else str(order)
        print(f"{name:<16} {tool:<21} {mu:>8.4f} {mu_c:>8.4f} {own:>9.4f} {sec:>7.1f} {o:>6}  {note}")
    return 0


def _ab13md_structure(S, complexify=False):
    nblock = [b.rows for b in S.blocks]
    itype = [2 if (complexify or b.kind != "real") else 1 for b in S.blocks]
    if any(b.rows != b.cols or b.kind == "scalar" and b.rows > 1 for b in S.blocks):
        raise SystemExit("AB13MD needs square full blocks or real/complex scalars")
    return nblock, itype


def verdicts(name, P, ny, nu, S, results, points: int = 300):
    """Rows (problem, tool, mu, mu C, own, s, order, note), every loop judged by
    ``benchmarks/_independent.py``: python-control's lft, 40-digit poles, dense LU
    responses, AB13MD peaks on a common grid (the pole-magnitude bands of all stable
    loops, 1.5 decades beyond, plus the frequencies of lightly damped poles)."""
    import control as ct
    loops = {}
    for tool, status, K, *_ in results:
        if K is not None:
            CL = indep.closed_loop(ct.ss(P.A, P.B, P.C, P.D), K, ny, nu)
            ok, text = indep.stability(CL)
            loops[tool] = (CL, ok, text, indep.poles(CL))
    bands = [np.abs(p[np.abs(p) > 0]) for CL, ok, text, p in loops.values() if ok]
    bands = [b for b in bands if b.size]
    grid = np.zeros(0)
    if bands:
        lo = min(b.min() for b in bands) / 10 ** 1.5
        hi = max(b.max() for b in bands) * 10 ** 1.5
        res = np.concatenate([np.abs(p.imag[(p.imag > 0) & (-p.real < 0.2 * np.abs(p))])
                              for CL, ok, text, p in loops.values() if ok])
        grid = np.unique(np.concatenate([np.logspace(np.log10(lo), np.log10(hi), points), res]))
    nb, it = _ab13md_structure(S)
    nbc, itc = _ab13md_structure(S, complexify=True)
    rows = []
    for tool, status, K, own, sec, note in results:
        if K is None:
            rows.append((name, tool, np.nan, np.nan, own, sec, None, f"{status}: {note}"))
            continue
        CL, ok, text, _ = loops[tool]
        if not ok:
            rows.append((name, tool, np.inf, np.inf, own, sec, K.nstates, text + "; " + note))
            continue
        mu, w = indep.mu_peak(CL, nb, it, grid)
        mu_c = mu if it == itc else indep.mu_peak(CL, nbc, itc, grid)[0]
        rows.append((name, tool, mu, mu_c, own, sec, K.nstates,
                     f"peak at {w:.4g} rad/s; {text.split(';')[0]}; {note}"))
    return rows


if __name__ == "__main__":
    sys.exit(main())
