"""ex06, a submission that does not solve: "none" for every sweep, nothing anywhere."""
import numpy as np


def sideband_frequencies(natural_frequencies_hz, speed_hz, orders, f_min, f_max):
    return np.array([])


def sideband_size(freq_hz, re, im, f_candidate, half_width_hz):
    return float(half_width_hz)


def classify(freq_hz, re, im, natural_frequencies_hz, speed_hz, noise):
    return 0
