"""Environmental disturbances and sensor models.

All randomness is drawn from the generator the env passes in (its seeded ``np_random``).
"""

from __future__ import annotations

import math

import numpy as np

from shipgym.scenarios.schema import CurrentConfig, SensorConfig

DEG = math.pi / 180.0


def current_velocity(config: CurrentConfig) -> tuple[float, float]:
    """Earth-frame current (Vcx, Vcy) [m/s] of a constant current flowing *to* direction_deg."""
    angle = config.direction_deg * DEG
    return config.speed * math.cos(angle), config.speed * math.sin(angle)


class SensorModel:
    """Heading and yaw-rate measurements: Gaussian noise, outliers, dropouts.

    * noise: ψ_m = ψ + N(0, σ_ψ²), r_m = r + N(0, σ_r²);
    * outliers (heading): with probability p per sample a spike of random sign and
      magnitude uniform in ``outlier_magnitude_deg`` (Liu et al. 2019 Case 3 — the paper's
      outlier figure is lost, the magnitudes are our assumption);
    * dropout: with probability p per sample the sensor repeats its previous value.
    """

    def __init__(self, config: SensorConfig) -> None:
        self.sigma_psi = config.heading_noise_deg * DEG
        self.sigma_r = config.yaw_rate_noise_deg_s * DEG
        self.p_outlier = config.outlier_probability
        self.outlier_range = (
            config.outlier_magnitude_deg[0] * DEG,
            config.outlier_magnitude_deg[1] * DEG,
        )
        self.p_dropout = config.dropout_probability
        self.ideal = (
            self.sigma_psi == 0
            and self.sigma_r == 0
            and self.p_outlier == 0
            and self.p_dropout == 0
        )
        self._last: tuple[float, float] | None = None

    def reset(self) -> None:
        self._last = None

    def measure(
        self, psi: np.ndarray, r: np.ndarray, rng: np.random.Generator
    ) -> tuple[np.ndarray, np.ndarray]:
        """Measured (ψ, r) for arrays of true samples (rad, rad/s)."""
        if self.ideal:
            return psi, r
        psi_m = psi.copy()
        r_m = r.copy()
        n = psi.shape[0]
        if self.sigma_psi > 0:
            psi_m += self.sigma_psi * rng.standard_normal(n)
        if self.sigma_r > 0:
            r_m += self.sigma_r * rng.standard_normal(n)
        if self.p_outlier > 0:
            hit = rng.random(n) < self.p_outlier
            k = int(hit.sum())
            if k:
                size = rng.uniform(*self.outlier_range, size=k)
                psi_m[hit] += np.where(rng.random(k) < 0.5, -size, size)
        if self.p_dropout > 0:
            drop = rng.random(n) < self.p_dropout
            for i in np.flatnonzero(drop):
                if i > 0:
                    psi_m[i], r_m[i] = psi_m[i - 1], r_m[i - 1]
                elif self._last is not None:
                    psi_m[i], r_m[i] = self._last
        self._last = (float(psi_m[-1]), float(r_m[-1]))
        return psi_m, r_m
