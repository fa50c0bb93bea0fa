"""System identification as the thesis did it (ch. 3 and 5), with no MuJoCo dependency.

Modules
-------
signals      excitation signals: maximum-length PRBS, random binary, uniform noise, 3211 multistep, doublet,
             square wave, multisine (Schroeder or random phases)
spectral     Welch PSD/CSD, coherence (eq. 3.1), H1 frequency response, modes, attenuation in dB
data         input/output extraction from a Record (deviations) or arrays; lag matrices
dataset      several experiments of one system (each from rest), fitted together by ARX/ARMAX
polynomial   the polynomial model object (ARX/ARMAX/OE/BJ): prediction, simulation, LTI views, modes
linear       ARX by least squares, ARMAX by the prediction-error method, order selection
pem          the prediction-error engine shared by ARMAX, OE and BJ (damped Gauss-Newton)
oe_bj        output-error and Box-Jenkins models (MATLAB oe, bj)
subspace     n4sid: subspace (PO-MOESP) identification of MIMO state-space models
frequency    frequency response with confidence bands from the parameter covariance
mimo         one-input-at-a-time MIMO identification with coherence-based coupling (ch. 3.4)
validation   fit %, residual and Billings-Voon correlation tests, OSA/MPO comparisons
rbf          Gaussian RBF NARX models with OLS (error-reduction ratio) centre selection
recursive    online ARX (recursive least squares) and ARMAX (RELS) with exponential forgetting
nonparametric spa (Blackman-Tukey), etfe (DFT ratio) and impulseest (FIR, TC-kernel regularised)
"""

from .data import SisoData, detrend, siso_data
from .dataset import Dataset
from .frequency import FrequencyResponse, frequency_response, plot_frequency_response
from .linear import OrderSelection, armax, arx, select_order
from .mimo import MimoIdentification, identify_mimo
from .nonparametric import ImpulseResponse, etfe, impulseest, spa
from .oe_bj import LocalMinimumWarning, bj, oe
from .polynomial import Mode, PolynomialModel
from .rbf import DegenerateWidthWarning, ExtrapolationWarning, NarxRbf, narx_rbf, ols_select
from .recursive import RecursiveEstimator, RecursiveResult, recursive_armax, recursive_arx
from .signals import Multisine, doublet, multisine, multistep_3211, prbs, random_binary, square_wave, uniform_noise
from .spectral import Peak, attenuation_db, coherence, csd, find_modes, psd, transfer_estimate
from .subspace import SubspaceModel, SubspaceOrder, UnstableModelWarning, n4sid, subspace_singular_values
from .validation import (
    Comparison,
    CorrelationTest,
    billings_voon_tests,
    compare,
    fit_percent,
    independence_test,
    residual_tests,
    residual_variance,
    whiteness_test,
)

__all__ = [
    "Dataset",
    "UnstableModelWarning",
    "Comparison",
    "DegenerateWidthWarning",
    "ExtrapolationWarning",
    "FrequencyResponse",
    "ImpulseResponse",
    "LocalMinimumWarning",
    "CorrelationTest",
    "MimoIdentification",
    "Mode",
    "Multisine",
    "NarxRbf",
    "OrderSelection",
    "Peak",
    "PolynomialModel",
    "RecursiveEstimator",
    "RecursiveResult",
    "SisoData",
    "SubspaceModel",
    "SubspaceOrder",
    "armax",
    "arx",
    "attenuation_db",
    "billings_voon_tests",
    "bj",
    "coherence",
    "compare",
    "csd",
    "doublet",
    "etfe",
    "find_modes",
    "fit_percent",
    "frequency_response",
    "identify_mimo",
    "impulseest",
    "independence_test",
    "multisine",
    "multistep_3211",
    "n4sid",
    "narx_rbf",
    "oe",
    "ols_select",
    "plot_frequency_response",
    "prbs",
    "psd",
    "random_binary",
    "recursive_armax",
    "recursive_arx",
    "residual_tests",
    "residual_variance",
    "select_order",
    "spa",
    "siso_data",
    "detrend",
    "square_wave",
    "subspace_singular_values",
    "transfer_estimate",
    "uniform_noise",
    "whiteness_test",
]
