"""What no hypothesis names: the identified controller K(s) becomes an element of the extended model.

The slow test hides in the three-mass chain a two-stage absorber at m3 (two masses in series, each on its own
spring and damper: two resonances of its own, which the one-resonance absorber hypothesis cannot hold). The
"measured" responses come from plain numpy mass, stiffness and damping matrices of the five-mass system, and
the impedance the absorber puts on m3 is computed here by eliminating its two masses (a Schur complement), so
every reference in the checks is independent of the package's fault and model code.

The fast tests check the realisation of a controller on its own: a known rational K is written with the
coefficients it has, a K that is a mass, damper and spring is written as one, and the exact held-out update
(Sherman-Morrison on the receptance) equals a direct solve with the element.
"""
from __future__ import annotations

import math
import os
import tomllib
from types import SimpleNamespace

import control as ct
import numpy as np
import pytest

from mutext.diagnose import HOLDOUT_EVERY, diagnose
from mutext.diagnose._extend import element_model_text, element_response, realise_controller
from mutext.mbi import fit_impedance, mbi_plant, relative_error
from mutext.report import mbi_lines, write_diagnosis
from mutext.response import FRF
from mutext.rotor import data_path
from mutext.rotor.model import loads_model

THREE_MASS = data_path("three_mass.toml")
# the chain of the model file (Table 3.1), written out again here
MASSES = [2.8113, 2.6396, 2.6074]
K1, K2, K3 = 842.3, 806.5, 386.0
DAMPERS = [5.2992, 1.9467, 10.7375]
# the hidden two-stage absorber at m3: masses [kg], tuning frequencies [Hz], dampers [N s/m]
MA = (0.25, 0.15)
FA = (2.2, 3.8)
CA = (0.6, 0.4)


def _chain_matrices(absorber: bool = True):
    """M, K, C of the chain (3 DOFs) or of the chain with the absorber (5 DOFs), by hand."""
    n = 5 if absorber else 3
    M = np.zeros((n, n))
    K = np.zeros((n, n))
    C = np.zeros((n, n))
    M[:3, :3] = np.diag(MASSES)

    def link(X, i, j, v):
        X[i, i] += v
        if j is not None:
            X[j, j] += v
            X[i, j] -= v
            X[j, i] -= v
    link(K, 0, 1, K1)
    link(K, 1, 2, K2)
    link(K, 2, None, K3)
    for i, c in enumerate(DAMPERS):
        link(C, i, None, c)
    if absorber:
        for a, (ma, fa, ca) in enumerate(zip(MA, FA, CA)):
            M[3 + a, 3 + a] = ma
            link(K, 2 + a, 3 + a, ma * (2 * np.pi * fa) ** 2)
            link(C, 2 + a, 3 + a, ca)
    return M, K, C


def absorber_impedance(omega) -> np.ndarray:
    """The dynamic stiffness the absorber adds at m3: its two masses eliminated (Schur complement)."""
    M, K, C = _chain_matrices(True)
    out = []
    for w in np.asarray(omega, float):
        Z = K - w * w * M + 1j * w * C
        base = (K3 - w * w * MASSES[2] + 1j * w * DAMPERS[2]) + K2       # m3's own diagonal term
        out.append(Z[2, 2] - base - Z[2, 3:] @ np.linalg.solve(Z[3:, 3:], Z[3:, 2]))
    return np.array(out)


def _measured(f, noise, seed):
    M, K, C = _chain_matrices(True)
    w = 2 * np.pi * f
    H = np.array([np.linalg.inv(K - x * x * M + 1j * x * C)[:3, :3] for x in w])
    rng = np.random.default_rng(seed)
    out = []
    for i, o in ((1, 1), (1, 3), (3, 3)):
        e = noise * (rng.standard_normal(f.size) + 1j * rng.standard_normal(f.size)) / math.sqrt(2)
        out.append(FRF(f, H[:, o - 1, i - 1] * (1 + e), input_station=i, output_station=o))
    return out


def _rel(H, meas):
    return float(np.sqrt(np.mean(np.concatenate([np.abs(h - m) ** 2 / np.abs(m) ** 2 for h, m in zip(H, meas)]))))


@pytest.mark.slow
def test_an_absorber_no_hypothesis_names_becomes_an_element_at_its_mass(tmp_path):
    f = np.linspace(0.3, 7.0, 300)
    data = _measured(f, noise=0.005, seed=1)
    d = diagnose(THREE_MASS, data, mbi=True, out_dir=tmp_path)
    assert d.status != "explained"
    assert d.localized["station"] == 3
    m = d.mbi
    assert m["location"] == "m3" and m["element"] is not None, d.report()
    el = m["element"]
    # the file written holds the element at m3
    path = m["extended_model"]
    assert os.path.basename(path) in ("model_extended.toml", "model_extended_mbi_NOT_CONFIRMED.toml")
    assert (os.path.basename(path) == "model_extended.toml") == (m["status"] == "explained")
    with open(path, "rb") as fh:
        doc = tomllib.load(fh)
    if el["kind"] == "impedance":
        (tbl,) = doc["impedance"]
        assert tbl["mass"] == "m3"
        num, den = np.array(tbl["numerator"]), np.array(tbl["denominator"])
        z_of = lambda w: np.polyval(num, 1j * w) / np.polyval(den, 1j * w)     # noqa: E731
    else:
        springs = [t for t in doc["spring"] if t["name"].startswith("k_mbi")]
        assert springs and springs[0]["between"] == ["m3", "ground"]
        z_of = lambda w: element_response(el, w)                                # noqa: E731

    # held-out lines (as the diagnosis holds them out): the extended model's error, computed here from the
    # numpy matrices of the chain with the written element's K(jw) on m3, is below the base model's
    keep = np.arange(f.size) % HOLDOUT_EVERY == HOLDOUT_EVERY // 2
    M, K, C = _chain_matrices(False)
    meas, base, ext = [], [], []
    for w, k in zip(2 * np.pi * f[keep], np.flatnonzero(keep)):
        Z = K - w * w * M + 1j * w * C
        Ze = Z.copy()
        Ze[2, 2] += z_of(np.array([w]))[0]
        R, Re = np.linalg.inv(Z), np.linalg.inv(Ze)
        for c, frf in enumerate(data):
            i, o = frf.input_station - 1, frf.output_station - 1
            meas.append(frf.response[k])
            base.append(R[o, i])
            ext.append(Re[o, i])
    e0, e1 = _rel([np.array(base)], [np.array(meas)]), _rel([np.array(ext)], [np.array(meas)])
    assert e1 < e0 / 3, (e0, e1)
    assert m["held_out_gain"] == pytest.approx(e0 / e1, rel=1e-6)

    # K against the impedance the absorber really adds (analytic), on the identifiable band, each frequency
    # weighted by how much it moves the measured output: within 8 %; and no worse than the impedance the
    # noisy data require frequency by frequency (mutext.mbi.required_impedance), which K smooths
    imp = m["impedance"]
    fz = np.array(imp["freq_hz"])
    wz = 2 * np.pi * fz
    band = np.array(imp["band"])
    sens = np.array(imp["sensitivity"])
    Kj = np.array([complex(*x) for x in imp["K"]])
    D = np.array([complex(*x) for x in imp["required"]])
    Zt = absorber_impedance(wz)
    assert band.sum() >= 0.5 * band.size
    err_k = relative_error(Kj[band], Zt[band], wz[band], weight=sens[band])
    err_d = relative_error(D[band], Zt[band], wz[band], weight=sens[band])
    assert err_k < 0.08, err_k
    assert err_k < err_d
    assert imp["band_error"] < 0.25
    # the realised element is K: its response equals the controller's on the data's frequencies
    assert relative_error(z_of(wz), Kj, wz, weight=sens) < 0.02
    # the report shows K beside the required impedance
    write_diagnosis(d, tmp_path)
    with open(tmp_path / "report.html", encoding="utf-8") as fh:
        page = fh.read()
    assert "mbi_impedance.png" in page and os.path.exists(tmp_path / "mbi_impedance.png")
    lines = "\n".join(mbi_lines(d))
    assert "held-out gain" in lines and f"{m['held_out_gain']:.3g}x" in lines and "required" in lines


# ---------------------------------------------------------------------------
# fast: the realisation of a controller on its own
# ---------------------------------------------------------------------------

def _engineering():
    text = open(THREE_MASS, encoding="utf-8").read() + ('\n[[force]]\nname = "u_mbi"\nmass = "m3"\n'
                                                        '[[sensor]]\nname = "y_mbi"\nmass = "m3"\n')
    return loads_model(text).state_space(inputs=["f1", "u_mbi"], outputs=["x1", "y_mbi"])


def _result_for(K):
    """What realise_controller reads of an identification result, for a given controller K."""
    E = _engineering()
    true = ct.ss(E.A, E.B[:, :1], E.C[:1], E.D[:1, :1], inputs=["f1"], outputs=["x1"])
    plant = mbi_plant(true, E, excitation="f1", measurement="x1", control_input="u_mbi", control_output="y_mbi",
                      Wz=1e-6)
    omega = 2 * np.pi * np.linspace(0.3, 7.0, 120)
    return SimpleNamespace(K=ct.ss(K), fit=fit_impedance(K, omega), omega=omega, plant=plant)


def test_a_rational_controller_is_written_with_its_own_coefficients():
    num, den = [30.0, 30.0, 3000.0], [1.0, 3.0, 400.0]          # a resonance of its own at 20 rad/s
    el = realise_controller(_result_for(ct.tf(num, den)), host_mass=MASSES[2])
    assert el["kind"] == "impedance" and el["order"] == 2
    np.testing.assert_allclose(el["numerator"], num, rtol=1e-6)
    np.testing.assert_allclose(el["denominator"], den, rtol=1e-6)


def test_a_controller_that_is_a_mass_damper_and_spring_is_written_as_one():
    # K = (dk + dc s - dm s^2 ...) rolled off far above the band: the reading is a mass, damper and spring
    dm, dc, dk = 0.05, 0.8, 40.0
    K = ct.tf([dm, dc, dk], [1 / 1e4 ** 2, 2 * 0.7 / 1e4, 1.0])
    el = realise_controller(_result_for(K), host_mass=MASSES[2])
    assert el["kind"] == "mass-damper-spring"
    assert el["dm"] == pytest.approx(dm, rel=0.02) and el["dc"] == pytest.approx(dc, rel=0.02)
    assert el["dk"] == pytest.approx(dk, rel=0.02)
    text = element_model_text(open(THREE_MASS, encoding="utf-8").read(), el, "m3", MASSES[2], "test")
    model = loads_model(text)
    assert model.parameter("m3").value == pytest.approx(MASSES[2] + el["dm"], rel=1e-12)
    assert model.parameter("k_mbi_m3").value == el["dk"] and model.parameter("c_mbi_m3").value == el["dc"]
    # the model file's response is the base chain's with dk + j w dc - w^2 dm on m3 (numpy, by hand)
    M, Kc, C = _chain_matrices(False)
    f = np.array([0.7, 2.0, 4.5])
    H = model.frf(f, inputs=["f1"], outputs=["x3"]).H[0, 0]
    for w, h in zip(2 * np.pi * f, H):
        Z = Kc - w * w * M + 1j * w * C
        Z[2, 2] += el["dk"] + 1j * w * el["dc"] - w * w * el["dm"]
        assert h == pytest.approx(np.linalg.inv(Z)[2, 0], rel=1e-9)


def test_a_mass_damper_spring_with_a_negative_spring_is_not_physical():
    K = ct.tf([0.05, 0.8, -40.0], [1 / 1e4 ** 2, 2 * 0.7 / 1e4, 1.0])
    el = realise_controller(_result_for(K), host_mass=MASSES[2])
    assert el["kind"] == "impedance"
