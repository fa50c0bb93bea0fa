"""Excitation signals for identification and validation (thesis ch. 3.2, 3.4, 5.4).

Every generator returns a 1-D float array of ``N = round(duration / sample_time)``
samples; sample ``k`` is held over ``[k Ts, (k + 1) Ts)`` (zero-order hold), which is the
input convention of :class:`trms.record.Record`.

What "bandwidth" means
----------------------
For the random signals (:func:`random_binary`, :func:`uniform_noise`) the bandwidth ``B`` (Hz) is
the *clock frequency* of the sequence: a new random level is drawn every ``1 / B``
seconds and held in between (at sample ``k`` the level index is ``floor(k Ts B)``, so a
clock period that is not a whole number of samples alternates between the two nearest
hold lengths and keeps the mean rate exactly ``B``). The power spectrum of such a held
random sequence is the ``sinc^2`` envelope

``S(f) ~ [sin(pi f / B) / (m sin(pi f Ts))]^2``  (``m = 1 / (B Ts)`` samples per level):

flat at low frequency, 3.9 dB down at ``B / 2`` and with its first null at ``B``. This
is how the thesis uses the word: its 5 Hz PRBS at 5 Hz sampling "excites 0-2.5 Hz"
(ch. 3.2.1) and its 2 Hz PRBS is chosen "to excite up to 1 Hz" (ch. 3.4.1). ``B`` may not
exceed the sample rate ``1 / Ts`` (one level per sample).

Two binary signals
------------------
* :func:`random_binary`: independent fair coin tosses held for a clock period. Its
  spectrum is the ``sinc^2`` envelope above *on average*; any one realisation scatters
  around it (a periodogram of independent levels has a chi-square spread), and its
  autocorrelation is only approximately a spike.
* :func:`prbs`: a true maximum-length sequence (``scipy.signal.max_len_seq``, MATLAB
  ``idinput(N, 'prbs', [0 B])``), deterministic. One period of ``L = 2^n - 1`` levels has
  the two-valued circular autocorrelation ``L`` at lag 0 and ``-1`` at every other lag, so
  its periodic spectrum is exactly flat: equal power ``(L + 1) / L^2`` (relative to the
  squared amplitude, per level) on every harmonic ``k / (L P Ts)``, ``k = 1 .. L - 1``, times
  the same ``sinc^2`` envelope of the hold; and only ``1 / L^2`` at DC. The band follows
  MATLAB: ``band = (0, B)`` with ``B`` a fraction of the Nyquist frequency, and the levels
  are held for the clock period ``P = 1 / B`` samples (a whole number), so the envelope
  ``|sin(pi f P Ts) / (P sin(pi f Ts))|^2`` is flat for ``B = 1``, 3.0 dB down at the band
  edge ``B`` times Nyquist for ``P = 2`` (tending to 3.9 dB for long clocks) and has its
  first null at ``2 B`` times Nyquist (the level rate ``1 / (P Ts)``), exactly as
  :func:`random_binary` with ``bandwidth = 2 B`` times Nyquist.

A periodic signal
-----------------
:func:`multisine` (MATLAB ``idinput(N, 'sine', band)``) is a sum of cosines of equal amplitude
on the FFT grid ``k / (P Ts)`` of its period of ``P`` samples, so the DFT of one period (or of
any whole number of periods) is exactly zero off the chosen lines: no leakage, and the ratio
of output and input DFTs is the frequency response at those lines once the transient has
died out. Its crest factor (peak over RMS) depends on the phases: aligned (zero) phases give
the worst, ``sqrt(2 K)`` for ``K`` lines; Schroeder's phases ``-pi k (k - 1) / K`` spread the
peaks out (about 1.7 for a flat band).

The deterministic signals (:func:`multistep_3211`, :func:`doublet`, :func:`square_wave`)
are defined by their step durations or period instead; their edges fall on the nearest
sample.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.signal

from trms.errors import InputError, check_choice, check_in_range, check_int, check_seed

__all__ = [
    "prbs",
    "random_binary",
    "uniform_noise",
    "multistep_3211",
    "doublet",
    "square_wave",
    "multisine",
    "Multisine",
    "PHASES",
    "sample_count",
    "make_rng",
]

#: Tolerance (in samples) when deciding on which sample an edge or clock tick falls.
_EDGE_TOL = 1e-9


def make_rng(seed: int | np.random.Generator | None) -> np.random.Generator:
    """Return a numpy Generator: ``seed`` itself if it is one, else ``default_rng(seed)``.

    Parameters
    ----------
    seed : int, numpy.random.Generator or None
        Seed (same seed, same bits) or a generator to draw from.

    Raises
    ------
    InputError
        A seed that is not a non-negative integer, a Generator or None (:func:`trms.errors.check_seed`).
    """
    return seed if isinstance(seed, np.random.Generator) else np.random.default_rng(check_seed("seed", seed))


def sample_count(duration: float, sample_time: float) -> int:
    """Number of samples ``N = round(duration / sample_time)`` of a signal, checked.

    Parameters
    ----------
    duration : float
        Signal length (s), > 0.
    sample_time : float
        Sample time ``Ts`` (s), > 0.

    Returns
    -------
    int
        ``N >= 1``.

    Raises
    ------
    InputError
        If either value is not a positive finite number or ``duration < Ts / 2``.
    """
    ts = check_in_range("sample_time", sample_time, 0.0, np.inf, unit=" s", low_open=True)
    dur = check_in_range("duration", duration, 0.0, np.inf, unit=" s", low_open=True)
    n = int(round(dur / ts))
    if n < 1:
        raise InputError(f"duration = {duration!r} s is shorter than one sample (sample_time = {ts} s)")
    return n


def _level_checks(amplitude: float, offset: float) -> tuple[float, float]:
    amp = check_in_range("amplitude", amplitude, 0.0, np.inf)
    off = check_in_range("offset", offset, -np.inf, np.inf)
    return amp, off


def _nyquist_band(band: tuple[float, float], pair: str) -> tuple[float, float]:
    """``band`` as ``(low, high)`` fractions of the Nyquist frequency, ``0 <= low <= high``, ``0 < high <= 1``."""
    try:
        low, high = (float(b) for b in band)
    except (TypeError, ValueError) as exc:
        raise InputError(f"band must be a pair {pair} of fractions of the Nyquist frequency, got {band!r}") from exc
    high = check_in_range("band upper edge", high, 0.0, 1.0, low_open=True)
    return check_in_range("band lower edge", low, 0.0, high), high


def _clock_index(n: int, sample_time: float, bandwidth: float) -> np.ndarray:
    """Level index ``floor(k Ts B)`` of each sample ``k`` for a clock of ``bandwidth`` Hz."""
    return np.floor(np.arange(n) * (sample_time * bandwidth) + _EDGE_TOL).astype(np.int64)


def _held_random(
    duration: float,
    sample_time: float,
    bandwidth: float,
    seed: int | np.random.Generator | None,
    draw: str,
) -> np.ndarray:
    """Random levels in [-1, 1] (``draw`` = "binary" or "uniform") held at a clock of ``bandwidth`` Hz."""
    n = sample_count(duration, sample_time)
    ts = float(sample_time)
    check_in_range("bandwidth", bandwidth, 0.0, 1.0 / ts, unit=" Hz", low_open=True)
    idx = _clock_index(n, ts, float(bandwidth))
    rng = make_rng(seed)
    n_levels = int(idx[-1]) + 1
    if draw == "binary":
        levels = np.where(rng.integers(0, 2, size=n_levels) == 1, 1.0, -1.0)
    else:
        levels = rng.uniform(-1.0, 1.0, size=n_levels)
    return levels[idx]


def random_binary(
    duration: float,
    sample_time: float,
    bandwidth: float,
    amplitude: float,
    offset: float = 0.0,
    seed: int | np.random.Generator | None = 0,
) -> np.ndarray:
    """Random binary signal: two levels ``offset +- amplitude`` at a clock of ``bandwidth`` Hz.

    Each level is an independent fair coin toss, drawn once per clock period ``1 / bandwidth``
    (see the module docstring for the spectrum: first null at ``bandwidth``, 3.9 dB down at
    ``bandwidth / 2``, on average over realisations). This is the signal the thesis's
    experiments were reproduced with; for a true maximum-length sequence see :func:`prbs`.

    Parameters
    ----------
    duration : float
        Length (s); ``N = round(duration / sample_time)`` samples.
    sample_time : float
        Sample time ``Ts`` (s).
    bandwidth : float
        Clock frequency ``B`` (Hz), in ``(0, 1 / Ts]``.
    amplitude : float
        Half the peak-to-peak swing (V), >= 0.
    offset : float
        Mid level (V).
    seed : int, numpy.random.Generator or None
        Randomness; the same seed gives the same sequence.

    Returns
    -------
    numpy.ndarray
        Shape ``(N,)``, values ``offset - amplitude`` or ``offset + amplitude``.

    Examples
    --------
    The thesis's 1-DOF excitation: 60 s of a 5 Hz binary signal at ``Ts = 0.2`` s (one level per sample).

    >>> u = random_binary(60.0, 0.2, 5.0, amplitude=0.5)
    >>> u.shape
    (300,)
    """
    amp, off = _level_checks(amplitude, offset)
    return off + amp * _held_random(duration, sample_time, bandwidth, seed, "binary")


#: Largest shift-register length of :func:`prbs` (``scipy.signal.max_len_seq`` has taps up to 32).
_MAX_MLS_ORDER = 32


def prbs(
    duration: float,
    sample_time: float,
    band: tuple[float, float] = (0.0, 1.0),
    amplitude: float = 1.0,
    offset: float = 0.0,
    order: int | None = None,
) -> np.ndarray:
    """Maximum-length pseudo-random binary sequence (MATLAB ``idinput(N, 'prbs', band)``).

    A shift register of ``order`` bits (``scipy.signal.max_len_seq``) gives ``L = 2^order - 1``
    levels per period, each held for the clock period ``P = 1 / B`` samples; the sequence
    repeats every ``L P`` samples. See the module docstring for its flat spectrum and
    two-valued autocorrelation. The sequence is deterministic (no seed).

    Parameters
    ----------
    duration : float
        Length (s); ``N = round(duration / sample_time)`` samples.
    sample_time : float
        Sample time ``Ts`` (s).
    band : (float, float)
        MATLAB's ``[0, B]``: the lower edge must be 0 (a binary sequence is low-pass) and
        ``B`` in ``(0, 1]`` is a fraction of the Nyquist frequency with ``1 / B`` a whole number
        of samples (the clock period ``P``). ``(0, 1)``: a new level every sample.
    amplitude : float
        Half the peak-to-peak swing (V), >= 0.
    offset : float
        Mid level (V).
    order : int, optional
        Register length ``n`` in ``[2, 32]``; default the smallest with one period
        ``(2^n - 1) P`` at least ``N`` samples (no repetition), as MATLAB chooses it. A smaller
        order gives a periodic signal (the periodogram of whole periods is then exactly flat).

    Returns
    -------
    numpy.ndarray
        Shape ``(N,)``, values ``offset - amplitude`` or ``offset + amplitude``.

    Raises
    ------
    InputError
        A band that is not ``(0, B)`` with ``1 / B`` a whole number, a bad order.

    Examples
    --------
    Two periods of a 31-level sequence held 2 samples (``band = (0, 0.5)``: up to half of Nyquist):

    >>> u = prbs(12.4, 0.1, band=(0.0, 0.5), order=5)
    >>> u.size, bool(np.all(u[:62] == u[62:]))
    (124, True)
    """
    amp, off = _level_checks(amplitude, offset)
    n = sample_count(duration, sample_time)
    low, b = _nyquist_band(band, "(0, B)")
    if low != 0.0:
        raise InputError(f"band = {band!r}: a PRBS is low-pass, its lower edge must be 0 (MATLAB's [0, B])")
    clock = int(round(1.0 / b))
    if abs(1.0 / b - clock) > 1e-9 * clock:
        raise InputError(f"band = {band!r}: the clock period 1 / B = {1.0 / b:g} samples must be a whole number")
    n_levels = -(-n // clock)
    if order is None:
        bits = max(2, int(np.ceil(np.log2(n_levels + 1))))
        if bits > _MAX_MLS_ORDER:
            raise InputError(
                f"{n} samples at a clock of {clock} samples need a register longer than {_MAX_MLS_ORDER} bits"
            )
    else:
        bits = check_int("order", order, 2, high=_MAX_MLS_ORDER)
    seq = scipy.signal.max_len_seq(bits, length=min(2**bits - 1, n_levels))[0]
    levels = np.resize(np.where(seq == 1, 1.0, -1.0), n_levels)
    return off + amp * np.repeat(levels, clock)[:n]


def uniform_noise(
    duration: float,
    sample_time: float,
    bandwidth: float,
    amplitude: float,
    offset: float = 0.0,
    seed: int | np.random.Generator | None = 0,
) -> np.ndarray:
    """Uniformly distributed noise on ``[offset - amplitude, offset + amplitude]``, band-limited by holding.

    A new independent uniform level is drawn every clock period ``1 / bandwidth`` and held,
    so the amplitude distribution stays exactly uniform (a linear low-pass filter would
    make it Gaussian-like) while the spectrum has the same ``sinc^2`` shape as :func:`random_binary`.
    The thesis (ch. 5.4) uses a 2 Hz band of this signal to expose nonlinearity that a
    two-level PRBS cannot.

    Parameters
    ----------
    duration : float
        Length (s).
    sample_time : float
        Sample time ``Ts`` (s).
    bandwidth : float
        Clock frequency ``B`` (Hz), in ``(0, 1 / Ts]``.
    amplitude : float
        Half-width of the uniform distribution (V), >= 0; the variance is ``amplitude**2 / 3``.
    offset : float
        Centre of the distribution (V).
    seed : int, numpy.random.Generator or None
        Randomness; the same seed gives the same sequence.

    Returns
    -------
    numpy.ndarray
        Shape ``(N,)``.
    """
    amp, off = _level_checks(amplitude, offset)
    return off + amp * _held_random(duration, sample_time, bandwidth, seed, "uniform")


def _pattern(
    sample_time: float,
    step_duration: float,
    units: tuple[int, ...],
    amplitude: float,
    offset: float,
    start: float,
    duration: float | None,
    what: str,
) -> np.ndarray:
    """Consecutive steps of ``units[i] * step_duration`` seconds at ``offset + amplitude``, ``offset - amplitude``, ...
    (alternating, starting high)."""
    amp, off = _level_checks(amplitude, offset)
    ts = check_in_range("sample_time", sample_time, 0.0, np.inf, unit=" s", low_open=True)
    step = check_in_range("step duration", step_duration, ts, np.inf, unit=" s")
    t0 = check_in_range("start", start, 0.0, np.inf, unit=" s")
    end = t0 + sum(units) * step
    if duration is None:
        duration = end
    n = sample_count(duration, ts)
    if n * ts < end - ts / 2:
        raise InputError(
            f"duration = {duration!r} s is shorter than the {what} (start {t0} s + {sum(units) * step} s = {end} s)"
        )
    edges = t0 + step * np.concatenate([[0], np.cumsum(units)])
    edge_samples = np.round(edges / ts + _EDGE_TOL).astype(np.int64)
    out = np.full(n, off)
    for i, (lo, hi) in enumerate(zip(edge_samples[:-1], edge_samples[1:])):
        out[lo:hi] = off + (-1.0) ** i * amp
    return out


def multistep_3211(
    sample_time: float,
    step_duration: float,
    amplitude: float,
    offset: float = 0.0,
    start: float = 0.0,
    duration: float | None = None,
) -> np.ndarray:
    """The 3211 multistep: steps of 3, 2, 1 and 1 ``step_duration`` with alternating sign.

    Levels are ``offset + amplitude`` for ``3 dt``, ``offset - amplitude`` for ``2 dt``,
    ``offset + amplitude`` for ``dt``, ``offset - amplitude`` for ``dt``, then ``offset``;
    ``offset`` before ``start``. Edges fall on the nearest sample.

    Parameters
    ----------
    sample_time : float
        Sample time ``Ts`` (s).
    step_duration : float
        The unit step length ``dt`` (s), >= ``Ts``.
    amplitude : float
        Step height from the offset (V), >= 0.
    offset : float
        Resting level (V).
    start : float
        Time of the first edge (s), >= 0.
    duration : float, optional
        Signal length (s), at least ``start + 7 dt``; default exactly ``start + 7 dt``.

    Returns
    -------
    numpy.ndarray
        Shape ``(round(duration / Ts),)``.
    """
    return _pattern(sample_time, step_duration, (3, 2, 1, 1), amplitude, offset, start, duration, "3211 multistep")


def doublet(
    sample_time: float,
    pulse_width: float,
    amplitude: float,
    offset: float = 0.0,
    start: float = 0.0,
    duration: float | None = None,
) -> np.ndarray:
    """A doublet: ``offset + amplitude`` for ``pulse_width``, then ``offset - amplitude`` for ``pulse_width``.

    Parameters
    ----------
    sample_time : float
        Sample time ``Ts`` (s).
    pulse_width : float
        Length of each half (s), >= ``Ts``.
    amplitude : float
        Pulse height from the offset (V), >= 0.
    offset : float
        Resting level (V), held before ``start`` and after the doublet.
    start : float
        Time of the first edge (s), >= 0.
    duration : float, optional
        Signal length (s), at least ``start + 2 pulse_width``; default exactly that.

    Returns
    -------
    numpy.ndarray
        Shape ``(round(duration / Ts),)``.
    """
    return _pattern(sample_time, pulse_width, (1, 1), amplitude, offset, start, duration, "doublet")


def square_wave(
    duration: float,
    sample_time: float,
    period: float,
    amplitude: float,
    offset: float = 0.0,
    start_high: bool = True,
) -> np.ndarray:
    """A square wave ``offset +- amplitude`` with 50 % duty cycle.

    Sample ``k`` is high when ``floor(2 k Ts / period)`` is even (odd if not ``start_high``),
    so each half period starts on the first sample at or after its edge.

    Parameters
    ----------
    duration : float
        Length (s).
    sample_time : float
        Sample time ``Ts`` (s).
    period : float
        Full period (s), >= ``2 Ts``.
    amplitude : float
        Half the peak-to-peak swing, >= 0 (V, or rad for a pitch command).
    offset : float
        Mid level.
    start_high : bool
        Begin with the high half.

    Returns
    -------
    numpy.ndarray
        Shape ``(N,)``.
    """
    amp, off = _level_checks(amplitude, offset)
    n = sample_count(duration, sample_time)
    ts = float(sample_time)
    check_in_range("period", period, 2.0 * ts, np.inf, unit=" s")
    half = _clock_index(n, ts, 2.0 / float(period))
    high = (half % 2 == 0) == bool(start_high)
    return off + amp * np.where(high, 1.0, -1.0)


#: Phase choices of :func:`multisine`.
PHASES = ("schroeder", "random", "zero")


@dataclass(frozen=True)
class Multisine:
    """A multisine and its design (what :func:`multisine` returns).

    Attributes
    ----------
    signal : numpy.ndarray
        The input (V), shape ``(N,)``.
    period : int
        Samples per period ``P``.
    lines : numpy.ndarray
        Excited DFT lines ``k`` of one period (int), shape ``(K,)``.
    frequency : numpy.ndarray
        Their frequencies ``k / (P Ts)`` (Hz).
    phases : numpy.ndarray
        Phase of each cosine (rad).
    crest_factor : float
        Peak of ``|signal - offset|`` over its RMS, over one period (samples, not the continuous curve).
    """

    signal: np.ndarray
    period: int
    lines: np.ndarray
    frequency: np.ndarray
    phases: np.ndarray
    crest_factor: float


def multisine(
    duration: float,
    sample_time: float,
    period: float | None = None,
    band: tuple[float, float] = (0.0, 1.0),
    amplitude: float = 1.0,
    offset: float = 0.0,
    phases: str = "schroeder",
    seed: int | np.random.Generator | None = 0,
    skip: int = 1,
) -> Multisine:
    """Periodic sum of equal-amplitude cosines on the FFT grid (MATLAB ``idinput(N, 'sine', band)``).

    ``u(t) = offset + s sum_k cos(2 pi k t / P + phi_k)``, the lines ``k`` every ``skip``-th
    line ``1 <= k < P / 2`` with ``2 k / P`` (the line's frequency as a fraction of Nyquist) in
    ``band``; ``s`` scales the peak of ``|u - offset|`` over a period to ``amplitude``.

    Parameters
    ----------
    duration : float
        Length (s); ``N = round(duration / sample_time)`` samples (whole periods for a leakage-free spectrum).
    sample_time : float
        Sample time ``Ts`` (s).
    period : float, optional
        Period (s), rounded to ``P`` samples, at most ``duration``; default ``duration`` (one period).
    band : (float, float)
        Lowest and highest line frequency as fractions of the Nyquist frequency, ``0 <= low < high <= 1``.
    amplitude : float
        Peak deviation from ``offset`` (V), >= 0.
    offset : float
        Mid level (V).
    phases : {"schroeder", "random", "zero"}
        Schroeder's ``-pi k (k - 1) / K`` (``k = 1 .. K`` along the lines, a low crest factor),
        independent uniform phases in ``[0, 2 pi)`` (seeded), or all zero (peak ``K`` at ``t = 0``).
    seed : int, numpy.random.Generator or None
        Randomness of ``"random"`` phases; the same seed gives the same signal.
    skip : int
        Use every ``skip``-th line of the band (``>= 1``), e.g. 2 leaves every other line free.

    Returns
    -------
    Multisine
        The signal with its lines, frequencies, phases and crest factor.

    Raises
    ------
    InputError
        A bad band, period or phase choice, or a band with no line in it.

    Examples
    --------
    One period of 100 samples, lines up to half of Nyquist:

    >>> ms = multisine(10.0, 0.1, band=(0.0, 0.5))
    >>> ms.lines[[0, -1]], float(np.max(np.abs(ms.signal))), bool(ms.crest_factor < 2.0)
    (array([ 1, 25]), 1.0, True)
    """
    amp, off = _level_checks(amplitude, offset)
    choice = check_choice("phases", phases, PHASES, error=InputError)
    n = sample_count(duration, sample_time)
    ts = float(sample_time)
    p = n if period is None else sample_count(period, ts)
    if p > n:
        raise InputError(f"period = {period!r} s is longer than duration = {duration!r} s")
    low, high = _nyquist_band(band, "(low, high)")
    if low == high:
        raise InputError(f"band = {band!r} is empty: the lower edge must be below the upper one")
    step = check_int("skip", skip, 1)
    k = np.arange(1, (p + 1) // 2)
    lines = k[(2.0 * k / p >= low - _EDGE_TOL) & (2.0 * k / p <= high + _EDGE_TOL)][::step]
    if lines.size == 0:
        raise InputError(f"band = {band!r} holds no line of a {p}-sample period (lines every {2.0 / p:g} of Nyquist)")
    if choice == "schroeder":
        j = np.arange(1, lines.size + 1)
        phi = -np.pi * j * (j - 1) / lines.size
    elif choice == "random":
        phi = make_rng(seed).uniform(0.0, 2.0 * np.pi, lines.size)
    else:
        phi = np.zeros(lines.size)
    spectrum = np.zeros(p // 2 + 1, complex)
    spectrum[lines] = 0.5 * p * np.exp(1j * phi)
    one = np.fft.irfft(spectrum, p)
    peak = float(np.max(np.abs(one)))
    crest = peak / float(np.sqrt(np.mean(one**2)))
    signal = off + amp / peak * np.resize(one, n)
    return Multisine(signal, p, lines, lines / (p * ts), phi, crest)
