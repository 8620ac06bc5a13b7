"""ex08, a submission that does not solve: a zero plant, no controller, the ends of the bracket, zeros
for the fit with the grid's ends as the band."""
import numpy as np


def mbi_plant(rig, Wz):
    return np.zeros((1, 1)), np.zeros((1, 4)), np.zeros((4, 1)), np.zeros((4, 4))


def synthesize(rig, Wz, omega):
    return np.zeros((1, 1)), np.zeros((1, 1)), np.zeros((1, 1)), np.zeros((1, 1))


def smallest_wz(rig, wz_low, wz_high, omega):
    return float(wz_high)


def read_controller(rig, Wz, K, omega):
    return np.array([0.0, 0.0, 0.0, omega[0], omega[-1]])
