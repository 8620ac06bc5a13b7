"""Benchmark: measured resonances (:func:`mutext.frfit.resonances`) against sdypy-EMA.

The three-mass rig of ``mutext/data/three_mass.toml`` (FRF f1 -> x1, 0.02-10 Hz
in 0.02 Hz steps) is "measured" with circular complex Gaussian noise of 0.3 %,
1 % and 3 % of |H| for several seeds.  The exact natural frequencies
:math:`f_n = |p|/2\\pi` and damping ratios :math:`\\zeta = -\\mathrm{Re}\\,p/|p|`
are the eigenvalues of the first-order form of the model's M, C, K (scipy).
Each noisy FRF goes to

* mutext: vector fitting with automatic order, bootstrap standard
  uncertainties (``n_boot`` = 20; also timed with ``n_boot=0``, the point
  estimates alone);
* sdypy-EMA: LSCF poles up to ``pol_order_high`` and its non-interactive
  ``select_closest_poles`` at the exact frequencies rounded to 0.1 Hz (as read
  off a plot).  sdypy's pole selection works with absolute windows of 2-25 Hz
  and masks unstable poles with zeros, so below ~2 Hz it picks the zeros: the
  frequency axis is handed over multiplied by 100 (a time scaling, which leaves
  damping ratios unchanged) and the frequencies scaled back.  LSFD (residues for
  fixed poles) is not needed for f_n and zeta and is not run.

Columns: exact f_n and zeta; mutext f_n +/- std and zeta +/- std; z = (mutext -
exact)/std; sdypy f_n and zeta; "in3" = sdypy value within 3 std of mutext's.
A summary per noise level gives the times per call and the error of each
package against the exact values in units of mutext's std.

Usage::

    python benchmarks/bench_resonances.py [--seeds 3] [--noise 0.003 0.01 0.03] [--pol-order-high 30]
"""
from __future__ import annotations

import argparse
import contextlib
import io
import os
import time

import numpy as np

SCALE = 100.0        # frequency scaling for sdypy's pole selection (see the docstring)
F_HZ = np.arange(1, 501) * 0.02     # uniform, starting at one step: sdypy's LSCF pads 0..f[0] with zeros


def exact_modes(M, C, K):
    """f_n [Hz] and zeta of the underdamped eigenvalues of M x'' + C x' + K x = 0, by frequency."""
    import scipy.linalg as sla
    n = M.shape[0]
    A = np.block([[np.zeros((n, n)), np.eye(n)], [-sla.solve(M, K), -sla.solve(M, C)]])
    lam = sla.eigvals(A)
    lam = lam[lam.imag > 0]
    lam = lam[np.argsort(np.abs(lam))]
    return np.abs(lam) / (2 * np.pi), -lam.real / np.abs(lam)


def sdypy_modes(EMA, f, G, approx_hz, pol_order_high):
    """sdypy-EMA LSCF + select_closest_poles; returns (f_n [Hz], zeta) in the order of approx_hz."""
    with contextlib.redirect_stderr(io.StringIO()):          # its stabilisation always draws a tqdm bar
        a = EMA.Model(frf=G, freq=f * SCALE, lower=f[0] * SCALE, upper=f[-1] * SCALE,
                      pol_order_high=pol_order_high, frf_form="receptance")
        a.get_poles(method="lscf", show_progress=False)
        a.select_closest_poles(list(np.asarray(approx_hz) * SCALE))
    return np.asarray(a.nat_freq, float) / SCALE, np.asarray(a.nat_xi, float)


def main(argv=None):
    import mutext
    from mutext.frfit import resonances
    from mutext.lti import blas_single_thread
    from mutext.rotor.model import load_model

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=3, help="noise realizations per level")
    ap.add_argument("--noise", type=float, nargs="+", default=[0.003, 0.01, 0.03])
    ap.add_argument("--pol-order-high", type=int, default=30, help="sdypy LSCF highest order")
    a = ap.parse_args(argv)
    try:
        from sdypy import EMA
    except ImportError:
        EMA = None
        print("sdypy-EMA is not installed, its columns stay empty; install it with\n"
              "    .venv/bin/pip install sdypy-EMA\n")

    model = load_model(os.path.join(os.path.dirname(mutext.__file__), "data", "three_mass.toml"))
    M, C, K, _ = model.matrices(model.values(None))
    fn, zn = exact_modes(M, C, K)
    H = model.frf(F_HZ, inputs=["f1"], outputs=["x1"]).H[0, 0]
    approx = np.round(fn, 1)

    hdr = (f"{'noise':>5} {'seed':>4} {'mode':>4} {'f_n exact':>9} {'zeta exact':>10} | {'mutext f_n +/- std':>21} "
           f"{'z':>5} {'zeta +/- std':>19} {'z':>5} | {'sdypy f_n':>9} {'in3':>3} {'zeta':>7} {'in3':>3}")
    print(hdr)
    print("-" * len(hdr))
    summary = []
    with blas_single_thread():              # both packages on one BLAS thread (small matrices)
        for level, noise in enumerate(a.noise):
            t_mx, t_mx0, t_sd = [], [], []
            z_mx, z_sd, in3 = [], [], []
            for seed in range(a.seeds):
                e = np.random.default_rng([level, seed]).standard_normal((2, F_HZ.size))
                G = H + noise * np.abs(H) * (e[0] + 1j * e[1]) / np.sqrt(2)
                t0 = time.perf_counter()
                R = resonances(F_HZ, G, rng=seed)
                t_mx.append(time.perf_counter() - t0)
                t0 = time.perf_counter()
                resonances(F_HZ, G, n_boot=0)
                t_mx0.append(time.perf_counter() - t0)
                if EMA is not None:
                    t0 = time.perf_counter()
                    sf, sz = sdypy_modes(EMA, F_HZ, G, approx, a.pol_order_high)
                    t_sd.append(time.perf_counter() - t0)
                else:
                    sf = sz = np.full(fn.size, np.nan)
                for i, (f0, z0) in enumerate(zip(fn, zn)):
                    r = min(R, key=lambda r: abs(r.freq_hz - f0)) if R else None
                    if r is None or abs(r.freq_hz - f0) > 0.1 * f0:
                        print(f"{noise:5.1%} {seed:4d} {i + 1:4d} {f0:9.5f} {z0:10.5f} | mutext found no resonance here")
                        continue
                    zf, zz = (r.freq_hz - f0) / r.freq_std, (r.damping_ratio - z0) / r.damping_std
                    okf = abs(sf[i] - r.freq_hz) <= 3 * r.freq_std
                    okz = abs(sz[i] - r.damping_ratio) <= 3 * r.damping_std
                    z_mx += [zf, zz]
                    if EMA is not None:
                        z_sd += [(sf[i] - f0) / r.freq_std, (sz[i] - z0) / r.damping_std]
                        in3 += [okf, okz]
                    yn = (lambda ok: "-" if EMA is None else "yes" if ok else "no")
                    print(f"{noise:5.1%} {seed:4d} {i + 1:4d} {f0:9.5f} {z0:10.5f} | "
                          f"{r.freq_hz:9.5f} +/- {r.freq_std:7.5f} {zf:5.1f} {r.damping_ratio:7.5f} +/- {r.damping_std:7.5f} "
                          f"{zz:5.1f} | {sf[i]:9.5f} {yn(okf):>3} {sz[i]:7.5f} {yn(okz):>3}")
            summary.append((noise, np.mean(t_mx), np.mean(t_mx0), np.mean(t_sd) if t_sd else np.nan,
                            np.sqrt(np.mean(np.square(z_mx))), np.mean(np.abs(z_mx) <= 3),
                            np.sqrt(np.mean(np.square(z_sd))) if z_sd else np.nan,
                            np.mean(in3) if in3 else np.nan))

    print("\nper noise level: seconds per call (mutext with bootstrap / point estimates only; sdypy LSCF "
          "+ selection),\nRMS error against the exact values in units of mutext's std, share within 3 std")
    h2 = (f"{'noise':>5} {'mutext s':>8} {'n_boot=0':>8} {'sdypy s':>8} | {'mutext RMS z':>12} {'in 3 std':>8} | "
          f"{'sdypy RMS z':>11} {'sdypy in 3 std of mutext':>24}")
    print(h2)
    print("-" * len(h2))
    for noise, tm, tm0, ts, rz, ok, rzs, oks in summary:
        sd = f"{rzs:11.2f} {oks:24.0%}" if EMA is not None else f"{'-':>11} {'-':>24}"
        print(f"{noise:5.1%} {tm:8.3f} {tm0:8.3f} {ts:8.3f} | {rz:12.2f} {ok:8.0%} | {sd}")


if __name__ == "__main__":
    main()
