"""Rocking structures reduced to the parameters the solvers need."""

from .block import Block, frequency_parameter, restitution_housner

__all__ = ["Block", "frequency_parameter", "restitution_housner"]
