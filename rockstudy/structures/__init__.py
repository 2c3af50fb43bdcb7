"""Rocking structures reduced to the parameters the solvers need (paper [003])."""

from .block import (
    Block,
    block_parameters,
    frequency_parameter,
    restitution_housner,
    uplift_acceleration,
    uplift_acceleration_block,
)
from .equivalent import (
    Arch,
    AsymmetricFrame,
    ConicalShell,
    PointMassStrut,
    RockingWall,
    SymmetricFrame,
    restitution_symmetric_body,
)
from .isolated import IsolatedBlock, isolated_restitution
from .mechanism import EquivalentBlock, Mechanism, RockingParameters
from .stacked import StackedBlocks

__all__ = [
    "Arch",
    "AsymmetricFrame",
    "Block",
    "ConicalShell",
    "EquivalentBlock",
    "IsolatedBlock",
    "Mechanism",
    "PointMassStrut",
    "RockingParameters",
    "RockingWall",
    "StackedBlocks",
    "SymmetricFrame",
    "block_parameters",
    "frequency_parameter",
    "isolated_restitution",
    "restitution_housner",
    "restitution_symmetric_body",
    "uplift_acceleration",
    "uplift_acceleration_block",
]
