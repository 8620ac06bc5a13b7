"""Submission that returns the wrong types and shapes, and ends the process in controller()."""
import os

import numpy as np
import control as ct


def mechanical_model(m1, m2, k1, k2):
    return np.eye(2)


def generalized_plant(m1=1.0, m2=2.0, k1=450.0, k2=175.0, f_max=10.0, eta_max=1e-4, x_max=0.035, u_max=50.0):
    return ct.ss(-np.eye(4), np.ones((4, 2)), np.ones((3, 4)), np.zeros((3, 2)))


def hinf_norm(sys):
    return "large"


def controller():
    os._exit(3)
