"""Benchmark: LMI H-infinity synthesis (mutext.hinf.hinfsyn) against slycot's Riccati hinfsyn.

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

Columns: ``d_gamma`` = (gamma_ours - gamma_slycot)/gamma_slycot;
``d_cl`` = (closed-loop norm of our controller - gamma_slycot)/gamma_slycot
(negative is better than slycot's claim); ``CL_slycot`` = the closed-loop
norm slycot's own controller achieves (inf if it does not stabilize).

Usage::

    python benchmarks/bench_hinf.py [--count 100] [--first-seed 0] [--timeout 20] [--jobs 2]
"""
from __future__ import annotations

import argparse
import multiprocessing as mp
import sys
import time

import numpy as np


def slycot_reference(P, nmeas, ncon, timeout):
    """(status, gamma, note, seconds, achieved) from :func:`mutext.hinf.slycot_hinfsyn`."""
    from mutext.hinf import slycot_hinfsyn
    r = slycot_hinfsyn(P, nmeas, ncon, timeout=timeout)
    return r.status, r.gamma, r.note, r.seconds, r.achieved


def ours(P, nmeas, ncon):
    from mutext.errors import MutextError
    from mutext.hinf import hinfsyn
    t0 = time.perf_counter()
    try:
        r = hinfsyn(P, nmeas, ncon)
    except MutextError as exc:
        return {"error": f"{type(exc).__name__}: {str(exc)[:80]}", "seconds": time.perf_counter() - t0}
    return {"gamma": r.gamma, "cl": r.closed_loop_norm, "cl_slycot": r.closed_loop_norm_slycot,
            "stable": r.stable, "backoff": r.backoff, "order": r.controller_order,
            "method": r.info.get("level_method", ""), "seconds": time.perf_counter() - t0}


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


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--count", type=int, default=100, help="number of random plants")
    ap.add_argument("--first-seed", type=int, default=0)
    ap.add_argument("--timeout", type=float, default=20.0, help="slycot time limit per plant (s)")
    ap.add_argument("--jobs", type=int, default=2, help="plants solved in parallel")
    a = ap.parse_args(argv)
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
            print(f"{name:<26} {desc:<44} {st:<10} {gs:13.7g} {o['gamma']:13.7g} {dg:9.1e} {o['cl']:13.7g} "
                  f"{dc:9.1e} {sach:13.7g} {str(o['stable']):>6} {o['seconds']:6.2f}  {note}", flush=True)
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
