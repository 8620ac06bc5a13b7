"""ex02 submission that solves nothing: random numbers of the right kinds, a random diagonal Delta, a
random stable LFT padded to 50 states (never computed)."""
import numpy as np

_rng = np.random.default_rng(12345)


def mu_full(M_re, M_im):
    return float(_rng.uniform(0.5, 10.0))


def mu_scalar_blocks_upper(M_re, M_im):
    return float(_rng.uniform(0.5, 10.0))


def destabilizing_delta(M_re, M_im):
    n = len(M_re)
    return np.diag(_rng.standard_normal(n)), np.diag(_rng.standard_normal(n))


def uncertain_spring_lft(m, k, rel):
    n = 50
    return -np.eye(n), _rng.standard_normal((n, 2)), _rng.standard_normal((2, n)), np.zeros((2, 2))


def mu_peak(M_re, M_im):
    return float(_rng.uniform(0.5, 10.0))
