r"""Many diagnoses at once: a class's hidden-effect sets, a fleet of machines, a Monte Carlo study.

:func:`diagnose_batch` finds every data set under a directory -- a folder
holding a model file ``model.toml`` and its measured FRFs in ``measured/``
(CSV or UFF 58), optionally ``validate/`` (held-out FRFs), ``repeat/`` (the same
sweeps at another excitation level, for the amplitude test) and an
``answer_key.json``, as ``mutext rig hide`` writes them -- runs :func:`mutext.diagnose.diagnose` on
each, writes each result beside its data (``<set>/diagnosis/``: report,
figures, ``diagnosis.json``, extended model) and a summary
(``summary.csv`` and ``index.html`` in the directory).  A data set that
fails is reported in the summary with its error; the others go on.

Parallel runs go through joblib (one process per data set, ``jobs``
workers, one BLAS thread each).  On a cluster, the same call runs on Dask
through joblib's Dask backend::

    from dask.distributed import Client
    import joblib
    client = Client("scheduler-address:8786")        # or Client() for a local cluster
    with joblib.parallel_backend("dask"):
        rows = diagnose_batch("cases/", jobs=-1)

With an answer key the summary says whether the verdict's kind and place
match it (the Monte Carlo success rate of ``benchmarks/bench_diagnose.py``).
"""
from __future__ import annotations

import contextlib
import csv
import html
import json
import os
import time
import traceback
from pathlib import Path

from ._validation import AnyOf, Integer, check_param
from .errors import ModelError

__all__ = ["SUMMARY_FIELDS", "check_jobs", "dask_backend", "diagnose_batch", "find_data_sets", "run_parallel"]

#: Columns of ``summary.csv``.
SUMMARY_FIELDS = ("data_set", "status", "diagnosis", "effects", "what", "kind", "station", "element", "value",
                  "unit", "std", "gain", "error_before", "error_after", "noise", "seconds", "key_kind", "key_station", "key_value",
                  "found", "error")


def find_data_sets(root) -> list[Path]:
    """Folders under ``root`` (itself included) with a ``model.toml`` and a non-empty ``measured/``.

    Parameters
    ----------
    root : str or path-like
        The folder to search (recursively).
    """
    root = Path(root)
    if not root.is_dir():
        raise ModelError(f"batch: '{root}' is not a directory")
    found = []
    for model in sorted(root.rglob("model.toml")):
        d = model.parent
        if (d / "measured").is_dir() and any(p.is_file() for p in (d / "measured").iterdir()):
            found.append(d)
    return found


def _files(folder: Path) -> list[str]:
    return [str(p) for p in sorted(folder.iterdir()) if p.is_file() and p.suffix.lower() in (".csv", ".uff", ".unv")] \
        if folder.is_dir() else []


def _one(folder: str, out_name: str, mbi: bool) -> dict:
    """Diagnose one data set and write its report; never raises (failures are rows too)."""
    from .diagnose import diagnose
    from .lti import blas_single_thread
    from .report import write_diagnosis
    d = Path(folder)
    row = {"data_set": str(d), "status": "ok"}
    t0 = time.perf_counter()
    try:
        with blas_single_thread():
            res = diagnose(str(d / "model.toml"), _files(d / "measured"), validate=_files(d / "validate") or None,
                           repeat=_files(d / "repeat") or None, mbi=mbi)
            write_diagnosis(res, d / out_name)
        v = res.verdict
        # the description names the element ("spring k2 (m2-m3) changed", "grounded spring added at m2"):
        # kind and station alone read alike for different effects
        row.update(diagnosis=res.status, effects="; ".join(f"{e.description} ({e.size_text(std=False)})"
                                                           for e in res.effects) or "none",
                   what=v.description if v.kind != "none" else "none", kind=v.kind, station=v.station, element=v.element, value=v.value, unit=v.unit, std=v.std,
                   gain=res.gain, error_before=res.error_before["rel"], error_after=res.error_after["rel"],
                   noise=res.noise)
    except Exception as exc:      # noqa: BLE001 - one bad data set must not stop the batch
        row.update(status="failed", error=f"{type(exc).__name__}: {exc}".splitlines()[0])
        if not isinstance(exc, ModelError):
            row["error"] += f" ({traceback.extract_tb(exc.__traceback__)[-1].name})"
    row["seconds"] = time.perf_counter() - t0
    key = d / "answer_key.json"
    if key.is_file():
        try:
            k = json.loads(key.read_text(encoding="utf-8"))
            row.update(key_kind=k.get("kind"), key_station=k.get("station"), key_value=k.get("value"))
            if row["status"] == "ok":
                row["found"] = (row["kind"], row["station"]) == (k.get("kind"), k.get("station"))
        except (OSError, ValueError) as exc:
            row["error"] = f"answer key unreadable: {exc}"
    return row


def check_jobs(jobs, what: str = "batch") -> int:
    """``jobs`` if it is a number of workers joblib accepts (positive, or negative for all cores but some).

    Parameters
    ----------
    jobs : int
        Number of joblib workers: positive, or negative for all cores but ``-jobs - 1``.
    what : str, optional
        Name of the caller in the error message.
    """
    return int(check_param(what, "jobs (the number of workers)", jobs, AnyOf(Integer(lo=1), Integer(hi=-1))))


def run_parallel(fn, tasks, *, jobs: int = 1, progress=None, describe=None):
    """Yield ``fn(*task)`` for every task (a tuple of arguments), in order, on ``jobs`` joblib workers.

    The engine of every batch in mutext (:func:`diagnose_batch`,
    :func:`mutext.grading.batch.grade_batch`, ``benchmarks/bench_diagnose.py``):
    ``jobs=1`` runs the tasks one after the other in this process; more
    workers are joblib's processes (loky), or the workers of the active
    joblib backend (e.g. Dask).  ``fn`` should catch its own errors and
    return them as results; an exception raised by ``fn`` or by the pool
    (a worker that died) ends the generator.

    Parameters
    ----------
    fn : callable, picklable (a module-level function)
    tasks : iterable of tuple
    jobs : int
    progress : callable(stage, fraction), optional
        Called after each result.
    describe : callable(k, n, result) -> str, optional
        The stage text for ``progress`` (default ``"case k/n"``).
    """
    import joblib
    tasks = [tuple(t) for t in tasks]
    n = len(tasks)
    if not n:
        return
    par = joblib.Parallel(n_jobs=check_jobs(jobs), return_as="generator")
    for k, out in enumerate(par(joblib.delayed(fn)(*t) for t in tasks), start=1):
        if progress is not None:
            progress(describe(k, n, out) if describe is not None else f"case {k}/{n}", k / n)
        yield out


@contextlib.contextmanager
def dask_backend(scheduler: str, workers: int = -1):
    """Run the batches inside the block on a Dask cluster, through joblib's Dask backend.

    ``scheduler`` is the address of a running scheduler (``tcp://host:8786``;
    start one with ``dask scheduler`` and workers with ``dask worker ADDRESS``)
    or ``"local"`` for a cluster of ``workers`` processes on this machine
    (one thread each; ``-1``: one per core).  Yields a line saying where the
    work runs.  Every worker needs mutext installed (the same version).

    Parameters
    ----------
    scheduler : str
        Address of a running Dask scheduler, or ``"local"``.
    workers : int, optional
        Number of worker processes of a local cluster (``-1``: one per core).

    Raises
    ------
    ModelError
        ``dask.distributed`` is not installed, or the scheduler cannot be reached.
    """
    try:
        import joblib
        from distributed import Client, LocalCluster
    except ImportError:
        raise ModelError("--scheduler needs Dask's distributed scheduler: pip install -e '.[cluster]' "
                         "(or pip install 'dask[distributed]')") from None
    cluster = None
    try:
        if scheduler == "local":
            n = (os.cpu_count() or 1) if workers in (None, -1) else check_jobs(workers)
            cluster = LocalCluster(n_workers=max(1, n), threads_per_worker=1, processes=True,
                                   dashboard_address=None)
            client = Client(cluster)
        else:
            client = Client(scheduler, timeout="10s")
    except (OSError, TimeoutError) as exc:
        if cluster is not None:
            cluster.close()
        raise ModelError(f"--scheduler {scheduler}: cannot reach the Dask scheduler ({exc})") from None
    try:
        n_workers = len(client.scheduler_info().get("workers", {}))
        where = f"scheduler {client.scheduler.address}, {n_workers} worker(s)"
        with joblib.parallel_backend("dask"):
            yield where
    finally:
        client.close()
        if cluster is not None:
            cluster.close()


def diagnose_batch(root, *, jobs: int = 1, out_name: str = "diagnosis", mbi: bool = False,
                   progress=None) -> list[dict]:
    """Diagnose every data set under ``root``; write each report beside its data and a summary.

    Parameters
    ----------
    root : path
        Directory searched by :func:`find_data_sets`.
    jobs : int
        Parallel workers (joblib; -1 for all cores, or the Dask backend's workers).
    out_name : str
        Folder written inside each data set.
    mbi : bool
        Also the model-based-identification reading (lumped chains; slower).
    progress : callable(stage, fraction), optional

    Returns
    -------
    list of dict
        One row per data set (:data:`SUMMARY_FIELDS`); also written to
        ``root/summary.csv`` and ``root/index.html``.
    """
    sets = find_data_sets(root)
    if not sets:
        raise ModelError(f"batch: no data set under '{root}' (a folder with model.toml and measured/*.csv, "
                         f"as 'mutext rig hide' writes)")
    check_jobs(jobs)
    rows = list(run_parallel(_one, [(str(d), out_name, mbi) for d in sets], jobs=jobs, progress=progress,
                             describe=lambda k, n, row: f"data set {k}/{n}: {Path(row['data_set']).name} "
                                                        f"{row['status']}"))
    _write_summary(Path(root), rows, out_name)
    return rows


def _write_summary(root: Path, rows: list, out_name: str):
    with open(root / "summary.csv", "w", newline="", encoding="utf-8") as fh:
        w = csv.DictWriter(fh, fieldnames=SUMMARY_FIELDS, extrasaction="ignore")
        w.writeheader()
        for r in rows:
            w.writerow({k: r.get(k, "") for k in SUMMARY_FIELDS})
    e = html.escape
    keyed = [r for r in rows if "found" in r]
    head = (f"<p>{sum(r['status'] == 'ok' for r in rows)} of {len(rows)} data sets diagnosed"
            + (f"; verdict right (kind and place) in {sum(bool(r['found']) for r in keyed)} of {len(keyed)} "
               f"with an answer key" if keyed else "") + ".</p>")
    body = "".join(_row_html(r, root, out_name) for r in rows)
    (root / "index.html").write_text(
        "<!DOCTYPE html><html><head><meta charset=\"utf-8\"><title>mutext diagnose: batch</title></head><body>"
        f"<h1>Diagnoses under {e(str(root))}</h1>{head}<table border=\"1\" cellpadding=\"3\"><tr><th>data set</th>"
        "<th>status</th><th>diagnosis</th><th>effects</th><th>gain</th><th>right</th><th>error</th></tr>"
        f"{body}</table></body></html>\n", encoding="utf-8")


def _row_html(r: dict, root: Path, out_name: str) -> str:
    e = html.escape
    name = e(os.path.relpath(r["data_set"], root))
    gain = "" if r.get("gain") is None else f"{r['gain']:.3g}"
    return (f"<tr><td><a href=\"{name}/{e(out_name)}/report.html\">{name}</a></td><td>{e(r['status'])}</td>"
            f"<td>{e(str(r.get('diagnosis', '')))}</td><td>{e(str(r.get('effects', '')))}</td>"
            f"<td>{gain}</td><td>{e(str(r.get('found', '')))}</td><td>{e(r.get('error', ''))}</td></tr>")
