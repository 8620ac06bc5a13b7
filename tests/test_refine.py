"""The controller refined with the D-G scalings of every frequency (mutext.dk.refine_controller),
judged independently: the loop rebuilt by python-control, its poles by numpy, its D-G bound by
SLICOT AB13MD, the model's derivatives by finite differences of numpy eigenvalues."""
import io

import control as ct
import numpy as np
import pytest

from mutext.dk import _Modal, _augmented_loop, dk_iteration, refine_controller
from mutext.errors import ModelError
from mutext.examples import two_mass_uncertain as tmu
from mutext.mu import Block, BlockStructure, mu_upper

from mu_cases import ab13md_sweep

TWO_MASS_KINDS = ["real"] * 4 + ["full2"]


@pytest.fixture(scope="module")
def refined():
    P = tmu.plant(0.041)
    S = tmu.structure()
    start = dk_iteration(P, S, 1, 1, max_iter=2)
    buf, calls = io.StringIO(), []
    res = refine_controller(P, S, start.K, 1, 1, max_steps=8, out=buf,
                            progress=lambda stage, frac: calls.append((stage, frac)))
    CL = ct.ss(P).lft(ct.ss(res.K), nu=1, ny=1)
    CL0 = ct.ss(P).lft(ct.ss(start.K), nu=1, ny=1)
    w = res.sweep.omega
    return start, res, CL, ab13md_sweep(CL, w, TWO_MASS_KINDS), ab13md_sweep(CL0, w, TWO_MASS_KINDS), \
        buf.getvalue(), calls


@pytest.mark.slow
def test_refined_loop_is_stable_and_lower_by_ab13md(refined):
    """Two-mass problem at 0.041 m: 25 steps lower the AB13MD bound of the D-K loop on the
    final grid (1.0186 to about 1.0165 when written), with a controller of the same order."""
    start, res, CL, ref, ref0, _, _ = refined
    assert np.linalg.eigvals(CL.A).real.max() < 0
    assert res.max_pole_real == pytest.approx(np.linalg.eigvals(CL.A).real.max(), rel=1e-6)
    assert res.K.nstates == start.K.nstates
    assert ref.max() < 0.999 * ref0.max()
    assert res.mu_upper_dg == pytest.approx(ref.max(), rel=1e-4)
    assert sum(h["accepted"] for h in res.history) >= 3
    # each accepted step lowered the bound on the refinement grid; rejected ones kept it
    # (frequencies added after a missed peak start a new round, which may start higher)
    rows = res.history
    assert all(b["mu_dg"] <= a["mu_dg"] * (1 + 1e-12) for a, b in zip(rows, rows[1:]) if a["round"] == b["round"])


@pytest.mark.slow
def test_refined_bound_is_met_by_a_real_perturbation(refined):
    _, res, CL, _, _, _, _ = refined
    assert res.mu_upper_dg * (1 - 1e-4) <= res.mu_lower <= res.mu_upper_dg * (1 + 1e-9)
    Delta, w = res.sweep.lower_delta, res.sweep.lower_frequency
    M = CL.D + CL.C @ np.linalg.solve(1j * w * np.eye(CL.nstates) - CL.A, CL.B)
    assert np.allclose(Delta[:4, :4], np.diag(np.diag(Delta[:4, :4]).real))
    assert np.linalg.svd(np.eye(6) - M @ Delta, compute_uv=False)[-1] < 1e-8


@pytest.mark.slow
def test_refine_reports_steps(refined):
    _, res, _, _, _, text, calls = refined
    assert "mu D-G (grid)" in text and "accepted" in text and "refined: fine grid" in text
    assert any(n.startswith("refine: ") for n in res.notes)
    assert any(st.startswith("refine step 1/8") for st, _ in calls)
    fr = [f for _, f in calls]
    assert all(0.0 <= f <= 1.0 for f in fr) and fr == sorted(fr)


@pytest.mark.slow
def test_refine_on_the_distillation_column():
    """A 2x2 controller with complex blocks only: 12 steps on the default D-K controller of
    the distillation column lower its AB13MD bound, judged on a grid that reaches below the
    weight's poles at -1e-6 rad/s, with the same 18 states; the report equals AB13MD there.

    Since the D-K defaults fit the scalings finely (commit ebd0ace) the start is 1.0273, not
    about 1.05, and 12 steps gain about 0.12 % (1.02728 -> 1.02600 and 1.02606 seen; from 1.0501
    they gained 0.44-0.65 %), so the bar is 0.05 %.  Below the weight's poles mu is set by the
    controller's slow poles, which sit at -1e-6 like the weight's: when the final analysis's grid
    stopped at 0.01 rad/s (the default grid's band capped at six decades, commit 3b9c00e), the
    refinement moved them to -4e-6 and -6e-6 unseen and returned a loop at 5.10 (at 1e-8 rad/s),
    five times its start; the fine grids reach 1.5 decades below the slowest pole again."""
    from mutext.examples import distillation
    P, S = distillation.plant(), distillation.structure()
    start = dk_iteration(P, S, 2, 2, omega=np.logspace(-3, 3, 61))
    res = refine_controller(P, S, start.K, 2, 2, max_steps=12)
    kinds = ["c1", "c1", "full2"]
    w = np.logspace(-8, 3, 400)
    CL = ct.ss(P).lft(ct.ss(res.K), nu=2, ny=2)
    CL0 = ct.ss(P).lft(ct.ss(start.K), nu=2, ny=2)
    assert np.linalg.eigvals(CL.A).real.max() < 0 and res.K.nstates == start.K.nstates
    # both final analyses reach below the weight's poles
    assert start.sweep.omega.min() < 1e-7 and res.sweep.omega.min() < 1e-7
    ref = ab13md_sweep(CL, np.union1d(w, res.sweep.omega), kinds).max()
    ref0 = ab13md_sweep(CL0, np.union1d(w, start.sweep.omega), kinds).max()
    assert ref < 0.9995 * ref0      # 1.02728 -> 1.02600 and 1.02606 seen
    assert res.mu_upper_dg == pytest.approx(ref, rel=1e-3)
    assert res.mu_upper == pytest.approx(res.mu_upper_dg, rel=1e-6)   # no real blocks: one bound


def _random_mimo(seed, n=3, ny=2, nu=2):
    rng = np.random.default_rng(seed)
    A = rng.standard_normal((n, n)) - 3 * np.eye(n)
    return ct.ss(A, rng.standard_normal((n, ny)), rng.standard_normal((nu, n)), rng.standard_normal((nu, ny)))


@pytest.mark.parametrize("seed", [0, 1])
def test_modal_form_and_its_derivatives(seed):
    """The modal realisation reproduces K(jw) (python-control), and dK/dtheta matches central
    differences of that response."""
    K = _random_mimo(seed)
    mod = _Modal(K)
    w = np.array([0.1, 1.0, 7.0])
    Kw, Cr, Br = mod.response(mod.theta, 1j * w)
    ref = np.moveaxis(ct.ss(K).frequency_response(w).frdata, -1, 0)
    assert np.allclose(Kw, ref, rtol=1e-10, atol=1e-12)
    J = mod.d_response(Cr, Br)
    h = 1e-6
    for i in range(mod.theta.size):
        e = np.zeros_like(mod.theta)
        e[i] = h * max(mod.scale[i], 1e-2 * np.abs(mod.theta).max())
        fd = (mod.response(mod.theta + e, 1j * w)[0] - mod.response(mod.theta - e, 1j * w)[0]) / (2 * e[i])
        assert np.allclose(J[:, :, i], fd.reshape(w.size, -1), rtol=1e-5, atol=1e-7 * np.abs(J).max())


def _small_problem():
    """A 4-state plant with a real and a complex 2x2 block (3 rows and columns), 2
    measurements and 2 controls, and a 2-state controller."""
    rng = np.random.default_rng(3)
    n, nr, nc, ny, nu = 4, 3, 3, 2, 2
    S = BlockStructure([Block("real", 1, 1), Block("full", 2, 2)])
    A = rng.standard_normal((n, n)) - 4 * np.eye(n)
    P = ct.ss(A, rng.standard_normal((n, nr + nu)), rng.standard_normal((nc + ny, n)),
              0.1 * rng.standard_normal((nc + ny, nr + nu)))
    P.D[nc:, nr:] = 0.0
    K = ct.ss(-2 * np.eye(2), 0.3 * rng.standard_normal((2, ny)), 0.3 * rng.standard_normal((nu, 2)),
              np.zeros((nu, ny)))
    return P, S, K


def test_step_model_matches_finite_differences_of_lambda_max():
    """The model's first-order change of lambda_max(Q) (Q with the D-G scalings held) equals
    central differences of numpy's largest eigenvalue of Q rebuilt from the loop of
    python-control, for a 2x2 controller on a plant with a real and a complex block."""
    P, S, K = _small_problem()
    nr, nc, ny, nu = 3, 3, 2, 2
    mod = _Modal(K)
    w0 = 0.9

    def loop(theta):
        Kt = ct.ss(*mod.matrices(theta))
        return ct.ss(P).lft(Kt, nu=nu, ny=ny)

    M0 = loop(mod.theta)(1j * w0)
    u = mu_upper(M0, S, method="lmi")
    ev, V = np.linalg.eigh(u.Dr)
    R = (V * ev ** -0.5) @ V.conj().T

    def lam(theta):
        M = loop(theta)(1j * w0)
        Q = R @ (M.conj().T @ u.Dl @ M + 1j * (u.G @ M - M.conj().T @ u.G.conj().T)) @ R
        return np.linalg.eigvalsh(Q)

    L0 = lam(mod.theta)
    assert L0[-1] - L0[-2] > 1e-3 * L0[-1]         # a simple top eigenvalue: the derivative exists
    CLa = _augmented_loop(ct.ss(P), ct.ss(K), nc, nr, ny, nu)
    F = CLa(1j * w0)
    M, U, Vm = F[:nc, :nr], F[:nc, nr:], F[nc:, :nr]
    assert np.allclose(M, M0, atol=1e-12)
    Q = R @ (M.conj().T @ u.Dl @ M + 1j * (u.G @ M - M.conj().T @ u.G.conj().T)) @ R
    _, Y = np.linalg.eigh(Q)
    Yk = Y[:, -1:]
    Lft = Yk.conj().T @ R @ (M.conj().T @ u.Dl + 1j * u.G) @ U
    Rgt = Vm @ R @ Yk
    _, Cr, Br = mod.response(mod.theta, np.array([1j * w0]))
    Fp = mod.sensitivity_factors(Lft, Rgt, Cr[0], Br[0])
    grad = 2 * np.real(Fp[:, 0, 0])
    h = 1e-6
    for i in range(mod.theta.size):
        e = np.zeros_like(mod.theta)
        e[i] = h * max(mod.scale[i], 1e-2 * np.abs(mod.theta).max())
        fd = (lam(mod.theta + e)[-1] - lam(mod.theta - e)[-1]) / (2 * e[i])
        assert grad[i] == pytest.approx(fd, rel=1e-4, abs=1e-7 * np.abs(grad).max())


@pytest.mark.slow
def test_a_peak_the_refinement_grid_missed_joins_it_and_the_descent_goes_on(monkeypatch):
    """When the fine grid of the final analysis reports a peak above the refinement grid's, its
    frequencies join the grid and ``regrid_every`` more steps follow, then the fine grid is
    checked again.  Here the first check is made to report a peak 5 % higher at a frequency
    off the grid; a run stopped by its time limit is not continued."""
    import mutext.dk._refine as dk          # where refine_controller looks the analysis up
    P, S, K = _small_problem()
    real = dk._final_analysis
    calls = []

    def first_check_misses(*args, **kwargs):
        final, low, low_c, mu_dg, extra = real(*args, **kwargs)
        calls.append(mu_dg)
        if len(calls) == 2:           # 1: the controller given; 2: the first check
            return final, low, low_c, 1.05 * mu_dg, np.append(extra, 12.345)
        return final, low, low_c, mu_dg, extra

    monkeypatch.setattr(dk, "_final_analysis", first_check_misses)
    res = refine_controller(P, S, K, 2, 2, max_steps=3, regrid_every=2)
    assert len(calls) >= 3
    rounds = [h["round"] for h in res.history]
    assert rounds[:5] == [0, 0, 0, 1, 1] and len(rounds) == 3 + 2 * max(rounds)
    assert res.history[3]["grid_points"] > res.history[2]["grid_points"]
    assert any("the fine grid found" in n and "up to 2 more steps follow" in n for n in res.notes)
    # the bound reported is the last check's, not the inflated one
    assert res.mu_upper_dg == pytest.approx(min(calls[-1], calls[0]), rel=1e-12)

    calls.clear()
    res = refine_controller(P, S, K, 2, 2, max_steps=3, time_limit=1e-6)
    assert len(calls) == 2 and res.history == []
    assert not any("the fine grid found" in n for n in res.notes)


def test_refine_bad_inputs():
    P = tmu.plant(0.041)
    S = tmu.structure()
    K = ct.ss([[-1.0]], [[1.0]], [[1.0]], [[0.0]])
    with pytest.raises(ModelError, match="K has 2 inputs and 1 outputs, but nmeas=1"):
        refine_controller(P, S, ct.ss([[-1.0]], [[1.0, 0.0]], [[1.0]], [[0.0, 0.0]]), 1, 1)
    with pytest.raises(ModelError, match="max_steps must be an integer >= 1"):
        refine_controller(P, S, K, 1, 1, max_steps=0)
    with pytest.raises(ModelError, match="time_limit must be a positive number"):
        refine_controller(P, S, K, 1, 1, time_limit=-1)
    with pytest.raises(ModelError, match="K does not stabilise P"):
        refine_controller(P, S, ct.ss([[1.0]], [[1.0]], [[1.0]], [[0.0]]), 1, 1)
    with pytest.raises(ModelError, match="size mismatch"):
        refine_controller(P, S, K, 2, 1)


# slow (13 CPU-s): the final analysis's peak refinement; D-K's results in the default run go through it
@pytest.mark.slow
def test_final_analysis_finds_the_dg_peak_between_grid_points():
    """A 20-state controller refined at 0.035 m (tests/data) equalises the D-G bound: its local
    maxima lie within 0.5 % of each other, and the highest (1.1213 near 89 rad/s) lies between
    the points of the grid refined around the complex bound's peaks, where the bound reads
    1.1165.  The reported peak is AB13MD's on a dense grid with its maxima refined, to 1e-4,
    and the real lower bound, taken at the reported peak, meets it."""
    import sys
    from pathlib import Path
    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
    from _independent import mu_peak          # the benchmark's judge: AB13MD, golden section
    from mutext.dk import _default_dk_grid, _final_analysis
    from mu_cases import ab13md_structure
    z = np.load(Path(__file__).parent / "data" / "two_mass_equalised_dg.npz")
    P = tmu.plant(0.035)
    CL = ct.ss(P).lft(ct.ss(z["A"], z["B"], z["C"], z["D"]), nu=1, ny=1)
    assert np.linalg.eigvals(CL.A).real.max() < 0
    final, low, _, mu_dg, added = _final_analysis(CL, tmu.structure(), _default_dk_grid(P, 80), 200, True)
    _, nblock, itype = ab13md_structure(TWO_MASS_KINDS)
    ref, _ = mu_peak(CL, nblock, itype, np.logspace(-3, 3, 1200))
    assert ref > 1.12
    assert mu_dg == pytest.approx(ref, rel=1e-4)
    # the complex grid alone misses it by far more than that
    on_grid = ab13md_sweep(CL, final.omega, TWO_MASS_KINDS).max()
    assert on_grid < ref * (1 - 2e-3)
    assert added.size > 0 and ref * (1 - 1e-4) <= low <= mu_dg * (1 + 1e-9)


def test_scalings_of_a_parameter_that_barely_matters_stay_usable():
    """The loop matrix of a D-G-K controller at 0.035 m at 167 rad/s (tests/data): there a
    real parameter barely matters, its optimal D scaling is 1e-20 of the largest and
    D_r^(-1/2) is 1e10, so the scaled form Q had entries of 1e16 and batched LAPACK read its
    top eigenvalue as 5.39 where it is 0.94 (the step model then saw a peak that was not
    there).  The scalings kept are floored: Q stays moderate, its top eigenvalue is the same
    either way, and the bound is exact: no higher than AB13MD's (which reads 0.96852 or
    0.96810 depending on the machine's LAPACK) and within 1e-6 of a destabilising real
    perturbation, checked here with numpy."""
    from slycot import ab13md
    from mutext.dk import _dg_point
    from mutext.mu import mu_lower
    from mu_cases import ab13md_structure
    from pathlib import Path
    M = np.load(Path(__file__).parent / "data" / "two_mass_loop_matrix_tiny_scaling.npy")
    _, nblock, itype = ab13md_structure(TWO_MASS_KINDS)
    pt = _dg_point(M, tmu.structure())
    Q = pt.q(M)
    assert np.abs(Q).max() < 1e9 * pt.value ** 2
    lam_batched = np.linalg.eigh(np.stack([Q, Q, Q]))[0][:, -1]
    np.testing.assert_allclose(lam_batched, np.linalg.eigvalsh(Q)[-1], rtol=1e-6)
    assert pt.value <= ab13md(M, nblock, itype)[0] * (1 + 1e-6)
    # the witness: real parameter entries, a complex performance block, I - M Delta singular
    low = mu_lower(M, tmu.structure())
    D = low.Delta
    assert np.allclose(D[:4, :4], np.diag(np.diag(D[:4, :4]).real), atol=1e-12)
    assert np.allclose(D[:4, 4:], 0) and np.allclose(D[4:, :4], 0)
    assert np.linalg.svd(np.eye(M.shape[0]) - M @ D, compute_uv=False)[-1] < 1e-8
    witness = 1.0 / np.linalg.norm(D, 2)
    assert witness <= pt.value * (1 + 1e-9)
    assert pt.value == pytest.approx(witness, rel=1e-6)


# both stored controllers are judged with the slow tests (10 and 40 CPU-s: AB13MD on a dense grid and a
# brute-force real perturbation); the book's build uses them
@pytest.mark.parametrize("x_max, upper, lower", [pytest.param(0.041, 0.97814, 0.97812, marks=pytest.mark.slow),
                                                 pytest.param(0.035, 1.10267, 1.10266, marks=pytest.mark.slow)])
def test_stored_refined_controllers_have_the_bounds_their_documentation_states(x_max, upper, lower):
    """The controllers of the book's longest refinements (``tmu.refined_controller``), judged
    without mutext: the loop closed by python-control and stable by its poles in 40 digits,
    SLICOT AB13MD's bound on a dense grid with its maxima refined by golden section, and at
    AB13MD's peak a real perturbation of the four parameters found by brute force."""
    import sys
    from pathlib import Path
    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
    from _independent import closed_loop, freqresp, mixed_mu_brute_force, mu_peak, stability
    from mu_cases import ab13md_structure
    K = tmu.refined_controller(x_max)
    CL = closed_loop(tmu.plant(x_max), K, 1, 1)
    ok, why = stability(CL)
    assert ok, why
    _, nblock, itype = ab13md_structure(TWO_MASS_KINDS)
    peak, w_peak = mu_peak(CL, nblock, itype, np.logspace(-3, 3.5, 1300), refine=8)
    # AB13MD's D-G bound is never below mu; it may read a little above the package's
    # (0.04 % on one matrix of this problem, tests above)
    assert lower <= peak <= upper * (1 + 5e-4)
    # brute force over the real parameters (main loop theorem) at that frequency: a lower
    # bound on mu, which meets the stated value
    exact = mixed_mu_brute_force(freqresp(CL, [w_peak])[0], 4, points=9, polish=4)
    assert upper * (1 - 1e-4) <= exact <= peak * (1 + 1e-9)


def test_a_refined_controller_not_stored_is_named():
    with pytest.raises(ModelError, match=r"stored for x_max in \[0.035, 0.041\] m, not 0.05"):
        tmu.refined_controller(0.05)
    with pytest.raises(ModelError, match=r"stored for x_max in \[0.035, 0.041\] m, not 'x'"):
        tmu.refined_controller("x")
