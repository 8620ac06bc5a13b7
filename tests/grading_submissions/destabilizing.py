"""Submission whose controller is positive position feedback stiffer than k2: the loop is unstable."""
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
    return ct.ss(np.zeros((0, 0)), np.zeros((0, 1)), np.zeros((1, 0)), [[1000.0]])
