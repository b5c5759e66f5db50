"""Small signal-processing helpers shared by tests, analysis and evaluation."""

from __future__ import annotations

import numpy as np


def zero_crossing_period(t: np.ndarray, y: np.ndarray) -> float:
    """Mean period from upward zero crossings of y - mean(y) (linear interpolation)."""
    s = np.asarray(y, float) - np.mean(y)
    i = np.where((s[:-1] < 0) & (s[1:] >= 0))[0]
    if len(i) < 2:
        return float("nan")
    tc = t[i] - s[i] * (t[i + 1] - t[i]) / (s[i + 1] - s[i])
    return float(np.mean(np.diff(tc)))


def dominant_period(t: np.ndarray, y: np.ndarray, fmin: float = 0.0, fmax: float = np.inf) -> float:
    """Period of the largest spectral peak of y in [fmin, fmax] Hz (zero-padded FFT, parabolic
    refinement of the peak)."""
    dt = float(t[1] - t[0])
    s = (np.asarray(y, float) - np.mean(y)) * np.hanning(len(y))
    nfft = 16 * len(s)
    spec = np.abs(np.fft.rfft(s, nfft))
    f = np.fft.rfftfreq(nfft, dt)
    band = np.where((f >= fmin) & (f <= fmax))[0]
    k = band[np.argmax(spec[band])]
    if 0 < k < len(spec) - 1:
        a, b, c = np.log(spec[k - 1:k + 2] + 1e-300)
        k = k + 0.5 * (a - c) / (a - 2 * b + c)
    return float(1.0 / (k * (f[1] - f[0])))
