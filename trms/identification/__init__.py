"""System identification as the thesis did it (ch. 3 and 5), with no MuJoCo dependency.

Modules
-------
spectral     Welch PSD/CSD, coherence (eq. 3.1), H1 frequency response, modes, attenuation in dB
data         input/output extraction from a Record (deviations) or arrays; lag matrices
dataset      several experiments of one system (each from rest), fitted together by ARX/ARMAX
polynomial   the polynomial model object (ARX/ARMAX/OE/BJ): prediction, simulation, LTI views, modes
linear       ARX by least squares, ARMAX by the prediction-error method
orders       order selection by information criterion or validation loss: ARX, ARMAX, OE, BJ and n4sid
pem          the prediction-error engine shared by ARMAX, OE and BJ (damped Gauss-Newton)
oe_bj        output-error and Box-Jenkins models (MATLAB oe, bj)
subspace     n4sid: subspace (PO-MOESP or CVA) identification of MIMO state-space models, refined by the simulation
ss_predictor the innovations predictor, its analytic gradient and the prediction-error search of ssest and n4sid
continuous   continuous-time transfer functions and process models (tfest, procest), delay estimated
ssest        state-space innovations models by the prediction-error method, started from n4sid
frequency    frequency response with confidence bands from the parameter covariance
mimo_pem     MIMO ARX (least squares) and MIMO ARMAX with diagonal C (prediction error), all inputs at once
mimo         one-input-at-a-time MIMO identification with coherence-based coupling (ch. 3.4)
validation   fit %, residual and Billings-Voon correlation tests, OSA/MPO comparisons
rbf          Gaussian RBF NARX models with OLS (error-reduction ratio) centre selection
frols        polynomial NARX models by forward regression OLS (FROLS), term by term
recursive    online ARX (recursive least squares) and ARMAX (RELS) with exponential forgetting
nonparametric spa (Blackman-Tukey), etfe (DFT ratio) and impulseest (FIR, TC-kernel regularised)

The excitation signals (PRBS, multisine, doublet ...) are :mod:`trms.signals`; a mode (frequency, damping)
is :class:`trms.modes.Mode`.
"""

from trms.identification.bootstrap import Bootstrap, bootstrap
from trms.identification.continuous import ContinuousModel, procest, tfest
from trms.identification.data import SisoData, detrend, siso_data
from trms.identification.dataset import Dataset
from trms.identification.frequency import (
    FrequencyResponse,
    frequency_response,
    plot_frequency_response,
    response_from_samples,
)
from trms.identification.frols import PolynomialNarx, narx_poly
from trms.identification.linear import armax, arx
from trms.identification.mimo import MimoIdentification, identify_mimo
from trms.identification.mimo_pem import MimoPolynomialModel, armax_mimo, arx_mimo
from trms.identification.nonparametric import ImpulseResponse, etfe, impulseest, spa
from trms.identification.oe_bj import LocalMinimumWarning, bj, oe
from trms.identification.ols import ols_select
from trms.identification.orders import OrderSelection, SubspaceSelection, select_n4sid_order, select_order
from trms.identification.polynomial import PolynomialModel
from trms.identification.rbf import DegenerateWidthWarning, ExtrapolationWarning, NarxRbf, narx_rbf
from trms.identification.recursive import RecursiveEstimator, RecursiveResult, recursive_armax, recursive_arx
from trms.identification.spectral import Peak, attenuation_db, coherence, csd, find_modes, psd, transfer_estimate
from trms.identification.ssest import PemStateSpace, ssest, state_space_residuals
from trms.identification.subspace import (
    SubspaceModel,
    SubspaceOrder,
    UnstableModelWarning,
    n4sid,
    subspace_singular_values,
)
from trms.identification.validation import (
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
    "Bootstrap",
    "bootstrap",
    "response_from_samples",
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
    "NarxRbf",
    "OrderSelection",
    "SubspaceSelection",
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
    "etfe",
    "find_modes",
    "fit_percent",
    "frequency_response",
    "identify_mimo",
    "impulseest",
    "independence_test",
    "n4sid",
    "narx_rbf",
    "oe",
    "ols_select",
    "narx_poly",
    "PolynomialNarx",
    "plot_frequency_response",
    "psd",
    "recursive_armax",
    "recursive_arx",
    "residual_tests",
    "residual_variance",
    "select_order",
    "select_n4sid_order",
    "spa",
    "siso_data",
    "detrend",
    "subspace_singular_values",
    "transfer_estimate",
    "whiteness_test",
    "PemStateSpace",
    "ssest",
    "state_space_residuals",
    "ContinuousModel",
    "procest",
    "tfest",
    "MimoPolynomialModel",
    "armax_mimo",
    "arx_mimo",
]
