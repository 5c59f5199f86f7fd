"""2D Gaussians fitted to sampled positions, and weighted mixtures of them (QSR paper, Fig. 5)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from conceptual_map.qsr.errors import QsrError

_JITTER = 1e-6  # m^2 added to the covariance diagonal so a degenerate fit stays invertible


@dataclass(frozen=True)
class Gaussian2D:
    """A bivariate normal: `mean` (2,), `cov` (2, 2)."""

    mean: np.ndarray
    cov: np.ndarray

    def pdf(self, points: np.ndarray) -> np.ndarray:
        """Density at points (N, 2)."""
        inv = np.linalg.inv(self.cov)
        d = np.asarray(points, dtype=float) - self.mean
        mahal = np.einsum("ni,ij,nj->n", d, inv, d)
        return np.exp(-0.5 * mahal) / (2.0 * np.pi * np.sqrt(np.linalg.det(self.cov)))


def fit_gaussian(samples: np.ndarray) -> Gaussian2D:
    """Maximum-likelihood mean and (unbiased) covariance of samples (N >= 2, 2)."""
    samples = np.asarray(samples, dtype=float)
    if samples.ndim != 2 or samples.shape[1] != 2 or samples.shape[0] < 2:
        raise QsrError(f"need at least two 2D samples to fit a Gaussian, got {samples.shape}")
    cov = np.cov(samples, rowvar=False) + _JITTER * np.eye(2)
    return Gaussian2D(samples.mean(axis=0), cov)


@dataclass(frozen=True)
class GaussianMixture:
    """Components with weights summing to 1; `sources[k]` says where component k came from."""

    weights: np.ndarray
    components: tuple[Gaussian2D, ...]
    sources: tuple[str, ...]

    def __post_init__(self) -> None:
        if len(self.components) != len(self.weights) or len(self.sources) != len(self.weights):
            raise QsrError("a mixture needs one weight and one source per component")

    @classmethod
    def from_weighted(cls, parts: list[tuple[float, Gaussian2D, str]]) -> GaussianMixture:
        """Normalise the weights of (weight, component, source) triples (total must be > 0)."""
        weights = np.array([w for w, _, _ in parts], dtype=float)
        if weights.size == 0 or weights.sum() <= 0.0 or np.any(weights < 0.0):
            raise QsrError("a mixture needs at least one component with positive weight")
        comps = tuple(g for _, g, _ in parts)
        return cls(weights / weights.sum(), comps, tuple(s for _, _, s in parts))

    def __len__(self) -> int:
        return len(self.components)

    def pdf(self, points: np.ndarray) -> np.ndarray:
        """Mixture density at points (N, 2), one vectorised pass over all components."""
        points = np.asarray(points, dtype=float)
        means = np.stack([g.mean for g in self.components])  # (K, 2)
        covs = np.stack([g.cov for g in self.components])  # (K, 2, 2)
        inv = np.linalg.inv(covs)
        norm = self.weights / (2.0 * np.pi * np.sqrt(np.linalg.det(covs)))
        d = points[None, :, :] - means[:, None, :]  # (K, N, 2)
        mahal = np.einsum("kni,kij,knj->kn", d, inv, d)
        return norm @ np.exp(-0.5 * mahal)

    def sample(self, n: int, rng: np.random.Generator) -> np.ndarray:
        """n points (n, 2) drawn from the mixture."""
        which = rng.choice(len(self), size=n, p=self.weights)
        out = np.empty((n, 2))
        for k, g in enumerate(self.components):
            idx = np.flatnonzero(which == k)
            out[idx] = rng.multivariate_normal(g.mean, g.cov, size=idx.size)
        return out
