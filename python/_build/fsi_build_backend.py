"""PEP 517 build backend: setuptools, without anything to download.

pip builds in an isolated environment and installs the backend's requirements into it
from the package index; offline that fails. This backend requires nothing: it runs
setuptools' own backend (setuptools.build_meta) with the setuptools and wheel that are
already installed (Debian: python3-setuptools, python3-wheel), found on the interpreter's
system site-packages when the isolated environment hides them. So

    python3 -m venv --system-site-packages v && v/bin/pip install ./python

works with no network and no --no-build-isolation.
"""
import contextlib
import os
import site
import sys
import warnings


def _missing():
    missing = []
    for name in ("setuptools", "wheel"):  # setuptools' bdist_wheel needs wheel
        try:
            __import__(name)
        except ImportError:
            missing.append(name)
    return missing


def _setuptools():
    if _missing():
        # pip's isolated build environment removes the system site-packages from sys.path; an
        # interpreter of Debian's minor version (a pyenv or venv Python 3.11) can also use
        # Debian's own pure-Python setuptools and wheel.
        paths = list(site.getsitepackages([sys.base_prefix]))
        if sys.version_info[:2] == (3, 11):
            paths.append("/usr/lib/python3/dist-packages")
        for path in paths:
            if path not in sys.path and os.path.isdir(path):
                sys.path.append(path)
    missing = _missing()
    if missing:
        raise RuntimeError(
            f"building fsi needs {' and '.join(missing)} in the interpreter that runs pip ({sys.executable}, "
            f"Python {sys.version_info[0]}.{sys.version_info[1]}), and pip cannot download them here. Either "
            f"install them into it ({sys.executable} -m pip install {' '.join(missing)}, from a package index or "
            f"a local wheel), or make the venv from Debian's Python: /usr/bin/python3 -m venv "
            f"--system-site-packages VENV (with apt-get install python3-setuptools python3-wheel python3-venv)")
    import setuptools.build_meta as backend
    return backend


with warnings.catch_warnings():
    warnings.simplefilter("ignore")
    _backend = _setuptools()


def _no_requirements(config_settings=None):
    # setuptools would ask pip for 'wheel', which pip would try to download.
    return []


get_requires_for_build_wheel = _no_requirements
get_requires_for_build_sdist = _no_requirements
get_requires_for_build_editable = _no_requirements


def prepare_metadata_for_build_wheel(metadata_directory, config_settings=None):
    return _backend.prepare_metadata_for_build_wheel(metadata_directory, config_settings)


@contextlib.contextmanager
def _source_tree_recorded():
    """fsi/_source_tree.py in the wheel: the source tree it was built from, so that an installed
    fsi.run() finds that tree's build/bin/fsi (fsi.results.find_fsi)."""
    tree = os.path.dirname(os.path.abspath(os.getcwd()))
    path = os.path.join("fsi", "_source_tree.py")
    if not os.path.isfile(os.path.join(tree, "CMakeLists.txt")) or os.path.exists(path):
        yield
        return
    with open(path, "w") as f:
        f.write(f"# Written by the build backend: the source tree this package was built from.\nSOURCE_TREE = {tree!r}\n")
    try:
        yield
    finally:
        os.remove(path)


def build_wheel(wheel_directory, config_settings=None, metadata_directory=None):
    with _source_tree_recorded():
        return _backend.build_wheel(wheel_directory, config_settings, metadata_directory)


def build_sdist(sdist_directory, config_settings=None):
    return _backend.build_sdist(sdist_directory, config_settings)


def prepare_metadata_for_build_editable(metadata_directory, config_settings=None):
    return _backend.prepare_metadata_for_build_editable(metadata_directory, config_settings)


def build_editable(wheel_directory, config_settings=None, metadata_directory=None):
    return _backend.build_editable(wheel_directory, config_settings, metadata_directory)
