"""The diagnosis's receptance of a rotor from its modes: the pieces asked for, equal to the inverse of the
dynamic stiffness, and a rotor on a finer mesh (59 stations) diagnosed.

The dynamic stiffness is built here from the model's M, C, K and G alone, and inverted with numpy.
"""
from __future__ import annotations

import sys
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

from mutext.diagnose._hypotheses import hypotheses
from mutext.diagnose._screen import _Data, _Evaluator, _Receptance
from mutext.diagnose.faults import structure
from mutext.diagnose.faults._base import local_change
from mutext.rotor import data_path, load_model

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))

#: Between the resonances of the thesis rotor (34, 191-195 Hz), and at or near them.
OFF, AT = (60.0, 100.0, 150.0, 225.0), (20.0, 33.9, 191.1)


@pytest.fixture(scope="module")
def rotor():
    m = load_model(data_path("rotor.toml"))
    M, C, K, G = m.matrices()
    return m, M, K, C + m.speed * G


def _Z(M, K, D, f):
    w = 2 * np.pi * f
    return K - w * w * M + 1j * w * D


def test_the_receptance_pieces_equal_the_inverse_of_the_dynamic_stiffness(rotor):
    m, M, K, D = rotor
    n = M.shape[0]
    f = np.array(OFF + AT)
    rec = _Receptance(m, None, m.speed, 2 * np.pi * f)
    assert rec.modal is not None and rec._R is None         # no (nfreq, n, n) array is held
    idx = np.arange(f.size)
    b = rec.input_vector(("port", m.input_names.index("i12")))
    o = m.layout.dof(13, "u")
    U = [m.layout.dof(15, d) for d in ("u", "v")] + [m.layout.dof(16, "u")]
    Rb, Ro, RUU = rec.apply(idx, b), rec.row(idx, o), rec.block(idx, U, U)
    whole = rec.R                                          # formed from the modes when asked for
    for k, fk in enumerate(f):
        Z = _Z(M, K, D, fk)
        R = np.linalg.inv(Z)
        # backward error of a direct solve, at every frequency
        assert np.linalg.norm(Z @ whole[k] - np.eye(n)) <= 1e-15 * np.linalg.norm(Z) * np.linalg.norm(whole[k])
        # the pieces are the entries of that one receptance
        np.testing.assert_allclose(Rb[k], whole[k] @ b, rtol=1e-12, atol=1e-12 * np.abs(Rb[k]).max())
        np.testing.assert_allclose(Ro[k], whole[k][o], rtol=0, atol=1e-12 * np.abs(Ro[k]).max())
        np.testing.assert_allclose(RUU[k], whole[k][np.ix_(U, U)], rtol=0, atol=1e-12 * np.abs(RUU[k]).max())
        # equal to the inverse: to 1e-10 between the resonances; near a resonance the inverse itself is known
        # only to its condition number times eps (8e8 at 20 Hz, 2.6e10 at 33.9 Hz): to 1 % of that
        err = np.linalg.norm(whole[k] - R) / np.linalg.norm(R)
        tol = 1e-10 if fk in OFF else 1e-2 * np.linalg.cond(Z) * np.finfo(float).eps
        assert err <= tol, (fk, err)
        for piece, ref in ((Rb[k], R @ b), (Ro[k], R[o]), (RUU[k], R[np.ix_(U, U)])):
            assert np.linalg.norm(piece - ref) <= tol * np.linalg.norm(ref)


def test_a_lumped_chain_keeps_its_inverse():
    m = load_model(data_path("three_mass.toml"))
    f = np.linspace(0.5, 8.0, 7)
    rec = _Receptance(m, None, 0.0, 2 * np.pi * f)
    assert rec.modal is None
    M, C, K, _ = m.matrices()
    for k, fk in enumerate(f):
        np.testing.assert_array_equal(rec.R[k], np.linalg.inv(_Z(M, K, C, fk)))


def test_hypotheses_on_the_modal_receptance_equal_a_direct_solve(rotor):
    """Every local kind (Woodbury on its DOFs) and the structure-wide ones (the damping scaled, the
    frequency axis off; with a local effect too) against a solve of the changed dynamic stiffness."""
    m, M, K, D = rotor
    f = np.concatenate([np.linspace(25.0, 45.0, 11), np.linspace(180.0, 210.0, 11)])
    w = 2 * np.pi * f
    rec = _Receptance(m, None, m.speed, w)
    b = rec.input_vector(("port", m.input_names.index("i12")))
    o = m.layout.dof(13, "u")
    idx = np.arange(f.size)
    H0 = rec.apply(idx, b)[:, o]
    data = _Data([SimpleNamespace(out_dof=o, frf=None)], [idx], [H0], [H0], [b], [f])
    hs = hypotheses(m)
    picks = [next(h for h in hs if h.kind == k) for k in ("bearing", "stiffness", "mass", "damping", "crack")]

    def solve(hyps, thetas, a=0.0, eps=0.0):
        ws = w * (1 + eps)
        Z = K[None] - (ws * ws)[:, None, None] * M[None] + 1j * ws[:, None, None] * ((1 + a) * D)[None]
        for h, t in zip(hyps, thetas):
            U = np.asarray(h.dofs)
            Z[:, U[:, None], U[None, :]] += local_change(h, t, ws)
        return np.linalg.solve(Z, np.broadcast_to(b.astype(complex), (w.size, b.size))[:, :, None])[:, o, 0]

    for h in picks:
        t = 0.3 if h.kind == "crack" else 0.5 * h.scale
        H = _Evaluator(rec, data, h).responses(t)[0]
        ref = solve([h], [t])
        assert np.max(np.abs(H - ref) / np.abs(ref)) < 1e-7, h.label
    damp, freq = structure.candidates(m)
    for extra in ([], [picks[1]]):
        th = [0.5 * h.scale for h in extra]
        H = structure.responses(rec, data, [damp] + extra, [0.4] + th)[0]
        assert np.max(np.abs(H / solve(extra, th, a=0.4) - 1)) < 1e-7
        H = structure.responses(rec, data, [freq] + extra, [0.003] + th)[0]
        assert np.max(np.abs(H / solve(extra, th, eps=0.003) - 1)) < 1e-7


def test_the_refined_mesh_keeps_the_rotor(tmp_path):
    """The benchmark's finer mesh: r = 1 is the shipped rotor; r = 2 (59 stations) has its modes."""
    from bench_diagnose_scaling import refined_rotor
    a = load_model(data_path("rotor.toml"))
    b = load_model(refined_rotor(tmp_path / "r1", 1))
    for x, y in zip(a.matrices(), b.matrices()):
        np.testing.assert_array_equal(x, y)
    assert sorted(a.output_names) == sorted(b.output_names) and a.input_names == b.input_names
    c = load_model(refined_rotor(tmp_path / "r2", 2))
    assert c.layout.n_nodes == 59
    np.testing.assert_allclose(c.natural_frequencies(n=4), a.natural_frequencies(n=4), rtol=1e-5)


@pytest.mark.slow
def test_a_crack_is_found_on_the_59_station_rotor(tmp_path):
    # about a minute of CPU (benchmarks/bench_diagnose_scaling.py times the diagnosis)
    from bench_diagnose_scaling import refined_rotor

    from mutext.diagnose import diagnose
    from mutext.hide import hidden_effect_data
    case = hidden_effect_data(refined_rotor(tmp_path / "model", 2), seed=4, kind="crack", noise=0.01,
                              out_dir=tmp_path / "case")
    d = diagnose(case.files["model"], case.files["measured"], validate=case.files["validate"], refit=0)
    assert (d.verdict.kind, d.verdict.station) == (case.key["kind"], case.key["station"])
    assert d.verdict.value == pytest.approx(case.key["value"], abs=3 * d.verdict.std + 0.01)
