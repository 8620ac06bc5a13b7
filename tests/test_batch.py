"""Many data sets at once: rig hide --count, diagnose --batch, a failing set reported, Dask through joblib."""
import csv
import json

import pytest

from mutext.batch import diagnose_batch, find_data_sets
from mutext.cli import main
from mutext.errors import ModelError


@pytest.fixture(scope="module")
def cases(tmp_path_factory):
    root = tmp_path_factory.mktemp("class")
    # three sets: two diagnosed by two worker processes, one broken below
    assert main(["rig", "hide", "--seed", "10", "--count", "3", "--out", str(root)]) == 0
    return root


def test_batch_diagnoses_every_set_and_reports_a_broken_one(cases, capsys):
    (cases / "case_12" / "measured" / "in1_out1.csv").write_text("not an FRF file\n")
    capsys.readouterr()
    assert main(["diagnose", "--batch", str(cases), "--jobs", "2", "--quiet"]) == 0
    out = capsys.readouterr().out
    assert "2 of 3 diagnosed, 1 failed; right in 2 of 2 with an answer key" in out
    rows = list(csv.DictReader(open(cases / "summary.csv", encoding="utf-8")))
    assert [r["status"] for r in rows] == ["ok", "ok", "failed"]
    bad = rows[2]
    assert "case_12/measured/in1_out1.csv" in bad["error"] and "FRFFileError" in bad["error"]
    for r in rows:
        if r["status"] == "ok":
            assert r["found"] == "True"
            rep = json.loads(open(f"{r['data_set']}/diagnosis/diagnosis.json", encoding="utf-8").read())
            assert rep["verdict"]["kind"] == r["kind"]
    index = (cases / "index.html").read_text()
    assert "report.html" in index
    for r in rows:
        if r["status"] == "ok":
            # the effect is named by its element (two kinds at one station read apart), never "none at None"
            assert " at None" not in r["effects"]
            if r["kind"] != "none":
                key = json.loads(open(f"{r['data_set']}/answer_key.json", encoding="utf-8").read())
                assert r["what"] in r["effects"] and r["what"] != r["kind"], (r, key)
            assert r["effects"] in index.replace("&#x27;", "'").replace("&quot;", '"')


def test_batch_errors_are_named(tmp_path, cases):
    with pytest.raises(ModelError, match="no data set under"):
        diagnose_batch(tmp_path)
    with pytest.raises(ModelError, match="not a directory"):
        find_data_sets(tmp_path / "nope")
    with pytest.raises(ModelError, match="jobs"):
        diagnose_batch(cases, jobs=0)
    assert main(["diagnose", "--batch", str(cases), "model.toml"]) == 2     # a usage error


@pytest.mark.slow
def test_batch_runs_on_a_local_dask_cluster(tmp_path):
    distributed = pytest.importorskip("distributed")
    import joblib
    assert main(["rig", "hide", "--seed", "20", "--count", "3", "--out", str(tmp_path)]) == 0
    with distributed.Client(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None):
        with joblib.parallel_backend("dask"):
            rows = diagnose_batch(tmp_path, jobs=-1)
    assert [r["status"] for r in rows] == ["ok"] * 3
    assert all(r["found"] for r in rows)


@pytest.mark.slow
def test_batch_on_a_running_dask_scheduler_from_the_command_line(tmp_path, capsys):
    distributed = pytest.importorskip("distributed")
    assert main(["rig", "hide", "--seed", "30", "--count", "2", "--out", str(tmp_path)]) == 0
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1",
                                  dashboard_address=None) as cluster:
        address = cluster.scheduler_address
        assert address.startswith("tcp://127.0.0.1:")
        capsys.readouterr()
        assert main(["diagnose", "--batch", str(tmp_path), "--scheduler", address]) == 0
    out = capsys.readouterr()
    assert f"Dask: scheduler {address}, 2 worker(s)" in out.err
    rows = list(csv.DictReader(open(tmp_path / "summary.csv", encoding="utf-8")))
    assert [r["status"] for r in rows] == ["ok", "ok"] and all(r["found"] == "True" for r in rows)


def test_scheduler_errors_are_named(tmp_path, capsys):
    # a usage mistake, and a scheduler that cannot be reached (or Dask not installed): named, no traceback
    assert main(["diagnose", "m.toml", "d.csv", "--scheduler", "local"]) == 2
    assert "--scheduler are for --batch" in capsys.readouterr().err
    assert main(["rig", "hide", "--seed", "31", "--out", str(tmp_path / "c")]) == 0
    capsys.readouterr()
    assert main(["diagnose", "--batch", str(tmp_path), "--scheduler", "tcp://127.0.0.1:9", "--quiet"]) == 1
    err = capsys.readouterr().err
    assert ("cannot reach the Dask scheduler" in err or "needs Dask's distributed" in err) and "Traceback" not in err
