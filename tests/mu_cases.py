"""Random test matrices and AB13MD-compatible block structures, shared by the mu tests."""
import numpy as np

from mutext.mu import Block, BlockStructure

#: the block kinds SLICOT AB13MD takes: 1 x 1 real, complex 1 x 1 and square full complex 2 x 2
_KINDS = {"real": (Block.real, 1, 1), "c1": (lambda: Block.full(1), 1, 2), "full2": (lambda: Block.full(2), 2, 2)}


def crandn(rng, *shape):
    return rng.standard_normal(shape) + 1j * rng.standard_normal(shape)


def ab13md_structure(kinds):
    """The structure of the given kinds ("real", "c1", "full2") and its arguments ``nblock``,
    ``itype`` for slycot.ab13md."""
    made = [_KINDS[k] for k in kinds]
    return (BlockStructure([make() for make, _, _ in made]), np.array([n for _, n, _ in made]),
            np.array([t for _, _, t in made]))
