"""fsi.study: parameter studies over `fsi run` (`fsi study`, tools/fsi_study.py; docs/studies.md).

- ``spec``: the study file, parameters, combinations, run names and hashes;
- ``runner``: running the cases here (local executor); ``executors``: on a Dask cluster;
- ``metrics`` / ``forms`` / ``analysis``: metrics against references, tables;
- ``plots``: PNGs; ``table.load_study``: one table of a study folder; ``cli.main``: the command line.

The names below are the ones tools/fsi_study.py always had (tests and scripts import them).
"""
from .analysis import (BASE_COLUMNS, analyse, outcome_counts, print_counts, read_probes, reference_series,
                       run_metrics, stability_table, write_tables)
from .forms import SCALAR_FORMS, SERIES_FORMS, added_mass_beta_c, evaluate, namespace, sdof_exact
from .metrics import (compare, compare_values, fft_frequency, phase_lag, signal_metrics, time_mean,
                      zero_crossing_frequency)
from .runner import REASON_KINDS, Runner, classify, descendants, kill_tree, log_tail
from .spec import (BisectionSource, GridSource, Study, build_sources, expand, flatten, load_study_file,
                   reference_spec)
from .table import load_study
from .util import (ABBREV, FINISHED, REPO, STUDY_KEYS, StudyError, clean_value, finite, fmt_num, read_json,
                   set_value, write_json)

__all__ = [n for n in dir() if not n.startswith("_")]
