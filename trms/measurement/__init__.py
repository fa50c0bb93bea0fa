"""Measuring the rig the thesis's way, below both the calibration and the experiments that use it.

protocol        the thesis's identification protocols run on twins (PRBS, hover, steps) and the ARMAX read off them
spectra         Welch PSD and coherence of protocol records as the thesis measured them, and their peaks
step_response   step responses read as the thesis read them: dead time, time constant, crossings, fit
"""
