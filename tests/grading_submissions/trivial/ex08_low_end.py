"""ex08, a submission that does not solve: the lower end of the bracket for (c), the other answers left
out."""
import numpy as np


def mbi_plant(rig, Wz):
    raise NotImplementedError


def synthesize(rig, Wz, omega):
    raise NotImplementedError


def smallest_wz(rig, wz_low, wz_high, omega):
    return float(wz_low)


def read_controller(rig, Wz, K, omega):
    raise NotImplementedError
