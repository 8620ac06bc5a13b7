"""ex01 submission that solves nothing: a zero model, the thesis plant whatever the arguments, the gain
at DC as the norm, a zero controller."""
import numpy as np
import control as ct


def mechanical_model(m1, m2, k1, k2):
    return ct.ss(np.zeros((0, 0)), np.zeros((0, 2)), np.zeros((2, 0)), np.zeros((2, 2)))


def generalized_plant(m1=1.0, m2=2.0, k1=450.0, k2=175.0, f_max=10.0, eta_max=1e-4, x_max=0.035, u_max=50.0):
    # the thesis plant, whatever the arguments
    A = [[0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 0.0, 1.0], [-450.0, 450.0, 0.0, 0.0], [225.0, -312.5, 0.0, 0.0]]
    B = [[0.0, 0.0, 0.0], [0.0, 0.0, 0.0], [10.0, 0.0, 0.0], [0.0, 0.0, 0.5]]
    C = [[1 / 0.035, 0.0, 0.0, 0.0], [0.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0]]
    D = [[0.0, 0.0, 0.0], [0.0, 0.0, 0.02], [0.0, 1e-4, 0.0]]
    return ct.ss(A, B, C, D)


def hinf_norm(sys):
    G = np.atleast_2d(ct.evalfr(sys, 0.0))
    return float(np.linalg.norm(G, 2))


def controller():
    return ct.ss(np.zeros((0, 0)), np.zeros((0, 1)), np.zeros((1, 0)), [[0.0]])
