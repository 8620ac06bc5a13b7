"""Benchmark: H-infinity synthesis (mutext.hinf.hinfsyn) against slycot's Riccati hinfsyn.

Plants: the two-mass problem of the thesis (rounded and exact weights) and a
seeded set of random well-posed plants (orders 2-12, stable and unstable,
badly scaled; see :mod:`mutext.examples.random_plants`).

For every plant:

* slycot (``control.hinfsyn``) runs in a child process under a time limit.
  Its claim counts as a reference only when verified: the closed loop rebuilt
  from P and slycot's controller is stable and its norm is within 1e-3 of the
  claimed gamma ("verified").  Otherwise the row says why not.
* ours: the optimal level gamma and the controller, whose closed loop is
  rebuilt and its norm recomputed independently.

Every verdict (slycot's and ours) comes from :func:`judge`, which does not use
mutext's numerics: the loop closed by python-control, stability from the
closed-loop poles in 40-digit arithmetic (mpmath), the norm by SLICOT AB13DD
(``benchmarks/_independent.py``).

Columns: ``d_gamma`` = (gamma_ours - gamma_slycot)/gamma_slycot;
``d_cl`` = (closed-loop norm of our controller - gamma_slycot)/gamma_slycot
(negative is better than slycot's claim); ``CL_slycot`` = the closed-loop
norm slycot's own controller achieves (inf if it does not stabilize).

Columns ``construction`` and ``level`` say how our controller was built (the
central controller from the Riccati solutions, or the LMI reconstruction) and
how the level was found (Riccati gamma iteration, or LMIs).

``--sizes 10 20 30 40`` prints instead the cost as plants grow: random well-posed plants with 2 disturbances, 2 controls, 2
errors and 2 measurements (generic ``D12``, ``D21``, half of them open-loop
unstable; :func:`sized_plant`), ``--per-size`` plants per order, ours with the
default ``method="auto"`` (and ``--lmi`` adds the LMI route) against slycot's
``hinfsyn`` in the same run, both verified on the rebuilt closed loop.

Measured (``--sizes 10 20 30 40 --per-size 3``, one core of a shared
machine; medians; d_gamma against slycot's claim)::

      n  t_slycot  t_ours  ratio  max |d_gamma|
     10      0.14    0.06   0.43        4.0e-09
     20      0.83    0.11   0.13        1.1e-09
     30      2.28    0.18   0.08        1.4e-09
     40      5.19    0.34   0.07        1.2e-09

Every one of our controllers achieved gamma * (1 + 1e-4) (the back-off) with a
stable loop; slycot's own controller failed the check (unstable rebuilt loop)
on one plant of three at n = 20, 30 and 40.  The LMI route (``--lmi``) took
1.35 s at n = 10 and 68 s at n = 20 for the same gamma.

Usage::

    python benchmarks/bench_hinf.py [--count 100] [--first-seed 0] [--timeout 20] [--jobs 2]
    python benchmarks/bench_hinf.py --sizes 10 20 30 40 [--per-size 3] [--lmi]
"""
from __future__ import annotations

import argparse
import multiprocessing as mp
import sys
import time

import numpy as np


def judge(P, K, nmeas, ncon):
    """(closed-loop norm, stable, text) of a controller, by code independent of mutext
    (``benchmarks/_independent.py``: python-control's loop, 40-digit poles, AB13DD)."""
    import _independent as ind
    CL = ind.closed_loop(P, K, nmeas, ncon)
    stable, text = ind.stability(CL)
    return (ind.hinf_norm(CL) if stable else float("inf")), stable, text


def slycot_reference(P, nmeas, ncon, timeout):
    """(status, gamma, note, seconds, achieved) of slycot's ``hinfsyn``, its claim judged by :func:`judge`:
    ``verified`` when its loop is stable and achieves the claimed gamma within 1e-3."""
    from mutext.hinf import slycot_hinfsyn
    r = slycot_hinfsyn(P, nmeas, ncon, timeout=timeout)
    if r.K is None:
        return r.status, r.gamma, r.note, r.seconds, r.achieved
    achieved, stable, text = judge(P, r.K, nmeas, ncon)
    if stable and abs(achieved - r.gamma) <= 1e-3 * r.gamma:
        return "verified", r.gamma, "", r.seconds, achieved
    why = text if not stable else f"its controller achieves {achieved:.7g}, not the claimed {r.gamma:.7g}"
    return "unverified", r.gamma, why, r.seconds, achieved


def ours(P, nmeas, ncon):
    from mutext.errors import MutextError
    from mutext.hinf import hinfsyn
    t0 = time.perf_counter()
    try:
        r = hinfsyn(P, nmeas, ncon)
    except MutextError as exc:
        return {"error": f"{type(exc).__name__}: {str(exc)[:80]}", "seconds": time.perf_counter() - t0}
    seconds = time.perf_counter() - t0
    cl, stable, _ = judge(P, r.K, nmeas, ncon)
    return {"gamma": r.gamma, "cl": cl, "stable": stable, "backoff": r.backoff, "order": r.controller_order,
            "method": r.info.get("level_method", ""), "construction": r.construction, "seconds": seconds}


def cases(count, first_seed):
    from mutext.examples import random_plants, two_mass
    yield "two-mass (thesis weights)", "n=4 nw=2 nu=1 nz=2 ny=1", two_mass.plant(two_mass.THESIS), 1, 1
    yield "two-mass (exact weights)", "n=4 nw=2 nu=1 nz=2 ny=1", two_mass.plant(two_mass.TwoMass()), 1, 1
    for s in range(first_seed, first_seed + count):
        rp = random_plants.random_plant(s)
        yield f"random seed {s}", rp.description, rp.P, rp.nmeas, rp.ncon


def _case_child(i, count, first_seed, timeout, q):
    name, desc, P, nmeas, ncon = list(cases(count, first_seed))[i]
    ref = ("error", np.nan, "", 0.0, np.nan)
    try:
        ref = slycot_reference(P, nmeas, ncon, timeout)
        res = ours(P, nmeas, ncon)
    except Exception as exc:  # a crash is a result too: report it in the table
        res = {"error": f"crashed: {type(exc).__name__}: {str(exc)[:80]}", "seconds": 0.0}
    q.put((i, name, desc, ref, res))


def run_cases(ncases, count, first_seed, timeout, jobs):
    """Yield results in case order; each case in its own (non-daemonic) process
    so that slycot can run in a grandchild under a time limit."""
    ctx = mp.get_context("fork")
    q = ctx.Queue()
    running, done, nxt, want = {}, {}, 0, 0
    while want < ncases:
        while nxt < ncases and len(running) < jobs:
            p = ctx.Process(target=_case_child, args=(nxt, count, first_seed, timeout, q))
            p.start()
            running[nxt] = p
            nxt += 1
        i, *res = q.get()
        running.pop(i).join()
        done[i] = res
        while want in done:
            yield done.pop(want)
            want += 1


def sized_plant(n, seed, nw=2, nu=2, nz=2, ny=2):
    """A random well-posed plant of order ``n``: ``D11 = 0``, generic ``D12``, ``D21``
    (full rank), ``D22 = 0``; even seeds open-loop stable (rightmost pole at -0.2),
    odd seeds with a few unstable poles (rightmost at +0.3)."""
    from mutext.lti import ss
    rng = np.random.default_rng(1000 * n + seed)
    A = rng.standard_normal((n, n)) / np.sqrt(n)
    A += ((0.3 if seed % 2 else -0.2) - np.linalg.eigvals(A).real.max()) * np.eye(n)
    B1, B2 = rng.standard_normal((n, nw)), rng.standard_normal((n, nu))
    C1, C2 = rng.standard_normal((nz, n)), rng.standard_normal((ny, n))
    D12, D21 = rng.standard_normal((nz, nu)), rng.standard_normal((ny, nw))
    D = np.block([[np.zeros((nz, nw)), D12], [D21, np.zeros((ny, nu))]])
    return ss(A, np.hstack([B1, B2]), np.vstack([C1, C2]), D)


def _sizes_child(n, seed, timeout, lmi, q):
    from mutext.errors import MutextError
    from mutext.hinf import hinfsyn
    P = sized_plant(n, seed)
    ref = slycot_reference(P, 2, 2, timeout)
    rows = {}
    for method in (["auto", "lmi"] if lmi else ["auto"]):
        t0 = time.perf_counter()
        try:
            r = hinfsyn(P, 2, 2, method=method)
            t = time.perf_counter() - t0
            cl, stable, _ = judge(P, r.K, 2, 2)
            rows[method] = (r.gamma, cl, stable, t,
                            r.construction.split(" ")[0], r.info["level_method"].split(" ")[0])
        except MutextError as exc:
            rows[method] = (np.nan, np.nan, False, time.perf_counter() - t0, f"failed: {type(exc).__name__}", "")
    q.put((ref, rows))


def run_sizes(sizes, per_size, timeout, lmi):
    """Cost against plant order, ours and slycot's in the same process tree (one plant
    at a time, so that the timings do not compete with each other)."""
    ctx = mp.get_context("fork")
    hdr = (f"{'n':>3} {'seed':>4} {'t_slycot':>9} {'slycot':<10} {'gamma_slycot':>13} {'t_ours':>7} "
           f"{'gamma_ours':>13} {'d_gamma':>9} {'CL_ours/g-1':>11} {'ratio':>6}  how")
    if lmi:
        hdr += f"   {'t_lmi':>7} {'gamma_lmi':>13}"
    print(hdr)
    print("-" * len(hdr))
    summary = []
    for n in sizes:
        for seed in range(per_size):
            q = ctx.Queue()
            p = ctx.Process(target=_sizes_child, args=(n, seed, timeout, lmi, q))
            p.start()
            ref, rows = q.get()
            p.join()
            st, gs, note, ts, _ = ref
            g, cl, stable, to, cons, lev = rows["auto"]
            # d_gamma against slycot's claim, also where its controller fails the check
            # (the note says why; its level is then a claim, not a verified level)
            dg = (g - gs) / gs
            line = (f"{n:3d} {seed:4d} {ts:9.2f} {st:<10} {gs:13.7g} {to:7.2f} {g:13.7g} {dg:9.1e} "
                    f"{cl / g - 1:11.1e} {to / ts if ts > 0 else np.nan:6.2f}  {cons}/{lev}"
                    + ("" if stable else " UNSTABLE") + (f"  [slycot: {note[:90]}]" if note else ""))
            if lmi:
                gl, _, _, tl, _, _ = rows["lmi"]
                line += f"   {tl:7.2f} {gl:13.7g}"
            print(line, flush=True)
            summary.append((n, ts, to, st, dg))
    print()
    print(f"{'n':>3} {'median t_slycot':>16} {'median t_ours':>14} {'ratio':>6} {'max |d_gamma|':>14}")
    for n in sizes:
        rs = [s for s in summary if s[0] == n]
        ts = float(np.median([s[1] for s in rs]))
        to = float(np.median([s[2] for s in rs]))
        dgs = [abs(s[4]) for s in rs if np.isfinite(s[4])]
        print(f"{n:3d} {ts:16.2f} {to:14.2f} {to / ts if ts > 0 else np.nan:6.2f} "
              f"{max(dgs) if dgs else np.nan:14.1e}")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--count", type=int, default=100, help="number of random plants")
    ap.add_argument("--first-seed", type=int, default=0)
    ap.add_argument("--timeout", type=float, default=20.0, help="slycot time limit per plant (s)")
    ap.add_argument("--jobs", type=int, default=2, help="plants solved in parallel")
    ap.add_argument("--sizes", type=int, nargs="*", help="plant orders for the cost table (2x2x2x2 plants)")
    ap.add_argument("--per-size", type=int, default=3, help="plants per order in the cost table")
    ap.add_argument("--lmi", action="store_true", help="cost table: also time the LMI route (slow)")
    a = ap.parse_args(argv)
    if a.sizes:
        run_sizes(a.sizes, a.per_size, max(a.timeout, 120.0), a.lmi)
        return 0
    ncases = a.count + 2
    t0 = time.perf_counter()
    hdr = (f"{'plant':<26} {'structure':<44} {'slycot':<10} {'gamma_slycot':>13} {'gamma_ours':>13} "
           f"{'d_gamma':>9} {'CL_ours':>13} {'d_cl':>9} {'CL_slycot':>13} {'stable':>6} {'t_ours':>6}  note")
    print(hdr)
    print("-" * len(hdr))
    rows = []
    if True:
        for name, desc, ref, o in run_cases(ncases, a.count, a.first_seed, a.timeout, a.jobs):
            st, gs, note, _, sach = ref
            if "error" in o:
                print(f"{name:<26} {desc:<44} {st:<10} {gs:13.7g} {'-':>13} {'-':>9} {'-':>13} {'-':>9} "
                      f"{sach:13.7g} {'-':>6} {o['seconds']:6.2f}  ours failed: {o['error']} {note}")
                rows.append((name, st, gs, None))
                continue
            dg = (o["gamma"] - gs) / gs if st == "verified" else np.nan
            dc = (o["cl"] - gs) / gs if st == "verified" else np.nan
            how = f"[{o['construction'].split(' ')[0]}; level {o['method'].split(' ')[0]}]"
            print(f"{name:<26} {desc:<44} {st:<10} {gs:13.7g} {o['gamma']:13.7g} {dg:9.1e} {o['cl']:13.7g} "
                  f"{dc:9.1e} {sach:13.7g} {str(o['stable']):>6} {o['seconds']:6.2f}  {how} {note}", flush=True)
            rows.append((name, st, gs, o))
    print()
    ver = [(n, gs, o) for n, st, gs, o in rows if st == "verified"]
    ok = [(n, gs, o) for n, gs, o in ver if o is not None]
    print(f"plants: {len(rows)}; slycot verified on {len(ver)}; "
          f"slycot error/timeout/unverified on {len(rows) - len(ver)}; ours failed on "
          f"{sum(o is None for *_, o in rows)}")
    if ok:
        dg = np.array([abs(o['gamma'] - gs) / gs for _, gs, o in ok])
        dc = np.array([(o['cl'] - gs) / gs for _, gs, o in ok])
        wg, wc = int(np.argmax(dg)), int(np.argmax(dc))
        print(f"gamma vs slycot (verified): median |d| {np.median(dg):.1e}, worst {dg[wg]:.2e} ({ok[wg][0]}); "
              f"within 1e-4 on {int(np.sum(dg <= 1e-4))}/{len(ok)}")
        print(f"our controller vs slycot gamma: worst d_cl {dc[wc]:.2e} ({ok[wc][0]}); "
              f"within 1e-3 on {int(np.sum(dc <= 1e-3))}/{len(ok)}; "
              f"closed loop stable on {sum(o['stable'] for *_, o in ok)}/{len(ok)}")
    unv = [(n, gs, o) for n, st, gs, o in rows if st != "verified" and o is not None]
    if unv:
        print(f"where slycot has no verified answer, ours returned a verified controller on "
              f"{sum(o['stable'] for *_, o in unv)}/{len(unv)}")
    print(f"total time {time.perf_counter() - t0:.1f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
