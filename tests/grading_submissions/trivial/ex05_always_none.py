"""ex05, a submission that does not solve: "none" in every case of (d), zeros and inputs elsewhere."""
import numpy as np


def log_misfit(model_re, model_im, meas_re, meas_im):
    return 0.0


def response_with_grounded_spring(M, C, K, f_hz, i_in, i_out, dof, k):
    return np.zeros((2, len(f_hz)))


def fit_grounded_spring(M, C, K, f_hz, i_in, i_out, meas_re, meas_im, dof):
    return float(K[dof][dof])          # an input


def find_effect(M, C, K, f_hz, channels, data_re, data_im, noise):
    return np.array([0.0, 0.0, 0.0])
