"""ex05, a submission that does not solve: the model's own response and misfit, the most common kind at the
station with the largest response in (d)."""
import numpy as np


def _h(M, C, K, f_hz, i, o):
    M, C, K = (np.array(X, float) for X in (M, C, K))
    w = 2 * np.pi * np.asarray(f_hz, float)
    return np.array([np.linalg.solve(K - x ** 2 * M + 1j * x * C, np.eye(len(M))[i])[o] for x in w])


def log_misfit(model_re, model_im, meas_re, meas_im):
    return float(np.sum((np.asarray(model_re) - np.asarray(meas_re)) ** 2
                        + (np.asarray(model_im) - np.asarray(meas_im)) ** 2))


def response_with_grounded_spring(M, C, K, f_hz, i_in, i_out, dof, k):
    h = _h(M, C, K, f_hz, i_in, i_out)             # the spring left out
    return np.array([h.real, h.imag])


def fit_grounded_spring(M, C, K, f_hz, i_in, i_out, meas_re, meas_im, dof):
    return float(np.mean(np.diag(np.asarray(K, float))))


def find_effect(M, C, K, f_hz, channels, data_re, data_im, noise):
    station = int(np.argmax([np.max(np.abs(np.asarray(r))) for r in data_re])) + 1
    return np.array([1.0, float(channels[station - 1][1] + 1), 0.1 * float(K[0][0])])
