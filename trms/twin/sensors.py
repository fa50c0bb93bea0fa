"""Angle encoders: quantisation to whole counts and optional electrical noise."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from trms.errors import InputError, check_in_range

__all__ = ["DEFAULT_COUNTS_PER_REV", "Encoder"]

#: Default encoder resolution (counts per revolution). The thesis and Feedback's public material do not
#: give it; 4096 is a 1024-line incremental encoder read in quadrature, the common choice on rigs of
#: this class (the comparable Quanser Aero 2 uses 2880 on pitch and 4096 on yaw). One count is 1.53 mrad:
#: its quantisation noise variance (count^2 / 12 = 2.0e-7 rad^2) is below the residual variance the
#: thesis reports (Table 5.1: 8.9e-6 rad^2), as it must be.
DEFAULT_COUNTS_PER_REV = 4096


@dataclass(frozen=True)
class Encoder:
    """An angle encoder zeroed at the hover attitude.

    Parameters
    ----------
    counts_per_rev : int
        Resolution (counts per revolution), >= 4; 0 disables quantisation.
    noise_std : float or tuple of float
        Standard deviation of white noise added to the angle before quantisation (rad): one for every
        angle, or one per measured angle.
    """

    counts_per_rev: int = DEFAULT_COUNTS_PER_REV
    noise_std: float | tuple[float, ...] = 0.0
    _per_sample: tuple[np.ndarray, bool, float] = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        if (
            isinstance(self.counts_per_rev, bool)
            or int(self.counts_per_rev) != self.counts_per_rev
            or not (self.counts_per_rev == 0 or 4 <= self.counts_per_rev <= 2**31)
        ):
            raise InputError(f"counts_per_rev = {self.counts_per_rev!r} must be 0 (off) or an integer in [4, 2**31]")
        if isinstance(self.noise_std, (tuple, list, np.ndarray)):
            values = tuple(
                check_in_range("encoder noise_std", v, 0.0, 1.0, unit=" rad") for v in np.ravel(self.noise_std)
            )
            object.__setattr__(self, "noise_std", values)
        else:
            check_in_range("encoder noise_std", self.noise_std, 0.0, 1.0, unit=" rad")
        # What measure() reads every sample, computed once: the noise, whether there is any, one count (rad).
        std = np.asarray(self.noise_std)
        object.__setattr__(self, "_per_sample", (std, bool(std.any()), self.resolution))

    @property
    def noisy(self) -> bool:
        """Whether any angle gets noise."""
        return bool(np.any(np.asarray(self.noise_std) > 0))

    @property
    def resolution(self) -> float:
        """One count (rad); 0 when quantisation is off."""
        return 2 * np.pi / self.counts_per_rev if self.counts_per_rev else 0.0

    def measure(self, angle: np.ndarray, rng: np.random.Generator) -> np.ndarray:
        """The encoder reading (rad) of true angles (rad): noise, then rounding to a whole count."""
        y = np.asarray(angle, float)
        std, noisy, count = self._per_sample
        if noisy:
            y = y + std * rng.standard_normal(y.shape)
        if count:
            y = np.round(y / count) * count
        return y
