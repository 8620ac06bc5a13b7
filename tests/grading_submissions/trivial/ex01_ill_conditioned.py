"""ex01 submission that solves nothing: the thesis masses whatever the arguments, only the channels of the
generalized plant that must be zero, |D| as the norm, and a controller that does nothing (its output is
1e-12 of one state) with a badly conditioned realisation of 12 states, so that rounding in the closed
loop's eigenvalues once passed the plant's undamped modes as stable."""
import numpy as np
import control as ct


def mechanical_model(m1, m2, k1, k2):
    M = np.diag([1.0, 2.0])
    K = np.array([[450.0, -450.0], [-450.0, 625.0]])
    Z = np.zeros((2, 2))
    A = np.block([[Z, np.eye(2)], [-np.linalg.solve(M, K), Z]])
    return ct.ss(A, np.vstack([Z, np.linalg.inv(M)]), np.hstack([np.eye(2), Z]), Z)


def generalized_plant(m1=1.0, m2=2.0, k1=450.0, k2=175.0, f_max=10.0, eta_max=1e-4, x_max=0.035, u_max=50.0):
    return ct.ss(np.zeros((0, 0)), np.zeros((0, 3)), np.zeros((3, 0)), np.zeros((3, 3)))


def hinf_norm(sys):
    return float(np.linalg.norm(np.asarray(sys.D, float), 2))


def controller():
    rng = np.random.default_rng(8)
    n = 12
    A = -np.eye(n) + 1e8 * np.triu(rng.standard_normal((n, n)), 1)
    B = 1e8 * rng.standard_normal((n, 1))
    C = np.zeros((1, n))
    C[0, -1] = 1e-12
    return ct.ss(A, B, C, [[0.0]])
