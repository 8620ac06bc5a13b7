"""D-K iteration: D-scale fits, the scaled plant, the iteration on a small problem, the two-mass demo."""
import io
import json

import control as ct
import numpy as np
import pytest

from mu_cases import ab13md_sweep

from mutext import cli
from mutext.dk import DScaleFit, dk_iteration, fit_dscale, scaled_plant
from mutext.errors import ModelError
from mutext.examples import distillation
from mutext.lti import freqresp, is_stable, lft_lower
from mutext.mu import Block, BlockStructure, mu_sweep


def stable_min_phase(fit: DScaleFit):
    """Poles and zeros in the open left half plane, for the stored roots and both realisations."""
    assert np.all(fit.poles.real < 0) and np.all(fit.zeros.real < 0)
    for sys in (fit.sys, fit.inverse()):
        if sys.nstates:
            assert np.all(np.linalg.eigvals(np.asarray(sys.A, float)).real < 0)


# ----------------------------------------------------------------------------
# D-scale fits
# ----------------------------------------------------------------------------

W = np.logspace(-2, 3, 60)


def test_fit_recovers_first_order_scaling():
    D = (1j * W + 1) / (1j * W + 10)
    fit = fit_dscale(W, np.abs(D), 1)
    assert fit.order == 1
    np.testing.assert_allclose(fit.zeros, [-1.0], rtol=1e-6)
    np.testing.assert_allclose(fit.poles, [-10.0], rtol=1e-6)
    assert fit.gain == pytest.approx(1.0, rel=1e-6)
    stable_min_phase(fit)
    # the realisations reproduce the magnitude, and the inverse inverts it
    np.testing.assert_allclose(np.abs(freqresp(fit.sys, W)[0, 0]), np.abs(D), rtol=1e-6)
    np.testing.assert_allclose(np.abs(freqresp(fit.inverse(), W)[0, 0]), 1 / np.abs(D), rtol=1e-6)


def test_fit_recovers_complex_poles():
    """A resonant scaling: |D|^2 then has complex poles in x = w^2."""
    s = 1j * np.logspace(-1, 3, 80)
    D = (s + 3) * (s + 30) / (s ** 2 + 8 * s + 400)
    fit = fit_dscale(s.imag, np.abs(D), 2)
    np.testing.assert_allclose(np.sort_complex(fit.poles), [-4 - np.sqrt(384) * 1j, -4 + np.sqrt(384) * 1j],
                               rtol=1e-6)
    np.testing.assert_allclose(np.sort(fit.zeros.real), [-30, -3], rtol=1e-6)
    assert fit.error < 1e-8
    stable_min_phase(fit)


@pytest.mark.parametrize("order", range(6))
def test_fit_of_noisy_data_is_stable_and_minimum_phase(order):
    rng = np.random.default_rng(order)
    mag = np.exp(np.cumsum(rng.normal(0, 0.15, W.size)))       # a random walk in log|D|
    fit = fit_dscale(W, mag, order)
    assert fit.order <= order
    stable_min_phase(fit)
    assert np.all(np.isfinite(fit(W)))
    # the fit error is what it says it is
    err = np.max(np.abs(np.log(np.abs(fit(W))) - np.log(mag)))
    assert fit.error == pytest.approx(err, rel=1e-9)
    if order == 0:
        assert fit.sys.nstates == 0


def test_higher_order_fits_better():
    """(s+0.1)(s+30)/((s+1)(s+3)) is exact at order 2 and not below."""
    s = 1j * W
    mag = np.abs((s + 0.1) * (s + 30) / ((s + 1) * (s + 3)))
    errors = [fit_dscale(W, mag, n).error for n in range(3)]
    assert errors[2] < 1e-8 < errors[1]
    assert errors[0] > 0.5


@pytest.mark.parametrize("args, match", [
    ((W, np.ones(3), 1), "equal length"),
    ((np.zeros(0), np.zeros(0), 1), "non-empty"),
    ((W, -np.ones(W.size), 1), "positive"),
    ((W, np.ones(W.size), 6), "between 0 and 5"),
])
def test_fit_rejects_bad_input(args, match):
    with pytest.raises(ModelError, match=match):
        fit_dscale(*args)


# ----------------------------------------------------------------------------
# scaled plant
# ----------------------------------------------------------------------------

def test_scaled_plant_is_pointwise_scaling():
    """D P D^-1 evaluated as a system equals diag(D_l(jw)) P(jw) diag(D_r(jw))^-1."""
    S = BlockStructure([Block.full(1, 1, "a"), Block.full(2, 1, "b"), Block.full(1, 2, "c")])
    nmeas, ncon = 1, 1
    P = ct.rss(5, S.ncols + nmeas, S.nrows + ncon, strictly_proper=False)
    s = 1j * W
    fits = [fit_dscale(W, np.abs((s + 1) / (s + 10)), 1),
            fit_dscale(W, np.abs(3 * (s ** 2 + 2 * s + 25) / ((s + 0.5) * (s + 40))), 2),
            None]
    PD = scaled_plant(P, S, fits, nmeas, ncon)
    assert PD.nstates == P.nstates + 1 * (1 + 1) + 2 * (2 + 1)
    d = [fits[0](W), fits[1](W), np.ones(W.size)]
    dl = np.array([d[k] for k in S.col_block] + [np.ones(W.size)] * nmeas)      # on z, then y
    dr = np.array([d[k] for k in S.row_block] + [np.ones(W.size)] * ncon)       # on w, then u
    expected = dl[:, None, :] * freqresp(P, W) / dr[None, :, :]
    np.testing.assert_allclose(freqresp(PD, W), expected, rtol=1e-8, atol=1e-10)


def test_scaled_plant_size_mismatch_names_both_sizes():
    S = BlockStructure([Block.full(1, 1), Block.full(2, 2)])
    P = ct.rss(3, 3, 3)
    with pytest.raises(ModelError, match=r"3 inputs and 3 outputs.*3 input and 3 output channels"):
        scaled_plant(P, S, [None, None], 1, 1)


# ----------------------------------------------------------------------------
# D-K iteration on a small problem
# ----------------------------------------------------------------------------

def siso_rp_plant():
    """Robust performance of G = 3(1 - 2s)/((5s+1)(10s+1)) with input uncertainty W_I and
    sensitivity weight W_P ([SP] sec. 7.6 style): inputs [w_I, d, u], outputs [z_I, z_P, y]."""
    G = ct.tf([-6, 3], [50, 15, 1])
    WI = ct.tf([1, 0.2], [0.5, 1])
    WP = ct.tf([0.5, 0.05], [1, 0.01])
    zero, one = ct.tf([0], [1]), ct.tf([1], [1])
    rows = [[zero, zero, WI], [WP * G, WP, WP * G], [-G, -one, -G]]
    P = ct.tf([[r.num[0][0] for r in row] for row in rows], [[r.den[0][0] for r in row] for row in rows])
    return ct.minreal(ct.ss(P), verbose=False)


SISO_S = BlockStructure([Block.full(1, 1, "input uncertainty"), Block.full(1, 1, "performance")])


PROGRESS = []


@pytest.fixture(scope="module")
def siso_dk():
    P = siso_rp_plant()
    out = io.StringIO()
    PROGRESS.clear()
    res = dk_iteration(P, SISO_S, 1, 1, out=out, progress=lambda stage, f: PROGRESS.append((stage, f)))
    return P, res, out.getvalue()


def test_dk_reduces_mu(siso_dk):
    P, res, _ = siso_dk
    first = res.history[0]["mu"]
    assert len(res.history) >= 2
    assert res.history[0]["orders"] == [0]
    assert min(h["mu"] for h in res.history) < 0.8 * first
    assert res.mu_upper < 0.8 * first
    # the first K step is plain H-infinity: its level bounds mu from above
    assert first <= res.history[0]["gamma"] * (1 + 1e-3)


def test_dk_final_bound_is_certified(siso_dk):
    P, res, _ = siso_dk
    assert is_stable(res.CL)
    CL = lft_lower(P, res.K, 1, 1)
    np.testing.assert_allclose(freqresp(CL, W), freqresp(res.CL, W), rtol=1e-8, atol=1e-12)
    # recomputed by the reference implementation on the same grid
    again = mu_sweep(CL, SISO_S, res.sweep.omega, method="osborne", lower="none", refine=False)
    assert res.mu_upper == pytest.approx(again.peak_upper, rel=1e-5)
    assert res.mu_lower <= res.mu_upper * (1 + 1e-9)
    # two complex blocks: the D bound is exact, so the bounds meet
    assert res.mu_lower == pytest.approx(res.mu_upper, rel=1e-3)
    assert res.controller_order == res.K.nstates


def test_dk_prints_iteration_table(siso_dk):
    _, res, text = siso_dk
    lines = text.strip().splitlines()
    assert "gamma" in lines[0] and "peak mu" in lines[0] and "D-fit orders" in lines[0]
    assert len(lines) >= len(res.history) + 2
    assert lines[-1].startswith("best:")


def test_dk_reports_progress_in_its_slow_steps(siso_dk):
    _, res, text = siso_dk
    stages = [s for s, _ in PROGRESS]
    fractions = np.array([f for _, f in PROGRESS])
    for head in ("K-step", "mu-sweep", "D-fit", "final-analysis"):
        assert any(s.startswith(head) for s in stages), head
    # every K step and every D step of the table was announced
    assert sum(s.startswith("K-step") and s.endswith(" 0 s") for s in stages) >= len(res.history)
    assert np.all((fractions >= 0) & (fractions <= 1))
    assert np.all(np.diff(fractions) >= -1e-12)        # overall progress never goes back
    assert stages[-1].startswith("final-analysis") and fractions[-1] == 1.0
    # the final analysis's slow steps are announced too (with their elapsed time)
    assert any(s.startswith("final-analysis: lower bounds at the peaks (") for s in stages)
    header = text.strip().splitlines()[0]
    assert "K order" in header and "plant" in header and "seconds" in header
    assert all(h["plant_states"] >= res.history[0]["plant_states"] for h in res.history)


def test_dk_progress_beats_during_a_slow_k_step():
    """The K step cannot report itself: a helper thread reports its elapsed time."""
    import time

    from mutext.hinf import hinfsyn

    def slow(PD, nmeas, ncon):
        time.sleep(1.6)
        return hinfsyn(PD, nmeas, ncon)
    calls = []
    res = dk_iteration(siso_rp_plant(), SISO_S, 1, 1, max_iter=1, synthesis=slow,
                       progress=lambda stage, f: calls.append(stage))
    assert len(res.history) == 1
    kstep = [s for s in calls if s.startswith("K-step 1/1")]
    seconds = [int(s.split()[-2]) for s in kstep]
    assert seconds[0] == 0 and max(seconds) >= 1 and len(seconds) >= 2


def test_dk_fits_track_the_optimal_scalings(siso_dk):
    """The level the K step starts from (fitted D on the old loop) is at or above the
    pointwise-optimal peak and within a few percent of it."""
    _, res, _ = siso_dk
    for prev, row in zip(res.history, res.history[1:]):
        if np.isfinite(row["fit_peak"]):
            assert prev["mu"] * (1 - 1e-6) <= row["fit_peak"] <= prev["mu"] * 1.05


def test_dk_rejects_structure_size_mismatch():
    P = siso_rp_plant()
    S = BlockStructure([Block.full(1, 1), Block.full(2, 2)])
    with pytest.raises(ModelError, match=r"3 inputs and 3 outputs.*3 input and 3 output channels.*"
                                          r"needs 4 inputs and 4 outputs"):
        dk_iteration(P, S, 1, 1, out=None)


def test_dk_rejects_empty_grid():
    with pytest.raises(ModelError, match="empty"):
        dk_iteration(siso_rp_plant(), SISO_S, 1, 1, omega=[], out=None)


@pytest.mark.parametrize("kw, match", [({"max_order": 6}, "max_order"), ({"max_iter": 0}, "max_iter"),
                                       ({"omega": [-1.0, 2.0]}, "positive")])
def test_dk_rejects_bad_options(kw, match):
    with pytest.raises(ModelError, match=match):
        dk_iteration(siso_rp_plant(), SISO_S, 1, 1, out=None, **kw)


# ----------------------------------------------------------------------------
# two-mass demo (thesis sec. 2.3.2)
# ----------------------------------------------------------------------------

# slow (5 CPU-s): the demo's D-K run; dk_iteration's Example checks the same problem in the default run
@pytest.mark.slow
def test_two_mass_mu_json_keys(capsys):
    assert cli.main(["demo", "two-mass-mu", "--json", "--max-iter", "2"]) == 0
    captured = capsys.readouterr()
    out = json.loads(captured.out)
    for key in ("mu_upper", "mu_lower", "iterations", "controller_order", "seconds"):
        assert key in out
    assert all({"gamma", "mu"} <= set(it) for it in out["iterations"])
    assert len(out["iterations"]) == 2
    assert out["mu_lower"] <= out["mu_upper"]
    assert out["nominal_stable"] and out["corners_stable"]
    assert "gamma (K step)" in captured.err           # progress on stderr


@pytest.mark.slow
def test_two_mass_mu_real_parameters(capsys):
    """``--real``: D-G-K; the tries are reported and the controller kept is the best of them by
    the D-G bound; the corners of the parameter box (rebuilt from M and K) stay stable."""
    assert cli.main(["demo", "two-mass-mu", "--xmax", "0.041", "--real", "--json"]) == 0
    captured = capsys.readouterr()
    out = json.loads(captured.out)
    assert len(out["tries"]) >= 2 and out["tries"][0]["scale"] == 1.0
    assert out["mu_upper_dg"] == min(t["mu_dg"] for t in out["tries"])
    assert out["mu_upper_dg"] < out["tries"][0]["mu_dg"]
    assert out["nominal_stable"] and out["corners_stable"]
    assert "D-G-K try 2/6" in captured.err


def test_two_mass_mu_bad_xmax(capsys):
    assert cli.main(["demo", "two-mass-mu", "--xmax", "-1"]) == 1
    assert "--xmax" in capsys.readouterr().err
    assert cli.main(["demo", "two-mass-mu", "--refine", "-1"]) == 1
    assert "--refine must be a number of steps >= 0, got -1" in capsys.readouterr().err


@pytest.mark.slow
def test_two_mass_mu_refined(capsys):
    """``--refine``: the design's controller moved by a few steps on the D-G bound; the bound
    never rises, the iterations reported are the design's, the corners (rebuilt from M and K)
    stay stable."""
    assert cli.main(["demo", "two-mass-mu", "--xmax", "0.041", "--max-iter", "2", "--refine", "3",
                     "--json"]) == 0
    captured = capsys.readouterr()
    out = json.loads(captured.out)
    assert len(out["iterations"]) == 2 and len(out["refine_steps"]) == 3
    assert out["mu_upper_dg"] <= out["refined_from"] * (1 + 1e-9)
    assert out["mu_lower"] <= out["mu_upper_dg"] * (1 + 1e-9)
    assert out["nominal_stable"] and out["corners_stable"]
    assert "mu D-G (grid)" in captured.err and any(n.startswith("refine: ") for n in out["notes"])


@pytest.mark.slow
def test_two_mass_mu_relaxed_bound_lowers_mu():
    from mutext.demos import two_mass_mu
    a = two_mass_mu.solve(0.035, out=None)
    b = two_mass_mu.solve(0.041, out=None)
    for r in (a, b):
        assert r["mu_lower"] <= r["mu_upper_dg"] * (1 + 1e-9) <= r["mu_upper"] * (1 + 1e-9)
        assert r["nominal_stable"] and r["corners_stable"]
        # the thesis's values (1.11, 0.989) sit a few percent lower, as its H-infinity level does
        assert r["mu_upper"] == pytest.approx(r["mu_thesis"], rel=0.06)
    assert b["mu_upper"] < a["mu_upper"]
    assert b["mu_upper"] < 1.05 < a["mu_upper"]


# ----------------------------------------------------------------------------
# weights with near-axis poles: the distillation column ([SP] Table 8.1, sec. 8.12.4)
# ----------------------------------------------------------------------------

DIST_S = distillation.structure()


def test_distillation_plant_is_the_textbook_interconnection():
    """[SP] Table 8.1 from its transfer functions, evaluated by numpy:
    z_Delta = W_I u, z_P = W_P (G (u_Delta + u) + w), y = -(G (u_Delta + u) + w)."""
    P = distillation.plant()
    I, Z = np.eye(2), np.zeros((2, 2))
    for s in 1j * np.array([1e-7, 3e-3, 0.37, 20.0]):
        G = np.array([[87.8, -86.4], [108.2, -109.6]]) / (75 * s + 1)
        Wi, Wp = (s + 0.2) / (0.5 * s + 1), 0.5 * (10 * s + 1) / (10 * s + 1e-5)
        ref = np.block([[Z, Z, Wi * I], [Wp * G, Wp * I, Wp * G], [-G, -I, -G]])
        np.testing.assert_allclose(P(s), ref, rtol=1e-10, atol=1e-10 * np.abs(ref).max())
    assert [b.kind for b in DIST_S.blocks] == ["full"] * 3 and DIST_S.nrows == DIST_S.ncols == 4


def _ab13md_peak(CL, omega):
    """Independent of mutext: dense complex solves for the response, SLICOT AB13MD for mu."""
    return float(np.max(ab13md_sweep(CL, omega, ["c1", "c1", "full2"])))


def test_near_axis_poles_are_set_apart():
    from mutext.dk import _default_dk_grid, near_axis_poles
    P = distillation.plant()
    np.testing.assert_allclose(np.sort(near_axis_poles(P).real), [-1e-6, -1e-6], rtol=1e-6)
    g = _default_dk_grid(P, 80)
    # the D-step grid spans the other poles (1/75 and 2 rad/s) 1.5 decades beyond, not 1e-6
    assert g.min() == pytest.approx((1 / 75) / 10 ** 1.5, rel=1e-6)
    assert g.max() == pytest.approx(2 * 10 ** 1.5, rel=1e-6)
    assert near_axis_poles(siso_rp_plant()).size == 0       # poles 0.01, 0.1, 0.2, 2: no gap of 1e3
    # an unstable slow pole is never set apart
    assert near_axis_poles(ct.ss([[1e-7, 0], [0, -5]], np.eye(2), np.eye(2), 0)).size == 0


def test_dk_on_a_weight_with_near_axis_poles():
    """The K step no longer fails with dynamic scalings; the verdict on the loop
    is independent of mutext: python-control's lft, numpy eigenvalues, AB13MD on a grid
    that reaches below the weight's poles."""
    P = distillation.plant()
    res = dk_iteration(P, DIST_S, 2, 2, max_iter=2, out=None)
    assert any(h["orders"] != [0, 0] for h in res.history if h["controller_order"] is not None)
    assert not any("failed" in n for n in res.notes)
    assert any("near-axis poles" in n for n in res.notes)
    CL = ct.ss(P).lft(ct.ss(res.K), nu=2, ny=2)
    p = np.linalg.eigvals(CL.A)
    assert p.real.max() < 0 and res.max_pole_real == pytest.approx(p.real.max(), rel=1e-6)
    # the weight's states are invisible to y: they stay closed-loop poles
    assert np.min(np.abs(p + 1e-6)) < 1e-9
    w = np.logspace(-8, 3, 300)
    ref = _ab13md_peak(CL, np.union1d(w, [res.peak_frequency]))
    assert res.mu_upper == pytest.approx(ref, rel=2e-3)
    assert res.mu_upper < 1.06 and res.mu_lower > 0.97 * res.mu_upper


@pytest.mark.slow
def test_dk_distillation_beats_dkpy():
    """dkpy 0.1.9 reports about 1.035 with a 22-state controller on the same problem and grid;
    finer fits and more patience get below it with 18 states."""
    P = distillation.plant()
    res = dk_iteration(P, DIST_S, 2, 2, omega=np.logspace(-3, 3, 61), fit_tol=5e-4, rel_improvement=1e-3,
                       max_iter=20, patience=2, max_states=22, out=None)
    CL = ct.ss(P).lft(ct.ss(res.K), nu=2, ny=2)
    assert np.linalg.eigvals(CL.A).real.max() < 0
    ref = _ab13md_peak(CL, np.union1d(np.logspace(-8, 3, 400), [res.peak_frequency]))
    assert ref < 1.035 and res.K.nstates <= 22
    assert res.mu_upper == pytest.approx(ref, rel=2e-3)


@pytest.mark.slow
def test_with_real_blocks_the_iteration_kept_has_the_lowest_d_g_bound():
    """Three-mass trial 5 (three real parameters at 10 %) at W_z = 4.86 mm: the D step after the
    H-infinity design lowers the complex bound but raises the D-G bound that judges the loop
    (its fitted D scalings treat the parameters as complex). The loop kept is the first, and
    SLICOT AB13MD (real blocks real) confirms its bound below 1, where the complex one is 1.18."""
    # covered in the default run by tests/test_dgk.py::test_dgk_reported_bound_is_the_ab13md_bound (with
    # real blocks the loop kept has the lowest D-G bound of its iterations, the bound checked by AB13MD)
    from mutext.examples import three_mass as tm
    from mutext.mbi import mbi_plant
    args = tm.mbi_arguments(tm.TRIALS["5"])
    pl = mbi_plant(args.pop("true"), args.pop("engineering"), Wz=4.858e-3, **args)
    res = dk_iteration(pl.P, pl.structure, 1, 1, max_iter=2, synthesis="lmi-first")
    dg = [h["mu_dg"] for h in res.history]
    cx = [h["mu"] for h in res.history]
    assert len(dg) == 2 and cx[1] < cx[0] and dg[1] > dg[0]        # the situation tested
    assert res.best_iteration == 1
    w = np.union1d(np.logspace(-0.3, 1.7, 200), res.sweep.omega)
    ab = ab13md_sweep(res.CL, w, ["real", "real", "real", "full2"])
    assert ab.max() <= res.mu_upper_dg * (1 + 2e-3) and ab.max() < 1.0 < dg[1]
    assert res.mu_upper > 1.1                                       # the complex bound of the loop kept
