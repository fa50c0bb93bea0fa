"""Angle encoders: quantisation to whole counts and optional electrical noise."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from trms.errors import InputError, check_in_range
from trms.twin.disturbances import NormalDraws, Normals

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
    _per_sample: tuple[np.ndarray, bool, float, float | list[float]] = field(init=False, repr=False, compare=False)

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
        object.__setattr__(self, "_per_sample", (std, bool(std.any()), self.resolution, std.tolist()))

    @property
    def noisy(self) -> bool:
        """Whether any angle gets noise."""
        return bool(np.any(np.asarray(self.noise_std) > 0))

    @property
    def resolution(self) -> float:
        """One count (rad); 0 when quantisation is off."""
        return 2 * np.pi / self.counts_per_rev if self.counts_per_rev else 0.0

    def measure(self, angle: np.ndarray, rng: Normals) -> np.ndarray:
        """The encoder reading (rad) of true angles (rad, any leading shape): noise, then rounding to a whole count.

        Examples
        --------
        >>> enc = Encoder(4096, 1e-3)
        >>> one = [enc.measure(np.array([0.1, -0.2]), np.random.default_rng(2)) for _ in range(2)]
        >>> both = enc.measure(np.array([[0.1, -0.2]] * 2), np.random.default_rng(2))  # the same draws
        >>> bool((both[0] == one[0]).all()), round(float(one[0][0]) / enc.resolution, 9).is_integer()
        (True, True)
        """
        y = np.asarray(angle, float)
        if y.ndim == 1 and y.size <= 4:  # one sample: plain floats, the same arithmetic, a few microseconds
            return self.measure_values(y.tolist(), rng)
        std, noisy, count, _ = self._per_sample
        if noisy:
            y = y + std * rng.standard_normal(y.shape)
        if count:
            y = np.rint(y / count) * count  # np.round's bits (half to even), without its wrapper
        return y

    def measure_values(self, angles: list[float], rng: Normals) -> np.ndarray:
        """:meth:`measure` of one sample's true angles given as plain floats (rad): the same draws and bits.

        Examples
        --------
        >>> enc = Encoder(4096, 1e-3)
        >>> a = enc.measure_values([0.1, -0.2], np.random.default_rng(5))
        >>> bool((a == enc.measure(np.array([0.1, -0.2]), np.random.default_rng(5))).all())
        True
        """
        _, noisy, count, scale = self._per_sample
        values = angles
        if noisy:
            w = rng.take(len(values)) if type(rng) is NormalDraws else rng.standard_normal(len(values)).tolist()
            if type(scale) is list:  # one std per angle
                values = [v + s * x for v, s, x in zip(values, scale, w)]
            else:
                values = [v + scale * x for v, x in zip(values, w)]
        if count and all(map(math.isfinite, values)):
            return np.array([_rint(v / count) * count for v in values])
        y = np.array(values, float)  # quantisation off, or a value not finite
        if count:
            y = np.rint(y / count) * count  # np.round's bits (half to even), without its wrapper
        return y


def _rint(x: float) -> float:
    """``np.rint`` of a finite float: the nearest whole number, half to even, a zero keeping its sign."""
    r = round(x)  # half to even
    return float(r) if r else math.copysign(0.0, x)
