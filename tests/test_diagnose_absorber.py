"""A tuned-mass absorber (an added degree of freedom) hidden in data from the independent generator.

The data come from ``benchmarks/_open_world.py`` (written apart from the package: the absorber is an
extra row and column of its numpy M, C, K, ``with_absorber``).  The diagnosis must name the kind and
the host mass, fit the absorber's mass, spring and damper within three of their reported standard
uncertainties, call the result explained, and write a model file that, loaded by the model reader,
reproduces the generator's noise-free data.
"""
import math
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
from _open_world import make_case, with_absorber  # noqa: E402

from mutext.diagnose import diagnose  # noqa: E402
from mutext.diagnose.faults.absorber import impedance  # noqa: E402
from mutext.rotor.model import load_model  # noqa: E402
from mutext.rotor.tuning import model_response  # noqa: E402

NOISE = 0.01


def _truth(case):
    det = case.key["details"]
    ma = det["value"] if "value" in det else det["size"]
    ka = ma * (2 * np.pi * det["tuned_hz"]) ** 2
    return det["station"], np.array([ma, ka, 2 * det["zeta"] * math.sqrt(ka * ma)])


def test_absorber_impedance_is_the_added_degree_of_freedom_condensed():
    # independent: the 2x2 dynamic stiffness of host + absorber, the absorber's row eliminated
    rng = np.random.default_rng(4)
    ma, ka, ca = 0.3, 2.0e3, 1.5
    w = 2 * np.pi * rng.uniform(0.5, 30, 50)
    M, C, K = with_absorber(np.eye(1), np.zeros((1, 1)), np.zeros((1, 1)), 0, ma, ka, ca)
    Z = K[None] - (w * w)[:, None, None] * M[None] + 1j * w[:, None, None] * C[None]
    schur = Z[:, 0, 0] - Z[:, 0, 1] * Z[:, 1, 0] / Z[:, 1, 1]
    host = 1.0 * -(w * w)                                    # the host's own unit mass
    assert np.allclose(impedance((ma, ka, ca), w), schur - host, rtol=1e-12, atol=0)


@pytest.mark.parametrize("example,seed", [("three_mass", 0),
                                          pytest.param("four_story", 1, marks=pytest.mark.slow)])
def test_a_hidden_absorber_is_found_sized_and_written(example, seed, tmp_path):
    case = make_case(example, "out_of_library", "tuned_absorber", seed, NOISE)
    station, truth = _truth(case)
    d = diagnose(case.model_path, case.measured, validate=case.validate, out_dir=tmp_path)
    assert d.status == "explained" and d.confirmed, d.report()
    assert [(f.kind, f.station) for f in d.effects] == [("absorber", station)], d.report()
    f = d.effects[0]
    for name, v, sd, t in zip(("m_a", "k_a", "c_a"), f.values, f.stds, truth):
        assert abs(v - t) <= 3 * sd, (name, v, sd, t)
        assert sd < 0.2 * t, (name, sd, t)            # a real measurement, not an unbounded one
    report = d.report()
    assert "m_a" in report and "k_a" in report and "c_a" in report
    assert f.as_dict()["parameters"]["k_a"]["unit"] == "N/m"
    # the model file written: the extra mass, its spring and damper; it reproduces the clean data
    ext = load_model(d.extended_model)
    assert ext.layout.n_nodes == load_model(case.model_path).layout.n_nodes + 1
    errs = []
    for frf, clean in zip(case.measured, case.clean):
        H = model_response(ext, frf)
        errs.append(np.abs(np.log(H / clean)))
    rms = float(np.sqrt(np.mean(np.concatenate(errs) ** 2)))
    assert rms < 0.3 * NOISE, rms


@pytest.mark.slow
def test_a_loss_shared_by_every_spring_is_found_as_a_distributed_change(tmp_path):
    """The generator's ``stiffness_loss`` (its K times 1 - d, every spring alike) is the run of all springs
    changed by -d: kind, run and size within three reported standard uncertainties, explained, and the
    written file reproduces the clean data."""
    case = make_case("three_mass", "out_of_library", "stiffness_loss", 0, NOISE)
    d = diagnose(case.model_path, case.measured, validate=case.validate, out_dir=tmp_path)
    assert d.status == "explained" and d.confirmed, d.report()
    assert [(f.kind, f.element) for f in d.effects] == [("distributed_stiffness", "k1..k3")], d.report()
    f = d.effects[0]
    assert abs(f.value - (-case.key["details"]["value"])) <= 3 * f.std, (f.value, f.std)
    ext = load_model(d.extended_model)
    errs = [np.abs(np.log(model_response(ext, frf) / clean)) for frf, clean in zip(case.measured, case.clean)]
    assert float(np.sqrt(np.mean(np.concatenate(errs) ** 2))) < 0.3 * NOISE


@pytest.mark.slow
def test_a_grounded_spring_on_a_pedestal_is_found_sized_and_written(tmp_path):
    """The three-mass rig's spring k3 (m3 to ground) set on a pedestal (mass m_p, spring k_p to ground),
    built with the independent generator's matrices: an added DOF, k3 moved onto it."""
    import _open_world as ow
    path = ow.example_path("three_mass")
    chain = ow.read_chain(path)
    M, C, K = chain.matrices()
    k3 = next(s for s in chain.springs if s["name"] == "k3")
    i = chain.index(k3["between"][0])
    mp, kp = 1.0, 3.0 * k3["value"]
    Mp, Cp, Kp = ow.with_absorber(M, C, K, i, mp, k3["value"], 0.0)     # m_p tied to m3 by k3 ...
    Kp[i, i] -= k3["value"]                                             # ... k3 no longer to ground ...
    Kp[-1, -1] += kp                                                    # ... the pedestal held by k_p
    data = ow._linear(chain, ow._State(Mp, Cp, Kp))
    meas_ch, val_ch = ow.channels(chain)
    f = ow.band_grid(M, K)
    rng = np.random.default_rng(11)
    measured = ow._frfs(chain, data, meas_ch, f, NOISE, rng, "measured")
    validate = ow._frfs(chain, data, val_ch, f + 0.5 * (f[1] - f[0]), NOISE, rng, "validate")
    d = diagnose(path, measured, validate=validate, out_dir=tmp_path)
    assert d.status == "explained" and d.confirmed, d.report()
    assert [(e.kind, e.station, e.element) for e in d.effects] == [("pedestal", i + 1, "k3")], d.report()
    e = d.effects[0]
    for v, sd, t in zip(e.values, e.stds, (mp, kp)):
        assert abs(v - t) <= 3 * sd and sd < 0.2 * t, (v, sd, t)
    ext = load_model(d.extended_model)
    clean = data(meas_ch, f)
    errs = [np.abs(np.log(model_response(ext, frf) / h)) for frf, h in zip(measured, clean)]
    assert float(np.sqrt(np.mean(np.concatenate(errs) ** 2))) < 0.3 * NOISE


@pytest.mark.slow
def test_a_spring_to_ground_split_by_a_mass_is_an_absorber(tmp_path):
    """The generator's wrong model "one more mass" with k3 (m3 to ground) split into 2 k3 - m_x - 2 k3: on the
    model's DOFs exactly an absorber at m3 with m_a = m_x / 4, k_a = k3 and no damper (eliminate m_x)."""
    case = make_case("three_mass", "out_of_library", "wrong_model_extra_mass", 1, NOISE, workdir=tmp_path)
    assert case.key["details"]["split_spring"] == "k3"
    d = diagnose(case.model_path, case.measured, validate=case.validate)
    assert d.status == "explained", d.report()
    assert [(f.kind, f.station) for f in d.effects] == [("absorber", 3)], d.report()
    f = d.effects[0]
    k3 = 386.0                                   # the shipped model's k3 [N/m]
    for v, sd, t in zip(f.values[:2], f.stds[:2], (case.key["details"]["value"] / 4, k3)):
        assert abs(v - t) <= 3 * sd, (v, sd, t)
    assert f.values[2] <= 3 * f.stds[2] + 1e-3   # no damper
