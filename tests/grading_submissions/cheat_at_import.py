"""Submission that imports the grader at module level (blocked; the whole file scores 0)."""
try:
    import mutext_grader as _grader
except Exception:
    _grader = None
import numpy as np
import control as ct
from mutext.lti import hinf_norm as _norm, mck_to_ss


def mechanical_model(m1, m2, k1, k2):
    M = np.diag([m1, m2])
    K = np.array([[k1, -k1], [-k1, k1 + k2]])
    return mck_to_ss(M, None, K, {"f_e": 0, "u": 1}, {"x1": 0, "x2": 1})


def generalized_plant(m1=1.0, m2=2.0, k1=450.0, k2=175.0, f_max=10.0, eta_max=1e-4, x_max=0.035, u_max=50.0):
    G = mechanical_model(m1, m2, k1, k2)
    A, B, C = G.A, G.B, G.C
    Bw = np.hstack([B[:, [0]] * f_max, np.zeros((4, 1))])
    Cz = np.vstack([C[[0]] / x_max, np.zeros((1, 4))])
    D = np.array([[0, 0, 0], [0, 0, 1 / u_max], [0, eta_max, 0]])
    return ct.ss(A, np.hstack([Bw, B[:, [1]]]), np.vstack([Cz, C[[1]]]), D)


def hinf_norm(sys):
    return _norm(sys).value


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
