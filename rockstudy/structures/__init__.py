"""Rocking structures reduced to the parameters the solvers need."""

from .block import Block, block_parameters, frequency_parameter, restitution_housner

__all__ = ["Block", "block_parameters", "frequency_parameter", "restitution_housner"]
