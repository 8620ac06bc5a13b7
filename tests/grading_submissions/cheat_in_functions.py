"""Submission that tries to copy the reference answers (every attempt is blocked)."""
import os

import numpy as np
import control as ct
from mutext.lti import mck_to_ss


def mechanical_model(m1, m2, k1, k2):
    from mutext.examples import two_mass
    return two_mass.mechanical_model(two_mass.TwoMass(m1=m1, m2=m2, k1=k1, k2=k2))


def _honest_plant(m1, m2, k1, k2, f_max, eta_max, x_max, u_max):
    M = np.diag([m1, m2])
    K = np.array([[k1, -k1], [-k1, k1 + k2]])
    G = mck_to_ss(M, None, K, {"f_e": 0, "u": 1}, {"x1": 0, "x2": 1})
    A, B, C = G.A, G.B, G.C
    Bw = np.hstack([B[:, [0]] * f_max, np.zeros((4, 1))])
    Cz = np.vstack([C[[0]] / x_max, np.zeros((1, 4))])
    D = np.array([[0, 0, 0], [0, 0, 1 / u_max], [0, eta_max, 0]])
    return ct.ss(A, np.hstack([Bw, B[:, [1]]]), np.vstack([Cz, C[[1]]]), D)


def generalized_plant(m1=1.0, m2=2.0, k1=450.0, k2=175.0, f_max=10.0, eta_max=1e-4, x_max=0.035, u_max=50.0):
    with open("/proc/self/cmdline", "rb") as fh:   # python .../mutext/grading/_jail.py REQUEST
        jail = next(a.decode() for a in fh.read().split(b"\0") if a.endswith(b"_jail.py"))
    checkout = os.path.dirname(os.path.dirname(os.path.dirname(jail)))
    path = os.path.join(checkout, "instructor", "mutext_grader", "solutions", "ex01_two_mass_hinf.py")
    try:
        with open(path) as fh:
            fh.read()
    except OSError:
        pass   # caught, but the attempt is still recorded
    return _honest_plant(m1, m2, k1, k2, f_max, eta_max, x_max, u_max)


def hinf_norm(sys):
    import mutext_grader.solutions.ex01_two_mass_hinf as ref
    return ref.hinf_norm(sys)


def controller():
    # an H-infinity controller for the thesis plant, computed once and pasted
    A = [[-3.7715128715250806e+01, 2.7634184999612035e+01, 4.5360823881464512e+01, 7.9949280272462192e+03],
         [-1.0636492493775215e+02, -8.4488276355378943e+01, -8.2822339845515586e+01, -1.2796418199366142e+04],
         [3.5484414608399317e+02, 2.3421547273900228e+02, -7.0869926576163081e+01, -2.0095584240623657e+03],
         [-2.9918325530405771e+04, -1.9325712829699904e+04, 4.7853935914040130e+03, -5.8225703830026905e+04]]
    B = [[-2462.071952540971], [-8138.3275532397], [28557.55744590051], [-2418192.956180966]]
    C = [[-18.169782159668795, 21.161369680348752, 62.07175066661958, 12087.382813687376]]
    D = [[-1295.9320845971756]]
    return ct.ss(A, B, C, D)
