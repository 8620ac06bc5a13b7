r"""slycot's H-infinity norm and Riccati synthesis, run in a child process with a time limit and
accepted only when the closed loop rebuilt from the plant passes the check.
"""
from __future__ import annotations

import time
import warnings
from dataclasses import dataclass

import control as ct
import numpy as np
import scipy.linalg as sla

from ..lti import as_ss, hinf_norm, lft_lower, ss, stability


def slycot_hinf_norm(sys) -> float:
    r"""H-infinity norm by SLICOT AB13DD (through slycot), used as an independent check.

    AB13DD is asked to equilibrate the system first (``EQUIL='S'``, as
    python-control's ``linfnorm`` does): without it, on the flat closed loops of
    near-optimal controllers of badly scaled plants, it overestimated the norm
    by up to 1.3e-3 relative, where a direct complex solve at its own peak
    frequency agreed with our value to 1e-7.

    Parameters
    ----------
    sys : control.StateSpace or control.TransferFunction
        Continuous-time, stable system (any number of inputs and outputs).

    Returns
    -------
    float
        :math:`\|G\|_\infty` (the peak of the largest singular value over
        frequency); the 2-norm of ``D`` for a static system; ``nan`` when slycot
        is not available or fails.
    """
    sys = as_ss(sys)
    try:
        from slycot import ab13dd
    except ImportError:  # pragma: no cover - slycot is a dependency
        return float("nan")
    n, m, p = sys.nstates, sys.ninputs, sys.noutputs
    if n == 0:
        return float(np.linalg.norm(np.asarray(sys.D, float), 2))
    try:
        gpeak, _ = ab13dd('C', 'I', 'S', 'D', n, m, p, np.asarray(sys.A, float), np.eye(n),
                          np.asarray(sys.B, float), np.asarray(sys.C, float),
                          np.asarray(sys.D, float))
    except Exception:  # slycot raises several error types; the check is advisory
        return float("nan")
    return float(gpeak)


@dataclass
class SlycotReference:
    """What slycot's Riccati ``hinfsyn`` returned for a plant, and whether it holds up.

    ``status`` is ``'verified'`` (its controller stabilises the rebuilt closed
    loop and achieves the claimed level to ``rtol``), ``'unverified'`` (it
    returned, but the claim does not hold: see ``note``), ``'error'`` (it
    refused the problem) or ``'timeout'``.

    Attributes
    ----------
    status : {"verified", "unverified", "error", "timeout"}
        The verdict (see above).
    gamma : float
        The level slycot claims for its controller (``nan`` on error or timeout).
    K : control.StateSpace or None
        Its controller (``nmeas`` inputs, ``ncon`` outputs); None on error or timeout.
    achieved : float
        The closed-loop H-infinity norm the controller achieves, recomputed by
        :func:`mutext.lti.hinf_norm` on the loop rebuilt from the plant (``inf``
        for an unstable loop, ``nan`` when not computed).
    note : str
        Why the result is not verified (slycot's error, the unstable pole, the
        claimed and achieved levels); empty when verified.
    seconds : float
        Time slycot took [s] (wall clock).
    """
    status: str
    gamma: float = float("nan")
    K: ct.StateSpace | None = None
    achieved: float = float("nan")
    note: str = ""
    seconds: float = 0.0


def _slycot_child(P, nmeas, ncon, conn, cpu_seconds=None):
    if cpu_seconds is not None:
        import resource
        soft = max(1, int(np.ceil(cpu_seconds)))
        # SIGXCPU at the soft limit, SIGKILL one second of CPU later
        resource.setrlimit(resource.RLIMIT_CPU, (soft, soft + 1))
    try:
        t0 = time.perf_counter()
        K, _, gam, _ = ct.hinfsyn(P, nmeas, ncon)
        conn.send(("ok", float(gam), (K.A, K.B, K.C, K.D), time.perf_counter() - t0))
    except Exception as exc:  # slycot raises several error types; each is a result to report
        conn.send(("error", f"{type(exc).__name__}: {str(exc).splitlines()[0][:80] if str(exc) else ''}",
                   None, 0.0))
    conn.close()


def slycot_hinfsyn(P, nmeas: int, ncon: int, timeout: float | None = 20.0,
                   rtol: float = 1e-3) -> SlycotReference:
    """Run python-control/slycot's ``hinfsyn`` as an independent reference, and check its claim.

    slycot (SB10AD) can take very long or never return on badly scaled or
    singular plants, so with ``timeout`` set it runs in a forked child process
    that is stopped once it has used ``timeout`` seconds of CPU time (the
    operating system's CPU-time limit, so the outcome does not depend on how
    busy the machine is; a child that waits without computing is stopped
    after ``10 * timeout + 60`` seconds of wall-clock time).  Its controller is
    then checked the same way ours is: closed loop rebuilt from ``P`` and
    ``K``, stability, norm recomputed by :func:`mutext.lti.hinf_norm`.

    Parameters
    ----------
    P : control.StateSpace
        Generalized plant with inputs ``[w; u]`` and outputs ``[z; y]``
        (continuous time).
    nmeas : int
        Number of measurements ``y`` (the last outputs of ``P``).
    ncon : int
        Number of control inputs ``u`` (the last inputs of ``P``).
    timeout : float or None
        CPU time [s] the child process may use; None runs slycot in this
        process, without a limit.
    rtol : float
        Largest relative difference between the claimed level and the
        recomputed closed-loop norm for the status ``'verified'``.

    Returns
    -------
    SlycotReference
        The claim, the controller, the achieved norm and the verdict.
    """
    import multiprocessing as mp
    P = as_ss(P, "P")
    t0 = time.perf_counter()
    if timeout is None:
        parent, child = mp.Pipe(duplex=False)
        _slycot_child(P, nmeas, ncon, child)
        msg = parent.recv()
    else:
        parent, child = mp.Pipe(duplex=False)
        import signal
        proc = mp.get_context("fork").Process(target=_slycot_child, args=(P, nmeas, ncon, child, timeout))
        with warnings.catch_warnings():  # fork from a threaded process: the child only runs slycot
            warnings.simplefilter("ignore", DeprecationWarning)
            proc.start()
        child.close()
        if not parent.poll(10 * timeout + 60):
            proc.kill()
            proc.join()
            return SlycotReference("timeout", note=f"no answer within {10 * timeout + 60:g} s (idle child)",
                                   seconds=time.perf_counter() - t0)
        try:
            msg = parent.recv()
        except EOFError:
            proc.join()
            if proc.exitcode in (-signal.SIGXCPU, -signal.SIGKILL):
                return SlycotReference("timeout", note=f"no answer within {timeout:g} s of CPU time",
                                       seconds=time.perf_counter() - t0)
            msg = ("error", f"slycot process died (exit code {proc.exitcode})", None, 0.0)
        proc.join()
    status, gam, mats, sec = msg
    if status == "error":
        return SlycotReference("error", note=gam, seconds=sec)
    K = ss(*mats)
    CL = lft_lower(P, K, nmeas, ncon)
    stab = stability(CL)
    if not stab.stable:
        return SlycotReference("unverified", gam, K, np.inf, f"its closed loop is {stab.message}", sec)
    with warnings.catch_warnings():  # slycot's controllers often have poles near 1e10 rad/s
        warnings.simplefilter("ignore", sla.LinAlgWarning)
        achieved = hinf_norm(CL).value
    if abs(achieved - gam) > rtol * gam:
        return SlycotReference("unverified", gam, K, achieved,
                               f"claims {gam:.7g}, its controller achieves {achieved:.7g}", sec)
    return SlycotReference("verified", gam, K, achieved, "", sec)
