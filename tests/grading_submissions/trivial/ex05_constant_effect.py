"""ex05, a submission that does not solve: always a grounded spring at mass 1 in (d), inputs elsewhere."""
import numpy as np


def log_misfit(model_re, model_im, meas_re, meas_im):
    return float(len(model_re)) * 1e-4          # the RSS of 1 % noise, N sigma^2, without looking at the data


def response_with_grounded_spring(M, C, K, f_hz, i_in, i_out, dof, k):
    return np.array([np.asarray(f_hz, float), np.zeros(len(f_hz))])


def fit_grounded_spring(M, C, K, f_hz, i_in, i_out, meas_re, meas_im, dof):
    return 0.2 * float(K[dof][dof])


def find_effect(M, C, K, f_hz, channels, data_re, data_im, noise):
    return np.array([1.0, 1.0, 0.15 * float(K[0][0])])
