"""H-infinity controllers that achieve their level on badly scaled plants.

Everything is checked against references independent of mutext:

* the closed loop is rebuilt by python-control (``StateSpace.lft``) and its poles by numpy;
* its norm by SLICOT AB13DD through python-control (``control.linfnorm``, equilibrated)
  and by a dense complex solve of ``C (jwI - A)^-1 B + D`` written here (scipy's
  diagonal balancing, numpy's LU) at AB13DD's peak and on a grid;
* the level by SLICOT SB10AD (slycot): at ``gamma (1 - 1e-3)`` it must not produce a
  controller that achieves that level (it refuses, or its controller misses), and in
  the slow test its full gamma iteration (``control.hinfsyn``) must agree with ours
  wherever its own controller achieves its claim.
"""
import warnings

import control as ct
import numpy as np
import pytest
import scipy.linalg as sla

from mutext.examples import random_plants, two_mass
from mutext.hinf import hinfsyn, slycot_hinfsyn
from mutext.lti import ss

FAMILY = range(60)


def scaled_plant(seed, k=3.0):
    """A random plant of :mod:`mutext.examples.random_plants` (states, time, u and y already
    scaled by up to 10^+-2) scaled once more: states, every input, every output and the
    time axis by independent factors 10^U(-k, k).  State units then span up to 1e10."""
    rp = random_plants.random_plant(seed)
    rng = np.random.default_rng(10_000 + seed)
    A, B, C, D = (np.asarray(X, float) for X in (rp.P.A, rp.P.B, rp.P.C, rp.P.D))
    n, m, p = A.shape[0], B.shape[1], C.shape[0]
    t = 10.0 ** rng.uniform(-k, k, n)          # x = diag(t) x_new
    si = 10.0 ** rng.uniform(-k, k, m)         # inputs [w; u] in new units
    so = 10.0 ** rng.uniform(-k, k, p)         # outputs [z; y] in new units
    c = 10.0 ** rng.uniform(-k, k)             # time scale: P(s / c)
    A = c * A * t[None, :] / t[:, None]
    B = c * B / t[:, None] * si[None, :]
    C = C * t[None, :] * so[:, None]
    D = D * si[None, :] * so[:, None]
    return ss(A, B, C, D), rp.nmeas, rp.ncon


def dense_gain(sys, w):
    """sigma_max(C (jwI - A)^-1 B + D) by one dense complex LU per frequency, on the
    states balanced by scipy (an exact diagonal similarity)."""
    A, B, C, D = (np.asarray(X, float) for X in (sys.A, sys.B, sys.C, sys.D))
    _, (sc, _) = sla.matrix_balance(A, permute=False, separate=True)
    A, B, C = A / sc[:, None] * sc[None, :], B / sc[:, None], C * sc[None, :]
    w = np.atleast_1d(np.asarray(w, float))
    M = np.broadcast_to(-A, (w.size,) + A.shape).astype(complex)
    M[:, np.arange(A.shape[0]), np.arange(A.shape[0])] += 1j * w[:, None]
    G = C[None] @ np.linalg.solve(M, B[None]) + D[None]
    return np.linalg.svd(G, compute_uv=False)[:, 0]


def independent_norm(CL, agree=1e-4):
    """(stable, norm) of a closed loop: AB13DD's norm, confirmed by a dense solve at its peak
    frequency and on a grid; the larger of the two is returned.  With ``agree=None`` a
    disagreement gives ``nan`` instead of failing (for other tools' controllers).

    The two agree to 1e-4, not to rounding: these loops are ill-conditioned (seed 8: the peak
    is the DC gain of a closed loop whose A has condition number 1.7e24; in 50-digit
    arithmetic it is 3307539.9248, the dense solve gives 3307540.97 and AB13DD 3307587.5).
    On slycot's controllers (poles up to 1e10 rad/s) they can differ by 5 % or more."""
    poles = np.linalg.eigvals(np.asarray(CL.A, float))
    if not np.all(poles.real < 0):
        return False, np.inf
    gpk, fpk = ct.linfnorm(CL)
    mags = np.abs(poles)
    grid = np.concatenate([[0.0, fpk], np.logspace(np.log10(mags.min()) - 3, np.log10(mags.max()) + 3, 300)])
    g = dense_gain(CL, grid)
    # AB13DD's peak is a gain the system has, and nothing on the grid exceeds it
    consistent = abs(g[1] / gpk - 1) <= (agree or 1e-4) and g.max() <= gpk * (1 + (agree or 1e-4))
    if agree is None and not consistent:
        return True, float("nan")
    assert consistent, (gpk, g[1], g.max())
    return True, float(max(gpk, g.max()))


def slicot_refuses_below(P, nmeas, ncon, level):
    """True if SLICOT SB10AD at fixed ``level`` finds no controller achieving it: it refuses,
    or the closed loop with its controller is unstable or has a larger norm."""
    from slycot import sb10ad
    A, B, C, D = (np.asarray(X, float) for X in (P.A, P.B, P.C, P.D))
    try:
        out = sb10ad(A.shape[0], B.shape[1], C.shape[0], ncon, nmeas, level, A, B, C, D, job=4)
    except Exception:   # slycot raises several error types; each one is a refusal
        return True
    CL = P.lft(ct.ss(*out[1:5]), nu=ncon, ny=nmeas)
    stable, achieved = independent_norm(CL)
    return (not stable) or achieved > level


def check_level_and_controller(P, nmeas, ncon, res, tol=1e-3):
    CL = P.lft(res.K, nu=ncon, ny=nmeas)                   # python-control's interconnection
    stable, achieved = independent_norm(CL)
    assert stable
    # the controller achieves the level to tol, and the level is not above what it achieves
    assert achieved <= res.gamma * (1 + tol), (achieved, res.gamma)
    assert res.gamma <= achieved * (1 + 1e-4)
    assert res.closed_loop_norm == pytest.approx(achieved, rel=1e-4)
    # SLICOT finds no controller 0.1 % below the level
    assert slicot_refuses_below(P, nmeas, ncon, res.gamma * (1 - tol))
    return achieved


# every third plant of the family in the default run (the rest with the slow tests)
@pytest.mark.parametrize("seed", [s if s % 3 == 0 else pytest.param(s, marks=pytest.mark.slow) for s in FAMILY])
def test_badly_scaled_plant_controller_achieves_level(seed):
    P, nmeas, ncon = scaled_plant(seed)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = hinfsyn(P, nmeas, ncon)
    assert res.construction.startswith("central")
    check_level_and_controller(P, nmeas, ncon, res)


@pytest.mark.slow
@pytest.mark.parametrize("seed", FAMILY)
def test_badly_scaled_plant_level_agrees_with_slycot_hinfsyn(seed):
    """slycot's full gamma iteration (``control.hinfsyn``, 10 s limit); compared only where its
    controller, checked by python-control and AB13DD, achieves its claim to 1e-4 (on this family
    it times out or misses its claim on about half of the plants)."""
    P, nmeas, ncon = scaled_plant(seed)
    ref = slycot_hinfsyn(P, nmeas, ncon, timeout=10)
    if ref.status in ("timeout", "error"):
        pytest.skip(f"slycot: {ref.status} {ref.note}")
    stable, achieved = independent_norm(P.lft(ref.K, nu=ncon, ny=nmeas), agree=None)
    if not stable or not abs(achieved / ref.gamma - 1) <= 1e-4:
        pytest.skip(f"slycot claims {ref.gamma:.7g}, its controller achieves {achieved:.7g} "
                    "(AB13DD and the dense solve, nan where they disagree)")
    res = hinfsyn(P, nmeas, ncon)
    # slycot's level carries its own tolerance (its iteration stops above the optimum, by
    # 8e-4 on seed 17, where our controller achieves less than slycot's claims): the two
    # agree to 1e-3 and our controller does at least as well as slycot's
    assert res.gamma == pytest.approx(ref.gamma, rel=1e-3)
    assert res.closed_loop_norm <= achieved * (1 + 1e-4)


# ---------------------------------------------------------------- the singular and scaled cases of the issue

def _two_mass(which=None, value=None, c=1.0):
    P = two_mass.plant()
    A, B, C, D = (np.asarray(X, float) for X in (P.A, P.B, P.C, P.D))
    if which == "D12":
        D[1, 2] = value        # z2 = value * u
    elif which == "D21":
        D[2, 1] = value        # y = ... + value * w2
    return ss(A * c, B * c, C * c, D * c)


@pytest.mark.parametrize("which", ["D12", "D21"])
def test_nearly_singular_two_mass(which):
    """D12 or D21 = 1e-5: the LMI controller sat at 30 % back-off; the central
    controller achieves the level at 1e-4.  slycot's gamma iteration answers here."""
    P = _two_mass(which, 1e-5)
    res = hinfsyn(P, 1, 1)
    achieved = check_level_and_controller(P, 1, 1, res)
    assert res.backoff <= 1e-3
    ref = slycot_hinfsyn(P, 1, 1, timeout=30)
    assert ref.status in ("verified", "unverified"), ref.note
    # slycot's level is within 1e-4 of ours (D21: its claim is 8e-6 below the level its own
    # controller achieves, and below ours, which our controller confirms to 1e-4)
    assert res.gamma == pytest.approx(ref.gamma, rel=1e-4)
    assert achieved <= ref.achieved * (1 + 1e-4)


@pytest.mark.parametrize("c", [1e8, 1e-4])
def test_two_mass_scaled_by_constant(c):
    """Every matrix times c: P'(s) = c P(s / c), level c * gamma.  At 1e8 slycot's own
    iteration does not return within a minute; the reference is slycot's level of the
    unscaled plant times c."""
    ref = slycot_hinfsyn(two_mass.plant(), 1, 1, timeout=30)
    assert ref.status == "verified"
    P = _two_mass(c=c)
    res = hinfsyn(P, 1, 1)
    achieved = check_level_and_controller(P, 1, 1, res)
    assert res.gamma / c == pytest.approx(ref.gamma, rel=1e-5)
    assert achieved / c <= ref.gamma * (1 + 2e-4)


def test_near_axis_plant_controller_achieves_level():
    """The D-scaled distillation plant with weight poles at -1e-6 rad/s (tests/data): the LMI
    controller needed 10 % back-off or failed; the central controller reaches 1e-4."""
    from pathlib import Path
    data = np.load(Path(__file__).parent / "data" / "near_axis_plant.npz")
    P = ss(data["A"], data["B"], data["C"], data["D"])
    res = hinfsyn(P, 2, 2)
    check_level_and_controller(P, 2, 2, res)
    assert res.backoff <= 1e-3
    ref = slycot_hinfsyn(P, 2, 2, timeout=30)
    if ref.status == "verified":
        assert res.gamma == pytest.approx(ref.gamma, rel=1e-5)


def test_construction_and_level_method_are_reported():
    P = two_mass.plant()
    res = hinfsyn(P, 1, 1)
    assert res.construction.startswith("central") and "Riccati" in res.info["level_method"]
    lmi = hinfsyn(P, 1, 1, method="lmi")
    assert lmi.construction.startswith("LMI") and lmi.info["level_method"].startswith("LMI")
    # both routes reach the same level, each proven by its own controller (AB13DD)
    for r in (res, lmi):
        check_level_and_controller(P, 1, 1, r)
    assert res.gamma == pytest.approx(lmi.gamma, rel=1e-6)


def test_nearly_singular_d21_not_worse_than_slycot():
    """D21 = 1e-6: the central controller achieves 0.8447 (AB13DD and a dense solve), and
    SLICOT finds no controller 0.1 % below our level.  Where slycot's gamma iteration stops
    depends on the machine's LAPACK on this nearly singular problem (0.8635 and 0.8495 seen,
    2 % and 0.6 % above the optimum); it never stops below ours."""
    P = _two_mass("D21", 1e-6)
    res = hinfsyn(P, 1, 1)
    achieved = check_level_and_controller(P, 1, 1, res)
    assert achieved == pytest.approx(0.8447, rel=1e-3)
    ref = slycot_hinfsyn(P, 1, 1, timeout=30)
    assert ref.status == "verified"
    assert achieved <= ref.achieved * (1 + 1e-6)


def test_singular_d21_regularised_central_controller():
    """D21 = 0 (noise-free measurement, the structure of model-based identification): outside
    the Riccati assumptions.  The LMI level read 0.8187 and its controller achieved 0.8175; the
    central controllers of regularised plants reach 0.8070 (AB13DD and a dense solve).  An
    independent upper bound of the singular infimum: slycot's verified level of the plant with
    D21 = 1e-6 (0.8635).  No independent lower bound is available (slycot refuses D21 = 0)."""
    P = _two_mass("D21", 0.0)
    res = hinfsyn(P, 1, 1)
    assert "regularised" in res.construction
    stable, achieved = independent_norm(P.lft(res.K, nu=1, ny=1))
    assert stable
    assert res.gamma == pytest.approx(achieved, rel=1e-4)
    ref = slycot_hinfsyn(_two_mass("D21", 1e-6), 1, 1, timeout=30)
    assert ref.status == "verified"
    assert achieved <= ref.achieved


def test_closed_loop_stability_verdict_names_the_deciding_pole():
    """The verdict recorded with the result names the closed-loop pole closest to failing;
    it is python-control's rightmost closed-loop pole."""
    import re
    P, nmeas, ncon = scaled_plant(3)
    res = hinfsyn(P, nmeas, ncon)
    m = re.search(r"closest is the pole at s = (\S+) \(real part (\S+), threshold (\S+)\)", res.info["stability"])
    assert m, res.info["stability"]
    poles = P.lft(res.K, nu=ncon, ny=nmeas).poles()
    assert float(m.group(2)) == pytest.approx(poles.real.max(), rel=1e-2)
    assert float(m.group(3)) < 0


@pytest.fixture(scope="module")
def mbi_plants():
    """The plants of the K steps of the cracked-rotor identification (``mutext demo crack``,
    thesis data path): D21 ~ 1e-10 (measurement noise regularisation), lightly damped rotor
    modes.  The LMI controller failed at every back-off on one of them, slycot times out.

    The demo identifies by the convex route (``identify(method="auto")``), which synthesizes no
    H-infinity controller; the K steps are those of the thesis's W_z search by D-K iteration,
    ``identify(method="dk")``, which the demo is made to run here.  Each W_z try hands its plant
    to :func:`mutext.dk.dk_iteration` (looked up in :mod:`mutext.dk` at every search), whose
    first K step synthesizes on it as given."""
    import mutext.dk as dkm
    import mutext.mbi as mbi
    from mutext.demos import crack
    cap = []
    orig, identify = dkm.dk_iteration, mbi.identify

    def record(P, structure, nmeas, ncon, **kw):
        cap.append((P, nmeas, ncon))
        return orig(P, structure, nmeas, ncon, **kw)

    def by_dk(*args, **kw):
        assert kw.get("method", "auto") == "auto", kw["method"]
        return identify(*args, **{**kw, "method": "dk"})
    mp = pytest.MonkeyPatch()
    mp.setattr(dkm, "dk_iteration", record)
    mp.setattr(mbi, "identify", by_dk)          # the demo imports it from mutext.mbi when it runs
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            crack.solve(out=None, thesis_tables=True)
    finally:
        mp.undo()
    assert len(cap) >= 3
    return cap


@pytest.mark.slow
def test_rotor_mbi_plants_controller_achieves_level(mbi_plants):
    for P, nmeas, ncon in mbi_plants:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            res = hinfsyn(P, nmeas, ncon)
        check_level_and_controller(P, nmeas, ncon, res)
        assert res.backoff <= 1e-3


@pytest.mark.parametrize("c", [1e-3, 1e-6, pytest.param(1e-9, marks=pytest.mark.xfail(
    strict=True, reason="the level comes out 1.2457e-9 instead of 1.0069e-9: the w -> z normalisation splits "
                        "one factor between w and z, which leaves D21 at about sqrt(1e-9) against C2 and the "
                        "filter problem nearly singular; scaling w and z separately fixes this plant but breaks "
                        "3 of the 60 badly scaled ones"))])
def test_optimal_level_near_zero(c):
    # scaling the disturbance inputs by c scales every closed-loop map from w, hence the
    # optimal level, by exactly c: a plant with a level near 0 is this plant's level times c
    P = two_mass.plant(two_mass.THESIS)
    nw = P.ninputs - 1
    A, B, C, D = (np.asarray(X, float) for X in (P.A, P.B, P.C, P.D))
    B, D = B.copy(), D.copy()
    B[:, :nw] *= c
    D[:, :nw] *= c
    Pc = ss(A, B, C, D)
    g1 = hinfsyn(P, 1, 1).gamma
    res = hinfsyn(Pc, 1, 1)
    assert res.gamma == pytest.approx(c * g1, rel=1e-4)
    check_level_and_controller(Pc, 1, 1, res)


def test_level_zero_not_attained():
    # square D12, D21 with A - B2 D12^-1 C1 and A - B1 D21^-1 C2 stable: X_inf = Y_inf = 0 at
    # every level, so the optimal level is 0 and only approached by ever larger controllers
    rng = np.random.default_rng(3)
    n = 8
    A = rng.standard_normal((n, n)) / np.sqrt(n)
    A -= (np.linalg.eigvals(A).real.max() - 0.3) * np.eye(n)      # open-loop unstable
    B2, C2 = rng.standard_normal((n, 2)), rng.standard_normal((2, n))
    F = np.linalg.lstsq(B2, A + 2 * np.eye(n), rcond=None)[0]      # A - B2 F has poles near -2
    L = np.linalg.lstsq(C2.T, (A + 2 * np.eye(n)).T, rcond=None)[0].T
    D12, D21 = rng.standard_normal((2, 2)), rng.standard_normal((2, 2))
    C1, B1 = D12 @ F, L @ D21
    assert np.linalg.eigvals(A - B2 @ F).real.max() < 0 and np.linalg.eigvals(A - L @ C2).real.max() < 0
    P = ss(A, np.hstack([B1, B2]), np.vstack([C1, C2]), np.block([[np.zeros((2, 2)), D12], [D21, np.zeros((2, 2))]]))
    res = hinfsyn(P, 2, 2)
    CL = P.lft(res.K, nu=2, ny=2)                                    # python-control's interconnection
    assert np.linalg.eigvals(CL.A).real.max() < 0
    achieved = ct.linfnorm(CL)[0]
    assert achieved < 1e-6 * np.linalg.norm(B1) * np.linalg.norm(C1)
    assert achieved == pytest.approx(res.gamma, rel=0.1)
    assert any("not attained" in note for note in res.notes)
