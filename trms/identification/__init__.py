"""System identification as the thesis did it (ch. 3 and 5), with no MuJoCo dependency.

Modules
-------
signals      excitation signals: PRBS, uniform noise, 3211 multistep, doublet, square wave
spectral     Welch PSD/CSD, coherence (eq. 3.1), H1 frequency response, modes, attenuation in dB
data         input/output extraction from a Record (deviations) or arrays; lag matrices
polynomial   the ARX/ARMAX model object: prediction, simulation, LTI views, modes
linear       ARX by least squares, ARMAX by the prediction-error method, order selection
mimo         one-input-at-a-time MIMO identification with coherence-based coupling (ch. 3.4)
validation   fit %, residual and Billings-Voon correlation tests, OSA/MPO comparisons
rbf          Gaussian RBF NARX models with OLS (error-reduction ratio) centre selection
"""

from .data import SisoData, detrend, siso_data
from .linear import OrderSelection, armax, arx, select_order
from .mimo import MimoIdentification, identify_mimo
from .polynomial import Mode, PolynomialModel
from .rbf import NarxRbf, narx_rbf, ols_select
from .signals import doublet, multistep_3211, prbs, square_wave, uniform_noise
from .spectral import Peak, attenuation_db, coherence, csd, find_modes, psd, transfer_estimate
from .validation import (
    Comparison,
    CorrelationTest,
    billings_voon_tests,
    compare,
    fit_percent,
    independence_test,
    residual_tests,
    whiteness_test,
)

__all__ = [
    "Comparison",
    "CorrelationTest",
    "MimoIdentification",
    "Mode",
    "NarxRbf",
    "OrderSelection",
    "Peak",
    "PolynomialModel",
    "SisoData",
    "armax",
    "arx",
    "attenuation_db",
    "billings_voon_tests",
    "coherence",
    "compare",
    "csd",
    "doublet",
    "find_modes",
    "fit_percent",
    "identify_mimo",
    "independence_test",
    "multistep_3211",
    "narx_rbf",
    "ols_select",
    "prbs",
    "psd",
    "residual_tests",
    "select_order",
    "siso_data",
    "detrend",
    "square_wave",
    "transfer_estimate",
    "uniform_noise",
    "whiteness_test",
]
