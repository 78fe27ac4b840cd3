"""Metrics of probe histories: the study tool uses fsi.stats (one statistics module for the
study tool, the benchmark scripts and notebooks); this module keeps the names the study code
and tools/fsi_study.py always had. Tested against closed forms in tests/study/test_metrics.py
and tests of fsi.stats."""
from fsi import stats as _stats
from fsi.stats import (compare, fft_frequency, phase_lag, signal_metrics, time_mean,  # noqa: F401
                       zero_crossing_frequency)
from fsi.stats import select_window as _window  # noqa: F401

from .util import StudyError


def compare_values(t, y, values, window=None, steady_fraction=0.1):
    """Errors against published values {steady, mean, amplitude, frequency, final} (fsi.stats);
    an unknown quantity is a StudyError (a bad study file)."""
    try:
        return _stats.compare_values(t, y, values, window, steady_fraction)
    except _stats.StatsError as e:
        raise StudyError(str(e)) from None
