"""Tuning model parameters to measured FRFs (IPOPT through CasADi) and FRF sensitivities."""
import os

import casadi as ca
import numpy as np
import pytest

from mutext.errors import ModelError, SolverError
from mutext.rig import FRF, measure, read_frfs, sweep_frequencies, write_frf
from mutext.rotor import data_path, load_model, loads_model
from mutext.rotor import units as U
from mutext.rotor.tuning import frf_sensitivity, model_response, select_points, tune

F = sweep_frequencies()          # thesis band 20-225 Hz, 0.5 Hz steps (411 points)
CHANNELS = ((13, "x13"), (24, "x24"))


@pytest.fixture(scope="module")
def rotor():
    return load_model(data_path("rotor.toml"))


@pytest.fixture(scope="module")
def cracked():
    text = open(data_path("rotor.toml")).read() + "\n[[crack]]\nstation = 15\ndepth_ratio = 0.4\n"
    return loads_model(text, source="cracked rotor", base_dir=os.path.dirname(data_path("rotor.toml")))


def rig_frfs(model, values=None, noise=None, seed=0, channels=CHANNELS, freqs=F):
    """Virtual sweeps i12 -> x<s> of ``model`` at ``values`` (exciter current in, displacement out)."""
    H = model.frf(freqs, inputs=["i12"], outputs=[name for _, name in channels], values=values).H
    return [measure(lambda w, k=k: H[k, 0], 0, 0, freqs, noise=noise, rng=seed + k, input_station=12,
                    output_station=s, input_quantity="current")
            for k, (s, _) in enumerate(channels)]


# ----------------------------------------------------------------------------
# sensitivities
# ----------------------------------------------------------------------------

def test_sensitivity_equals_casadi_algorithmic_derivative():
    """Adjoint formula == automatic differentiation through a symbolic CasADi solve (no modal damping)."""
    m = load_model(data_path("three_mass.toml"))
    pars = ["m1", "k2", "c3", "k1"]
    f = np.array([0.7, 1.3, 2.2, 3.5, 6.0])
    S = frf_sensitivity(m, f, pars, inputs=["f1"], outputs=["x1", "x3"])
    p = ca.MX.sym("p", len(m.parameter_names))
    w = ca.MX.sym("w")
    Mx, Cx, Kx, Bx = (m.functions[k](p) for k in "MCKB")
    A = Kx - w**2 * Mx
    big = ca.blockcat([[A, -w * Cx], [w * Cx, A]])
    n = m.ndof
    x = ca.solve(big, ca.vertcat(Bx[:, 0], ca.MX(n, 1)))
    d = [m.output_dofs[m.output_names.index(o)] for o in ("x1", "x3")]
    h = ca.vertcat(*[x[i] for i in d], *[x[n + i] for i in d])
    fun = ca.Function("h", [p, w], [h, ca.jacobian(h, p)])
    idx = [m.parameter_names.index(q) for q in pars]
    for k, fk in enumerate(f):
        hv, J = (np.asarray(a.full()) for a in fun(m.nominal, 2 * np.pi * fk))
        Hc = hv[:2, 0] + 1j * hv[2:, 0]
        assert np.allclose(S.H[:, 0, k], Hc, rtol=1e-12)
        dH = J[:2][:, idx] + 1j * J[2:][:, idx]              # (outputs, parameters)
        assert np.allclose(S.dH[:, :, 0, k].T, dH, rtol=1e-9, atol=1e-12 * np.abs(dH).max())


def test_sensitivity_with_modal_damping_matches_finite_differences(rotor):
    pars = ["rho", "bearing2.k", "disk16.m", "exciter12.ki", "shaft15.do"]
    f = np.linspace(25.0, 220.0, 40)
    S = frf_sensitivity(rotor, f, pars, inputs=["i12", "F15"], outputs=["x13", "y13"])
    H0 = rotor.frf(f, inputs=["i12", "F15"], outputs=["x13", "y13"]).H
    assert np.allclose(S.H, H0, rtol=1e-10)
    v0 = rotor.values()

    def central(i, rel):
        h = rel * abs(v0[i])
        vp, vm = v0.copy(), v0.copy()
        vp[i] += h
        vm[i] -= h
        return (rotor.frf(f, inputs=["i12", "F15"], outputs=["x13", "y13"], values=vp).H
                - rotor.frf(f, inputs=["i12", "F15"], outputs=["x13", "y13"], values=vm).H) / (2 * h)

    for j, name in enumerate(pars):
        i = rotor.parameter_names.index(name)
        # Richardson-extrapolated central differences, O(h^4): a 0.1 % step moves a 1 %-damped
        # resonance by a tenth of its half-power width, too far for plain central differences,
        # and smaller steps drown in round-off
        fd = (4 * central(i, 1e-3) - central(i, 2e-3)) / 3
        err = np.linalg.norm(S.dH[j] - fd) / np.linalg.norm(fd)
        assert err < 2e-5, (name, err)
    # relative sensitivities: d ln H / d ln ki = 1 exactly (the exciter constant is a pure gain on i12)
    rel = S.relative()
    assert np.allclose(rel[pars.index("exciter12.ki"), :, 0], 1.0, atol=1e-9)
    assert np.allclose(rel[pars.index("exciter12.ki"), :, 1], 0.0, atol=1e-9)
    assert np.array_equal(S("x13", "i12", "rho"), S.dH[0, 0, 0])
    with pytest.raises(ModelError, match="parameters"):
        S("x13", "i12", "E")


def test_model_response_uses_the_channel_of_the_frf(rotor):
    frf = rig_frfs(rotor)[1]
    H = model_response(rotor, frf)
    assert np.allclose(H, frf.response, rtol=1e-10)
    assert np.allclose(model_response(rotor, frf, freq_hz=[50.0]),
                       rotor.frf([50.0], inputs=["i12"], outputs=["x24"]).H[0, 0], rtol=1e-10)


# ----------------------------------------------------------------------------
# fits
# ----------------------------------------------------------------------------

# slow (8 CPU-s): tune() on sweeps in the default run: the crack depth ratio and the thesis hand tuning
@pytest.mark.slow
def test_recovers_bearing_stiffness_and_density_with_consistent_uncertainty(rotor):
    k0, rho0 = rotor.parameter("bearing2.k").value, rotor.parameter("rho").value
    truth = {"bearing2.k": 1.3 * k0, "bearing29.k": 1.3 * k0, "rho": 0.97 * rho0}
    true = {"bearing2.k+bearing29.k": 1.3 * k0, "rho": 0.97 * rho0}
    pars = [("bearing2.k", "bearing29.k"), "rho"]
    fits = {}
    for noise in (0.01, 0.002):
        frfs = rig_frfs(rotor, truth, noise=noise, seed=11)
        res = tune(rotor, frfs, pars, max_points=120)
        fits[noise] = res
        assert res.status in ("Solve_Succeeded", "Solved_To_Acceptable_Level")
        for k, v in true.items():
            assert abs(res.values[k] - v) < 3 * res.std[k], (noise, k, res.values[k], v, res.std[k])
            assert abs(res.values[k] / v - 1) < 0.02
        # circular complex noise of relative size s gives log residuals of std s / sqrt(2)
        assert res.sigma == pytest.approx(noise / np.sqrt(2), rel=0.15)
        assert res.residual_rms_db < res.start_rms_db / 10
        assert np.allclose(np.diag(res.correlation), 1.0) and np.allclose(res.correlation, res.correlation.T)
        assert res.member_values["bearing29.k"] == pytest.approx(res.values["bearing2.k+bearing29.k"])
    # five times less noise: five times smaller uncertainty
    for k in true:
        assert fits[0.002].std[k] / fits[0.01].std[k] == pytest.approx(0.2, rel=0.2)


# slow (5 CPU-s): tune() on sweeps stays in the default run with the thesis hand tuning and the unit checks
@pytest.mark.slow
def test_recovers_crack_depth_ratio(cracked):
    frfs = rig_frfs(cracked, noise=0.005, seed=3)
    res = tune(cracked, frfs, ["crack15.depth_ratio"], start={"crack15.depth_ratio": 0.2}, max_points=120)
    d = res.values["crack15.depth_ratio"]
    assert res.start["crack15.depth_ratio"] == 0.2
    assert res.bounds["crack15.depth_ratio"] == (0.0, 0.5)
    assert abs(d - 0.4) < 3 * res.std["crack15.depth_ratio"]
    assert abs(d - 0.4) < 0.004


def test_reproduces_thesis_hand_tuning(rotor):
    """Density and disk weight of the healthy table, fitted to the cracked-table model's sweep."""
    tuned = load_model(data_path("rotor.toml"), station_table=data_path("rotor_cracked.txt"))
    frfs = rig_frfs(tuned, channels=((13, "x13"),))
    res = tune(rotor, frfs, ["rho", "disk16.m"], max_points=100)
    rho_lb_in3 = res.values["rho"] / U.to_si(1.0, "density", "inch-pound")
    disk_lb = res.values["disk16.m"] / U.POUND_MASS
    assert res.start["rho"] / U.to_si(1.0, "density", "inch-pound") == pytest.approx(0.30)
    assert rho_lb_in3 == pytest.approx(0.29, rel=1e-6)
    assert disk_lb == pytest.approx(5.21, rel=1e-6)
    assert res.residual_rms_db < 1e-4 and res.residual_rms_deg < 1e-3
    assert res.iterations < 30


def test_fit_from_frf_files_in_other_units(rotor, tmp_path):
    frfs = rig_frfs(rotor, {"exciter12.ki": 46.0}, noise=0.003, seed=2)
    paths = []
    for k, frf in enumerate(frfs):
        frf.speed_hz = 10.0                   # the thesis sweeps ran at 600 rpm, as the model
        paths.append(write_frf(tmp_path / f"ch{k}.frf", frf, output_unit="um"))
    read = read_frfs(str(tmp_path / "ch*.frf"))
    res = tune(data_path("rotor.toml"), read, ["exciter12.ki"], max_points=60)
    assert res.values["exciter12.ki"] == pytest.approx(46.0, rel=3e-3)
    assert abs(res.values["exciter12.ki"] - 46.0) < 3 * res.std["exciter12.ki"]
    assert res.units["exciter12.ki"] == "N/A"


def test_verbose_prints_and_progress_reports_every_iteration(rotor, capsys):
    frfs = rig_frfs(rotor, {"rho": 8100.0}, channels=((13, "x13"),))
    calls = []
    res = tune(rotor, frfs, ["rho"], max_points=40, verbose=True,
               progress=lambda stage, frac: calls.append((stage, frac)))
    out = capsys.readouterr().out
    lines = [ln for ln in out.splitlines() if ln.strip().startswith("iter")]
    assert len(lines) == res.iterations + 1 == len(res.history)
    # the same lines through the progress callback, then the end at fraction 1
    assert [stage for stage, _ in calls[:-1]] == [f"tune: {ln.strip()}" for ln in lines]
    assert calls[-1][1] == 1.0 and all(0.0 <= frac < 1.0 for _, frac in calls[:-1])
    assert "objective" in lines[0] and "rho=" in lines[0]
    assert res.history[-1] < 1e-10 * res.history[0]
    assert "rho" in str(res) and "IPOPT" in str(res)


def test_solver_failure_raises_solver_error_with_ipopt_status(rotor):
    frfs = rig_frfs(rotor, {"rho": 8100.0}, channels=((13, "x13"),))
    with pytest.raises(SolverError, match="Maximum_Iterations_Exceeded"):
        tune(rotor, frfs, ["rho"], max_points=40, max_iter=1)


def test_select_points_keeps_resonances(rotor):
    frf = rig_frfs(rotor, channels=((13, "x13"),))[0]
    idx = select_points(frf.freq_hz, frf.response, 80)
    assert 40 <= idx.size <= 100 and np.all(np.diff(idx) > 0)
    peak = int(np.argmax(np.abs(frf.response)))
    assert peak in idx
    assert np.array_equal(select_points(frf.freq_hz, frf.response, 1000), np.arange(frf.freq_hz.size))


# ----------------------------------------------------------------------------
# bad input
# ----------------------------------------------------------------------------

def test_bad_inputs(rotor):
    frfs = rig_frfs(rotor, channels=((13, "x13"),))
    with pytest.raises(ModelError, match="unknown parameter 'density'") as exc:
        tune(rotor, frfs, ["density"])
    assert "Valid parameter names" in str(exc.value) and "bearing29.k" in str(exc.value)
    bad = FRF(F, frfs[0].response, input_station=12, output_station=31, input_quantity="current")
    with pytest.raises(ModelError, match=r"output station 31 is not in the model.*1\.\.30"):
        tune(rotor, [bad], ["rho"])
    nostation = FRF(F, frfs[0].response, input_quantity="current")
    with pytest.raises(ModelError, match="input_station is not set"):
        tune(rotor, [nostation], ["rho"])
    wrong_exciter = FRF(F, frfs[0].response, input_station=15, output_station=13, input_quantity="current")
    with pytest.raises(ModelError, match="no exciter there.*i12"):
        tune(rotor, [wrong_exciter], ["rho"])
    with pytest.raises(ModelError, match="no frequency inside the fitted band 300-400 Hz"):
        tune(rotor, frfs, ["rho"], band_hz=(300.0, 400.0))
    with pytest.raises(ModelError, match="lo = 9000 > hi = 8000"):
        tune(rotor, frfs, ["rho"], bounds={"rho": (9000.0, 8000.0)})
    with pytest.raises(ModelError, match="outside its bounds"):
        tune(rotor, frfs, ["rho"], bounds={"rho": (9000.0, 10000.0)})
    with pytest.raises(ModelError, match="starts at 0"):
        tune(rotor, frfs, ["bearing2.c"])
    with pytest.raises(ModelError, match="given twice"):
        tune(rotor, frfs, ["rho", ("rho", "E")])
    with pytest.raises(ModelError, match="not fitted"):
        tune(rotor, frfs, ["rho"], bounds={"E": (1e11, 3e11)})
    with pytest.raises(ModelError, match="no FRFs"):
        tune(rotor, [], ["rho"])
    with pytest.raises(ModelError, match="weights"):
        tune(rotor, frfs, ["rho"], weights=[1.0, 2.0])
    with pytest.raises(ModelError, match="unknown parameter"):
        frf_sensitivity(rotor, [50.0], ["rhoo"])


@pytest.mark.slow
def test_full_sweep_three_parameters_and_monte_carlo_uncertainty(rotor):
    """All 411 points of two channels, three parameters; the reported std matches the scatter."""
    k0 = rotor.parameter("bearing2.k").value
    truth = {"bearing2.k": 1.3 * k0, "bearing29.k": 1.3 * k0, "rho": 8050.0, "exciter12.ki": 44.0}
    pars = [("bearing2.k", "bearing29.k"), "rho", "exciter12.ki"]
    est, std = [], []
    for seed in range(8):
        res = tune(rotor, rig_frfs(rotor, truth, noise=0.01, seed=100 + 7 * seed), pars)
        est.append([res.values[k] for k in res.parameters])
        std.append([res.std[k] for k in res.parameters])
    est, std = np.array(est), np.array(std)
    true = np.array([1.3 * k0, 8050.0, 44.0])
    assert np.all(np.abs(est.mean(axis=0) / true - 1) < 0.01)
    ratio = est.std(axis=0, ddof=1) / std.mean(axis=0)
    assert np.all((ratio > 0.4) & (ratio < 2.0)), ratio      # 8 samples: a loose check


def test_tune_with_force_inputs_recovers_a_lumped_spring():
    """Force-input channels (a unit force at a DOF): the derivative of the input column is zero.

    The data come from a plain numpy assembly of the chain (not from the model being tuned)."""
    import tomllib
    from importlib import resources
    from mutext.hide import plain_chain
    from mutext.rig import FRF
    from mutext.rotor.model import load_model
    path = resources.files("mutext") / "data" / "three_mass.toml"
    with open(path, "rb") as fh:
        doc = tomllib.load(fh)
    M, C, K, forces, sensors, _ = plain_chain(doc)
    K = K.copy()
    K[2, 2] += 150.0                       # k3: 386 -> 536 N/m
    f = np.linspace(0.3, 7.0, 200)
    w = 2 * np.pi * f
    frfs = []
    for s in ("x1", "x3"):
        H = np.array([np.linalg.solve(K - wk ** 2 * M + 1j * wk * C, np.eye(3)[:, forces["f1"]])[sensors[s]]
                      for wk in w])
        frfs.append(FRF(f, H, input_station=1, output_station=sensors[s] + 1))
    res = tune(load_model(str(path)), frfs, ["k3"])
    assert res.values["k3"] == pytest.approx(536.0, rel=1e-6)
    assert res.iterations < 30
