"""Model-based identification (thesis ch. 3): plant assembly, the reading of K, and the trials.

The analytic checks close the plant with the known difference D_u (exact for a
spring): the engineering model must then reproduce the true one exactly.  The
trial tests hide a mass, damper and/or spring difference on cart 3 and require
that the identification finds it.
"""
import io

import control as ct
import numpy as np
import pytest

from three_mass_plain import half_gaps

from mutext.errors import IllPosedError, ModelError
from mutext.examples import three_mass as tm
from mutext.lti import freqresp, lft_lower, mck_to_ss
from mutext.mbi import (controlled_engineering, fit_impedance, identify, impedance_response, mbi_plant,
                        relative_error, wz_floor)

W = np.logspace(0, 2, 60)


def _plant(trial, regularization=None, Wz=4e-4, uncertain=False):
    args = tm.mbi_arguments(tm.TRIALS[trial])
    if not uncertain:
        args["true"] = tm.mechanical_model(tm.TRIALS[trial].true)
    return mbi_plant(**args, Wz=Wz, regularization=regularization)


@pytest.mark.parametrize("trial, k", [("1a", 186.0), ("1b", -186.0)])
def test_exact_difference_closes_the_error(trial, k):
    """K = D_u (a spring) makes the nominal error vanish; the sign convention is K = +D_u."""
    pl = _plant(trial)
    K = ct.ss([], [], [], [[k]])
    CL = lft_lower(pl.P, K, 1, 1)
    open_loop = np.abs(freqresp(pl.P, W)[0, 0]).max()
    assert open_loop > 10          # the models do differ (normalised error >> 1)
    assert np.abs(freqresp(CL, W)[0, 0]).max() < 1e-9 * open_loop
    # the wrong sign does not
    CLw = lft_lower(pl.P, ct.ss([], [], [], [[-k]]), 1, 1)
    assert np.abs(freqresp(CLw, W)[0, 0]).max() > 1.0


def test_controlled_engineering_matches_true():
    tr = tm.TRIALS["1a"]
    pl = _plant("1a")
    G = controlled_engineering(pl, ct.ss([], [], [], [[tr.Du["dk"]]]))
    T = tm.mechanical_model(tr.true)
    np.testing.assert_allclose(freqresp(G, W)[0, 0], freqresp(T, W)[0, 0], rtol=1e-9)


def test_plant_structure_and_uncertainty_channels():
    pl = _plant("4", regularization=1e-4, uncertain=True)
    names = [b.name for b in pl.structure.blocks]
    assert names == ["m3", "c3", "k3", "performance"]
    assert pl.structure.blocks[-1].rows == 2            # error and control penalty
    assert pl.P.ninputs == pl.structure.nrows + 1 and pl.P.noutputs == pl.structure.ncols + 1
    assert pl.eps_u > 0 and pl.eps_y > 0
    # closing the true system's uncertainty at a corner equals the rig rebuilt there
    U = tm.true_model(tm.TRIALS["4"])
    d = np.array([1.0, -1.0, 0.5])
    closed = U.close(d)
    rebuilt = U.at(U.values(d))
    np.testing.assert_allclose(freqresp(closed, W), freqresp(rebuilt, W), rtol=1e-8, atol=1e-14)


def test_fit_impedance_recovers_mass_damper_spring():
    rng = np.random.default_rng(3)
    for _ in range(5):
        dm, dc, dk = rng.normal(size=3) * [1.0, 5.0, 200.0]
        Kj = impedance_response({"dm": dm, "dc": dc, "dk": dk}, W)
        f = fit_impedance(Kj, W, weight=rng.uniform(0.1, 10, W.size))
        assert f.fits and f.residual < 1e-10
        np.testing.assert_allclose([f.dm, f.dc, f.dk], [dm, dc, dk], rtol=1e-8)


def test_fit_impedance_says_when_the_form_does_not_fit():
    K = ct.tf([1e4], [1, 0.5, 400])       # a resonance: no mass-damper-spring reading
    f = fit_impedance(K, W)
    assert not f.fits and f.residual > 0.1
    assert "not a mass-damper-spring" in f.description


def test_relative_error():
    K = ct.ss([], [], [], [[186.0 * 1.02]])
    assert relative_error(K, {"dk": 186.0}, W) == pytest.approx(0.02, rel=1e-9)


def test_bad_inputs_get_clear_errors():
    tr = tm.TRIALS["1a"]
    E = tm.mechanical_model(tr.engineering)
    T = tm.mechanical_model(tr.true)
    ports = dict(excitation="f1", measurement="x1", control_input="f3", control_output="x3")
    with pytest.raises(ModelError, match="no input named 'f9'"):
        mbi_plant(T, E, **{**ports, "excitation": "f9"})
    with pytest.raises(ModelError, match="no output named 'x2'"):
        mbi_plant(T, E, **{**ports, "control_output": "x2"})
    with pytest.raises(ModelError, match="Wz must be positive"):
        mbi_plant(T, E, **ports, Wz=0.0)
    M, C, Kmat = tm.matrices(tr.true)
    Kmat[2, 2] -= 1500.0                     # a negative spring to ground on cart 3
    unstable = mck_to_ss(M, C, Kmat, inputs={"f1": 0, "f3": 2}, outputs={"x1": 0, "x3": 2})
    with pytest.raises(IllPosedError, match="true system is unstable"):
        mbi_plant(unstable, E, **ports)
    with pytest.raises(ModelError, match="grid is empty"):
        identify(T, E, **ports, omega=[], out=None)
    with pytest.raises(ModelError, match="no frequency overlap: the grid spans 1000-1e"):
        identify(T, E, **ports, omega=np.logspace(3, 4, 50), out=None)
    with pytest.raises(ModelError, match="positive, finite"):
        identify(T, E, **ports, omega=[0.0, 1.0, 2.0], out=None)
    with pytest.raises(IllPosedError, match="nothing to identify"):
        identify(E, E, **ports, out=None)
    with pytest.raises(ModelError, match="real must be True or False, got 'no'"):
        identify(T, E, **ports, real="no", out=None)


def _check_trial(name, res, rtol):
    tr = tm.TRIALS[name]
    assert 0.9 <= res.mu_upper <= 1.0 + 1e-9
    assert res.mu_lower <= res.mu_upper + 1e-9
    assert tr.Wz / 5 < res.Wz < tr.Wz * 5                 # same order as the thesis
    assert res.fit.fits
    fit = {"dm": res.fit.dm, "dc": res.fit.dc, "dk": res.fit.dk}
    for key, expected in tr.Du.items():
        if expected:
            assert fit[key] == pytest.approx(expected, rel=rtol), (key, fit, tr.Du)
    # the fitted impedance (zero coefficients included) against D_u on the band
    band = res.fit.omega
    D = impedance_response(tr.Du, band)
    assert np.sqrt(np.mean(np.abs(res.fit.response(band) - D) ** 2 / np.abs(D) ** 2)) < rtol
    # the controlled model follows every true rig in the set within its bound (per unit force):
    # W_z, or W_z |S(jw)| with a bound shaped by the spread
    U = tm.true_model(tr)
    for d in U.sample(4, rng=1, vertices=True):
        err = res.error(U.at(U.values(d)))
        assert np.all(err <= 1.05 * res.bound())


@pytest.mark.slow
def test_identify_spring_trial_1a():
    # covered in the default run by test_identify_from_a_measured_frf_file (identify on trial 1a: the
    # W_z search, the hidden spring read from K); the controlled model against every true rig is
    # checked with the other trials (test_identify_trial, slow)
    buf = io.StringIO()
    res = identify(**tm.mbi_arguments(tm.TRIALS["1a"]), Wz=tm.TRIALS["1a"].Wz, out=buf)
    _check_trial("1a", res, 0.05)
    assert "[mbi] try 1: Wz = 0.0004" in buf.getvalue()
    assert len(res.tries) >= 1 and all(t.mu_upper > 0 for t in res.tries)


def test_wz_floor_spring_trial():
    """One uncertain spring: the floor is half the largest gap between the two extreme rigs,
    computed here from the M, C, K matrices independently of the LFT."""
    tr = tm.TRIALS["1a"]
    f = wz_floor(tm.true_model(tr), excitation="f1", measurement="x1")
    w = np.linspace(5.0, 7.0, 20001)
    lo, hi = (tm.mechanical_model(tr.true.with_(k3=tr.true.k3 * s)) for s in (0.99, 1.01))
    gap = np.abs(freqresp(lo, w)[0, 0] - freqresp(hi, w)[0, 0]) / 2
    assert f.value == pytest.approx(gap.max(), rel=1e-4)
    assert f.value < tr.Wz                                    # the thesis's W_z is above it
    # no uncertainty, no floor
    assert wz_floor(tm.mechanical_model(tr.true), excitation="f1", measurement="x1").value == 0.0


# slow (8 CPU-s): the floor itself is checked in the default run (test_wz_floor_spring_trial); that the
# floor is a floor (mu > 1 below it) runs with the slow tests
@pytest.mark.slow
def test_below_the_floor_mu_exceeds_one():
    """Below the floor, the mu lower bound of the D-K controller (an independent computation:
    a destabilising perturbation found by power iteration) must exceed 1; the search starts above it."""
    from mutext.dk import dk_iteration
    tr = tm.TRIALS["1a"]
    args = tm.mbi_arguments(tr)
    f = wz_floor(args["true"], excitation="f1", measurement="x1")
    pl = mbi_plant(**args, Wz=0.95 * f.value)
    res = dk_iteration(pl.P, pl.structure, 1, 1, max_iter=2, out=None)
    assert res.mu_lower > 1.0
    buf, calls = io.StringIO(), []
    r = identify(**args, Wz=0.5 * f.value, max_tries=1, out=buf, dk_options={"max_iter": 1},
                 progress=lambda stage, frac: calls.append((stage, frac)))
    assert r.tries[0].Wz == pytest.approx(1.1 * r.floor.value)
    assert r.floor.value == pytest.approx(f.value, rel=1e-3)     # same floor on identify's grid
    assert any("below the floor" in n for n in r.notes)
    assert "W_z floor" in buf.getvalue()
    # the W_z search reports through the callback (the D-K stages inside the try), ending at 1
    assert calls[0][0].startswith("W_z try 1/1") and calls[-1][1] == 1.0
    assert any(stage.startswith("K-step") and "W_z try 1/1" in stage for stage, _ in calls)
    assert all(0.0 <= frac <= 1.0 for _, frac in calls)


# slow (11 CPU-s): identify() in the default run: test_identify_from_a_measured_frf_file
@pytest.mark.slow
def test_identify_with_the_parameters_kept_real():
    """``real=True``: each W_z try is a D-G-K search (mutext.dk.dgk_iteration); the mu reported
    is the D-G bound of its best try, and the hidden spring is still read from K."""
    tr = tm.TRIALS["1a"]
    res = identify(**tm.mbi_arguments(tr), Wz=tr.Wz, max_tries=1, real=True,
                   dk_options={"max_iter": 2, "max_tries": 2}, out=None)
    assert [t["scale"] for t in res.dk.tries] == [1.0, 0.97]
    assert res.mu_upper == pytest.approx(min(t["mu_dg"] for t in res.dk.tries), rel=1e-12)
    assert res.fit.dk == pytest.approx(tr.Du["dk"], rel=0.05)
    # without real parameters there is nothing to keep real: plain D-K
    plain = identify(**{**tm.mbi_arguments(tr), "true": tm.mechanical_model(tr.true)}, Wz=tr.Wz, max_tries=1,
                     real=True, dk_options={"max_iter": 1}, out=None)
    assert plain.dk.tries == []


@pytest.mark.slow
def test_trial_5_within_the_uncertainty():
    """Trial 5 (10 %) with the thesis's flat bound: W_z near the floor, the thesis's W_z below
    it, K against D_u no further off than D_u itself moves across the uncertainty box, and a
    band so narrow that the coefficients are not determined (the spring to no better than
    +-30 %; the bound shaped by the spread pins them down, test_identify_trial)."""
    from mutext.demos.three_mass import solve
    r = solve("5", out=None)
    res = r["result"]
    assert res.floor.value > tm.TRIALS["5"].Wz               # the thesis's 2.6 mm cannot be certified
    assert res.floor.value < r["Wz"] < 1.5 * res.floor.value
    assert 0.9 <= r["mu"] <= 1.0 + 1e-9
    assert r["K_rel_error"] < r["Du_spread"]
    assert res.fit.band[1] - res.fit.band[0] < 5.0
    assert r["fit_sigma"]["dk"] > 0.3 * tm.TRIALS["5"].Du["dk"]
    U = tm.true_model(tm.TRIALS["5"])
    for d in U.sample(6, rng=2, vertices=True):
        assert res.error(U.at(U.values(d))).max() <= 1.05 * r["Wz"]


@pytest.mark.slow
def test_branch_and_bound_certifies_a_tighter_bound_on_trial_5():
    """Trial 5 judged by branch and bound on the three real parameters: the accepted W_z is
    one the D-G bound rejects (its mu there is above 1) and lower than the D-G search's,
    and the controlled model follows the true rigs (vertices and samples) within it."""
    from mutext.demos.three_mass import solve
    plain = solve("5", out=None)
    r = solve("5", out=None, branch=True)
    res = r["result"]
    best = next(t for t in res.tries if t.Wz == res.Wz)
    assert res.mu_upper <= 1.0 and best.mu_dg > 1.0
    assert any(n.startswith("branch and bound on the real parameters judged") for n in res.notes)
    assert "(D-G " not in " ".join(plain["result"].notes)
    assert res.mu_lower <= res.mu_upper
    assert res.floor.value < res.Wz < plain["Wz"]
    U = tm.true_model(tm.TRIALS["5"])
    for d in U.sample(8, rng=3, vertices=True):
        assert res.error(U.at(U.values(d))).max() <= 1.05 * res.Wz


def test_identify_names_a_bad_branch_option():
    with pytest.raises(ModelError, match="branch must be True or False"):
        identify(**tm.mbi_arguments(tm.TRIALS["1a"]), branch="yes")


def test_spread_weight_covers_the_spread_and_sets_the_shaped_floor():
    """The shape covers the half-gaps of the true rigs at every grid frequency, tightly where
    they are widest and at low frequency; the shaped floor is their largest ratio to it."""
    from mutext.mbi import spread_weight
    args = tm.mbi_arguments(tm.TRIALS["5"])
    w = np.logspace(np.log10(0.5), np.log10(300), 300)
    S = spread_weight(args["true"], excitation="f1", measurement="x1", omega=w)
    half = half_gaps("5", w)
    Sj = np.abs(freqresp(S.sys, w)[0, 0])
    ratio = half / Sj
    f = wz_floor(args["true"], excitation="f1", measurement="x1", omega=w, shape=S)
    assert f.value >= ratio.max() * (1 - 1e-6)            # the zoom can only find a wider spread
    assert f.value == pytest.approx(ratio.max(), rel=0.02)
    # a cover of the spread scaled to its peak: |S| >= half / max(half), tight at the peak
    # and below 2 rad/s (where the spring is read), looser in the dips
    assert np.all(Sj * half.max() >= half * (1 - 1e-6))
    assert ratio.max() == pytest.approx(half.max(), rel=0.05)
    assert np.all(ratio[w < 2.0] > 0.85 * f.value)
    flat = wz_floor(args["true"], excitation="f1", measurement="x1", omega=w)
    assert flat.value == pytest.approx(half.max(), rel=1e-3)
    with pytest.raises(ModelError, match="needs an uncertain true model"):
        spread_weight(tm.mechanical_model(tm.TRIALS["5"].true), excitation="f1", measurement="x1")
    with pytest.raises(ModelError, match="spread_weight: the frequency grid is empty"):
        spread_weight(args["true"], excitation="f1", measurement="x1", omega=[])


def test_shaped_plant_divides_the_error_by_the_shape():
    """The error output of the shaped plant is (x_t - x_e) / (W_z S), checked with K = 0 against
    the two rigs solved from their matrices, and closed exactly by K = D_u (a spring)."""
    from mutext.mbi import spread_weight
    tr = tm.TRIALS["1a"]
    args = tm.mbi_arguments(tr)
    S = spread_weight(args["true"], excitation="f1", measurement="x1")
    args["true"] = tm.mechanical_model(tr.true)
    pl = mbi_plant(**args, Wz=2e-4, Wz_shape=S, regularization=None)
    flat = mbi_plant(**args, Wz=2e-4, regularization=None)
    assert pl.P.nstates == flat.P.nstates + S.sys.nstates

    def x1(p, x):
        M, C, K = tm.matrices(p)
        return np.linalg.solve(K - x * x * M + 1j * x * C, [1.0, 0, 0])[0]
    z = freqresp(lft_lower(pl.P, ct.ss([], [], [], [[0.0]]), 1, 1), W)[0, 0]
    expected = np.array([x1(tr.true, x) - x1(tr.engineering, x) for x in W]) / (2e-4 * S(W))
    np.testing.assert_allclose(z, expected, rtol=1e-7)
    np.testing.assert_allclose(pl.bound(W), 2e-4 * np.abs(S(W)), rtol=1e-12)
    assert np.all(flat.bound(W) == 2e-4)
    closed = freqresp(lft_lower(pl.P, ct.ss([], [], [], [[tr.Du["dk"]]]), 1, 1), W)[0, 0]
    assert np.abs(closed).max() < 1e-8 * np.abs(expected).max()
    with pytest.raises(ModelError, match="Wz_shape must be a mutext.frfit.MagnitudeFit"):
        mbi_plant(**args, Wz=2e-4, Wz_shape=S.sys)


def test_identify_names_a_bad_weight():
    args = tm.mbi_arguments(tm.TRIALS["1a"])
    with pytest.raises(ModelError, match="weight must be 'flat' or 'spread', got 'wide'"):
        identify(**args, weight="wide")
    args["true"] = tm.mechanical_model(tm.TRIALS["1a"].true)
    with pytest.raises(ModelError, match="needs an uncertain true model"):
        identify(**args, weight="spread", out=None)


@pytest.mark.slow
@pytest.mark.parametrize("name", ["1b", "2", "3", "4", "5"])
def test_identify_trial(name):
    """Trials 1b-4 with the thesis's flat bound; trial 5 (10 %) with the bound shaped by the
    spread of the true rigs: a flat bound holds K only around the first resonance, where
    only dk - w^2 dm is seen (test_trial_5_within_the_uncertainty), the shaped one over
    0.5-30 rad/s, and the three coefficients come out within 15 %.  Trial 5 with the settings of
    ``mutext demo three-mass --trial 5 --weight spread`` (each try the H-infinity design alone): the
    full D-K iteration of every try keeps the same loop and took 22-30 minutes of the slow run."""
    tr = tm.TRIALS[name]
    spread = {"weight": "spread", "dk_options": {"max_iter": 1}} if name == "5" else {}
    res = identify(**tm.mbi_arguments(tr), Wz=tr.Wz, out=None, **spread)
    _check_trial(name, res, 0.15 if name == "5" else 0.05)
    if name == "5":
        assert res.fit.band[0] < 1.0 and res.fit.band[1] > 20.0
        assert res.Wz < 1.5 * res.floor.value
        # the coefficients are determined by the data, not only close
        assert res.fit.sigma[2] < 0.05 * tr.Du["dk"] and res.fit.sigma[0] < 0.2 * tr.Du["dm"]


@pytest.mark.slow
def test_regularization_does_not_change_the_identified_dynamics():
    """Halving the control penalty and sensor noise changes K by far less than its error to D_u."""
    tr = tm.TRIALS["1a"]
    args = tm.mbi_arguments(tr)
    a = identify(**args, Wz=tr.Wz, regularization=1e-4, out=None, max_tries=1)
    b = identify(**args, Wz=tr.Wz, regularization=5e-5, out=None, max_tries=1)
    band = a.fit.omega
    # K where the measurement constrains it (weighted by the sensitivity); outside
    # that, K is free and may move by ~10 % between the two runs
    Ka = freqresp(a.K, band)[0, 0]
    assert relative_error(b.K, Ka, band, weight=a.fit.weight) < 0.01
    assert b.fit.dk == pytest.approx(a.fit.dk, rel=0.01)
    assert abs(a.mu_upper - b.mu_upper) < 0.01


def _measured(trial, tmp_path, freq_hz, noise=0.01):
    """The true rig of a trial swept on the virtual rig, written to an FRF file (in mm) and read back."""
    from mutext.rig import measure, read_frf, write_frf
    T = tm.mechanical_model(tm.TRIALS[trial].true)
    frf = measure(T, "f1", "x1", freq_hz, noise=noise, rng=0, input_station=1, output_station=1)
    return read_frf(write_frf(tmp_path / "x1_f1.csv", frf, output_unit="mm"))


def test_identify_from_a_measured_frf_file(tmp_path):
    """A spring hidden in a noisy (1 %) measured sweep, read from a file, is found."""
    args = tm.mbi_arguments(tm.TRIALS["1a"])
    args["true"] = _measured("1a", tmp_path, np.arange(0.2, 10.0, 0.02))
    buf = io.StringIO()
    res = identify(**args, out=buf)
    assert "measured FRF: 490 frequencies" in buf.getvalue()
    assert res.measured_fit.order == 6 and res.measured_fit.residual < 0.013
    assert res.fit.dk == pytest.approx(186.0, rel=0.02)
    assert abs(res.fit.dm) < 0.02 and abs(res.fit.dc) < 0.3
    assert 0.9 <= res.mu_upper <= 1.0 + 1e-9
    assert np.array_equal(res.omega, 2 * np.pi * args["true"].freq_hz)
    # the controlled model matches the data to their noise level
    assert any("against the measured data themselves the controlled model is off by 0.00" in n for n in res.notes)


def test_measured_frf_without_frequency_overlap(tmp_path):
    args = tm.mbi_arguments(tm.TRIALS["1a"])
    args["true"] = _measured("1a", tmp_path, np.arange(50.0, 100.0, 0.5))
    with pytest.raises(ModelError, match=r"x1_f1.csv: no frequency overlap: it covers 50-99.5 Hz, "
                                         r"the engineering model's modes lie at 0\.7397, 2\.959, 4\.882 Hz"):
        identify(**args, out=None)
    args["true"] = _measured("1a", tmp_path, np.arange(0.2, 10.0, 0.05))
    with pytest.raises(ModelError, match="no frequency overlap between the grid and the measured FRF"):
        identify(**args, omega=np.logspace(3, 4, 20), out=None)


# slow (6 CPU-s): identify() from a measured FRF file stays in the default run
@pytest.mark.slow
def test_demo_from_a_measured_sweep(tmp_path, capsys):
    """`mutext demo three-mass --trial 4 --measured 0.01`: all three hidden parts from a noisy sweep."""
    import json

    from mutext import cli
    assert cli.main(["demo", "three-mass", "--trial", "4", "--measured", "0.01", "--json", "--quiet",
                     "--plots", str(tmp_path)]) == 0
    r = json.loads(capsys.readouterr().out)
    assert (tmp_path / "three_mass_4_x1_f1.csv").exists() and (tmp_path / "three_mass_trial_4.png").exists()
    assert r["measured_fit"]["order"] == 6 and r["Du_spread"] is None
    for key, expected in r["Du"].items():
        assert r["fit"][key] == pytest.approx(expected, rel=0.03), key
    assert cli.main(["demo", "three-mass", "--measured", "1.5", "--quiet"]) == 1
