"""fsi: Python side of the fsi-cosim co-simulation framework.

- ``fsi.server``: write an external solid in a few lines (the protocol, errors, sessions,
  checkpoints and the launcher's command line are handled for you).
- ``fsi.run(scene, out, set={...})`` runs ``fsi run``; ``fsi.load(out)`` reads a run folder.
- ``fsi.load_study(folder)``: one table (pandas, else numpy arrays) of a study folder (``fsi.study``).
- ``fsi.stats``: mean, amplitude, frequency, phase lag, settling time, Turek-Hron midrange.
- ``fsi.vtk``: read the VTK files of a run (binary or ascii) with numpy alone.
- ``fsi.plots``: legends in numeric order, titles that fit, medians of repeated times.
- ``fsi.interpreter``: re-run a script with the build's Python when a module is missing.
- ``fsi.v1.coupling_pb2``: the generated protocol module.

Importing ``fsi`` imports nothing heavy: each submodule loads on first use.
"""
import importlib

__version__ = "0.1.0"
PROTOCOL_VERSION = 1

__all__ = ["run", "load", "RunError", "Run", "load_study", "server", "stats", "results", "plots", "vtk", "interpreter", "v1", "__version__", "PROTOCOL_VERSION"]

_LAZY = {"run": "results", "load": "results", "RunError": "results", "Run": "results",
         "load_study": "study"}


def __getattr__(name):
    if name in _LAZY:
        return getattr(importlib.import_module(f"fsi.{_LAZY[name]}"), name)
    if name in ("server", "stats", "results", "plots", "vtk", "interpreter", "v1"):
        return importlib.import_module(f"fsi.{name}")
    raise AttributeError(f"module 'fsi' has no attribute '{name}'")
