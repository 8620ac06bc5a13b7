"""Every hostile, trivial and cheating submission of the test suite, graded in course mode, as root and
as a plain user (Landlock path), with what it left on the machine; the reference solutions beside them.

Usage (as root, from the repository root; several minutes)::

    .venv/bin/python benchmarks/bench_grading_attacks.py [--only PATTERN] [--modes root user]

Course mode: ``--require-isolation`` and a course secret, as the Gradescope scripts run it.  For each
submission the table prints the exercise, the mode, the score, the isolation that was enforced, the
seconds, and what changed on the machine while it ran: new entries in /tmp, /var/tmp and /dev/shm
(names beginning with ``mutext`` or owned by ``nobody``), and the change of shared memory (``Shmem`` in
/proc/meminfo).  Other processes on the machine (a test run making its own ``mutext-*`` directories)
count in those two columns too; the last line lists what is still there after all gradings.  A row whose score is above 0 for a submission that does not solve the
exercise is marked ``<-``.
"""
from __future__ import annotations

import argparse
import fnmatch
import os
import pwd
import secrets
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "instructor"))
SUBS = ROOT / "tests" / "grading_submissions"
SOLUTIONS = ROOT / "instructor" / "mutext_grader" / "solutions"
SHARED = ("/tmp", "/var/tmp", "/dev/shm")
#: submissions that are meant to score points (partly right answers; graded for the table, not marked)
HONEST = {"infinite_loop", "destabilizing", "missing_noise", "wrong_weight", "one_exception", "wrong_types", "ex02_crude",
          "ex02_dmd_sign", "ex02_spectral_radius", "ex03_decrement_not_per_cycle", "ex03_hz", "ex03_thesis_eq33",
          "ex04_hz_and_pi", "ex04_lumped_mass", "ex04_missing_L", "ex04_no_supports", "ex05_hz_as_rad",
          "ex05_never_none", "ex05_unwrapped_phase", "ex05_zero_based", "ex06_centre_in_fit",
          "ex06_fixed_threshold", "ex06_rad_per_s", "ex07_negative_feedback", "ex07_hz", "ex07_shortcuts",
          "ex07_stretch", "ex08_plus_u", "ex08_no_wz", "ex08_whole_grid"}
#: files that cheat on one question and answer the others honestly (their points come from those; the
#: tests check that the cheated question scores 0)
PART_CHEAT = {"cheat_in_functions", "ex02_cheat_mu", "ex04_cheat_rotor", "ex07_cheat_mu"}
#: not submissions (helpers of the tests)
SKIP = {"probe", "reader"}


def _exercise(name: str) -> str:
    return name[:4] if name[:2] == "ex" and name[2:4].isdigit() else "ex01"


def _cases():
    out = []
    for p in sorted(SOLUTIONS.glob("ex0*.py")):
        out.append(("reference", p.stem, p))
    for group, folder in (("cheat", SUBS), ("hostile", SUBS / "hostile"), ("trivial", SUBS / "trivial"),
                          ("report", SUBS / "reports")):
        for p in sorted(folder.glob("*.py")):
            if p.stem in SKIP or p.stem.startswith("_"):
                continue
            if group == "cheat" and p.stem == "syntax_error":
                group_ = "broken"
            elif group == "cheat":
                group_ = "partial" if p.stem in HONEST else ("cheat+" if p.stem in PART_CHEAT else "cheat")
            else:
                group_ = group
            out.append((group_, p.stem, p))
    return out


def _litter():
    try:
        nobody = pwd.getpwnam("nobody").pw_uid
    except KeyError:
        nobody = None
    found = set()
    for d in SHARED:
        try:
            for e in os.scandir(d):
                try:
                    if e.name.startswith("mutext") or e.stat(follow_symlinks=False).st_uid == nobody:
                        found.add(e.path)
                except OSError:
                    pass
        except OSError:
            pass
    return found


def _shmem_mib() -> float:
    with open("/proc/meminfo") as fh:
        for line in fh:
            if line.startswith("Shmem:"):
                return int(line.split()[1]) / 1024
    return float("nan")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--only", default="*", help="glob on the submission name")
    ap.add_argument("--modes", nargs="+", default=["root", "user"], choices=["root", "user"])
    ap.add_argument("--time-limit", type=float, default=60.0)
    args = ap.parse_args(argv)
    from mutext.grading import sandbox
    from mutext_grader import grade
    secret = secrets.token_bytes(32)
    start = _litter()
    rows = []
    print(f"{'group':<9} {'submission':<28} {'ex':<5} {'mode':<5} {'score':>11} {'isolation':<9} {'s':>6} "
          f"{'litter':>6} {'shm MiB':>8}")
    for mode in args.modes:
        for group, name, path in _cases():
            if not fnmatch.fnmatch(name, args.only):
                continue
            sandbox.FORCE_MODE = mode
            before, shm0 = _litter(), _shmem_mib()
            t0 = time.perf_counter()
            try:
                rep = grade(_exercise(name), path, time_limit=args.time_limit, require_isolation=True,
                            secret=secret)
                score, mx, iso = rep.score, rep.max_score, rep.isolation
            except Exception as exc:   # noqa: BLE001 - a row says what happened
                score, mx, iso = float("nan"), float("nan"), f"error: {type(exc).__name__}: {exc}"[:60]
            dt = time.perf_counter() - t0
            litter = len(_litter() - before)
            dshm = _shmem_mib() - shm0
            flag = "  <-" if group in ("cheat", "hostile", "trivial", "report", "broken") and score > 0 else ""
            if group == "reference" and score != mx:
                flag = "  <- reference below full marks"
            rows.append((group, name, mode, score, mx, iso, dt, litter, dshm))
            print(f"{group:<9} {name:<28} {_exercise(name):<5} {mode:<5} {score:>5.2f}/{mx:<5g} {iso:<9} "
                  f"{dt:6.1f} {litter:>6d} {dshm:>+8.1f}{flag}", flush=True)
    sandbox.FORCE_MODE = None
    bad = [r for r in rows if r[0] not in ("reference", "partial", "cheat+") and r[3] > 0]
    refs = [r for r in rows if r[0] == "reference"]
    left = sorted(_litter() - start)
    print(f"\nleft on the machine after all gradings (in /tmp, /var/tmp, /dev/shm): {left or 'nothing'}")
    print(f"{len(rows)} gradings; submissions that do not solve and scored above 0: {len(bad)}; "
          f"references at full marks: {sum(r[3] == r[4] for r in refs)}/{len(refs)}; "
          f"gradings that left litter: {sum(r[7] > 0 for r in rows)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
