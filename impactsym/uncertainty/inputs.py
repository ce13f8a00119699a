"""Uncertain inputs: distributions (normal, uniform, triangular, a two-way choice) and their Gaussian copula.

An `Input` is an uncertain leaf of a scene (path, kind, parameters in scene
units). Draws start as correlated standard-normal scores (Cholesky factor of
the correlation matrix) and are mapped to each input's distribution by its
inverse CDF (scipy.special's ndtr and ndtri: the ``uncertainty`` extra).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = ["CHOICE", "Input", "correlation_matrix", "cholesky"]

#: The kind of a choice between 0 and 1 (a run-out wheel locked or rolling):
#: params (probability of 1,).
CHOICE = "choice"


@dataclass(frozen=True)
class Input:
    """An uncertain leaf: its path, distribution kind and parameters (scene units);
    kind CHOICE: 1.0 with probability params[0], else 0.0."""

    path: str
    kind: str
    params: tuple[float, ...]

    @property
    def nominal(self) -> float:
        """Mean (normal), midpoint (uniform) or mode (triangular, choice)."""
        p = self.params
        if self.kind == CHOICE:
            return 1.0 if p[0] > 0.5 else 0.0
        return {"normal": p[0], "uniform": (p[0] + p[1]) / 2}.get(self.kind, p[1])

    @property
    def discrete(self) -> bool:
        """A choice between two values (no derivative: the linear method leaves it out)."""
        return self.kind == CHOICE

    @property
    def sd(self) -> float:
        """The distribution's standard deviation."""
        p = self.params
        if self.kind == "normal":
            return p[1]
        if self.kind == "uniform":
            return (p[1] - p[0]) / math.sqrt(12.0)
        if self.kind == CHOICE:
            return math.sqrt(p[0] * (1.0 - p[0]))
        a, c, b = p
        return math.sqrt((a * a + b * b + c * c - a * b - a * c - b * c) / 18.0)

    def from_scores(self, z: np.ndarray, in_place: bool = False) -> np.ndarray:
        """Values with normal scores `z` (inverse CDF of Φ(z)); `in_place`:
        a normal input's values are written over `z` (the same numbers)."""
        if self.kind == "normal":
            if in_place:
                z *= self.params[1]
                z += self.params[0]
                return z
            return self.params[0] + self.params[1] * z
        return self.from_unit(_normal_cdf(z))

    def from_unit(self, u: np.ndarray) -> np.ndarray:
        """Values at probabilities `u` (inverse CDF)."""
        p = self.params
        if self.kind == "normal":
            return p[0] + p[1] * _normal_ppf(u)
        if self.kind == "uniform":
            return p[0] + (p[1] - p[0]) * u
        if self.kind == CHOICE:  # 1 with probability p[0], at the top of u (monotone in the score)
            return np.where(u > 1.0 - p[0], 1.0, 0.0)
        a, c, b = p
        left = (c - a) / (b - a)
        return np.where(
            u < left, a + np.sqrt(u * (b - a) * (c - a)), b - np.sqrt((1.0 - u) * (b - a) * (b - c))
        )


def _normal_cdf(z):
    from scipy.special import ndtr

    return ndtr(z)


def _normal_ppf(u):
    from scipy.special import ndtri

    return ndtri(u)


def correlation_matrix(inputs: tuple[Input, ...], correlations) -> np.ndarray:
    """The inputs' correlation matrix from ``(path_a, path_b, rho)`` pairs."""
    index = {x.path: i for i, x in enumerate(inputs)}
    corr = np.eye(len(inputs))
    for a, b, rho in correlations:
        corr[index[a], index[b]] = corr[index[b], index[a]] = rho
    return corr


def cholesky(corr: np.ndarray) -> np.ndarray:
    """A factor L with L Lᵀ = corr (positive semi-definite: by eigenvalues)."""
    try:
        return np.linalg.cholesky(corr)
    except np.linalg.LinAlgError:
        values, vectors = np.linalg.eigh(corr)
        return vectors * np.sqrt(np.clip(values, 0.0, None))
