"""System identification as the thesis did it (ch. 3 and 5), with no MuJoCo dependency.

Modules
-------
signals     excitation signals: PRBS, uniform noise, 3211 multistep, doublet, square wave
"""

from .signals import doublet, multistep_3211, prbs, square_wave, uniform_noise

__all__ = ["doublet", "multistep_3211", "prbs", "square_wave", "uniform_noise"]
