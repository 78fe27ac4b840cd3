"""Run a script with a Python that has its modules, whichever `python3` comes first on PATH.

    import fsi.interpreter
    fsi.interpreter.require("numpy", "zmq", "google.protobuf")   # before importing them

When one of the modules is missing (e.g. a pyenv python3 first on PATH, without Debian's
python3-numpy, python3-zmq, ...), the script is started again with the interpreter the build
found, printing one line to stderr saying so. The interpreter is, in this order: $FSI_PYTHON,
FSI_PYTHON from build/CMakeCache.txt of the source tree this package belongs to, /usr/bin/python3.
If none of them differs from the running one (or the restarted script still misses a module),
the script goes on and the import fails as usual. Standard library only: importing this
module works with any Python 3.
"""
import importlib.util
import os
import sys

__all__ = ["require", "candidates", "missing"]

_GUARD = "FSI_PYTHON_REEXEC"
_REEXECUTED = False
_SOURCE = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def missing(modules):
    """The modules of the list that this interpreter cannot import."""
    out = []
    for name in modules:
        try:
            if importlib.util.find_spec(name) is None:
                out.append(name)
        except (ImportError, ValueError):
            out.append(name)
    return out


def _from_cmake_cache(source=_SOURCE):
    try:
        with open(os.path.join(source, "build", "CMakeCache.txt")) as fh:
            for line in fh:
                if line.startswith("FSI_PYTHON:"):
                    return line.split("=", 1)[1].strip() or None
    except OSError:
        pass
    return None


def candidates():
    """[(interpreter, where it comes from)] in the order they are tried."""
    out = []
    if os.environ.get("FSI_PYTHON"):
        out.append((os.environ["FSI_PYTHON"], "$FSI_PYTHON"))
    cached = _from_cmake_cache()
    if cached:
        out.append((cached, "FSI_PYTHON in build/CMakeCache.txt"))
    out.append(("/usr/bin/python3", "Debian's python3"))
    return out


def _same(a, b):
    # by path, not by file: a venv's bin/python3 links to the base interpreter, whose modules differ
    return os.path.normpath(os.path.abspath(a)) == os.path.normpath(os.path.abspath(b))


def require(*modules, script=None):
    """Make sure this interpreter can import every module; else re-run the script (default:
    sys.argv[0]) with the first candidate interpreter that is not this one. Returns only when
    the modules are importable (or no other interpreter can be tried)."""
    global _REEXECUTED
    if os.environ.pop(_GUARD, None):  # this process is the re-run: never again, but its children may
        _REEXECUTED = True
    absent = missing(modules)
    if not absent or _REEXECUTED:
        return
    if script is None:
        main = sys.modules.get("__main__")
        # only a script run as `python3 path/script.py` (not -c, -m or interactive) is re-run
        if getattr(main, "__spec__", None) is not None or not os.path.isfile(getattr(main, "__file__", "") or ""):
            return
        script = main.__file__
    script = os.path.abspath(script)
    name = os.path.basename(script)
    for exe, where in candidates():
        if not (os.path.isfile(exe) and os.access(exe, os.X_OK)) or _same(exe, sys.executable):
            continue
        print(f"{name}: {sys.executable} has no module {', '.join(absent)}; running with {exe} ({where})",
              file=sys.stderr, flush=True)
        env = dict(os.environ)
        env[_GUARD] = "1"
        os.execve(exe, [exe, script] + sys.argv[1:], env)
